"""Fuzzy inference systems of Chand (2011) ch.5, built from data tables, and the robot capability scores they give
(§5.3, Figs 5.6-5.10, Tables 5.1-5.19; spec §3.3-3.4).

Every FIS is a row of tables in ``data/allocation/fis.toml`` (membership functions, rule table, settings of Table
5.1): :func:`systems` reads it once and builds a :class:`FuzzySystem` per table, cached, so one evaluation costs
only the arithmetic. The inference is MATLAB's Mamdani (the thesis used the MATLAB 2007a Fuzzy Logic Toolbox):
rule firing = min (AND) or max (OR) of the antecedent memberships, ``not X`` = 1 - mu_X, times the rule weight;
implication clips each rule's output set at its firing (min); aggregation **sums** the clipped sets rule by rule
(Table 5.1: "sum", chosen for a gradual output); defuzzification is the centroid over 101 samples of the output
range (MATLAB's default), ``sum(x mu) / sum(mu)``. Membership functions are scikit-fuzzy's ``trimf``/``trapmf``,
which are MATLAB's.

Why not scikit-fuzzy's control API (``skfuzzy.control``): it cannot express Table 5.1. Its accumulation merges
the firings of all rules that conclude the same term into one cut of that term and then takes the **max** over
terms; MATLAB's sum aggregation adds every rule's clipped set. With several rules on one term (every rule table
here) the two give different centroids. It is also slow: a Python object walk per rule per evaluation
(``teamsim bench allocate`` measures both on the same FIS). So this module evaluates the rule tables itself,
vectorised over a batch of inputs with numpy. With ``aggregation = "max"`` it reproduces the control API, which
the tests check.

Inputs outside a variable's range are clipped to it, as MATLAB's ``evalfis`` does.

Capability scores (the VOM simplified to one score per resource, r_jRCS_type):

- processing: the MC or the PC FIS by the robot's class (benchmark, memory);
- communication: bandwidth and range;
- sensing: the IR cascade of Fig 5.9 (sensor score -> obstacle avoidance and mapping/exploration -> overall);
  only IR sensors are scored, as in the thesis (``RCS_sense = RCS_sense1``);
- actuation: the cascade of Fig 5.10 (base performance and base size -> overall). The base size rules depend on
  the size a task asks for ('any', 'small', 'medium', 'large'), so the actuation score does too.
"""
from __future__ import annotations

import functools
import tomllib
from dataclasses import dataclass
from importlib import resources

import numpy as np
import skfuzzy

from teamsim.config import ConfigError

FIS_TABLES = "fis.toml"
SIZES = ("any", "small", "medium", "large")
_SHAPES = {"tri": (skfuzzy.trimf, 3), "trap": (skfuzzy.trapmf, 4)}


def data_file(name: str):
    """A file of ``controllers/allocation/data`` (package data)."""
    return resources.files("teamsim.controllers.allocation").joinpath("data", name)


@dataclass(frozen=True)
class Variable:
    """One input or output: its range, its terms and their membership functions, and optional grade values."""
    name: str
    lo: float
    hi: float
    terms: tuple[str, ...]
    shapes: tuple[tuple[str, tuple[float, ...]], ...]
    reference: dict

    def memberships(self, x: np.ndarray) -> np.ndarray:
        """(B,) crisp values -> (B, terms) degrees; values are clipped to the range first."""
        x = np.clip(np.asarray(x, dtype=float), self.lo, self.hi)
        return np.stack([_SHAPES[kind][0](x, params) for kind, params in self.shapes], axis=1)

    def crisp(self, value, field: str) -> float:
        """A number, or a grade name with a reference value (Table 5.23's small/medium/large)."""
        if isinstance(value, str):
            if value not in self.reference:
                raise ConfigError(f"{field}: unknown grade {value!r}; allowed: a number or "
                                  f"{', '.join(self.reference)}")
            return float(self.reference[value])
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"{field}: expected a number, got {value!r}")
        return float(value)


@dataclass(frozen=True)
class RuleTrace:
    number: int
    text: str
    firing: float  # antecedent degree times the rule weight


@dataclass(frozen=True)
class Trace:
    """What one FIS did for one input: for ``--explain``."""
    name: str
    title: str
    inputs: dict
    fired: tuple[RuleTrace, ...]
    outputs: dict


