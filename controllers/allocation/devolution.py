"""Primary and secondary task devolution (Chand 2011 §5.5, Tables 5.25-5.28; spec §3.6): who manages and who works.

Suitability (5.4): ``VOTS_typeij = r_jRCS_type - t_iRCS_type``; robot j is capable of task i when every VOTS is
>= 0 and its processor class (mc/pc) is the task's. VOTSWS_ij and the value V_ij come from the ``task_value``
FIS (Tables 5.25-5.26), whose rules 1-12 carry the task's VOTS summation weights and rules 13-15 the task
diversity TD_ij.

Primary devolution (managers), on the base station:

1. robots capable of at least one management task, ranked by VOTSWS summed over the tasks each can do,
   descending;
2. the top robot takes the combination of still unassigned management tasks whose VOTSWS is closest to 0 (the
   most use of its resources, so the fewest managers); a combination requires the **sum** of its tasks'
   requirements; the robot leaves the ranking; repeat while tasks and robots remain;
3. if tasks remain, multi-task combinations are overrated by (5.5) ``CO = 1 + w_CO n_1c / n_1cp`` and the
   greedy pass is rerun, w_CO = 0.1, 0.2, ... 1, until every task is assigned.

Secondary devolution (workers), on the manager: capable non-manager robots per worker task; TD_ij = (number of
*other* worker tasks robot j can do) / (number of worker tasks); V_ij and VOTSWS_ij from the FIS; per task,
candidates by V descending; tasks by number of candidates ascending (scarce first): that is the robot-task
capability matrix (RTCM). Each task then takes its initial quantity from the top of its column, skipping a robot
that cannot run the task beside the ones it already has (concurrency); RU is set to the task's [on] or [off]
mapping; task scores (5.6) ``TS_ij = VOTSWS_ij / VOTSWS_imax`` over the robots assigned task i.

Choices where the thesis is silent (also in docs/decisions.md):

- "Rank the capable robots ... based on VOTSWS_ij for all tasks that they are capable of performing": by the
  sum over those tasks, so a robot that can take more of them ranks higher (fewer managers, step 4's aim).
- Ties in a ranking (equal within ``TIE_TOLERANCE`` = 1e-9, see :func:`rank`) go to the robot earlier in the
  robot file: MATLAB's sort is stable and §7.4 breaks the planner tie under W9 and the explorer ties of Fig 7.16
  by lowest ID. Managers get the same rule, although under Table 7.1's W9 (communication only) R1 and R2 tie
  exactly and §7.3 reports the same managers as under W1-W8: no ID order can give that in all five robot sets,
  because R1 ranks first under W1-W8 in sets (b) and (e) and R2 in (c) and (d) (with Table 7.4's scores as with
  ours), so the lowest ID gives R1 the harder task in (c) and (d). A score-based second key (e.g. the ranking
  under equal weights) would make the managers stable, but the spec names none, and used for workers too it
  would contradict §7.4's own lowest-ID outcomes (set (b), one explorer, W7: R3 over R5, whose equal-weight
  value is higher). So it is not used; docs/decisions.md records the disagreement.
- A combination's VSW is the mean of its tasks' VSW; its processor class must be common to its tasks; its size
  is the one size a task names (two different sizes cannot combine).
- n_1cp of (5.5) is the number of management tasks. CO multiplies only combinations of two or more tasks. When
  a combination and a smaller one have the same (overrated) VOTSWS, the robot takes the larger (fewer managers).
- Concurrency: a robot may take task i beside task k when either lists the other as concurrent and the robot is
  capable of the summed requirements of all its tasks (as for manager combinations).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from teamsim.controllers.allocation.fuzzy_capability import capability_scores, run
from teamsim.controllers.allocation.spec import CATEGORIES, RESOURCES, RobotSpec, TaskSpec

OVERRATING_STEPS = tuple(round(0.1 * k, 1) for k in range(11))  # w_CO of (5.5)


def vsw_params(vsw) -> dict:
    """The rule-weight parameters of the ``task_value`` FIS for VOTS summation weights ``vsw`` ((B, 4) or (4,))."""
    vsw = np.asarray(vsw, dtype=float)
    return {f"vsw_{resource}": vsw[..., k] for k, resource in enumerate(RESOURCES)}


def task_value(vots, diversity, vsw) -> tuple[np.ndarray, np.ndarray]:
    """VOTSWS and V (Tables 5.25-5.26) for rows of VOTS (B, 4), TD (B,) and VSW (B, 4)."""
    vots = np.asarray(vots, dtype=float).reshape(-1, 4)
    out = run("task_value", np.column_stack([vots, np.broadcast_to(diversity, len(vots))]), **vsw_params(vsw))
    return out[:, 0], out[:, 1]


class Suitability:
    """Capability scores of a set of robots, and their VOTS and capability for any task or task combination."""

    def __init__(self, tasks: list[TaskSpec], robots: list[RobotSpec]):
        self.tasks = {t.id: t for t in tasks}
        self.robots = list(robots)
        self.ids = [r.id for r in robots]
        sizes = dict.fromkeys(["any", *(t.size for t in tasks)])
        self.scores = {size: capability_scores(robots, size) for size in sizes}
        self.pc = np.array([r.proc_class == "pc" for r in robots], dtype=bool)

    def combined(self, task_ids) -> tuple[str, str, np.ndarray] | None:
        """(processor class, size, summed requirement) of tasks run together; None if they cannot combine."""
        tasks = [self.tasks[i] for i in task_ids]
        classes = {t.proc_class for t in tasks}
        sizes = {t.size for t in tasks} - {"any"}
        if len(classes) > 1 or len(sizes) > 1:
            return None
        return classes.pop(), (sizes.pop() if sizes else "any"), np.sum([t.requirement for t in tasks], axis=0)

    def vots(self, task_ids) -> tuple[np.ndarray, np.ndarray]:
        """(robots, 4) VOTS of the combined tasks and the (robots,) capable mask."""
        combination = self.combined(task_ids)
        if combination is None:
            return np.full((len(self.robots), 4), -1.0), np.zeros(len(self.robots), dtype=bool)
        kind, size, requirement = combination
        vots = self.scores[size] - requirement
        return vots, (self.pc == (kind == "pc")) & (vots >= 0).all(axis=1)

    def fits(self, robot: int, task_ids) -> bool:
        """Whether robot (index) is capable of all ``task_ids`` together."""
        combination = self.combined(task_ids)
        if combination is None:
            return False
        kind, size, requirement = combination
        return bool(self.pc[robot] == (kind == "pc") and (self.scores[size][robot] >= requirement).all())



# Values closer than this are a tie. FIS outputs lie in [0, 1]; round-off is ~1e-16, and the smallest real gap in
# the ch.7 experiments is 7e-6 (robot set (d), planner, W4: R4 over R5).
TIE_TOLERANCE = 1e-9


def rank(robots, values, tolerance: float = TIE_TOLERANCE) -> list:
    """``robots`` (indices) sorted by ``values`` descending; ties keep file order (lowest index first).

    A tie is equality within ``tolerance``, not bit equality: a value that is mathematically the same for two
    robots (same VOTS on every weighted resource, same TD) may differ in the last bits, and a 1e-16 difference
    must not overrule the thesis's tie-break, the lowest ID (§7.4: the planner under W9, the one-explorer
    choices of Fig 7.16). Robots are grouped from the top: a robot joins the current group while its value is
    within ``tolerance`` of the group's best, and each group is then put in file order."""
    ordered = sorted(zip(values, robots), key=lambda x: (-x[0], x[1]))
    out, group, top = [], [], None
    for value, robot in ordered:
        if group and top - value > tolerance:
            out += sorted(group)
            group = []
        if not group:
            top = value
        group.append(robot)
    return out + sorted(group)


