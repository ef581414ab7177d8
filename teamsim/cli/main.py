"""``teamsim``: run missions headless, render videos, export robots, benchmark.

Every bad input ends in one line, ``teamsim: error: ...``, and exit status 2.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

from teamsim.config import ConfigError, TrialConfig, VideoConfig
from teamsim.faults import FAULT_KINDS, SPEC_FORM
from teamsim.gl import RenderBackendError

# teamsim.tasks.studies.cleanup_faults.CONDITIONS, spelled out so that building the parser imports no physics
CLEANUP_CONDITIONS = ("none", "kill-red", "radio-off", "break-gripper")
BOX_EXPERIMENTS = ("robot-failure", "heterogeneity")  # teamsim.tasks.studies.box_pushing.EXPERIMENTS
JANITORIAL_RHOS = (0.0, 0.1, 0.5, 2.0)  # teamsim.tasks.studies.janitorial_rho.JanitorialRhoStudy.rhos
FORMATION_STRATEGIES = ("I", "II", "III", "IV")  # teamsim.controllers.behaviours.formation.STRATEGIES
EXPLORATION_TEAMS = ("1 1", "1 3", "1 5")  # teamsim.tasks.studies.exploration.TEAMS
FEEDBACK_LEVELS = ("task-score", "poor", "partial", "complete", "combined")  # teamsim.tasks.studies.feedback.LEVELS
# teamsim.tasks.studies.robustness.MISSIONS
ROBUSTNESS_MISSIONS = ("wander", "navigate", "hazardous-waste", "box-pushing", "explore", "janitorial",
                       "bounding-overwatch", "formation")

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl-C


class UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, not argparse's usage block
        raise UsageError(message)


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="teamsim", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    commands.add_parser("list", help="robots, missions and studies")

    run = commands.add_parser("run", help="run one trial of a mission")
    _trial_arguments(run)
    run.add_argument("--video", action="store_true", help="write video.mp4 (H.264)")
    run.add_argument("--video-size", metavar="WxH", help="video frame size in pixels (default: 640x480; even sides, "
                                                         "width 64-3840, height 48-2160)")
    run.add_argument("--camera", default="top", help="'top', 'perspective' (the whole arena from 50 degrees up) or a "
                                                     "robot name for its tracking camera")
    run.add_argument("--out", default="renders", help="output root (default: renders)")
    run.add_argument("--run-id", help="run folder name (default: seed and timestamp)")

    view = commands.add_parser("view", help="watch a mission live in MuJoCo's interactive viewer (needs a display)")
    _trial_arguments(view)
    view.add_argument("--speed", type=float, default=1.0, help="simulated seconds per second (default: 1, real time)")
    view.set_defaults(video=False, camera="top", out="renders", run_id=None)

    scenario = commands.add_parser("scenario", help="scenario files: a world, a team and its faults in one YAML "
                                                    "file (docs/scenarios.md)")
    scenario_commands = scenario.add_subparsers(dest="scenario_command", required=True, parser_class=_Parser)
    show = scenario_commands.add_parser("show", help="print the exact scenario a run would use")
    _trial_arguments(show)
    show.add_argument("--output", type=Path, metavar="FILE", help="write it to FILE instead")
    show.set_defaults(video=False, camera="top", out="renders", run_id=None)

    render = commands.add_parser("render", help="re-render runs' videos from their trajectory.npz, several in "
                                                "parallel")
    render.add_argument("run_dirs", type=Path, nargs="+", metavar="RUN_DIR")
    render.add_argument("--workers", type=_positive_int("--workers"), help="runs rendered at once (default: one "
                                                                          "per core)")
    render.add_argument("--camera", default="top", help="'top', 'perspective' or a robot name, as for run")
    render.add_argument("--out", type=Path, help="video path, with one RUN_DIR (default: RUN_DIR/video-CAMERA.mp4)")
    render.add_argument("--video-size", metavar="WxH", default="640x480", help="frame size in pixels, as for run "
                                                                               "(default: 640x480)")

    export = commands.add_parser("export", help="standalone MJCF of one robot on a floor")
    export.add_argument("robot")
    export.add_argument("--out", type=Path, required=True)

    allocate = commands.add_parser("allocate", help="Chand ch.5: fuzzy task allocation (default: the thesis's "
                                                    "Tables 5.20-5.22)")
    allocate.add_argument("tasks", nargs="?", type=Path, help="task specification (TOML)")
    allocate.add_argument("robots", nargs="?", type=Path, help="robot specification (TOML)")
    allocate.add_argument("--json", action="store_true", help="the same data as JSON")
    allocate.add_argument("--explain", action="store_true", help="each FIS's inputs, fired rules and output")

    study = commands.add_parser("study", help="re-run a thesis's experiments and compare with its figures")
    studies = study.add_subparsers(dest="study", required=True, parser_class=_Parser)
    navigation = studies.add_parser("navigation", help="Chand ch.3: navigation methods x robots x densities")
    navigation.add_argument("--robots", type=_csv_of("robot", ("A", "B", "C", "tricycle", "diffdrive", "tracked")))
    navigation.add_argument("--densities", type=_csv_of("density", None, float))
    navigation.add_argument("--controllers", type=_csv_of("controller", ("FRC", "HRDK", "HRDU", "ODW", "ODWDS",
                                                                      "RFRC", "FRC-printed")))
    navigation.add_argument("--trials", type=_positive_int("--trials"))
    navigation.add_argument("--workers", type=_positive_int("--workers"))
    navigation.add_argument("--seed", type=_study_seed)
    navigation.add_argument("--out", type=Path, help="output folder (default: renders/study-navigation)")
    _resume_option(navigation, "renders/study-navigation")
    navigation.add_argument("--backend", choices=("kinematic", "physics"),
                            help="kinematic (default: no dynamics, as the thesis simulated; minutes) or physics "
                                 "(every trial a MuJoCo navigate mission)")
    navigation.add_argument("--worlds", choices=("strata", "uniform"),
                            help="world family: strata (default: even, gaps at least Robot C's diameter) or uniform "
                                 "(boxes anywhere, any size up to 1.6 m, overlapping)")

    two_tier = studies.add_parser("two-tier-astar", help="Chand ch.4: memory-constrained vs monolithic A*")
    two_tier.add_argument("--trials", type=_positive_int("--trials"), help="worlds per size and density")
    _sweep_options(two_tier, "§4.6's whole grid of sizes and local maps (hours)", workers=1,
                   out="renders/study-two-tier-astar")

    lalliance = studies.add_parser("lalliance", help="Parker §4.5: abstract L-ALLIANCE allocation study")
    lalliance.add_argument("--runs", type=_positive_int("--runs"), help="runs per scenario")
    _sweep_options(lalliance, "the thesis's full sweep (slow)", workers=2, out="renders/study-lalliance")

    awareness = studies.add_parser("awareness", help="Parker ch.5: hazardous waste with and without awareness, "
                                                     "2 and 3 robots (versions I-IV)")
    awareness.add_argument("--missions", type=_positive_int("--missions"), default=10, help="missions per version")
    _duration_option(awareness, "simulated seconds per mission (mission default if unset)")
    _run_options(awareness, workers=2, out="renders/study-awareness")

    rho = studies.add_parser("janitorial-rho", help="Parker §6.2.3: the janitorial service's mission time at "
                                                    "broadcast rates rho (Fig. 6-13)")
    rho.add_argument("--missions", type=_positive_int("--missions"), default=10, help="missions per rate")
    rho.add_argument("--rhos", type=_csv_of("rho", None, float), default=JANITORIAL_RHOS,
                     help="comma-separated broadcasts per second per robot, 0 = no messages (default: "
                          f"{','.join(f'{r:g}' for r in JANITORIAL_RHOS)})")
    _duration_option(rho, "simulated seconds per mission (mission default if unset)")
    _run_options(rho, workers=2, out="renders/study-janitorial-rho")

    faults = studies.add_parser("cleanup-faults", help="Parker §3.8.4: the 3-robot cleanup with red killed during "
                                                       "the search, the radio off, a gripper broken")
    faults.add_argument("--missions", type=_positive_int("--missions"), default=10, help="missions per condition")
    faults.add_argument("--conditions", type=_csv_of("condition", CLEANUP_CONDITIONS), default=CLEANUP_CONDITIONS,
                        help=f"comma-separated: {','.join(CLEANUP_CONDITIONS)}")
    _run_options(faults, workers=2, out="renders/study-cleanup-faults")

    boxes = studies.add_parser("box-pushing", help="Parker §6.1.2: an R-2 taken away and returned; an R-2 replaced "
                                                   "by Genghis-II")
    boxes.add_argument("--trials", type=_positive_int("--trials"), default=20, help="trials per experiment")
    boxes.add_argument("--experiments", type=_csv_of("experiment", BOX_EXPERIMENTS), default=BOX_EXPERIMENTS,
                       help=f"comma-separated: {','.join(BOX_EXPERIMENTS)}")
    _run_options(boxes, workers=2, out="renders/study-box-pushing")

    formation = studies.add_parser("formation", help="Parker §7.2: keeping formation under strategies I-IV "
                                                     "(Fig. 7-2)")
    formation.add_argument("--runs", type=_positive_int("--runs"), default=10,
                           help="runs per strategy (the thesis: 10)")
    formation.add_argument("--strategies", type=_csv_of("strategy", FORMATION_STRATEGIES),
                           default=FORMATION_STRATEGIES, help=f"comma-separated: {','.join(FORMATION_STRATEGIES)}")
    _duration_option(formation, "simulated seconds per run (mission default if unset)")
    _run_options(formation, workers=2, out="renders/study-formation")

    exploration = studies.add_parser("exploration", help="Chand §8.3: exploration without feedback, teams [1 1], "
                                                         "[1 3], [1 5] x densities x bogs (Table 8.1 level 1.1)")
    exploration.add_argument("--worlds", type=_positive_int("--worlds"), help="worlds per environment type "
                                                                              "(default 3; --full: 10)")
    exploration.add_argument("--repeats", type=_positive_int("--repeats"), help="runs per world (default 1; "
                                                                                "--full: 10)")
    exploration.add_argument("--teams", type=_csv_of("team", EXPLORATION_TEAMS, _team), default=EXPLORATION_TEAMS,
                             help="comma-separated [planners explorers] teams: 1-1,1-3,1-5 (default: all)")
    exploration.add_argument("--densities", type=_csv_of("density", (5, 10, 15), int), default=(5, 10, 15),
                             help="obstacle densities in %% (default: 5,10,15)")
    exploration.add_argument("--terrain", type=_csv_of("terrain", ("dry", "bog")), default=("dry", "bog"),
                             help="worlds without bogs (dry), with about 5 %% bogs (bog), or both (default)")
    exploration.add_argument("--backend", choices=("kinematic", "physics"), default="kinematic",
                             help="kinematic (default, as the thesis simulated) or physics (MuJoCo; a spot check)")
    exploration.add_argument("--ray", action="store_true", help="run the trials on a local Ray instance (pip "
                                                                "install 'teamsim[ray]') instead of --workers")
    _duration_option(exploration, "simulated seconds per run (default: MET, §8.2)")
    _sweep_options(exploration, "the thesis's design: 10 worlds x 10 repeats per environment type (hours)",
                   workers=2, out="renders/study-exploration")

    feedback = studies.add_parser("feedback", help="Chand §8.4-8.5: feedback coordination against none, tuned "
                                                   "level by level (Table 8.1 levels 2-3.4)")
    feedback.add_argument("--levels", type=_csv_of("level", FEEDBACK_LEVELS), default=FEEDBACK_LEVELS,
                          help=f"comma-separated (default: all, in §8.2's tuning order): {','.join(FEEDBACK_LEVELS)}")
    feedback.add_argument("--worlds", type=_positive_int("--worlds"), help="worlds per environment type "
                                                                           "(default 1; --full: 10)")
    feedback.add_argument("--repeats", type=_positive_int("--repeats"), help="runs per world (default 1; "
                                                                             "--full: 10)")
    feedback.add_argument("--densities", type=_csv_of("density", (5, 10, 15), int), default=(5, 10, 15),
                          help="obstacle densities in %% (default: 5,10,15)")
    feedback.add_argument("--terrain", type=_csv_of("terrain", ("dry", "bog")), default=("dry", "bog"),
                          help="worlds without bogs (dry), with about 5 %% bogs (bog), or both (default)")
    feedback.add_argument("--no-retune", action="store_true", help="tune at T_m 60 s only (skip re-running each "
                                                                   "level's best at 180 and 300 s)")
    feedback.add_argument("--ray", action="store_true", help="run the trials on a local Ray instance")
    _duration_option(feedback, "simulated seconds per run (default: MET, §8.2)")
    _sweep_options(feedback, "the thesis's design: 10 worlds x 10 repeats per environment type (days)",
                   workers=2, out="renders/study-feedback")

    robust = studies.add_parser("robustness", help="every mission under every fault kind it supports, over seeds "
                                                   "(issue 29)")
    robust.add_argument("--seeds", default="1", metavar="N|A-B", help="trial seeds: N (0..N-1) or a range A-B "
                                                                      "(default: 1, i.e. 60 runs)")
    robust.add_argument("--missions", type=_csv_of("mission", ROBUSTNESS_MISSIONS), default=ROBUSTNESS_MISSIONS,
                        help=f"comma-separated (default: all): {','.join(ROBUSTNESS_MISSIONS)}")
    robust.add_argument("--faults", type=_csv_of("fault", FAULT_KINDS), default=FAULT_KINDS,
                        help=f"comma-separated fault kinds (default: all): {','.join(FAULT_KINDS)}")
    _duration_option(robust, "simulated seconds per run (default: each mission's own)")
    _run_options(robust, workers=2, out="renders/study-robustness")

    bench = commands.add_parser("bench", help="benchmarks")
    bench.add_argument("what", choices=("physics", "cleanup", "box-pushing", "janitorial", "formation", "overwatch",
                                        "render", "nav", "alliance", "allocate", "sweep", "explore"))
    bench.add_argument("--seconds", type=_seconds("--seconds"), default=None,
                       help="simulated seconds per measurement")
    return parser


def _trial_arguments(parser: argparse.ArgumentParser) -> None:
    """What defines a trial, for `run` and `scenario show` (precedence: teamsim/cli/scenario.py)."""
    parser.add_argument("mission")
    parser.add_argument("--scenario", type=Path, metavar="FILE", help="scenario file (YAML) to run")
    parser.add_argument("--seed", type=int, help="trial seed (default: the scenario's, else 0)")
    parser.add_argument("--duration", type=float, help="simulated seconds (default: the scenario's or mission's)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="mission parameter (robots=5), group.key (radio.loss=0.2) or any scenario field by "
                             "its dotted path (robots.red.pose=[1,2,0])")
    parser.add_argument("--fault", action="append", default=[], metavar="SPEC",
                        help=f"{SPEC_FORM}; kinds: {', '.join(FAULT_KINDS)}; ROBOT may be @ROLE where the "
                             "mission elects roles (bounding-overwatch: @leader, @leader:A, @leader:B)")


def _sweep_options(parser: argparse.ArgumentParser, full_help: str, workers: int, out: str) -> None:
    """--full, --workers, --seed and --out of a study that runs a reduced grid unless asked for the full one."""
    parser.add_argument("--full", action="store_true", help=full_help)
    _run_options(parser, workers, out)


def _run_options(parser: argparse.ArgumentParser, workers: int, out: str) -> None:
    """--workers, --seed and --out of a study."""
    parser.add_argument("--workers", type=_positive_int("--workers"), default=workers)
    parser.add_argument("--seed", type=_study_seed, default=0)
    parser.add_argument("--out", type=Path, help=f"output folder (default: {out})")
    _resume_option(parser, out)


def _duration_option(parser: argparse.ArgumentParser, meaning: str) -> None:
    parser.add_argument("--duration", type=_seconds("--duration"), help=meaning)


def _resume_option(parser: argparse.ArgumentParser, out: str) -> None:
    parser.add_argument("--resume", type=Path, metavar="DIR", help="continue a study killed in DIR (its --out): the "
                                                                   "trials in DIR/trials.jsonl are not run again")
    parser.set_defaults(default_out=Path(out))


def _study_out(args) -> None:
    """``--resume DIR`` is ``--out DIR`` with the journal reused; --out alone defaults to the study's folder."""
    if args.resume is not None and args.out is not None and args.out.resolve() != args.resume.resolve():
        raise UsageError(f"--out {args.out} and --resume {args.resume}: a study resumes in its own folder; give one")
    args.out = args.resume or args.out or args.default_out
    args.resume = args.resume is not None


