"""The 2D plane-stress Green-strain reference (paper sec. 2.2.2) in FEniCSx, with debond contact.

Public entry points: :func:`solve` (scene -> :class:`sandwich.results.Solution`) and
:func:`write_fields` (XDMF time series for ParaView).
"""

from sandwich.plane2d.fields import write_fields
from sandwich.plane2d.solve import solve

__all__ = ["solve", "write_fields"]
