"""``python -m sandwich.cli ...``: the ``sandwich`` command."""

import sys

from sandwich.cli.commands import main

sys.exit(main())