def _csv_of(name: str, allowed: tuple | None, kind=str):
    """An argparse type: a comma-separated list of ``kind`` values, each in ``allowed`` when given."""
    def parse(text: str) -> tuple:
        try:
            values = tuple(dict.fromkeys(kind(item.strip()) for item in text.split(",") if item.strip()))
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name}s must be {kind.__name__}s separated by commas") from None
        bad = [v for v in values if allowed is not None and v not in allowed]
        if bad or not values:
            raise argparse.ArgumentTypeError(f"{name} {bad[0] if bad else text!r} not allowed; allowed: "
                                             f"{', '.join(map(str, allowed or ()))}")
        return values
    return parse


def _team(text: str) -> str:
    """A team written 1-3 (or "1 3") as the explore mission writes it, "1 3"."""
    return " ".join(text.replace("-", " ").split())


def _seconds(flag: str):
    """An argparse type: simulated seconds, a number in (0, 1e7] (TrialConfig.duration's bounds)."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not 0 < value <= 1e7:  # (NaN fails too)
            raise argparse.ArgumentTypeError(f"{flag} must be a number of simulated seconds in (0, 1e7]")
        return value
    return parse


STUDY_SEEDS = 2**62  # a study's trials take seeds from its --seed upwards: headroom below the trial limit 2**63


def _study_seed(text: str) -> int:
    """An argparse type: a study's --seed, a whole number in [0, 2**62)."""
    if not (text.isascii() and text.isdigit()) or int(text) >= STUDY_SEEDS:
        raise argparse.ArgumentTypeError("--seed must be a whole number in [0, 2**62)")
    return int(text)