@dataclass(frozen=True)
class Candidate:
    """One row of the robot-task capability matrix."""
    robot: str
    value: float  # V_ij; feedback coordination re-ranks by OTES_ijind instead
    votsws: float
    diversity: float  # TD_ij
    vots: tuple[float, float, float, float]


@dataclass
class Allocation:
    """The result of both devolution stages (Tables 5.27-5.28)."""
    suitability: Suitability
    managers: dict[str, str]  # management task -> robot
    manager_ranking: list[tuple[str, float]]  # capable robots and their summed VOTSWS, best first
    manager_votsws: dict[str, float]  # robot -> VOTSWS of the combination it took (before overrating)
    overrating: float  # the w_CO at which the greedy pass ended
    unassigned: list[str]  # management tasks no robot could take
    rtcm: dict[str, list[Candidate]]  # worker task -> candidates by V; tasks in allocation order
    workers: dict[str, list[str]] = field(default_factory=dict)  # worker task -> robots, in RTCM order
    shortfall: dict[str, int] = field(default_factory=dict)  # worker task -> robots missing
    task_scores: dict[str, dict[str, float]] = field(default_factory=dict)  # (5.6)
    ru: dict[str, dict[str, dict[str, tuple]]] = field(default_factory=dict)  # robot -> task -> cat -> RU

    @property
    def tasks(self) -> dict[str, TaskSpec]:
        return self.suitability.tasks


