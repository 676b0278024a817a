"""Limit points and bifurcations carry the load factors of the states that enclose them.

Reference: the synthetic state sequences themselves (which states enclose the point is read off
by hand); the summary.json round trip through the result writer and reader.
"""

from dataclasses import dataclass, field

from sandwich.results import LimitPoint, Solution, StepRecord, load_result, write_solution
from sandwich.solver.limits import find_limit_points


@dataclass
class _S:
    step: int
    load_factor: float
    negative_pivots: int | None
    probes: dict = field(default_factory=dict)


def _states(lams, negs):
    return [_S(i, lam, n) for i, (lam, n) in enumerate(zip(lams, negs, strict=True))]


def test_a_maximum_lies_between_the_states_either_side():
    # λ rises to 10 at state 3, a zero increment (3 → 4), then falls: the enclosing states
    # are 2 (before the rise's last increment) and 5 (after the first falling one)
    lp, = find_limit_points(_states([0, 4, 8, 10, 10, 9, 7], [0, 0, 0, 0, 1, 1, 1]))
    assert (lp.kind, lp.step, lp.load_factor, lp.between) == ("max", 3, 10.0, (8.0, 9.0))


def test_a_bifurcation_lies_between_the_state_before_and_the_one_reported():
    lp, = find_limit_points(_states([0, 3, 6, 9, 12], [0, 0, 0, 1, 1]))
    assert (lp.kind, lp.step, lp.between) == ("bifurcation", 3, (6.0, 9.0))


def test_the_bracket_goes_through_summary_json_and_older_files_read_without_it(tmp_path):
    history = [StepRecord(0, 0.0, {"w": 0.0}, 0), StepRecord(1, 9.0, {"w": -1.0}, 3)]
    lps = [LimitPoint("bifurcation", 1, 9.0, {"w": -1.0}, (6.0, 9.0)),
           LimitPoint("max", 1, 9.0, {"w": -1.0})]
    sol = Solution("beam", "s", history, [], True, "reached", lps, 1.0, 10, {})
    write_solution(sol, tmp_path)
    back = load_result(tmp_path, fields=False)
    assert [lp.between for lp in back.limit_points] == [(6.0, 9.0), None]


def test_a_located_bifurcation_goes_through_summary_json(tmp_path):
    # located at 0.4 of its step (sandwich.solver.critical): the fraction is written and read
    # back; a point without it reads back as None (files written before it existed)
    history = [StepRecord(0, 0.0, {"w": 0.0}, 0), StepRecord(1, 9.0, {"w": -1.0}, 3)]
    lps = [LimitPoint("bifurcation", 1, 7.2, {"w": -0.4}, (6.0, 9.0), 0.4),
           LimitPoint("max", 1, 9.0, {"w": -1.0})]
    sol = Solution("beam", "s", history, [], True, "reached", lps, 1.0, 10, {})
    write_solution(sol, tmp_path)
    back = load_result(tmp_path, fields=False)
    assert [lp.located_at for lp in back.limit_points] == [0.4, None]
    assert back.limit_points[0].load_factor == 7.2 and back.limit_points[0].probes == {"w": -0.4}