def _positive_int(flag: str):
    def parse(text: str) -> int:
        if not (text.isascii() and text.isdigit()) or int(text) < 1:
            raise argparse.ArgumentTypeError(f"{flag} must be a whole number >= 1")
        return int(text)
    return parse


def cmd_study(args) -> int:
    _study_out(args)
    if args.study == "navigation":
        from teamsim.tasks.studies.navigation import run_study, study_from_args

        if args.densities and not all(0.0 < d <= 0.3 for d in args.densities):
            raise ConfigError("--densities: each must be in (0, 0.3]")
        study = study_from_args(robots=args.robots, densities=args.densities, controllers=args.controllers,
                                trials=args.trials, workers=args.workers, out=args.out, seed=args.seed,
                                backend=args.backend, worlds=args.worlds, resume=args.resume)
        out = run_study(study)
        print(f"wrote {out / 'report.md'} and {out / 'results.csv'}")
    elif args.study == "two-tier-astar":
        from teamsim.tasks.studies.two_tier_astar import plan, run_study

        written = run_study(plan(args.full, args.trials, args.seed), args.out, args.workers, resume=args.resume)
        print(f"wrote {written['report']} and {written['results']} ({written['rows']} plans, "
              f"{written['wall_s']:.0f} s)")
    elif args.study == "awareness":
        from teamsim.tasks.studies.awareness import AwarenessStudy, run_study

        out = run_study(AwarenessStudy(missions=args.missions, seed=args.seed, workers=args.workers, out=args.out,
                                       duration=args.duration, resume=args.resume))
        print(f"wrote {out / 'report.md'} and {out / 'results.csv'}")
    elif args.study == "janitorial-rho":
        if not all(0.0 <= rho <= 100.0 for rho in args.rhos):  # (NaN fails too)
            raise ConfigError("--rhos: each must be a number of broadcasts per second in [0, 100]")
        from teamsim.tasks.studies.janitorial_rho import JanitorialRhoStudy, run_study

        out = run_study(JanitorialRhoStudy(rhos=args.rhos, missions=args.missions, seed=args.seed,
                                           workers=args.workers, out=args.out, duration=args.duration,
                                           resume=args.resume))
        print(f"wrote {out / 'report.md'}, {out / 'times.png'} and {out / 'results.csv'}")
    elif args.study == "cleanup-faults":
        from teamsim.tasks.studies.cleanup_faults import CleanupFaultStudy, run_study

        out = run_study(CleanupFaultStudy(missions=args.missions, seed=args.seed, conditions=args.conditions,
                                          workers=args.workers, out=args.out, resume=args.resume))
        print(f"wrote {out / 'report.md'} and {out / 'results.csv'}")
    elif args.study == "box-pushing":
        from teamsim.tasks.studies.box_pushing import BoxPushingStudy, run_study

        out = run_study(BoxPushingStudy(trials=args.trials, seed=args.seed, experiments=args.experiments,
                                        workers=args.workers, out=args.out, resume=args.resume))
        print(f"wrote {out / 'report.md'} and {out / 'results.csv'}")
    elif args.study == "formation":
        from teamsim.tasks.studies.formation import FormationStudy, run_study

        out = run_study(FormationStudy(runs=args.runs, seed=args.seed, strategies=args.strategies,
                                       workers=args.workers, out=args.out, duration=args.duration,
                                       resume=args.resume))
        print(f"wrote {out / 'report.md'}, {out / 'fig7-2.png'} and {out / 'results.csv'}")
    elif args.study == "exploration":
        from teamsim.tasks.studies.exploration import ExplorationStudy, run_study

        full = args.full
        out = run_study(ExplorationStudy(worlds=args.worlds or (10 if full else 3),
                                         repeats=args.repeats or (10 if full else 1), seed=args.seed,
                                         teams=args.teams, densities=tuple(d / 100 for d in args.densities),
                                         bogs=tuple(t == "bog" for t in args.terrain), backend=args.backend,
                                         workers=args.workers, ray=args.ray, duration=args.duration, out=args.out,
                                         resume=args.resume))
        print(f"wrote {out / 'report.md'}, {out / 'exploration.png'} and {out / 'results.csv'}")
    elif args.study == "feedback":
        from teamsim.tasks.studies.feedback import FeedbackStudy, run_study

        full = args.full
        out = run_study(FeedbackStudy(levels=args.levels, worlds=args.worlds or (10 if full else 1),
                                      repeats=args.repeats or (10 if full else 1), seed=args.seed,
                                      densities=tuple(d / 100 for d in args.densities),
                                      bogs=tuple(t == "bog" for t in args.terrain), retune_t_m=not args.no_retune,
                                      workers=args.workers, ray=args.ray, duration=args.duration, out=args.out,
                                      resume=args.resume))
        print(f"wrote {out / 'report.md'}, {out / 'feedback.png'} and {out / 'results.csv'}")
    elif args.study == "lalliance":
        from teamsim.tasks.studies.lalliance import run_study

        written = run_study(args.out, args.workers, full=args.full, runs=args.runs, seed=args.seed,
                            resume=args.resume)
        print(f"wrote {written['report']} and {written['results']} ({written['rows']} runs, "
              f"{written['wall_s']:.0f} s)")
    elif args.study == "robustness":
        import time

        from teamsim.tasks.studies.robustness import RobustnessStudy, run_study, seeds_from

        began = time.perf_counter()
        out = run_study(RobustnessStudy(seeds=seeds_from(args.seeds), seed=args.seed, missions=args.missions,
                                        faults=args.faults, duration=args.duration, workers=args.workers,
                                        out=args.out, resume=args.resume))
        print(f"wrote {out / 'report.md'} and {out / 'results.csv'} ({time.perf_counter() - began:.0f} s)")
    return 0


