"""Batch throughput: scenarios per minute with 1 and 2 workers for the local process pool and for
Ray, on the 36-direction sweep of ``examples/sweep_facing.toml``.

    python benchmarks/bench_batch.py [--limit 12] [--workers 1,2] [--runners local,ray]

Each run starts from an empty results folder, with the clip cache and search index already on
disk (one warm-up scenario runs first). Pool timings include spawning its workers. Ray timings
exclude ``ray.init`` (printed apart: a cluster pays it once, not per sweep) but include Ray's
worker start-up and scheduling.

"workers busy" is the share of the workers' wall time spent inside scenarios (in-worker time x
scenarios / (workers x wall)): it isolates the runner's own overhead (start-up, scheduling,
result handling) from contention for the cores, which shows as a growing in-worker time.

Targets (issue 6): 2-worker efficiency >= 85% (rate with 2 / (2 x rate with 1)) and Ray
overhead <= 10% over the pool at the same worker count.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from pathlib import Path

from reactmocap.batch import load_sweep, run_batch

SWEEP = Path(__file__).resolve().parents[1] / "examples" / "sweep_facing.toml"


def _timed(sweep, runner: str, workers: int, root: Path) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """Wall seconds of the batch and the mean in-worker seconds per scenario: when the latter
    grows with the worker count, the cores are contended (not a runner overhead)."""
    out = Path(tempfile.mkdtemp(prefix=f"{runner}{workers}-", dir=root))
    t0 = time.perf_counter()
    res = run_batch(sweep, out, runner=runner, workers=workers, progress=False, log=lambda s: None)
    wall = time.perf_counter() - t0
    failed = res.summary.failures
    if failed:
        raise SystemExit(f"{failed} scenarios failed in {out}")
    per = sum(r["time_total_s"] for r in res.rows) / len(res.rows)
    return wall, per


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--limit", type=int, default=None, help="run only N of the 36 scenarios")
    ap.add_argument("--workers", default="1,2", help="comma-separated worker counts")
    ap.add_argument("--runners", default="local,ray", help="comma-separated runners")
    args = ap.parse_args()
    sweep = load_sweep(SWEEP)
    if args.limit:
        sweep = dataclasses.replace(sweep, subsample=args.limit)
    n = len(sweep.points())
    counts = [int(w) for w in args.workers.split(",")]
    runners = args.runners.split(",")
    print(f"{n} scenarios of {SWEEP.name}, {os.cpu_count()} CPUs")

    from reactmocap.response.pipeline import run_scenario

    run_scenario(sweep.points()[0].scenario)  # warm the on-disk clip cache and index

    wall: dict[tuple[str, int], float] = {}
    per: dict[tuple[str, int], float] = {}
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as tmp:
        for runner in runners:
            for w in counts:
                if runner == "ray":
                    import ray

                    t0 = time.perf_counter()
                    ray.init(num_cpus=w, include_dashboard=False, logging_level="WARNING")
                    init = time.perf_counter() - t0
                    try:
                        wall[runner, w], per[runner, w] = _timed(sweep, runner, w, Path(tmp))
                    finally:
                        ray.shutdown()
                    extra = f"  (ray.init {init:.1f} s, not counted)"
                else:
                    wall[runner, w], per[runner, w] = _timed(sweep, runner, w, Path(tmp))
                    extra = ""
                rate = 60 * n / wall[runner, w]
                print(
                    f"{runner:6s} {w} worker(s): {wall[runner, w]:6.1f} s  {rate:6.1f}/min  "
                    f"{per[runner, w]:.2f} s/scenario in-worker{extra}"
                )

    print(
        "\n| runner | workers | wall s | scenarios/min | efficiency vs 1 worker "
        "| in-worker s/scenario | workers busy |"
    )
    print("|---|---|---|---|---|---|---|")
    for (runner, w), t in wall.items():
        base = wall.get((runner, 1))
        eff = f"{100 * base / (w * t):.0f}%" if base and w > 1 else "-"
        # share of the workers' wall time spent inside scenarios: the runner's own overhead,
        # independent of how contended the cores are
        busy = n * per[runner, w] / (w * t)
        print(
            f"| {runner} | {w} | {t:.1f} | {60 * n / t:.1f} | {eff} | {per[runner, w]:.2f} "
            f"| {busy:.0%} |"
        )
    if "local" in runners and "ray" in runners:
        for w in counts:
            if ("local", w) in wall and ("ray", w) in wall:
                over = 100 * (wall["ray", w] / wall["local", w] - 1)
                print(f"Ray overhead over the pool with {w} worker(s): {over:+.0f}%")


if __name__ == "__main__":
    main()
