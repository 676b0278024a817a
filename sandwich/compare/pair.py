"""The two models a comparison puts side by side (registry names of :mod:`sandwich.models`)."""

BEAM, REFERENCE = "beam", "2d"
PAIR = (BEAM, REFERENCE)  # the order in which a comparison runs them