def _trial_config(args) -> TrialConfig:
    from teamsim.runner import trial_config

    video = VideoConfig(enabled=args.video, camera=args.camera)
    if getattr(args, "video_size", None) is not None:
        video.width, video.height = video.parse_size(args.video_size)
    return trial_config(args.mission, scenario=args.scenario, seed=args.seed, duration=args.duration,
                        settings=args.set, faults=args.fault, out=args.out, run_id=args.run_id, video=video)


def cmd_scenario(args) -> int:
    from teamsim.runner import mission_of
    from teamsim.scenario import not_supported, supports
    from teamsim.cli.scenario import show

    mission = mission_of(args.mission)
    if not supports(mission):
        raise not_supported(mission)
    return show(args, mission, _trial_config(args))


def cmd_run(args) -> int:
    from teamsim.runner import run_trial

    result = run_trial(_trial_config(args))
    s = result.summary
    print(f"{s['status']}: {result.run_dir} ({s['sim_time_s']:.1f} s simulated in {s['wall_time_s']:.1f} s, "
          f"{s['real_time_factor']}x real time)")
    if s.get("error"):
        print(f"  {s['error']}", file=sys.stderr)
    return {"completed": 0, "interrupted": EXIT_INTERRUPTED}.get(result.status, 1)


def cmd_view(args) -> int:
    from teamsim.runner import mission_of
    from teamsim.viewer import view

    result = view(_trial_config(args), mission_of(args.mission), speed=args.speed)
    print(f"{result.status}: {result.sim_time_s:.1f} s simulated in {result.wall_time_s:.1f} s")
    return 0 if result.status in ("completed", "closed") else 1


