"""``python -m worldgen.cli``, as before the command line became a folder."""

import sys

from worldgen.cli.main import main

sys.exit(main())
