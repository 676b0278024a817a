"""``python -m sandwich_cli ...``: the ``sandwich`` command."""

import sys

from sandwich_cli.commands import main

sys.exit(main())
