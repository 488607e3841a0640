"""The ``rolltouch`` console script: driver's commands plus ``montecarlo`` (which needs bench)."""

from __future__ import annotations

import sys

from driver import cli as driver_cli

__all__ = ["main", "build_parser"]


def build_parser():
    parser = driver_cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    mc = sub.add_parser("montecarlo", help="run a Monte Carlo study of localization success",
                        description="Run the simulated trials of a study file in parallel, appending each to "
                                    "DIR/trials.csv as it finishes; write DIR/summary.json and plots.")
    mc.add_argument("study", help="study file (TOML), e.g. bench/studies/paper.toml")
    mc.add_argument("--out", required=True, metavar="DIR", help="output folder")
    mc.add_argument("--trials", type=int, metavar="N", help="trials per level (overrides the study file)")
    mc.add_argument("--engine", choices=("kinematic", "pymunk"), help="overrides the study file")
    mc.add_argument("--workers", type=int, metavar="N", help="local worker processes (default: all cores)")
    mc.add_argument("--scheduler", metavar="ADDRESS", help="run on this Dask distributed scheduler")
    mc.add_argument("--resume", action="store_true", help="keep finished trials, run only the missing ones")
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command != "montecarlo":
        return driver_cli.main(argv)
    from bench.montecarlo import print_summary, run_study
    from bench.study import StudyError, load_study

    try:
        if args.workers is not None and args.workers < 1:
            raise StudyError(f"--workers {args.workers} must be at least 1")
        study = load_study(args.study).with_overrides(trials=args.trials, engine=args.engine)
        summary = run_study(study, args.out, workers=args.workers, scheduler=args.scheduler, resume=args.resume)
    except StudyError as exc:
        print(f"rolltouch: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\nrolltouch: interrupted: finished trials are kept; rerun with --resume", file=sys.stderr)
        return 130
    print_summary(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
