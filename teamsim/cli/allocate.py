"""``teamsim allocate [TASKS ROBOTS] [--json] [--explain]``: Chand's fuzzy task allocation (2011 ch.5).

Without files it runs the thesis's example (Tables 5.20-5.22). It prints the capability scores (beside the
thesis's published ones, naming each difference over 0.02 and its cause), the managers, the robot-task
capability matrix and the allocation; ``--json`` writes the same data as JSON; ``--explain`` adds, for every FIS
evaluated, its inputs, the rules that fired (firing strength times weight) and its output.
"""
from __future__ import annotations

import dataclasses
import json

import numpy as np

from teamsim.config import ConfigError
from teamsim.controllers.allocation.devolution import Allocation, allocate, vsw_params
from teamsim.controllers.allocation.fuzzy_capability import Trace, capability_scores, published_misses, run
from teamsim.controllers.allocation.spec import RESOURCES, load_robots, load_tasks


def cmd_allocate(args) -> int:
    if (args.tasks is None) != (args.robots is None):
        raise ConfigError("give both TASKS and ROBOTS files, or neither for the thesis's example")
    tasks = load_tasks(args.tasks)
    robots = load_robots(args.robots)
    allocation = allocate(tasks, robots)
    report = allocation_report(allocation, explain=args.explain)
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print(format_report(report, allocation))
    return 0


def allocation_report(allocation: Allocation, explain: bool = False) -> dict:
    """Everything ``teamsim allocate`` shows, as JSON-ready data."""
    suitability = allocation.suitability
    scores = suitability.scores["any"]
    report = {
        "scores": [{"robot": r.id, "type": r.type, "class": r.proc_class,
                    **{res: round(float(v), 4) for res, v in zip(RESOURCES, scores[j])},
                    "published": r.published,
                    "misses": [{"resource": res, "ours": round(ours, 4), "thesis": thesis, "cause": cause}
                               for res, ours, thesis, cause in published_misses(r, scores[j])]}
                   for j, r in enumerate(suitability.robots)],
        "managers": allocation.managers,
        "manager_ranking": [{"robot": r, "votsws_sum": round(v, 4)} for r, v in allocation.manager_ranking],
        "manager_votsws": {r: round(v, 4) for r, v in allocation.manager_votsws.items()},
        "overrating_w_co": allocation.overrating,
        "unassigned": allocation.unassigned,
        "rtcm": {task: [{"robot": c.robot, "value": round(c.value, 4), "votsws": round(c.votsws, 4),
                         "td": round(c.diversity, 4), "vots": [round(v, 4) for v in c.vots]} for c in column]
                 for task, column in allocation.rtcm.items()},
        "workers": allocation.workers,
        "task_scores": {t: {r: round(v, 4) for r, v in s.items()} for t, s in allocation.task_scores.items()},
        "shortfall": allocation.shortfall,
        "ru": {robot: {task: {cat: list(v) for cat, v in cats.items()} for task, cats in tasks.items()}
               for robot, tasks in allocation.ru.items()},
    }
    if explain:
        report["explain"] = {"robots": _robot_traces(allocation), "task_value": _value_traces(allocation)}
    return report


def _trace_json(trace: Trace) -> dict:
    data = dataclasses.asdict(trace)
    data["fired"] = [{**rule, "firing": round(rule["firing"], 4)} for rule in data["fired"]]
    return data


def _robot_traces(allocation: Allocation) -> dict:
    sizes = [size for size in dict.fromkeys(t.size for t in allocation.tasks.values()) if size != "any"]
    out = {}
    for robot in allocation.suitability.robots:
        traces: list = []
        capability_scores([robot], "any", traces)
        for size in sizes:  # a task that asks for a size: its base size and actuation FISs
            extra: list = []
            capability_scores([robot], size, extra)
            traces += extra[-2:]
        out[robot.id] = [_trace_json(t) for t in traces]
    return out


def _value_traces(allocation: Allocation) -> dict:
    """The VOTSWS/V FIS for every capable single-task pair: managers (TD 0, V unused) and the RTCM."""
    suitability = allocation.suitability
    out = {}
    for task in allocation.tasks.values():
        if task.role == "manager":
            vots, capable = suitability.vots([task.id])
            rows = [(suitability.ids[j], vots[j], 0.0) for j in np.nonzero(capable)[0]]
        else:
            rows = [(c.robot, c.vots, c.diversity) for c in allocation.rtcm.get(task.id, [])]
        out[task.id] = {}
        for robot, vots, diversity in rows:
            traces: list = []
            run("task_value", [*vots, diversity], traces, **vsw_params(task.vsw))
            out[task.id][robot] = _trace_json(traces[0])
    return out


