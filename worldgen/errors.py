"""The exceptions worldgen raises.

One root, :class:`WorldgenError`, so a caller (and the CLI) can catch every
mistake worldgen reports on purpose; narrow subclasses say which kind it is.
Anything else that escapes is a bug in worldgen, not a user's mistake.
"""

from __future__ import annotations

__all__ = [
    "WorldgenError",
    "ParameterError",
    "UnknownGeneratorError",
    "InfeasibleError",
    "SceneError",
    "OutputError",
    "MissingDependencyError",
    "SimulatorMissingError",
    "SimulatorError",
    "BagError",
    "CallOrderError",
    "require_optional",
    "optional_available",
    "quoted",
    "did_you_mean",
    "read_user_text",
    "QUOTE_LIMIT",
]

#: Longest quotation of a user's value in a message (characters), so one line stays readable.
QUOTE_LIMIT = 80


#: Exit statuses of the ``worldgen`` command, documented in docs/cli.md.
EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_NO_WORLD = 0, 1, 2, 3


class WorldgenError(Exception):
    """Root of every error worldgen raises for a user's input or request."""

    #: The command's exit status when this error ends it: a usage mistake.
    exit_status = EXIT_USAGE


class ParameterError(WorldgenError, ValueError):
    """A parameter is unknown, of the wrong type, or outside its allowed range."""


class UnknownGeneratorError(WorldgenError, LookupError):
    """No generator is registered under the requested name."""


class SceneError(WorldgenError, ValueError):
    """The scene asked for cannot exist: a shape of no size, a name used twice, a pose that is not finite."""


class InfeasibleError(WorldgenError):
    """No drivable world was found within the attempt budget.

    ``failures`` maps each feasibility check's name to how many draws failed it. Not a usage
    mistake: the request was well formed and no such world exists, so the command says so with
    its own exit status.
    """

    exit_status = EXIT_NO_WORLD

    def __init__(self, message: str, failures: dict[str, int] | None = None):
        super().__init__(message)
        self.failures = dict(failures or {})


class CallOrderError(WorldgenError, RuntimeError):
    """A method called before what it needs (``step()`` before ``reset()``)."""


class OutputError(WorldgenError, OSError):
    """The output folder cannot be written (missing permission, not a folder, ...)."""


class MissingDependencyError(WorldgenError, ImportError):
    """An optional dependency that a feature needs is not installed; the message says what to install.

    Raised only by :func:`require_optional`, the one way any room asks for an optional extra.
    """


class SimulatorMissingError(WorldgenError):
    """A simulator that a feature runs (Gazebo, for ``worldgen.sim``) is not installed; the message says where
    it was looked for and how to install it. A system program, not a Python extra, hence not a
    :class:`MissingDependencyError`."""


class SimulatorError(WorldgenError):
    """A simulator ran but did not do what was asked (a world that never came up, a service that did not
    answer), or printed what cannot be read."""

    exit_status = EXIT_FAILED


class BagError(WorldgenError, ValueError):
    """A recorded run (a bag) cannot be used: missing, not a bag, truncated, or holding no pose source.

    The reader library's own exceptions never reach a caller: they are re-raised as this, with the reason.
    """


def optional_available(module: str) -> bool:
    """True when the optional ``module`` can be imported; nothing is imported by asking. A module blocked in
    ``sys.modules`` (``sys.modules[name] = None``) or a broken entry counts as missing."""
    import importlib.util

    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def require_optional(module: str, extra: str, needs: str):
    """The imported ``module``, or :class:`MissingDependencyError` saying what to install, in one line.

    ``extra`` is the optional extra of worldgen's pyproject.toml that brings it; ``needs`` says who
    needs it (``"worldgen.envs needs Gymnasium"``). A module blocked in ``sys.modules`` counts as missing.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(f"{needs}, which is not installed: pip install 'worldgen[{extra}]'") from None


def quoted(value, limit: int = QUOTE_LIMIT) -> str:
    """``repr(value)`` for a message, cut to ``limit`` characters (saying how long it was) and on one line."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit - 3]}... ({len(text)} characters)"


def did_you_mean(name, allowed) -> str:
    """`` (did you mean 'x'?)`` when ``name`` is a likely typo of one of ``allowed`` (difflib), else ``""``.

    Goes right after the unknown name in a message, before the list of what is allowed.
    """
    from difflib import get_close_matches

    close = get_close_matches(str(name), [str(a) for a in allowed], n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


def read_user_text(path, what: str) -> str:
    """The UTF-8 text of the file a user named; every way it can fail is one :class:`ParameterError` line.

    ``what`` names the file's role in the message (e.g. ``recipe file``). A
    missing path, a directory, an unreadable file and bytes that are not UTF-8
    text (a binary file) each get their own message.
    """
    from pathlib import Path

    path = Path(path)
    if path.is_dir():
        raise ParameterError(f"{what} '{path}' is a directory, not a file")
    if not path.exists():
        raise ParameterError(f"{what} '{path}' does not exist")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ParameterError(f"{what} '{path}' cannot be read: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{what} '{path}' is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
                             "is it a binary file?") from None
    if "\x00" in text:
        raise ParameterError(f"{what} '{path}' is not text (it holds NUL bytes); is it a binary file?")
    return text
