"""The ``sandwich`` command line: validate | mesh | solve | compare | gallery | demo.

It sits above every other package (scene → models → registry/runner → comparisons → CLI);
nothing imports it. ``python -m sandwich.cli`` and the ``sandwich`` console script both run
:func:`main`.
"""

from sandwich.cli.commands import EXIT_BAD_INPUT, EXIT_INTERNAL, EXIT_OK, EXIT_STOPPED, main

__all__ = ["EXIT_BAD_INPUT", "EXIT_INTERNAL", "EXIT_OK", "EXIT_STOPPED", "main"]
