"""``batch SWEEP.toml --out DIR``, ``batch plot DIR`` and ``regress DIR --baseline B.json``:
thin wrappers over :mod:`reactmocap.batch`."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path
from types import FrameType

from reactmocap.commands import output_dir

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    b = sub.add_parser(
        "batch",
        help="run a scenario sweep (TOML), or `batch plot DIR` to draw its figures",
        description="Run every scenario of a sweep file into DIR/results.csv and results.jsonl "
        "(a rerun resumes), or with `batch plot DIR` draw metrics against the swept axes and a "
        "contact sheet of the saved animations.",
    )
    b.add_argument("target", metavar="SWEEP.toml|plot", help="a sweep file, or `plot`")
    b.add_argument("dir", nargs="?", type=Path, metavar="DIR", help="results folder (for plot)")
    b.add_argument("--out", type=output_dir, metavar="DIR", help="results folder (for a sweep)")
    b.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="parallel workers (default: CPU count)",
    )
    ray = b.add_mutually_exclusive_group()
    ray.add_argument("--ray", action="store_true", help="run on a local Ray runtime")
    ray.add_argument("--ray-address", metavar="ADDR", help="join a Ray cluster (e.g. auto)")
    ray.add_argument(
        "--runner",
        default=None,
        metavar="NAME",
        help="runner by name: local (default), ray, serial",
    )
    b.add_argument(
        "--save-animations",
        action="store_true",
        help="keep each scenario's outputs under DIR/scenarios/ID/",
    )
    b.add_argument("--retry-failed", action="store_true", help="rerun scenarios that failed")
    b.set_defaults(func=_batch, _parser=b)

    r = sub.add_parser(
        "regress",
        help="compare a batch results folder with a baseline of metric statistics",
        description="Exit 1 when a quality metric got worse beyond its tolerance (or, with "
        "--strict, when anything drifted); --update writes the baseline instead.",
    )
    r.add_argument("dir", type=Path, metavar="DIR")
    r.add_argument("--baseline", type=Path, required=True, metavar="BASELINE.json")
    r.add_argument("--update", action="store_true", help="write the baseline from DIR")
    r.add_argument(
        "--strict", action="store_true", help="also fail on improvements and per-scenario drift"
    )
    r.set_defaults(func=_regress)


def _sigterm(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt  # a terminated batch saves its tables like Ctrl-C does


def _batch(args: argparse.Namespace) -> int:
    parser: argparse.ArgumentParser = args._parser
    if args.target == "plot":  # a sweep file named plot can be given as ./plot
        if args.dir is None:
            parser.error("batch plot needs a results folder: reactmocap batch plot DIR")
        from reactmocap.batch import plot_batch

        for path in plot_batch(args.dir):
            print(path)
        return 0
    if args.dir is not None:
        parser.error(f"unexpected argument {str(args.dir)!r}; the results folder goes in --out")
    if args.out is None:
        parser.error("--out DIR is required to run a sweep")
    from reactmocap.batch import describe, load_sweep, run_batch

    runner = args.runner or ("ray" if args.ray or args.ray_address else "local")
    sweep = load_sweep(args.target)
    previous = signal.signal(signal.SIGTERM, _sigterm)
    try:
        result = run_batch(
            sweep,
            args.out,
            runner=runner,
            workers=args.workers,
            address=args.ray_address,
            save_animations=args.save_animations,
            retry_failed=args.retry_failed,
        )
    except KeyboardInterrupt:
        print(
            f"interrupted: finished rows are in {args.out / 'results.jsonl'} and results.csv; "
            "rerun the same command to resume",
            file=sys.stderr,
        )
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    print(describe(result))
    failed = [r for r in result.rows if r.get("status") != "ok"]
    for r in failed[:5]:
        print(f"  failed {r['id']}: {r.get('error')}")
    return 0


def _regress(args: argparse.Namespace) -> int:
    from reactmocap.batch import regress

    code, text = regress(args.dir, args.baseline, update=args.update, strict=args.strict)
    print(text)
    return code
