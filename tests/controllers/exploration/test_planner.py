"""The planner (Chand §6.3): the two-tiered A* path to an environment keeps out of environments assigned to other
explorers and, for a wheeled explorer only, out of boggy ones; two planners settle a contested environment by
distributed mutual exclusion, the loser proposing again without it."""
from __future__ import annotations

import numpy as np

from teamsim.controllers.exploration.assignment import ExplorerState
from teamsim.controllers.exploration.planner import Planner
from teamsim.controllers.exploration.territory import Territory

TERRITORY = Territory(28.8, 0.3, 3)  # nine environments of 9.6 m
WEST, MIDDLE, EAST = (TERRITORY.environment_of(x, -9.6) for x in (-9.6, 0.0, 9.6))  # the southern row
NORTH_MIDDLE = TERRITORY.environment_of(0.0, 0.0)


def path_job(explorer: ExplorerState, environment: int, boggy=()) -> dict:
    return {"job_id": 1, "kind": "path", "explorer": explorer, "environment": environment, "radius": 0.35,
            "global_map": np.full((TERRITORY.cells, TERRITORY.cells), 0.5), "bog_points": [],
            "boggy": [e in boggy for e in range(TERRITORY.environments)]}


def planned_path(planner: Planner, job: dict) -> np.ndarray:
    planner.receive("job", job, 100)
    planner.step(0.0)
    planner.step(60.0)  # past the map fetches' transmission time
    return [p for p in planner.outbox if p.kind == "plan"][-1].payload["path"]


def environments_crossed(path: np.ndarray) -> set[int]:
    return {TERRITORY.environment_of(x, y) for x, y in path}


def test_a_path_goes_round_an_environment_assigned_to_another_explorer():
    explorer = ExplorerState("Robot2", TERRITORY.centre(WEST), 1.0, False, WEST)
    free = planned_path(Planner("Robot4", TERRITORY, manager="Robot3"), path_job(explorer, EAST))
    assert MIDDLE in environments_crossed(free)  # the straight way east
    planner = Planner("Robot4", TERRITORY, manager="Robot3")
    planner.receive("assigned", {"environment": MIDDLE, "explorer": "Robot5"}, 100)
    around = planned_path(planner, path_job(explorer, EAST))
    assert MIDDLE not in environments_crossed(around) and NORTH_MIDDLE in environments_crossed(around)
    assert np.allclose(around[-1], TERRITORY.centre(EAST), atol=TERRITORY.resolution)


def test_a_wheeled_explorer_is_routed_round_a_boggy_environment_and_a_tracked_one_through_it():
    wheeled = ExplorerState("Robot2", TERRITORY.centre(WEST), 1.0, False, WEST)
    tracked = ExplorerState("Robot4", TERRITORY.centre(WEST), 1.0, True, WEST)
    around = planned_path(Planner("Robot4", TERRITORY, manager="Robot3"), path_job(wheeled, EAST, boggy={MIDDLE}))
    through = planned_path(Planner("Robot4", TERRITORY, manager="Robot3"), path_job(tracked, EAST, boggy={MIDDLE}))
    assert MIDDLE not in environments_crossed(around)
    assert MIDDLE in environments_crossed(through)


def assignment_job(job_id: int, explorer: ExplorerState, other: ExplorerState, status: list[str]) -> dict:
    return {"job_id": job_id, "kind": "environment", "explorer": explorer, "others": [other],
            "environment": None, "radius": 0.35, "status": status, "boggy": [False] * len(status),
            "bog_points": [], "excluded": set(), "global_map": np.full((TERRITORY.cells, TERRITORY.cells), 0.5),
            "unexplored": [1.0] * len(status), "t_m": 60.0, "ect": {}}


