"""The ``montecarlo`` command of ``rolltouch``, added to driver's command line through its registry
(the entry point ``montecarlo`` of the group ``rolltouch.commands`` in pyproject.toml)."""

from __future__ import annotations

import argparse

from driver.cli import UsageError, add_command

__all__ = ["register", "montecarlo_command", "report_command"]


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add ``montecarlo`` to the subparsers ``sub``."""
    mc = add_command(
        sub,
        "montecarlo",
        montecarlo_command,
        help="run a Monte Carlo study of localization success",
        description="Run the simulated trials of a study file in parallel, appending each to "
        "DIR/trials.csv as it finishes; write DIR/summary.json and plots.",
    )
    mc.add_argument("study", help="study file (TOML), e.g. bench/studies/paper.toml")
    mc.add_argument("--out", required=True, metavar="DIR", help="output folder")
    mc.add_argument("--trials", type=int, metavar="N", help="trials per level (overrides the study file)")
    mc.add_argument("--engine", choices=("kinematic", "pymunk"), help="overrides the study file")
    mc.add_argument("--workers", type=int, metavar="N", help="local worker processes (default: all cores)")
    mc.add_argument("--scheduler", metavar="ADDRESS", help="run on this Dask distributed scheduler")
    mc.add_argument("--resume", action="store_true", help="keep finished trials, run only the missing ones")
    mc.set_defaults(interrupted="finished trials are kept; rerun with --resume")
    rep = add_command(
        sub,
        "report",
        report_command,
        help="write a study's outputs as one HTML page",
        description="Write STUDY_DIR/report.html: the settings, each method's results per level and per part, "
        "the plots, and the trials not right with the command that replays each (bench.reports.study_page).",
    )
    rep.add_argument("study_dir", metavar="STUDY_DIR", help="the --out folder of 'rolltouch montecarlo'")


def montecarlo_command(args: argparse.Namespace) -> int:
    from .montecarlo import run_study
    from .study import load_study
    from .summary import print_summary

    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers {args.workers} must be at least 1")
    study = load_study(args.study).with_overrides(trials=args.trials, engine=args.engine)
    summary = run_study(study, args.out, workers=args.workers, scheduler=args.scheduler, resume=args.resume)
    print_summary(summary)
    return 0


def report_command(args: argparse.Namespace) -> int:
    from .reports.study_page import write_report

    print(f"written {write_report(args.study_dir)}")
    return 0