class FuzzySystem:
    """A Mamdani FIS built from one ``[fis.NAME]`` table (see the module docstring for the inference)."""

    def __init__(self, name: str, table: dict, rules: list, mf_sets: dict, settings: dict):
        self.name = name
        self.title = table.get("title", name)
        self.inputs = tuple(_variable(f"fis.{name}.inputs", spec, mf_sets) for spec in table["inputs"])
        self.outputs = tuple(_variable(f"fis.{name}.outputs", spec, mf_sets) for spec in table["outputs"])
        self.aggregation = settings["aggregation"]
        if (settings["and"], settings["or"], settings["implication"], settings["defuzzification"]) != \
                ("min", "max", "min", "centroid") or self.aggregation not in ("sum", "max"):
            raise ConfigError("settings: supported are and=min, or=max, implication=min, aggregation=sum|max, "
                              "defuzzification=centroid (Table 5.1)")
        n_in, n_out = len(self.inputs), len(self.outputs)
        count = len(rules)
        self.antecedent = np.full((count, n_in), -1)
        self.negated = np.zeros((count, n_in), dtype=bool)
        self.use_or = np.zeros(count, dtype=bool)
        self.consequent = np.full((count, n_out), -1)
        self.weight = np.ones(count)
        self.weight_param: dict[int, str] = {}
        for r, row in enumerate(rules):
            where = f"fis.{name}.rules[{r}]"
            if len(row) != n_in + n_out + 2:
                raise ConfigError(f"{where}: expected {n_in} inputs, connection, {n_out} outputs and a weight")
            for i, cell in enumerate(row[:n_in]):
                if cell != "-":
                    self.negated[r, i] = cell.startswith("not ")
                    self.antecedent[r, i] = _term(self.inputs[i], cell.removeprefix("not "), where)
            if row[n_in] not in ("-", "and", "or"):
                raise ConfigError(f"{where}: connection must be '-', 'and' or 'or'")
            self.use_or[r] = row[n_in] == "or"
            for o, cell in enumerate(row[n_in + 1:n_in + 1 + n_out]):
                if cell != "-":
                    self.consequent[r, o] = _term(self.outputs[o], cell, where)
            weight = row[-1]
            if isinstance(weight, str):
                self.weight_param[r] = weight
            else:
                self.weight[r] = float(weight)
        self.parameters = frozenset(self.weight_param.values())
        points = settings["points"]
        self._grid = [np.linspace(v.lo, v.hi, points) for v in self.outputs]
        self._output_sets = [v.memberships(grid).T for v, grid in zip(self.outputs, self._grid)]  # (terms, P)

    def firing(self, x: np.ndarray, params: dict) -> np.ndarray:
        """(B, inputs) -> (B, rules): antecedent degree times rule weight."""
        batch = x.shape[0]
        degree_and = np.ones((batch, len(self.weight)))
        degree_or = np.zeros((batch, len(self.weight)))
        for i, variable in enumerate(self.inputs):
            used = np.nonzero(self.antecedent[:, i] >= 0)[0]
            if used.size == 0:
                continue
            mu = variable.memberships(x[:, i])[:, self.antecedent[used, i]]
            mu = np.where(self.negated[used, i], 1.0 - mu, mu)
            degree_and[:, used] = np.minimum(degree_and[:, used], mu)
            degree_or[:, used] = np.maximum(degree_or[:, used], mu)
        degree = np.where(self.use_or, degree_or, degree_and)
        weight = np.broadcast_to(self.weight, degree.shape).copy()
        for r, param in self.weight_param.items():
            if param not in params:
                raise ValueError(f"FIS {self.name}: rule weight parameter {param!r} not given")
            weight[:, r] = params[param]
        return degree * weight

    def evaluate(self, x, **params) -> np.ndarray:
        """(B, inputs) crisp inputs -> (B, outputs) crisp outputs. ``params``: named rule weights, each a scalar
        or one value per row."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        firing = self.firing(x, params)
        out = np.empty((x.shape[0], len(self.outputs)))
        for o, variable in enumerate(self.outputs):
            rules = np.nonzero(self.consequent[:, o] >= 0)[0]
            clipped = np.minimum(firing[:, rules, None], self._output_sets[o][self.consequent[rules, o]][None])
            shape = clipped.sum(axis=1) if self.aggregation == "sum" else clipped.max(axis=1)
            area = shape.sum(axis=1)
            grid = self._grid[o]
            # The centroid's numerator is a per-row numpy sum, not ``shape @ grid``: BLAS (OpenBLAS dgemv) sums a
            # row in an order that depends on the row's position in the batch, so identical inputs came out
            # 1 ulp apart (0.38743243243243236 vs ...24 for the last of 9 rows), and the devolution broke exact
            # ties by that noise instead of by file order (Fig 7.16's one-explorer choices under W7).
            numerator = (shape * grid).sum(axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                # MATLAB returns the middle of the range when no rule fires.
                out[:, o] = np.where(area > 0, numerator / area, 0.5 * (variable.lo + variable.hi))
        return out

    def trace(self, x, **params) -> Trace:
        """Inputs, fired rules (firing > 0) and outputs for one input row."""
        row = np.asarray(x, dtype=float).reshape(1, -1)
        firing = self.firing(row, params)[0]
        fired = tuple(RuleTrace(r + 1, self.rule_text(r), float(f)) for r, f in enumerate(firing) if f > 0)
        outputs = self.evaluate(row, **params)[0]
        return Trace(self.name, self.title, {v.name: float(value) for v, value in zip(self.inputs, row[0])}, fired,
                     {v.name: float(value) for v, value in zip(self.outputs, outputs)})

    def rule_text(self, r: int) -> str:
        parts = [f"{v.name} is {'not ' if self.negated[r, i] else ''}{v.terms[self.antecedent[r, i]]}"
                 for i, v in enumerate(self.inputs) if self.antecedent[r, i] >= 0]
        then = [f"{v.name} is {v.terms[self.consequent[r, o]]}"
                for o, v in enumerate(self.outputs) if self.consequent[r, o] >= 0]
        weight = self.weight_param.get(r, f"{self.weight[r]:g}")
        return f"if {(' or ' if self.use_or[r] else ' and ').join(parts)} then {', '.join(then)} (w {weight})"


def _variable(where: str, spec: dict, mf_sets: dict) -> Variable:
    mfs = spec["mfs"]
    if isinstance(mfs, str):
        if mfs not in mf_sets:
            raise ConfigError(f"{where}: unknown membership set {mfs!r}; known: {', '.join(mf_sets)}")
        mfs = mf_sets[mfs]
    shapes = []
    for term, shape in mfs.items():
        kind, *params = shape
        if kind not in _SHAPES or len(params) != _SHAPES[kind][1] or list(params) != sorted(params):
            raise ConfigError(f"{where}.{spec['name']}.{term}: expected ['tri', a, b, c] or ['trap', a, b, c, d] "
                              "with a <= b <= ...")
        shapes.append((kind, tuple(float(p) for p in params)))
    lo, hi = spec["range"]
    return Variable(spec["name"], float(lo), float(hi), tuple(mfs), tuple(shapes), dict(spec.get("reference", {})))


def _term(variable: Variable, term: str, where: str) -> int:
    if term not in variable.terms:
        raise ConfigError(f"{where}: {variable.name} has no term {term!r}; terms: {', '.join(variable.terms)}")
    return variable.terms.index(term)


@functools.cache
def tables() -> dict:
    """``fis.toml`` as read."""
    with data_file(FIS_TABLES).open("rb") as stream:
        return tomllib.load(stream)


@functools.cache
def systems() -> dict[str, FuzzySystem]:
    """Every FIS of ``fis.toml``, built once. A table with ``rule_sets`` gives one system per set, named
    ``NAME:SET`` (the base size FIS per required size)."""
    data = tables()
    built = {}
    for name, table in data["fis"].items():
        if "rule_sets" in table:
            for variant, rules in table["rule_sets"].items():
                built[f"{name}:{variant}"] = FuzzySystem(name, table, rules, data["mfs"], data["settings"])
        else:
            built[name] = FuzzySystem(name, table, table["rules"], data["mfs"], data["settings"])
    return built


def control_api(system: FuzzySystem, **params):
    """The same FIS in scikit-fuzzy's control API, for comparison (tests, ``teamsim bench allocate``). The API
    aggregates by max (per term, then over terms), so it equals ``system`` built with ``aggregation = "max"``,
    up to its centroid: a piecewise-linear integral where MATLAB sums 101 samples. Inputs are sampled at 1001
    points so that their membership functions keep their corners."""
    from skfuzzy import control

    def variable(kind, v: Variable, points: int):
        made = kind(np.linspace(v.lo, v.hi, points), v.name)
        for term, (shape, params_) in zip(v.terms, v.shapes):
            made[term] = _SHAPES[shape][0](made.universe, params_)
        return made

    inputs = [variable(control.Antecedent, v, 1001) for v in system.inputs]
    outputs = [variable(control.Consequent, v, tables()["settings"]["points"]) for v in system.outputs]
    rules = []
    for r in range(len(system.weight)):
        terms = []
        for i, v in enumerate(inputs):
            if system.antecedent[r, i] >= 0:
                term = v[system.inputs[i].terms[system.antecedent[r, i]]]
                terms.append(~term if system.negated[r, i] else term)
        antecedent = terms[0]
        for term in terms[1:]:
            antecedent = (antecedent | term) if system.use_or[r] else (antecedent & term)
        weight = float(params[system.weight_param[r]]) if r in system.weight_param else system.weight[r]
        rules.append(control.Rule(antecedent, [v[system.outputs[o].terms[system.consequent[r, o]]] % weight
                                               for o, v in enumerate(outputs) if system.consequent[r, o] >= 0]))
    return control.ControlSystemSimulation(control.ControlSystem(rules), cache=False)  # no stored answers


def run(name: str, x, traces: list | None = None, **params) -> np.ndarray:
    """Evaluate FIS ``name`` on a batch; when ``traces`` is a list (batch of one), append its :class:`Trace`."""
    system = systems()[name]
    if traces is not None:
        traces.append(system.trace(x, **params))
    return system.evaluate(x, **params)


# ---------------------------------------------------------------------------------------------------------------
# Capability scores (the VOM of §5.3 simplified to r_jRCS_type).

RESOURCES = ("proc", "comm", "sense", "act")


def capability_scores(robots, size: str = "any", traces: list | None = None) -> np.ndarray:
    """(robots, 4) scores [proc, comm, sense, act] for :class:`~teamsim.controllers.allocation.spec.RobotSpec`
    objects, the actuation score for a task that asks for robots of ``size``. Pass ``traces`` (a list) with one
    robot to collect every FIS's :class:`Trace` in cascade order."""
    if size not in SIZES:
        raise ConfigError(f"size {size!r} unknown; allowed: {', '.join(SIZES)}")
    scores = np.empty((len(robots), 4))
    pc = np.array([r.proc_class == "pc" for r in robots], dtype=bool)
    proc = np.array([[r.benchmark, r.memory] for r in robots], dtype=float).reshape(-1, 2)
    for kind, rows in (("pc", pc), ("mc", ~pc)):
        if rows.any():
            scores[rows, 0] = run(f"processing_{kind}", proc[rows], traces)[:, 0]
    scores[:, 1] = run("communication", [[r.bandwidth, r.comm_range] for r in robots], traces)[:, 0]
    ir = np.array([[r.ir_quantity, r.ir_range, r.ir_distribution] for r in robots], dtype=float)
    sensor = run("sensor_score", ir[:, :2], traces)[:, 0]
    avoidance = run("obstacle_avoidance", np.column_stack([ir[:, 2], sensor]), traces)[:, 0]
    mapping = run("mapping_exploration", np.column_stack([ir[:, 2], sensor]), traces)[:, 0]
    scores[:, 2] = run("sensing", np.column_stack([avoidance, mapping]), traces)[:, 0]
    act = np.array([[r.operation_h, r.radius, r.speed, r.traversability] for r in robots], dtype=float)
    performance = run("base_performance", act[:, 2:4], traces)[:, 0]
    size_score = run(f"base_size:{size}", act[:, 1:2], traces)[:, 0]
    scores[:, 3] = run("actuation", np.column_stack([act[:, 0], performance, size_score]), traces)[:, 0]
    return scores