def allocate(tasks: list[TaskSpec], robots: list[RobotSpec]) -> Allocation:
    """Primary then secondary task devolution of ``tasks`` over ``robots``."""
    suitability = Suitability(tasks, robots)
    managers = [t for t in tasks if t.role == "manager"]
    allocation = primary_devolution(suitability, managers)
    secondary_devolution(allocation, [t for t in tasks if t.role == "worker"])
    return allocation


def primary_devolution(suitability: Suitability, managers: list[TaskSpec]) -> Allocation:
    """Managers (§5.5.1, primary steps 1-6 and the overrating (5.5))."""
    n = len(managers)
    combos = [c for k in range(1, n + 1) for c in itertools.combinations(range(n), k)]
    p = len(suitability.robots)
    votsws = np.zeros((len(combos), p))
    capable = np.zeros((len(combos), p), dtype=bool)
    rows = []
    for c, combo in enumerate(combos):
        vots, capable[c] = suitability.vots([managers[k].id for k in combo])
        vsw = np.mean([managers[k].vsw for k in combo], axis=0)
        rows += [(c, j, vots[j], vsw) for j in np.nonzero(capable[c])[0]]
    if rows:
        ws, _ = task_value(np.array([r[2] for r in rows]), 0.0, np.array([r[3] for r in rows]))
        votsws[[r[0] for r in rows], [r[1] for r in rows]] = ws
    size = np.array([len(combo) for combo in combos], dtype=int)
    singles = size == 1
    eligible = [j for j in range(p) if capable[singles, j].any()]
    summed = [votsws[singles & capable[:, j], j].sum() for j in eligible]
    ranking = rank(eligible, summed)
    for w_co in OVERRATING_STEPS:
        overrated = votsws * np.where(size > 1, 1 + w_co * size / n, 1.0)[:, None]
        remaining, assigned = set(range(n)), {}
        for j in ranking:
            options = [c for c, combo in enumerate(combos) if capable[c, j] and remaining.issuperset(combo)]
            if options:
                chosen = min(options, key=lambda c: (overrated[c, j], -size[c], c))  # ties: more tasks
                assigned[j] = chosen
                remaining -= set(combos[chosen])
            if not remaining:
                break
        if not remaining:
            break
    ids = suitability.ids
    owner = {k: j for j, c in assigned.items() for k in combos[c]}
    return Allocation(
        suitability=suitability,
        managers={managers[k].id: ids[owner[k]] for k in sorted(owner)},  # in file order
        manager_ranking=[(ids[j], float(summed[eligible.index(j)])) for j in ranking],
        manager_votsws={ids[j]: float(votsws[c, j]) for j, c in assigned.items()},
        overrating=w_co, unassigned=[managers[k].id for k in sorted(remaining)], rtcm={})


