"""``python -m worldgen``: the same as the ``worldgen`` command."""

import sys

from worldgen.cli import main

__all__: list[str] = []

if __name__ == "__main__":
    sys.exit(main())
