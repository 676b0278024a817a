"""``python -m sandwich.cli ...``: the ``sandwich`` command."""

import sys

from sandwich.cli.commands import main

if __name__ == "__main__":
    sys.exit(main())