def cmd_list(_args) -> int:
    from teamsim.models import ROBOT_BUILDERS, ROBOT_KINDS, build_robot
    from teamsim.tasks import MISSIONS

    print("robots:")
    for kind in ROBOT_KINDS:
        if kind not in ROBOT_BUILDERS:
            print(f"  {kind:<10} (not built yet)")
            continue
        robot = build_robot(kind, "x")
        sensors = [f"{len(robot.ir_sensors)} IR ({robot.ir.max_range:g} m)"]
        sensors += [f"touch {name}" for name in robot.touch]
        sensors += [f"{len(robot.beams)} break-beams"] if robot.beams else []
        sensors += ["inclinometer"] if robot.inclinometer else []
        print(f"  {kind:<10} {type(robot.drive).__name__.removesuffix('Spec').lower()} drive, "
              f"v <= {robot.limits.v_max:g} m/s, traversability {robot.traversability:g}")
        print(f"  {'':<10} sensors: {', '.join(sensors)}")
        print(f"  {'':<10} actuators: {', '.join(robot.motors)}"
              + "".join(f"; {name}: {', '.join(e.actuators)}" for name, e in robot.effectors.items()))
    print("missions:")
    for name, mission in MISSIONS.items():
        print(f"  {name:<10} {mission.summary}")
    print("studies:")
    print("  navigation       Chand ch.3: FRC, HRDK, HRDU, ODW, ODWDS, RFRC x robots A, B, C x densities")
    print("  two-tier-astar   Chand ch.4: memory-constrained two-tiered A* vs monolithic, no physics")
    print("  lalliance        Parker §4.5: L-ALLIANCE strategies I-IV, abstract (no physics)")
    print("  awareness        Parker ch.5: the cleanup with and without awareness, versions I-IV")
    print("  janitorial-rho   Parker §6.2.3: the janitorial service's mission time at broadcast rates rho")
    print("  cleanup-faults   Parker §3.8.4: the cleanup with red killed, the radio off, a gripper broken")
    print("  box-pushing      Parker §6.1.2: an R-2 taken away and returned; an R-2 replaced by Genghis-II")
    print("  formation        Parker §7.2: keeping formation under strategies I-IV (Fig. 7-2)")
    print("  exploration      Chand §8.3: exploration without feedback, teams [1 1], [1 3], [1 5]")
    print("  feedback         Chand §8.4-8.5: feedback coordination against none, level by level")
    print("  robustness       every mission under every fault kind it supports, over seeds (issue 29)")
    return 0


