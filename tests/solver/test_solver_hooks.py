"""The optional methods a model may add (``sandwich.solver.system.OptionalHooks``) are the ones
the solver looks up: every ``getattr(system, "name", …)`` in the solver's sources names a hook
the Protocol declares, and every declared hook is looked up somewhere (reference: the sources)."""

import re
from pathlib import Path

from sandwich.solver import OptionalHooks

SOLVER = Path(__file__).resolve().parents[2] / "sandwich" / "solver"


def test_the_hooks_looked_up_are_the_hooks_declared():
    looked_up = set()
    for path in SOLVER.rglob("*.py"):
        looked_up |= set(re.findall(r'getattr\(system, "(\w+)"', path.read_text("utf-8")))
    declared = {n for n in vars(OptionalHooks) if not n.startswith("_")}
    assert looked_up and looked_up == declared
