"""The command line's side of scenarios: ``teamsim run MISSION [--scenario FILE]`` and ``teamsim scenario show``.

Precedence, lowest first (docs/scenarios.md):

1. the scenario: the file given with ``--scenario``, or else the world the mission generates from its
   parameters (``--seed``, ``--duration``, and ``--set`` of a mission parameter or a ``timing.``/``radio.``/
   ``positioning.`` setting, as for any run);
2. ``--seed`` and ``--duration``, over a file's values;
3. ``--set PATH=VALUE`` of any scenario field by its dotted path (``robots.red.pose=[1,2,0]``,
   ``arena.boxes[0].x=2``), in command-line order, so a later one wins;
4. ``--fault``: appended after the scenario's faults.
"""
from __future__ import annotations

import dataclasses
import sys
import typing
from pathlib import Path

import yaml

from teamsim.config import ConfigError, TrialConfig
from teamsim.scenario import Scenario, dump, scenario_of, supports, to_data


def show(args, mission, config: TrialConfig) -> int:
    """Print (or write to ``--output``) the exact scenario ``config`` runs."""
    text = (f"# teamsim scenario: run it with `teamsim run {mission.name} --scenario FILE`; every field is in "
            f"docs/scenarios.md\n" + dump(scenario_of(config, mission)))
    if args.output is None:
        sys.stdout.write(text)
        return 0
    try:
        Path(args.output).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"--output {args.output}: not writable ({exc.strerror or exc})") from None
    print(f"wrote {args.output}")
    return 0


def reference(missions: dict) -> str:
    """Markdown tables of every scenario field: its default, what is allowed and its meaning (with units).
    docs/scenarios.md embeds this text, and a test keeps the two the same."""
    lines: list[str] = []
    done: set = set()

    def table(title: str, cls: type) -> None:
        if cls in done:
            return
        done.add(cls)
        lines.extend([f"### {title}", "", "| field | default | allowed | meaning |", "|---|---|---|---|"])
        nested = []
        hints = typing.get_type_hints(cls)
        for f in dataclasses.fields(cls):
            if f.default is not dataclasses.MISSING:
                default = f"`{_inline(f.default)}`"
            else:
                default = {list: "`[]`", dict: "`{}`"}.get(f.default_factory, "see below")
            meaning = f.metadata.get("meaning") or f"see `{cls.__name__}` in `{cls.__module__}`"
            lines.append(f"| `{f.name}` | {default} | {_allowed(f)} | {meaning} |")
            inner = [a for a in (hints[f.name], *typing.get_args(hints[f.name])) if dataclasses.is_dataclass(a)]
            key = f"{f.name}.NAME" if typing.get_origin(hints[f.name]) is dict else f.name
            nested += [(f"{title}.{key}", a) for a in inner]
        if not dataclasses.fields(cls):
            lines.append(f"| (none) | | | {cls.__doc__} |")
        lines.append("")
        for name, inner in nested:
            table(name, inner)

    table("scenario", Scenario)
    for name, mission in missions.items():
        if supports(mission):
            table(f"task ({name})", mission.Task)
            table(f"robots.NAME.controller ({name})", mission.Controller)
    return "\n".join(lines)


def _allowed(f: dataclasses.Field) -> str:
    meta = f.metadata
    if not meta and isinstance(f.default, (int, float)) and not isinstance(f.default, bool) and f.default > 0:
        return "(0, inf]"  # a size, mass, rate or period of a model or controller (teamsim.scenario._object)
    if meta.get("choices"):
        return ", ".join(map(str, meta["choices"]))
    if meta.get("lo") is None and meta.get("hi") is None:
        return ""
    low = "-inf" if meta.get("lo") is None else f"{meta['lo']:g}"
    high = "inf" if meta.get("hi") is None else f"{meta['hi']:g}"
    return f"{'(' if meta.get('open_lo') else '['}{low}, {high}]"


def _inline(value) -> str:
    return yaml.safe_dump(to_data(value), default_flow_style=True, width=10**6).strip().removesuffix("...").strip()
