"""``PathFollower`` is its parts composed (sandwich/solver/path/follower.py): every method is
defined in exactly one part, so the order of the bases decides nothing (reference: the classes'
own namespaces along the method resolution order)."""

from collections import defaultdict

from sandwich.solver.path import PathFollower


def test_no_part_of_the_follower_overrides_another():
    defined = defaultdict(list)
    for part in PathFollower.__mro__[:-1]:
        for name, value in vars(part).items():
            if callable(value) or isinstance(value, property):
                defined[name].append(part.__name__)
    assert len(PathFollower.__mro__) > 3
    assert {n: parts for n, parts in defined.items() if len(parts) > 1} == {}
