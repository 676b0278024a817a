"""Keep the FEniCSx stack's log lines off the terminal (the CLI and the study workers).

The JIT compiler logs "INFO:root:running build_ext ..." on the root logger (setuptools sets its
level to INFO) and UFL warns about the DQ element on its own logger with its own handler; the
libraries reset their loggers' levels, so filters on those loggers are what holds.
"""

from __future__ import annotations

import logging

__all__ = ["QUIET_LOGGERS", "hush_libraries", "unhush_libraries"]

QUIET_LOGGERS = ("UFL", "FFCx", "ffcx", "dolfinx", "py.warnings")


class _Below(logging.Filter):
    """Drops records below a level."""

    def __init__(self, level: int):
        super().__init__()
        self.level = level

    def filter(self, record: logging.LogRecord) -> bool:
        return record.levelno >= self.level


def hush_libraries() -> None:
    """Root logger: warnings and up; the FEniCSx stack's loggers: errors only (idempotent)."""
    for name, level in (("", logging.WARNING), *((n, logging.ERROR) for n in QUIET_LOGGERS)):
        logger = logging.getLogger(name)
        if not any(isinstance(f, _Below) for f in logger.filters):
            logger.addFilter(_Below(level))


def unhush_libraries() -> None:
    """Remove the filters of :func:`hush_libraries`."""
    for name in ("", *QUIET_LOGGERS):
        logger = logging.getLogger(name)
        for f in [f for f in logger.filters if isinstance(f, _Below)]:
            logger.removeFilter(f)
