"""A cohesive path's summary, on hand-made scenes and rows."""

from benchmarks.cases.growth_cases import cohesive_cantilever
from sandwich.growth import cohesive_summary
from sandwich.results import StepRecord


def _row(step, lam, tip, zone):
    return StepRecord(step=step, load_factor=lam, probes={}, iterations=1,
                      extra={"tip_0_end": tip, "process_zone_0_end": zone})


def test_summary_reads_first_growth_residual_strength_and_the_span_end():
    sc = cohesive_cantilever(zone=20.0)  # span [40, 60]
    rows = [_row(0, 0.0, 40.0, 0.0), _row(1, 0.1, 40.0, 3.0), _row(2, 0.15, 40.0, 5.0),
            _row(3, 0.12, 45.0, 5.0), _row(4, 0.11, 55.0, 5.0), _row(5, 0.4, 55.0, 5.0)]
    out, warnings = cohesive_summary(sc, rows, element=0.5)
    assert out["first_growth_load"] == 0.12 and out["first_growth_step"] == 3
    # the load rising once the tip is held at the span's end (step 4 on) is not the debond's
    assert out["residual_strength"] == 0.15 and out["bounded"]
    assert out["span_end_step"] == 4
    tip = out["tips"]["0_end"]
    assert (tip["from"], tip["to"], tip["grew_mm"]) == (40.0, 55.0, 15.0)
    assert tip["longest_process_zone_mm"] == 5.0
    assert len(warnings) == 1 and "x = 60 mm" in warnings[0]  # 55 + 5 reaches the span's end
    out, warnings = cohesive_summary(sc, rows[:3], element=0.5)
    assert out["first_growth_load"] is None and not warnings and out["span_end_step"] is None