def format_report(report: dict, allocation: Allocation) -> str:
    """The text tables of ``teamsim allocate``."""
    lines = ["capability scores r_jRCS (the thesis's published score in brackets)"]
    width = max(len(row["robot"]) for row in report["scores"])
    lines.append(f"  {'robot':<{width}}  class  " + "  ".join(f"{res:<12}" for res in RESOURCES))
    for row in report["scores"]:
        cells = [f"{row[res]:.3f}" + (f" ({row['published'][res]:.2f})" if res in row["published"] else "")
                 for res in RESOURCES]
        lines.append(f"  {row['robot']:<{width}}  {row['class']:<5}  " + "  ".join(f"{c:<12}" for c in cells))
    misses = [(row["robot"], m) for row in report["scores"] for m in row["misses"]]
    if misses:
        lines.append("  differences from the published scores over 0.02:")
        lines += [f"    {robot} {m['resource']}: {m['ours']:.3f}, thesis {m['thesis']:.2f}: {m['cause']}"
                  for robot, m in misses]
    elif any(row["published"] for row in report["scores"]):
        lines.append("  every published score reproduced within 0.02")
    tasks = allocation.tasks
    lines += ["", "primary devolution (managers); candidates by summed VOTSWS: "
              + (", ".join(f"{r['robot']} {r['votsws_sum']:.3f}" for r in report["manager_ranking"]) or "none")]
    for task, robot in report["managers"].items():
        lines.append(f"  {task:<4} {tasks[task].name:<40} -> {robot} (VOTSWS of its tasks together "
                     f"{report['manager_votsws'][robot]:.3f})")
    if report["overrating_w_co"]:
        lines.append(f"  overrating (5.5) needed: w_CO = {report['overrating_w_co']:g}")
    if report["unassigned"]:
        lines.append(f"  unassigned (no capable robot left): {', '.join(report['unassigned'])}")
    lines += ["", "robot-task capability matrix (tasks in allocation order, candidates by value V)"]
    for task, column in report["rtcm"].items():
        lines.append(f"  {task} {tasks[task].name}: {len(column)} capable")
        lines.append("    rank  robot" + " " * max(0, width - 5) + "  V       VOTSWS  TD    VOTS [proc comm sense act]")
        for k, c in enumerate(column, 1):
            vots = " ".join(f"{v:.2f}" for v in c["vots"])
            lines.append(f"    {k:<4}  {c['robot']:<{max(width, 5)}}  {c['value']:.4f}  {c['votsws']:.4f}  "
                         f"{c['td']:.2f}  [{vots}]")
    lines += ["", "allocation (Table 5.27; worker task score TS in brackets)"]
    lines += [f"  {task:<4} {robot} (manager)" for task, robot in report["managers"].items()]
    for task, robots in report["workers"].items():
        scores = report["task_scores"].get(task, {})
        lines.append(f"  {task:<4} " + (", ".join(f"{r} ({scores[r]:.3f})" for r in robots) or "nobody")
                     + (f"  short of {report['shortfall'][task]}" if task in report["shortfall"] else ""))
    if "explain" in report:
        lines += ["", "explain: capability FISs per robot"]
        for robot, traces in report["explain"]["robots"].items():
            lines.append(f"  {robot}")
            lines += _format_traces(traces, "    ")
        lines += ["", "explain: VOTSWS/V FIS per capable task-robot pair"]
        for task, pairs in report["explain"]["task_value"].items():
            for robot, trace in pairs.items():
                lines.append(f"  {task} {robot}")
                lines += _format_traces([trace], "    ")
    return "\n".join(lines)


def _format_traces(traces: list, indent: str) -> list[str]:
    lines = []
    for t in traces:
        inputs = " ".join(f"{k}={v:.4g}" for k, v in t["inputs"].items())
        outputs = " ".join(f"{k}={v:.4f}" for k, v in t["outputs"].items())
        lines.append(f"{indent}{t['name']}: {inputs} -> {outputs}")
        lines += [f"{indent}  rule {r['number']:>2} {r['firing']:.3f}  {r['text']}" for r in t["fired"]]
    return lines