def published_misses(robot, scores, tolerance: float = 0.02) -> list[tuple[str, float, float, str]]:
    """(resource, ours, published, cause) for each score of ``robot`` more than ``tolerance`` from the one its
    file says the thesis published (rounded to 2 decimals there); the cause is the file's note, if any."""
    return [(resource, float(ours), robot.published[resource], robot.published_note.get(resource, "cause unknown"))
            for resource, ours in zip(RESOURCES, scores)
            if resource in robot.published and abs(ours - robot.published[resource]) > tolerance + 1e-9]


def quantity(area, ratio, output: str, field: str) -> int:
    """Robot quantity criteria FIS (Tables 5.23-5.24): the number of explorers or planners for an area (m^2 or
    small/medium/large) and an explorer-planner ratio (1-10 or low/medium/high).

    The thesis's example, [1600 m^2, medium], gives raw outputs 4.47 explorers and 1.59 planners and the thesis
    allocates 4 and 1: the outputs are floored (the rounding is not stated; rounding would give 2 planners)."""
    system = systems()["robot_quantity"]
    names = [v.name for v in system.outputs]
    if output not in names:
        raise ConfigError(f"{field}.output: unknown {output!r}; allowed: {', '.join(names)}")
    x = [system.inputs[0].crisp(area, f"{field}.area"), system.inputs[1].crisp(ratio, f"{field}.ratio")]
    return int(np.floor(system.evaluate([x])[0, names.index(output)]))
