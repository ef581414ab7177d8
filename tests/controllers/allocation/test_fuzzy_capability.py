"""Fuzzy inference systems built from tables (teamsim.controllers.allocation.fuzzy_capability): MATLAB's Mamdani with
sum aggregation, agreement with scikit-fuzzy's control API where both apply, and the capability scores of Chand's
Table 5.22 and Table 7.4."""
from __future__ import annotations

import numpy as np
import pytest

from teamsim.config import ConfigError
from teamsim.controllers.allocation.fuzzy_capability import (FuzzySystem, capability_scores, control_api,
                                                             published_misses, quantity, systems, tables)
from teamsim.controllers.allocation.spec import load_robots


WITHIN = 0.02 + 1e-9  # "within 0.02" of a score the thesis printed to 2 decimals


def score(name, *inputs, **params) -> float:
    return float(systems()[name].evaluate([inputs], **params)[0, 0])


def test_table_5_22_scores_within_0_02_or_a_named_cause():
    robots = load_robots()
    scores = capability_scores(robots)
    misses = {}
    for robot, row in zip(robots, scores):
        for resource, ours, thesis, cause in published_misses(robot, row):
            assert cause != "cause unknown", f"{robot.id} {resource}: {ours:.3f} vs {thesis} has no cause"
            misses[robot.id, resource] = round(ours - thesis, 3)
    # The spec's two known gaps (communication at 11 Mbit/s, Robot3's processing) and the reconstructed
    # actuation rule table (Robot8); every other published score of the 32 is within 0.02.
    eleven_mbit = {(f"Robot{k}", "comm"): 0.067 for k in (2, 4, 5, 6, 7, 8)}
    assert misses == {**eleven_mbit, ("Robot3", "proc"): -0.105, ("Robot8", "act"): 0.025}


@pytest.mark.parametrize("kind, benchmark, memory, published", [
    ("pc", 3.2, 0.5, 0.48), ("pc", 3.1, 1, 0.54), ("pc", 2.1, 1, 0.53), ("pc", 2.1, 0.5, 0.46), ("pc", 3.1, 0.5, 0.47),
    ("mc", 6, 10, 0.52), ("mc", 10, 16, 0.87), ("mc", 6, 4, 0.37), ("mc", 6, 2, 0.33),
])
def test_processing_scores_of_tables_5_22_and_7_4(kind, benchmark, memory, published):
    assert score(f"processing_{kind}", benchmark, memory) == pytest.approx(published, abs=WITHIN)


@pytest.mark.parametrize("quantity_ir, published", [(10, 0.49), (11, 0.51), (12, 0.52), (13, 0.54), (14, 0.55)])
def test_ir_sensing_cascade_scores(quantity_ir, published):
    sensor = score("sensor_score", quantity_ir, 1.5)
    avoidance = score("obstacle_avoidance", 360, sensor)
    mapping = score("mapping_exploration", 360, sensor)
    assert score("sensing", avoidance, mapping) == pytest.approx(published, abs=WITHIN)


def test_actuation_cascade_fits_the_18_published_scores_as_the_spec_reports():
    published = [([2.04, .5, .5, .3], .60), ([2.14, .5, .5, .3], .65), ([2.15, .4, .5, .1], .66),
                 ([2.53, .6, .4, 1], .67), ([1.25, .4, .5, .1], .5), ([1.40, .4, .5, .1], .5),
                 ([1.19, .4, .5, .1], .48), ([0.95, .6, .4, 1], .30), ([2.0, .6, .5, .3], .58),
                 ([2.0, .6, .4, 1], .58), ([1.06, .25, .4, 1], .39), ([1.5, .4, .5, .1], .5),
                 ([0.95, .15, .5, .3], .30), ([1.19, .25, .5, .3], .49), ([1.43, .4, .5, .3], .5),
                 ([1.25, .25, .5, .1], .5), ([0.85, .15, .4, 1], .26), ([2.0, .6, .5, .1], .58)]
    errors = []
    for (hours, radius, speed, terrain), thesis in published:
        performance = score("base_performance", speed, terrain)
        size = score("base_size:any", radius)
        errors.append(abs(score("actuation", hours, performance, size) - thesis))
    assert np.mean(errors) == pytest.approx(0.014, abs=0.002)
    assert max(errors) == pytest.approx(0.09, abs=0.005)


def test_discrete_centroid_of_summed_rule_outputs_as_matlab():
    # [54 Mbit/s, 100 m]: rules 3 and 6 both fire fully on 'high' = tri [0.6 1 1.4]; sum aggregation stacks the
    # two sets and the centroid is over 101 samples of [0, 1].
    x = np.linspace(0, 1, 101)
    high = np.clip((x - 0.6) / 0.4, 0, 1)
    assert score("communication", 54, 100) == pytest.approx((x @ (2 * high)) / (2 * high).sum(), abs=1e-12)
    # Unequal firings of two rules on different terms: each clipped set is added, not maxed.
    medium = np.clip(np.minimum((x - 0.3) / 0.2, (0.7 - x) / 0.2), 0, 1)
    mu_medium = (36 - 20) / 25  # bandwidth 20 Mbit/s on medium [3.5 11 36]
    mu_high = (20 - 16.5) / 37.5  # and on high [16.5 54 75.6]; range 100 m is high
    shape = np.minimum(medium, mu_medium) + np.minimum(high, mu_high) + high
    assert score("communication", 20, 100) == pytest.approx((x @ shape) / shape.sum(), abs=1e-12)


def test_inputs_are_clipped_to_their_range():
    assert score("communication", 80, 300) == score("communication", 54, 100)
    assert score("processing_mc", -3, 0) == score("processing_mc", 0, 0)