def negotiate(planners: dict[str, Planner], until: float) -> tuple[list, list[dict]]:
    """Step the planners every 0.1 s, delivering each one's broadcasts to the others; the proposals and the
    assignments made."""
    proposals, assignments = [], []
    for tick in range(round(until / 0.1)):
        for name, planner in planners.items():
            planner.step(tick * 0.1)
        for name, planner in planners.items():
            for packet in planner.outbox:
                if packet.to is None:  # a broadcast: to the other planners (and the manager)
                    for other_name, other in planners.items():
                        if other_name != name:
                            other.receive(packet.kind, packet.payload, packet.size)
                if packet.kind == "propose":
                    proposals.append(packet.payload["proposal"])
                if packet.kind == "assigned":
                    assignments.append(packet.payload)
            planner.outbox.clear()
    return proposals, assignments


def test_two_planners_proposing_one_environment_settle_it_by_the_lowest_job_id_at_equal_trade_offs():
    """Two explorers on either side of the only two open environments' line, each the same distance from both:
    both planners propose the same one at the same trade-off; job 1 gets it and the other planner's explorer the
    other environment, after a second round."""
    status = ["E"] * TERRITORY.environments
    status[MIDDLE] = status[NORTH_MIDDLE] = "UE"
    west = ExplorerState("Robot2", (-4.8, -4.8), 1.0, False, WEST)
    east = ExplorerState("Robot5", (4.8, -4.8), 1.0, False, EAST)
    planners = {"Robot4": Planner("Robot4", TERRITORY, manager="Robot3"),
                "Robot6": Planner("Robot6", TERRITORY, manager="Robot3")}
    planners["Robot4"].receive("job", assignment_job(2, west, east, status), 100)
    planners["Robot6"].receive("job", assignment_job(1, east, west, status), 100)
    proposals, assignments = negotiate(planners, until=3.0)
    first_round = sorted(proposals[:2], key=lambda p: p.job_id)
    assert first_round[0].environment == first_round[1].environment
    assert first_round[0].tradeoff == first_round[1].tradeoff
    by_explorer = {a["explorer"]: (a["environment"], a["job_id"]) for a in assignments}
    assert len(assignments) == 2 and len({env for env, _ in by_explorer.values()}) == 2
    contested = first_round[0].environment
    assert by_explorer["Robot5"][0] == contested  # job 1 won it
    assert by_explorer["Robot2"][0] == ({MIDDLE, NORTH_MIDDLE} - {contested}).pop()
    for planner in planners.values():
        assert planner.taken == {env: name for name, (env, _) in by_explorer.items()}


def test_when_environments_run_short_a_slow_explorer_s_ect_is_not_acceptable():
    """§6.4.3 with the manager's figures: one environment left for two explorers. (5.23) by each one's observed
    rate (t > T_m): Robot2 explored 100 cells in 600 s and has 200 left where it is, ECT 600 (200 + 1024) / 100 =
    7344 s; Robot5 explored 400 cells in 600 s with nothing left, ECT 600 x 1024 / 400 = 1536 s. Robot2 ranks second:
    no environment for it; Robot5's proposal goes ahead."""
    status = ["E"] * TERRITORY.environments
    status[MIDDLE] = "UE"
    west = ExplorerState("Robot2", (-4.8, -4.8), 1.0, False, WEST)
    east = ExplorerState("Robot5", (4.8, -4.8), 1.0, False, EAST)
    figures = {"Robot2": {"time": 600.0, "unexplored_current": 200.0, "explored": 100.0, "rate": 1.0},
               "Robot5": {"time": 600.0, "unexplored_current": 0.0, "explored": 400.0, "rate": 1.0}}
    for explorer, other, refused in ((west, east, True), (east, west, False)):
        job = assignment_job(1, explorer, other, status) | {"ect": figures, "unexplored": [1024.0] * len(status)}
        planner = Planner("Robot4", TERRITORY, manager="Robot3")
        planner.receive("job", job, 100)
        planner.step(0.0)
        kinds = [p.kind for p in planner.outbox]
        assert kinds == (["no-environment"] if refused else ["propose"])


