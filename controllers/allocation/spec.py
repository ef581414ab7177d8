"""Task and robot specifications of Chand (2011) §5.2-5.3 (Figs 5.2-5.3; spec §3.1-3.2): the schema, loading from
TOML files, and validation in one place.

A task file holds ``[tasks.ID]`` tables, a robot file ``[robots.ID]`` tables; order in the file is kept and is the
final tie-break of every ranking. The thesis's example (Tables 5.20-5.22, with the feedback weights of Table 5.29)
ships as ``data/allocation/thesis_tasks.toml`` and ``thesis_robots.toml``; those files document every field.

Requirement grades 'low', 'medium', 'high' map to 0, 0.35, 0.65 (§5.2). Which fields a basic user may leave out
(the '#' marks of Fig 5.2) cannot be read from the thesis, so the required ones are ours: ``role`` and the four
resource grades. Defaults: name = the task's ID; type continuous; VSW equal (0.25 each); size any; worker
quantity [1, 1, max] with max the largest initial quantity of the worker tasks (§5.4); no concurrent tasks;
initial RU on; no RU mapping; no feedback weights (then only complete failures can be detected).

Every error is a :class:`~teamsim.config.ConfigError` of one line naming the file and the field, e.g.
``tasks.toml: tasks.W2.vsw: weights must sum to 1 (sum 0.9)``.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from teamsim.config import ConfigError
from teamsim.controllers.allocation.fuzzy_capability import RESOURCES, SIZES, data_file, quantity

GRADES = {"low": 0.0, "medium": 0.35, "high": 0.65}
CATEGORIES = ("plan", "comm", "sense", "act")  # resource utilisation / achievement categories (5.1), (5.7)
PROC_CLASSES = ("mc", "pc")
THESIS_TASKS = "thesis_tasks.toml"
THESIS_ROBOTS = "thesis_robots.toml"
_MISSING = object()


@dataclass(frozen=True)
class FeedbackSpec:
    """Feedback coordination weights of one worker task (Table 5.29, (5.10)-(5.20))."""
    achievement: dict[str, tuple[str, ...]]  # category -> achievement sub-category names (5.7)
    ka: dict[str, tuple[float, ...] | str]  # category -> sub-category weights KA (5.10), or "max"
    ws: tuple[float, ...]  # achievement-success bias weights WS (5.11), per category
    ku: dict[str, tuple[float, ...]]  # rate categories -> RU sub-category weights KU (5.17)
    wl: tuple[float, ...]  # load-success bias weights WL (5.18)
    tes_threshold: float  # TES_T (5.19); -1 disables partial-failure detection
    otes_threshold: float  # OTES_T (5.20); -1 disables poor-performance detection


@dataclass(frozen=True)
class TaskSpec:
    """One task of the global task (§5.2, Fig 5.2)."""
    id: str
    role: str  # "manager" or "worker"
    name: str
    kind: str  # "one-off" or "continuous"
    proc_class: str  # "mc" or "pc"
    grades: tuple[str, str, str, str]  # proc, comm, sense, act as the user wrote them
    size: str  # actuation size: any, small, medium, large
    vsw: tuple[float, float, float, float]  # VOTS summation weights (5.2)
    group_task: str = ""
    quantity: tuple[int, int, int] = (1, 1, 1)  # initial, minimum, maximum robots
    concurrent: frozenset[str] = frozenset()
    initial_ru: str = "on"
    ru_on: dict[str, tuple[float, ...]] = field(default_factory=dict)  # (5.1): -1 event-driven, 0 off, >0 Hz
    ru_off: dict[str, tuple[float, ...]] = field(default_factory=dict)
    feedback: FeedbackSpec | None = None

    @property
    def requirement(self) -> tuple[float, float, float, float]:
        """t_iRCS_type for proc, comm, sense, act."""
        return tuple(GRADES[g] for g in self.grades)


@dataclass(frozen=True)
class RobotSpec:
    """One robot's vector of merit (§5.3, (5.3)): only IR sensing is scored, as in the thesis."""
    id: str
    type: str
    proc_class: str
    benchmark: float  # MC: CoreMark scaled to [0, 10]; PC: MATLAB bench, [0, 5]
    memory: float  # MC: MB; PC: GB
    bandwidth: float  # Mbit/s
    comm_range: float  # m
    ir_quantity: float
    ir_range: float  # m
    ir_distribution: float  # degrees of the perimeter covered
    operation_h: float
    radius: float  # enclosing radius, m
    speed: float  # m/s
    traversability: float  # difficult terrain, 0-1
    published: dict[str, float] = field(default_factory=dict)  # the thesis's scores, for comparison only
    published_note: dict[str, str] = field(default_factory=dict)  # why ours differ, where they do


