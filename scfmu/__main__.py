"""``python -m scfmu``: the ``scfmu`` command line."""

import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while Python loads the command line: one line, not a traceback
    print("\nscfmu: interrupted (Ctrl-C) while starting; nothing was done", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