def secondary_devolution(allocation: Allocation, workers: list[TaskSpec]) -> None:
    """Workers (§5.5.1, secondary steps 1-10): fills the RTCM, the assignment, RU and task scores."""
    suitability = allocation.suitability
    pool = np.array([r not in allocation.managers.values() for r in suitability.ids], dtype=bool)
    capable = {}
    vots = {}
    for task in workers:
        vots[task.id], mask = suitability.vots([task.id])
        capable[task.id] = mask & pool
    count = np.sum(list(capable.values()), axis=0) if workers else np.zeros(0)
    rows = [(task, j) for task in workers for j in np.nonzero(capable[task.id])[0]]
    if rows:
        diversity = np.array([(count[j] - 1) / len(workers) for _, j in rows])
        ws, value = task_value(np.array([vots[t.id][j] for t, j in rows]), diversity,
                               np.array([t.vsw for t, _ in rows]))
        for (task, j), w, v, td in zip(rows, ws, value, diversity):
            vots_row = tuple(float(x) for x in vots[task.id][j])
            allocation.rtcm.setdefault(task.id, []).append(Candidate(suitability.ids[j], float(v), float(w),
                                                                     float(td), vots_row))
    for task in workers:
        candidates = allocation.rtcm.get(task.id, [])
        order = rank([suitability.ids.index(c.robot) for c in candidates], [c.value for c in candidates])
        by_robot = {c.robot: c for c in candidates}
        allocation.rtcm[task.id] = [by_robot[suitability.ids[j]] for j in order]
    order = sorted(workers, key=lambda t: len(allocation.rtcm.get(t.id, [])))  # stable: file order on ties
    allocation.rtcm = {t.id: allocation.rtcm.get(t.id, []) for t in order}
    columns = {task: [c.robot for c in column] for task, column in allocation.rtcm.items()}
    counts = {t.id: t.quantity[0] for t in workers}
    allocation.workers, allocation.shortfall = assign_workers(suitability, columns, counts)
    allocation.ru = resource_utilisation(suitability, allocation.workers)
    votsws = {(task, c.robot): c.votsws for task, column in allocation.rtcm.items() for c in column}
    allocation.task_scores = {task: normalised({r: votsws[task, r] for r in robots})
                              for task, robots in allocation.workers.items()}


def assign_workers(suitability: Suitability, columns: dict[str, list[str]], counts: dict[str, int]):
    """Secondary steps 6-8: each task in ``columns`` order takes ``counts[task]`` robots from the top of its
    column, skipping robots that cannot run it beside their tasks so far. Returns (workers, shortfall)."""
    held: dict[str, list[str]] = {}
    workers, shortfall = {}, {}
    for task, column in columns.items():
        chosen = []
        for robot in column:
            if len(chosen) == counts[task]:
                break
            current = held.get(robot, [])
            concurrent = all(task in suitability.tasks[k].concurrent or k in suitability.tasks[task].concurrent
                             for k in current)
            if concurrent and suitability.fits(suitability.ids.index(robot), [*current, task]):
                chosen.append(robot)
                held.setdefault(robot, []).append(task)
        workers[task] = chosen
        if len(chosen) < counts[task]:
            shortfall[task] = counts[task] - len(chosen)
    return workers, shortfall


def resource_utilisation(suitability: Suitability, workers: dict[str, list[str]], also=()) -> dict:
    """Secondary step 9: robot -> worker task -> category -> the task's RU [on] vector if the robot holds the
    task (and its initial RU is on), else its [off] vector; for the robots holding a worker task and the robots
    ``also`` (those that just lost theirs)."""
    holders = [robot for robots in workers.values() for robot in robots]
    ru = {}
    for robot in dict.fromkeys([*holders, *also]):
        ru[robot] = {}
        for task_id in workers:
            task = suitability.tasks[task_id]
            on = robot in workers[task_id] and task.initial_ru == "on"
            ru[robot][task_id] = {cat: (task.ru_on if on else task.ru_off)[cat] for cat in CATEGORIES
                                  if cat in task.ru_on}
    return ru


def normalised(values: dict[str, float]) -> dict[str, float]:
    """Each value over the largest, (5.6) and (5.21)-(5.22); all zero stays zero."""
    top = max(values.values(), default=0.0)
    return {k: (v / top if top > 0 else 0.0) for k, v in values.items()}
