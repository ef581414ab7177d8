"""examples/overwatch_seeds.py: its rows and counts from run summaries (no simulation)."""
import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "overwatch_seeds", Path(__file__).parents[2] / "examples" / "overwatch_seeds.py")
overwatch_seeds = importlib.util.module_from_spec(spec)
spec.loader.exec_module(overwatch_seeds)


def summary(seed, kinds_a, kinds_b, leaders, completed, alternated, status="completed"):
    return {"seed": seed, "status": status, "metrics": {
        "completion_time_s": 200.0 + seed if status == "completed" else None,
        "group_kinds": {"A": kinds_a, "B": kinds_b}, "balanced": True, "switches": 0, "leaders": leaders,
        "bounds_completed": completed, "route_length": 5, "alternated": alternated}}


def test_the_report_counts_each_claim_only_where_it_held():
    even = {"diffdrive": 2, "tricycle": 2}
    rows = [overwatch_seeds.row_of(s) for s in (
        summary(1, even, even, [["B", "cyan", 20.3, None], ["A", "red", 22.6, None]], 5, True),
        summary(2, {"diffdrive": 3, "tricycle": 1}, {"diffdrive": 1, "tricycle": 3}, [["A", "red", 21.0, None]],
                3, False, status="failed"))]
    assert rows[0]["leader_A"] == "red at 22.6 s" and rows[1]["leader_B"] == ""
    text = overwatch_seeds.report(rows)
    for claim in ("completed", "each group two of each kind", "a leader emerged in each group",
                  "every bound completed, alternating A-B-A-..."):
        assert f"| {claim} | 1/2 |" in text
    assert "Completion: 201.0-201.0 s" in text
