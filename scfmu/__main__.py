"""``python -m scfmu``: the ``scfmu`` command line."""

import sys

from .cli import main

sys.exit(main())