def cmd_render(args) -> int:
    from teamsim.config import VideoConfig
    from teamsim.rerender import rerender, rerender_all

    width, height = VideoConfig.parse_size(args.video_size)
    if args.out is not None and len(args.run_dirs) > 1:
        raise UsageError(f"--out names one video; got {len(args.run_dirs)} RUN_DIRs (leave --out out)")
    if args.out is not None:
        outs = [rerender(args.run_dirs[0], args.camera, args.out, width, height)]
    else:
        outs = rerender_all(args.run_dirs, args.camera, width, height, args.workers)
    for out in outs:
        print(f"wrote {out}")
    return 0


def cmd_export(args) -> int:
    from teamsim.cli.export import export_robot

    export_robot(args.robot, args.out)
    print(f"wrote {args.out}")
    return 0


def cmd_allocate(args) -> int:
    from teamsim.cli.allocate import cmd_allocate as allocate

    return allocate(args)


# teamsim bench WHAT: the module that measures it and its function (imported only when asked for)
BENCHES = {"allocate": ("allocate", "bench_allocate"), "nav": ("nav", "bench_nav"), "sweep": ("sweep", "bench_sweep"),
           "alliance": ("alliance", "bench_alliance"), "explore": ("explore", "bench_explore")}


def cmd_bench(args) -> int:
    import importlib

    if args.what in BENCHES:
        module, function = BENCHES[args.what]
        bench_function = getattr(importlib.import_module(f"teamsim.bench.{module}"), function)
        bench_function(seconds=args.seconds) if args.what == "explore" else bench_function()
        return 0
    from teamsim.bench import physics as bench

    if args.what == "physics":
        bench.physics(seconds=args.seconds or 10.0)
        print()
        bench.robot_kinds(seconds=args.seconds or 10.0)
    elif args.what == "cleanup":
        bench.cleanup(seconds=args.seconds or 300.0)
    elif args.what == "box-pushing":
        bench.box_pushing(seconds=args.seconds or 120.0)
    elif args.what == "janitorial":
        bench.janitorial(seconds=args.seconds or 300.0)
    elif args.what == "formation":
        bench.formation(seconds=args.seconds or 120.0)
    elif args.what == "overwatch":
        bench.overwatch(seconds=args.seconds or 120.0)
    else:
        from teamsim.bench.video import video_cost

        bench.render(seconds=args.seconds or 4.0)
        print()
        video_cost()
    return 0


# Every character that ends a line (str.splitlines) or moves the cursor back over it, as its escape.
_LINE_BREAKS = {ord(c): c.encode("unicode_escape").decode() for c in "\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029"}


def one_line(message: str) -> str:
    """An error message on one line: a line break in it (from an argument: ``--set 'robots=1<newline>2'``) is
    written as its escape."""
    return message.translate(_LINE_BREAKS)


def main(argv: list[str] | None = None) -> int:
    parser = _build_parser()
    args = None
    try:
        args = parser.parse_args(argv)
        return {"run": cmd_run, "list": cmd_list, "render": cmd_render, "export": cmd_export,
                "bench": cmd_bench, "study": cmd_study, "allocate": cmd_allocate,
                "scenario": cmd_scenario, "view": cmd_view}[args.command](args)
    except (UsageError, ConfigError, RenderBackendError) as exc:
        print(f"teamsim: error: {one_line(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM in a study: the trials that ended are in its journal
        resume = f": continue it with --resume {args.out}" if getattr(args, "command", None) == "study" else ""
        print(f"teamsim: interrupted{resume}", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the output went to a program that stopped reading (teamsim list | head)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at interpreter exit
        return 1