class _Table:
    """Reads the fields of one TOML table, naming ``where`` in every error, and rejects unknown fields."""

    def __init__(self, data, where: str):
        if not isinstance(data, dict):
            raise ConfigError(f"{where}: expected a table")
        self.data, self.where, self.read = data, where, set()

    def get(self, name: str, parse, default=_MISSING, expected: str = ""):
        self.read.add(name)
        if name not in self.data:
            if default is _MISSING:
                raise ConfigError(f"{self.where}.{name}: missing{'; expected ' + expected if expected else ''}")
            return default
        return parse(self.data[name], f"{self.where}.{name}")

    def done(self) -> None:
        unknown = [k for k in self.data if k not in self.read]
        if unknown:
            raise ConfigError(f"{self.where}.{unknown[0]}: unknown field; allowed: {', '.join(sorted(self.read))}")


def _number(value, where: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not lo <= value <= hi:
        bounds = f" in [{lo:g}, {hi:g}]" if math.isfinite(lo) or math.isfinite(hi) else ""
        raise ConfigError(f"{where}: expected a number{bounds}, got {value!r}")
    return float(value)


def _numbers(value, where: str, length: int | None = None, lo: float = -math.inf, hi: float = math.inf):
    if not isinstance(value, list) or (length is not None and len(value) != length) or not value:
        raise ConfigError(f"{where}: expected a list of {length or 'one or more'} numbers, got {value!r}")
    return tuple(_number(v, f"{where}[{k}]", lo, hi) for k, v in enumerate(value))


def _choice(value, where: str, allowed, what: str = "value") -> str:
    if value not in allowed:
        raise ConfigError(f"{where}: unknown {what} {value!r}; allowed: {', '.join(allowed)}")
    return value


def _grade(value, where: str) -> str:
    if isinstance(value, list) and len(value) == 1:  # the thesis writes [medium]
        value = value[0]
    return _choice(value, where, GRADES, "grade")


def _weights(value, where: str, length: int) -> tuple[float, ...]:
    weights = _numbers(value, where, length, 0.0, 1.0)
    if abs(sum(weights) - 1.0) > 1e-6:
        raise ConfigError(f"{where}: weights must sum to 1 (sum {sum(weights):g})")
    return weights


def _text(value, where: str) -> str:
    if not isinstance(value, str) or not value:
        raise ConfigError(f"{where}: expected a non-empty string, got {value!r}")
    return value


def _categories(value, where: str, parse) -> dict:
    table = _Table(value, where)
    parsed = {cat: table.get(cat, parse, None) for cat in CATEGORIES}
    table.done()
    return {cat: v for cat, v in parsed.items() if v is not None}


def _load(path: Path | None, default: str, key: str) -> tuple[dict, str]:
    source = data_file(default) if path is None else Path(path)
    name = default if path is None else str(path)
    try:
        with source.open("rb") as stream:
            data = tomllib.load(stream)
    except FileNotFoundError:
        raise ConfigError(f"{name}: no such file") from None
    except OSError as exc:  # a folder, a name too long, no permission
        raise ConfigError(f"{name}: cannot read ({exc.strerror or exc})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{name}: not valid TOML ({exc})") from None
    if not isinstance(data.get(key), dict) or not data[key]:
        raise ConfigError(f"{name}: {key}: missing; expected one [{key}.ID] table per {key[:-1]}")
    unknown = [k for k in data if k != key]
    if unknown:
        raise ConfigError(f"{name}: {unknown[0]}: unknown top-level table; expected only [{key}.ID] tables")
    return data[key], name


# ---------------------------------------------------------------------------------------------------------------


def load_tasks(path: Path | str | None = None) -> list[TaskSpec]:
    """The tasks of a TOML file, validated; None: the thesis's Tables 5.20-5.21."""
    tables, name = _load(path, THESIS_TASKS, "tasks")
    try:
        raw = [_task(task_id, table) for task_id, table in tables.items()]
        ids = [t.id for t in raw]
        workers = [t for t in raw if t.role == "worker"]
        largest = max((t.quantity[0] for t in workers), default=1)
        tasks = []
        for task in raw:
            if task.role == "worker" and task.quantity[2] == 0:  # maximum defaults to the largest initial (§5.4)
                task = replace(task, quantity=(task.quantity[0], task.quantity[1], largest))
            for other in sorted(task.concurrent):  # the same error in every process
                _choice(other, f"tasks.{task.id}.concurrent", [i for i in ids if i != task.id], "task")
            tasks.append(task)
    except ConfigError as exc:
        raise ConfigError(f"{name}: {exc}") from None
    return tasks


def _task(task_id: str, data) -> TaskSpec:
    where = f"tasks.{task_id}"
    t = _Table(data, where)
    role = t.get("role", lambda v, w: _choice(v, w, ("manager", "worker"), "role"), expected="manager or worker")
    proc = t.get("processing", _processing, expected="[mc|pc, low|medium|high]")
    comm = t.get("communication", _grade, expected="low, medium or high")
    sense = t.get("sensing", _grade, expected="low, medium or high")
    act_grade, size = t.get("actuation", _actuation, expected="low|medium|high or [grade, any|small|medium|large]")
    common = dict(
        id=task_id, role=role, name=t.get("name", _text, task_id),
        kind=t.get("type", lambda v, w: _choice(v, w, ("one-off", "continuous"), "type"), "continuous"),
        proc_class=proc[0], grades=(proc[1], comm, sense, act_grade), size=size,
        vsw=t.get("vsw", lambda v, w: _weights(v, w, 4), (0.25, 0.25, 0.25, 0.25)))
    if role == "manager":
        t.done()
        return TaskSpec(**common)
    explicit = t.get("quantity", _quantity, None)
    criteria = t.get("quantity_criteria", _quantity_criteria, None)
    if explicit is not None and criteria is not None:
        raise ConfigError(f"{where}.quantity_criteria: give quantity or quantity_criteria, not both")
    count = explicit or ((criteria, 1, 0) if criteria is not None else (1, 1, 0))
    if count[2] and not count[1] <= count[0] <= count[2]:
        raise ConfigError(f"{where}.quantity: expected [initial, minimum, maximum] with minimum <= initial <= "
                          f"maximum, got {list(count)}")
    ru = t.get("ru", _ru_mapping, {})
    task = TaskSpec(
        **common, group_task=t.get("group_task", _text, ""), quantity=count,
        concurrent=frozenset(t.get("concurrent", _task_ids, ())),
        initial_ru=t.get("initial_ru", lambda v, w: _choice(v, w, ("on", "off")), "on"),
        ru_on=ru.get("on", {}), ru_off=ru.get("off", {}),
        feedback=t.get("feedback", _feedback, None))
    t.done()
    if task.feedback:
        for cat, weights in task.feedback.ku.items():
            if len(weights) != len(task.ru_on.get(cat, ())):
                raise ConfigError(f"{where}.feedback.ku.{cat}: one weight per ru.on.{cat} entry "
                                  f"({len(task.ru_on.get(cat, ()))})")
    return task


def _processing(value, where: str) -> tuple[str, str]:
    if not isinstance(value, list) or len(value) != 2:
        raise ConfigError(f"{where}: expected [mc|pc, low|medium|high], got {value!r}")
    return _choice(value[0], f"{where}[0]", PROC_CLASSES, "processor class"), _grade(value[1], f"{where}[1]")


def _actuation(value, where: str) -> tuple[str, str]:
    if isinstance(value, list) and len(value) == 2:
        return _grade(value[0], f"{where}[0]"), _choice(value[1], f"{where}[1]", SIZES, "size")
    return _grade(value, where), "any"


def _quantity(value, where: str) -> tuple[int, int, int]:
    if isinstance(value, int) and not isinstance(value, bool):
        value = [value, 1, 0]
    elif not (isinstance(value, list) and len(value) == 3):
        raise ConfigError(f"{where}: expected a whole number or [initial, minimum, maximum], got {value!r}")
    numbers = _numbers(value, where, 3, 0)
    if any(n != int(n) for n in numbers) or numbers[0] < 1:
        raise ConfigError(f"{where}: expected whole numbers with initial >= 1, got {value!r}")
    return tuple(int(n) for n in numbers)


def _quantity_criteria(value, where: str) -> int:
    t = _Table(value, where)
    area = t.get("area", lambda v, w: v, expected="m^2 or small/medium/large")
    ratio = t.get("ratio", lambda v, w: v, expected="1-10 or low/medium/high")
    output = t.get("output", _text, expected="explorers or planners")
    t.done()
    count = quantity(area, ratio, output, where)
    if count < 1:
        raise ConfigError(f"{where}: the robot quantity FIS gives {count} {output}; need at least 1")
    return count


def _task_ids(value, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of task IDs, got {value!r}")
    return tuple(value)


def _ru_mapping(value, where: str) -> dict:
    t = _Table(value, where)
    on = t.get("on", lambda v, w: _categories(v, w, lambda x, y: _numbers(x, y, None, -1)), expected="a table")
    off = t.get("off", lambda v, w: _categories(v, w, lambda x, y: _numbers(x, y, None, -1)), expected="a table")
    t.done()
    for cat in CATEGORIES:
        if len(on.get(cat, ())) != len(off.get(cat, ())):
            raise ConfigError(f"{where}.off.{cat}: needs as many entries as on.{cat}")
    return {"on": on, "off": off}


def _feedback(value, where: str) -> FeedbackSpec:
    t = _Table(value, where)
    achievement = t.get("achievement", lambda v, w: _categories(v, w, _names), expected="sub-category names")
    given_ka = t.get("ka", lambda v, w: _categories(v, w, _ka), {})
    ku = t.get("ku", lambda v, w: _categories(v, w, _ka), {})
    ws = t.get("ws", lambda v, w: _weights(v, w, 4), expected="4 weights")
    wl = t.get("wl", lambda v, w: _weights(v, w, 4), expected="4 weights")
    tes = t.get("tes_threshold", lambda v, w: _number(v, w, -1, 1), expected="-1 (off) to 1")
    otes = t.get("otes_threshold", lambda v, w: _number(v, w, -1, 1), expected="-1 (off) to 1")
    t.done()
    for cat, weight in zip(CATEGORIES, ws):
        if weight > 0 and cat not in achievement:
            raise ConfigError(f"{where}.achievement.{cat}: missing; ws gives {cat} weight {weight:g}")
    for cat in given_ka:
        if cat not in achievement:
            raise ConfigError(f"{where}.ka.{cat}: no achievement sub-categories for {cat}")
    for cat, weights in ku.items():
        if weights == "max":
            raise ConfigError(f"{where}.ku.{cat}: expected weights summing to 1")
    ka = {}
    for cat, names in achievement.items():
        ka[cat] = given_ka.get(cat, (1.0,) if len(names) == 1 else None)
        if ka[cat] is None:
            raise ConfigError(f"{where}.ka.{cat}: missing; {len(names)} sub-categories need weights or 'max'")
        if ka[cat] != "max" and len(ka[cat]) != len(names):
            raise ConfigError(f"{where}.ka.{cat}: one weight per sub-category ({len(names)})")
    return FeedbackSpec(achievement, ka, ws, ku, wl, tes, otes)


def _names(value, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of sub-category names, got {value!r}")
    return tuple(value)


def _ka(value, where: str):
    if value == "max":
        return "max"
    if not isinstance(value, list):
        raise ConfigError(f"{where}: expected weights summing to 1 or 'max', got {value!r}")
    return _weights(value, where, len(value))


# ---------------------------------------------------------------------------------------------------------------


def load_robots(path: Path | str | None = None) -> list[RobotSpec]:
    """The robots of a TOML file, validated; None: the thesis's Table 5.22."""
    tables, name = _load(path, THESIS_ROBOTS, "robots")
    try:
        return [_robot(robot_id, table) for robot_id, table in tables.items()]
    except ConfigError as exc:
        raise ConfigError(f"{name}: {exc}") from None


def _robot(robot_id: str, data) -> RobotSpec:
    where = f"robots.{robot_id}"
    t = _Table(data, where)
    proc = t.get("processing", _robot_processing, expected="[benchmark, memory, mc|pc]")
    comm = t.get("communication", lambda v, w: _numbers(v, w, 2, 0), expected="[Mbit/s, range m]")
    sense = t.get("sensing", _sensing, expected="IR [quantity, range m, distribution deg]")
    act = t.get("actuation", _robot_actuation, expected="[operation h, radius m, speed m/s, traversability]")
    published = t.get("published", lambda v, w: _categories_of(v, w, RESOURCES, _number), {})
    notes = t.get("published_note", lambda v, w: _categories_of(v, w, RESOURCES, _text), {})
    robot = RobotSpec(robot_id, t.get("type", _text, ""), proc[2], proc[0], proc[1], *comm, *sense, *act,
                      published=published, published_note=notes)
    t.done()
    return robot


def _categories_of(value, where: str, keys, parse) -> dict:
    table = _Table(value, where)
    parsed = {k: table.get(k, parse, None) for k in keys}
    table.done()
    return {k: v for k, v in parsed.items() if v is not None}


def _robot_processing(value, where: str):
    if not isinstance(value, list) or len(value) != 3:
        raise ConfigError(f"{where}: expected [benchmark, memory, mc|pc], got {value!r}")
    kind = _choice(value[2], f"{where}[2]", PROC_CLASSES, "processor class")
    return (*_numbers(value[:2], where, 2, 0), kind)


def _sensing(value, where: str):
    quantity, sensing_range, distribution = _numbers(value, where, 3, 0)
    if distribution > 360:
        raise ConfigError(f"{where}[2]: distribution must be in [0, 360] degrees, got {distribution:g}")
    return quantity, sensing_range, distribution


def _robot_actuation(value, where: str):
    values = _numbers(value, where, 4, 0)
    if values[3] > 1:
        raise ConfigError(f"{where}[3]: traversability must be in [0, 1], got {values[3]:g}")
    return values