def test_a_tracked_explorer_gets_the_last_boggy_environment_while_dry_ones_remain():
    """Three explorers; two UE environments are left, one boggy: Fig 6.7 offers the tracked Robot4 only the boggy
    one, and Robot4 is the slowest by ECT. Two environments for three explorers is "running short", so ECT ranks
    Robot4 third of three: no environment. With a third (dry) environment open the environments do not run short
    and Robot4 is given the boggy one, though it is its only candidate (counting its candidates retired it:
    docs/decisions.md, "ECT when environments run short")."""
    tracked = ExplorerState("Robot4", (-4.8, -4.8), 1.0, True, WEST)
    others = [ExplorerState("Robot2", (4.8, -4.8), 1.0, False, EAST),
              ExplorerState("Robot5", (4.8, 4.8), 1.0, False, None)]
    figures = {"Robot4": {"time": 600.0, "unexplored_current": 0.0, "explored": 50.0, "rate": 1.0},
               "Robot2": {"time": 600.0, "unexplored_current": 0.0, "explored": 400.0, "rate": 1.0},
               "Robot5": {"time": 600.0, "unexplored_current": 0.0, "explored": 400.0, "rate": 1.0}}
    for open_environments, expected in (((MIDDLE, NORTH_MIDDLE), "no-environment"),
                                        ((MIDDLE, NORTH_MIDDLE, EAST), "propose")):
        status = ["E"] * TERRITORY.environments
        for environment in open_environments:
            status[environment] = "UE"
        job = assignment_job(1, tracked, others[0], status) | {
            "others": others, "ect": figures, "unexplored": [1024.0] * len(status),
            "boggy": [e == MIDDLE for e in range(len(status))]}
        planner = Planner("Robot6", TERRITORY, manager="Robot3")
        planner.receive("job", job, 100)
        planner.step(0.0)
        assert [p.kind for p in planner.outbox] == [expected]
        if expected == "propose":
            assert planner.outbox[0].payload["proposal"].environment == MIDDLE


def test_a_wheeled_explorer_s_path_keeps_out_of_the_bog_ahead_of_where_it_was_met():
    """Robot2 met a bog going east at (-7.6, -9.6) and backed out 2 m west: the bog lies ahead of that spot, so
    its path east keeps 3 m clear of (-4.6, -9.6), 3 m ahead of it; a tracked explorer's goes straight through."""
    start, spot, bog_centre = (-9.6, -9.6), (-7.6, -9.6, 0.0), (-4.6, -9.6)

    def path(bog_capable: bool) -> np.ndarray:
        explorer = ExplorerState("Robot2", start, 1.0, bog_capable, WEST)
        return planned_path(Planner("Robot4", TERRITORY, manager="Robot3"),
                            path_job(explorer, EAST) | {"bog_points": [spot]})

    clearance = np.hypot(*(path(False) - bog_centre).T).min()
    assert clearance >= 3.0 - TERRITORY.resolution
    assert np.hypot(*(path(True) - bog_centre).T).min() < 0.5


def test_an_environment_another_explorer_explored_in_part_is_offered_again():
    """15 % world 3, [1 3]: Robot2 explored environment 7 in part (PE) and gave it back; the planner still had it
    as Robot2's, so it was never offered to anyone and the run ended at 93.7 % explored. The manager's "explored"
    tells the planners it is no longer anyone's: PE is on offer to every explorer but the one that left it."""
    status = ["E"] * TERRITORY.environments
    status[MIDDLE] = "PE"
    east = ExplorerState("Robot5", (4.8, -4.8), 1.0, False, EAST)
    west = ExplorerState("Robot2", (-4.8, -4.8), 1.0, False, WEST)
    planner = Planner("Robot4", TERRITORY, manager="Robot3")
    planner.receive("assigned", {"environment": MIDDLE, "explorer": "Robot2"}, 100)
    planner.receive("job", assignment_job(1, east, west, status), 100)
    planner.step(0.0)
    assert [p.kind for p in planner.outbox] == ["no-environment"]  # still Robot2's, as far as it knows
    planner.outbox.clear()
    planner.receive("explored", {"environment": MIDDLE, "status": "PE"}, 100)
    planner.receive("job", assignment_job(2, east, west, status), 100)
    planner.step(0.1)
    assert [p.kind for p in planner.outbox] == ["propose"]
    assert planner.outbox[0].payload["proposal"].environment == MIDDLE
