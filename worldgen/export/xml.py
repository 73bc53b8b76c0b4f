"""What every XML exporter shares: safe parsing, the template skeletons, stable bytes.

Two ways to write: lxml elements (``sub``, ``to_bytes``), and :class:`XmlText`,
which writes the same pretty-printed bytes as text. Building hundreds of lxml
elements a world costs about 2.5 us each; the SDF and URDF bodies are written
as text (3 to 4 times faster) into a skeleton that lxml fills and serialises
(:func:`fill`). The tests hold the two to the same bytes.
"""

from __future__ import annotations

import re
from importlib import resources

from lxml import etree

from worldgen.errors import SceneError

__all__ = ["safe_parser", "parse_bytes", "load_template", "to_bytes", "sub", "XmlText", "escape_attr", "escape_text", "fill"]


def safe_parser() -> etree.XMLParser:
    """An lxml parser that resolves no entities and never touches the network."""
    return etree.XMLParser(resolve_entities=False, no_network=True, remove_blank_text=True, load_dtd=False, huge_tree=False)


def parse_bytes(data: bytes) -> etree._ElementTree:
    return etree.ElementTree(etree.fromstring(data, safe_parser()))


def load_template(name: str) -> etree._ElementTree:
    """A fresh copy of the skeleton ``templates/<name>``."""
    data = resources.files("worldgen.templates").joinpath(name).read_bytes()
    return parse_bytes(data)


def to_bytes(tree) -> bytes:
    """UTF-8 bytes with a declaration, two-space indentation and a final newline."""
    root = tree.getroot() if hasattr(tree, "getroot") else tree
    etree.indent(root, space="  ")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


def sub(parent, tag: str, text: str | None = None, **attrs) -> etree._Element:
    """Append ``<tag attrs>text</tag>`` to ``parent``; attribute order is as given."""
    el = etree.SubElement(parent, tag, attrs)
    if text is not None:
        el.text = text
    return el


#: Characters XML 1.0 cannot hold at all (lxml refuses them too), and lone surrogates.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_ATTR_ESCAPES = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}
_ATTR_SPECIAL = re.compile('[&<>"\n\r\t]')
_TEXT_ESCAPES = {"&": "&amp;", "<": "&lt;", ">": "&gt;", "\r": "&#13;"}
_TEXT_SPECIAL = re.compile("[&<>\r]")


def _checked(value: str) -> str:
    if _NOT_XML.search(value):
        raise SceneError(f"{value!r} holds a character XML cannot carry")
    return value


def escape_attr(value: str) -> str:
    """A user's string (a name, a uri) escaped for a double-quoted attribute, exactly as lxml writes it.

    Numbers from :mod:`worldgen.floats` need no escaping and are written as they are.
    """
    return _ATTR_SPECIAL.sub(lambda m: _ATTR_ESCAPES[m.group()], _checked(value))


def escape_text(value: str) -> str:
    """A user's string escaped as element text, exactly as lxml writes it."""
    return _TEXT_SPECIAL.sub(lambda m: _TEXT_ESCAPES[m.group()], _checked(value))


class XmlText:
    """Pretty-printed XML (two-space indentation) as lxml's ``indent`` + ``tostring`` write it.

    Attribute strings are passed pre-rendered (``' name="a" type="fixed"'``) and
    must already be escaped with :func:`escape_attr` where they hold a user's text.
    """

    __slots__ = ("parts", "depth")

    def __init__(self, depth: int = 0):
        self.parts: list[str] = []
        self.depth = depth

    def open(self, tag: str, attrs: str = "") -> None:
        self.parts.append(f"{'  ' * self.depth}<{tag}{attrs}>\n")
        self.depth += 1

    def close(self, tag: str) -> None:
        self.depth -= 1
        self.parts.append(f"{'  ' * self.depth}</{tag}>\n")

    def leaf(self, tag: str, content: str, attrs: str = "") -> None:
        """``<tag attrs>content</tag>`` (``content`` already escaped where it is a user's text)."""
        self.parts.append(f"{'  ' * self.depth}<{tag}{attrs}>{content}</{tag}>\n")

    def empty(self, tag: str, attrs: str = "") -> None:
        self.parts.append(f"{'  ' * self.depth}<{tag}{attrs}/>\n")

    def getvalue(self) -> str:
        return "".join(self.parts)


_SLOT = "worldgen-body"


def fill(skeleton: etree._Element, parent: etree._Element, body: XmlText) -> bytes:
    """The bytes of ``skeleton`` with ``body`` written at the end of ``parent``, as if built there with lxml.

    ``body`` must have been written at ``parent``'s depth + 1, and must not be empty
    when ``parent`` has no other children (lxml would write ``<parent/>``).
    """
    parent.append(etree.Comment(_SLOT))
    head, tail = to_bytes(skeleton).split(f"<!--{_SLOT}-->\n".encode(), 1)
    return head[:head.rfind(b"\n") + 1] + body.getvalue().encode() + tail
