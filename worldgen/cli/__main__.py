"""``python -m worldgen.cli``, as before the command line became a folder."""

import sys

from worldgen.cli.main import main

__all__: list[str] = []

if __name__ == "__main__":
    sys.exit(main())