def test_no_rule_fires_gives_the_middle_of_the_range():
    # VOTSWS rules all carry VSW weights; with every weight 0 none of them fires, as MATLAB, the middle.
    out = systems()["task_value"].evaluate([[0.2, 0.9, 0.4, 0.7, 0.0]], vsw_proc=0, vsw_comm=0, vsw_sense=0,
                                           vsw_act=0)
    assert out[0, 0] == 0.5
    assert out[0, 1] < 0.4  # V still has its task diversity rules: TD 0 is 'low'


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # inside scikit-fuzzy's control API
@pytest.mark.parametrize("name", ["communication", "mapping_exploration", "actuation", "task_value"])
def test_max_aggregation_agrees_with_scikit_fuzzy_control_api(name):
    data = tables()
    table = data["fis"][name]
    system = FuzzySystem(name, table, table["rules"], data["mfs"], {**data["settings"], "aggregation": "max"})
    params = dict(vsw_proc=0.4, vsw_comm=0.4, vsw_sense=0.1, vsw_act=0.1) if name == "task_value" else {}
    simulation = control_api(system, **params)
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = [rng.uniform(v.lo, v.hi) for v in system.inputs]
        for variable, value in zip(system.inputs, x):
            simulation.input[variable.name] = value
        simulation.compute()
        ours = system.evaluate([x], **params)[0]
        for o, variable in enumerate(system.outputs):
            # the control API integrates a piecewise-linear shape, MATLAB sums 101 samples
            assert ours[o] == pytest.approx(simulation.output[variable.name], abs=0.01)


def test_sum_and_max_aggregation_differ_where_rules_overlap():
    data = tables()
    table = data["fis"]["communication"]
    as_max = FuzzySystem("communication", table, table["rules"], data["mfs"],
                         {**data["settings"], "aggregation": "max"})
    # [20 Mbit/s, 100 m]: 'high' from two rules (0.09 and 1) and 'medium' (0.64); summing stacks the highs.
    assert score("communication", 20, 100) - as_max.evaluate([[20, 100]])[0, 0] > 0.005


def test_batch_evaluation_equals_row_by_row():
    rng = np.random.default_rng(3)
    rows = np.column_stack([rng.uniform(0, 54, 30), rng.uniform(0, 100, 30)])
    batch = systems()["communication"].evaluate(rows)[:, 0]
    assert batch == pytest.approx([score("communication", *row) for row in rows], abs=1e-12)


def test_identical_rows_give_bit_identical_outputs_anywhere_in_a_batch():
    # The devolution breaks exact ties by file order, so a row's output must not depend on its position in the
    # batch: with the centroid as a BLAS matrix-vector product the last of 9 identical rows came out 1 ulp
    # higher (V 0.38743243243243240 against ...236) and won a tie it should lose (Fig 7.16, set (a) under W7).
    rng = np.random.default_rng(5)
    row = [0.87, 0.687284, 0.15, 0.15, 0.5]
    for size in (1, 2, 3, 5, 8, 9, 17, 100):
        batch = rng.uniform(0, 1, (size, 5))
        batch[::2] = row
        out = systems()["task_value"].evaluate(batch, vsw_proc=0, vsw_comm=0, vsw_sense=0, vsw_act=1.0)
        alone = systems()["task_value"].evaluate([row], vsw_proc=0, vsw_comm=0, vsw_sense=0, vsw_act=1.0)[0]
        assert (out[::2] == alone).all(), size


def test_rule_weight_parameters_per_row():
    vots = [[0.2, 0.6, 0.4, 0.9, 0.5]] * 2
    out = systems()["task_value"].evaluate(vots, vsw_proc=np.array([1.0, 0.0]), vsw_comm=np.array([0.0, 1.0]),
                                           vsw_sense=0.0, vsw_act=0.0)
    assert out[0, 0] < out[1, 0]  # VOTSWS follows proc (0.2) in row 0 and comm (0.6) in row 1
    with pytest.raises(ValueError, match="vsw_act"):
        systems()["task_value"].evaluate(vots, vsw_proc=1, vsw_comm=0, vsw_sense=0)


def test_trace_lists_inputs_fired_rules_with_weighted_strength_and_outputs():
    system = systems()["sensing"]
    trace = system.trace([0.55, 0.59])
    assert trace.inputs == {"obstacle_avoidance": 0.55, "mapping_exploration": 0.59}
    fired = {rule.number: rule for rule in trace.fired}
    assert set(fired) == {3, 6}
    assert fired[3].firing == pytest.approx(0.1 * (0.7 - 0.55) / 0.2)  # degree times weight 0.1
    assert fired[3].text == "if obstacle_avoidance is medium then score is medium (w 0.1)"
    assert trace.outputs["score"] == pytest.approx(system.evaluate([[0.55, 0.59]])[0, 0])


def test_robot_quantity_fis_gives_four_explorers_and_one_planner():
    raw = systems()["robot_quantity"].evaluate([[1600, 5.5]])[0]
    assert raw == pytest.approx([4.47, 1.59], abs=0.01)
    assert quantity(1600, "medium", "explorers", "q") == 4
    assert quantity(1600, "medium", "planners", "q") == 1
    assert quantity("large", "low", "planners", "q") >= 8
    with pytest.raises(ConfigError, match="q.ratio: unknown grade 'lots'; allowed: a number or low, medium, high"):
        quantity(1600, "lots", "planners", "q")


def test_base_size_rules_follow_the_size_a_task_asks_for():
    any_size = [score("base_size:any", r) for r in (0.1, 0.5, 0.9)]
    assert min(any_size) > 0.6  # Table 5.17: every size is preferred
    assert score("base_size:small", 0.1) > 0.6 > 0.4 > score("base_size:small", 0.9)
    assert score("base_size:large", 0.9) > 0.6 > 0.4 > score("base_size:large", 0.1)
