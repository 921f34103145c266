"""Bicycle, rider and group-riding figures (issue 21; the table in docs/athletics.md). Run
``.venv/bin/python benchmarks/bench_athletics_bicycle.py [--only SECTION ...] [--workers N]``.

Sections:

1. ``stability``: the uncontrolled benchmark bicycle (Meijaard et al. 2007) coasting at 3-7.5 m/s:
   its modes fitted from the simulated roll and steer, the weave and capsize speeds where their
   rates cross zero, against the benchmark's; and the wheel's collision shape compared.
2. ``speed``: a rider holding 2-10 m/s on level ground: RMS speed error after 5 s of a 10 s ride,
   and 60 s rides (falls, RMS error from 5 s on).
3. ``heading``: heading steps of +-30 and +-90 degrees at 5 m/s (and 90 at 3 and 8 m/s): settle
   time (within 5 degrees for good) and overshoot.
4. ``hills``: 5% and 10% grades at 5 m/s for 20 s (gear 2.8, and 2.0 on the 10%).
5. ``group``: 8 and 16 riders around the corner on a hill with five obstacles
   (``examples/athletics/courses/corner_on_a_hill.toml``), 60 s: collisions, falls, minimum
   separation, finish times.
6. ``realtime``: one rider's real-time factor (wall clock and CPU time); the group's are in 5.

Independent rides run in ``--workers`` processes (a process pool: every ride is its own world).
A group is one world, one process: its riders touch and see each other every step, so it cannot
be split across processes (see docs/athletics.md).
"""

from __future__ import annotations

import argparse
import datetime
import math
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.athletics.bicycle import (
    BENCHMARK,
    BENCHMARK_CAPSIZE_SPEED,
    BENCHMARK_WEAVE_SPEED,
    linear_eigenvalues,
)
from reactmocap.athletics.course import load_course
from reactmocap.athletics.cycling import group_ride, ride
from reactmocap.athletics.stability import self_stable_speeds, stability_sweep

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "examples" / "athletics" / "courses" / "corner_on_a_hill.toml"
SECTIONS = ("stability", "speed", "heading", "hills", "group", "realtime")


def _ride(kwargs: dict[str, Any]) -> dict[str, Any]:
    """One ride in a worker: its report and the speed trace's stats (picklable)."""
    res = ride(**kwargs)
    rep = dict(res.report)
    log = res.logs[0]
    rep["_max_speed_dev"] = float(np.abs(log["speed"] - log["speed_cmd"]).max())
    late = log["t"] >= 5.0
    rep["_torque_mean"] = float(np.mean(log["crank_torque"][late])) if late.any() else None
    rep["_torque_saturated"] = (
        float(np.mean(np.abs(log["crank_torque"][late]) >= 179.9)) if late.any() else None
    )
    return rep


def _map(jobs: list[dict[str, Any]], workers: int) -> list[dict[str, Any]]:
    if workers <= 1:
        return [_ride(j) for j in jobs]
    with ProcessPoolExecutor(workers) as pool:
        return list(pool.map(_ride, jobs))


def _f(v: Any, fmt: str = ".2f") -> str:
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)


# ---------------------------------------------------------------------------------- sections
def stability() -> None:
    print(
        "## 1. Benchmark bicycle, uncontrolled (modes fitted from the simulated roll and steer)\n"
    )
    speeds = np.round(np.arange(3.0, 7.51, 0.25), 3)
    t0 = time.perf_counter()
    points = stability_sweep(speeds)
    wall = time.perf_counter() - t0
    print(
        "| speed m/s | weave (sim) 1/s | weave (linear) 1/s | capsize (sim) 1/s | capsize (linear) 1/s | roll |"
    )
    print("|---|---|---|---|---|---|")
    for p in points:
        lin = linear_eigenvalues(p.speed)
        osc = lin[np.abs(lin.imag) > 1e-9]
        lw = osc[np.argmax(np.abs(osc.imag))] if osc.size else complex("nan")
        lc = lin[np.abs(lin.imag) <= 1e-9].real.max()
        print(f"| {p.speed:.2f} | {p.weave.real:+.3f} {abs(p.weave.imag):.3f}i | {lw.real:+.3f} "
              f"{abs(lw.imag):.3f}i | {p.capsize:+.4f} | {lc:+.4f} | "
              f"{'decays' if p.stable else 'grows'} |")  # fmt: skip
    weave, capsize = self_stable_speeds(points)
    print(f"\nweave speed {weave:.3f} m/s (benchmark {BENCHMARK_WEAVE_SPEED:.3f}, "
          f"{100 * (weave / BENCHMARK_WEAVE_SPEED - 1):+.2f}%); capsize speed {capsize:.3f} m/s "
          f"(benchmark {BENCHMARK_CAPSIZE_SPEED:.3f}, {100 * (capsize / BENCHMARK_CAPSIZE_SPEED - 1):+.2f}%); "
          f"goal within 5%; {len(points)} coasts of 4 s in {wall:.1f} s")  # fmt: skip
    print("\nwheel collision shape at 5 m/s (benchmark: weave -0.775, capsize -0.323 1/s):")
    for shape in ("ellipsoid", "cylinder", "sphere"):
        p = stability_sweep([5.0], replace(BENCHMARK, wheel_shape=shape))[0]
        print(
            f"  {shape:9s} weave {p.weave.real:+.3f} {abs(p.weave.imag):.3f}i, capsize {p.capsize:+.3f}"
        )
    print()


def speed(workers: int) -> None:
    print("## 2. Speed control on level ground\n")
    vs = [2.0, 4.0, 6.0, 8.0, 10.0]
    short = _map([{"speed": v, "seconds": 10.0} for v in vs], workers)
    long = _map([{"speed": v, "seconds": 60.0} for v in vs], workers)
    print(
        "| speed m/s | RMS error 5-10 s | max error 0-10 s | 60 s: fell | 60 s: RMS error 5-60 s | 60 s: max roll deg |"
    )
    print("|---|---|---|---|---|---|")
    for v, a, b in zip(vs, short, long):
        print(f"| {v:g} | {_f(a['speed_error_m_s'], '.3f')} | {a['_max_speed_dev']:.3f} | {b['fell']} | "
              f"{_f(b['speed_error_m_s'], '.3f')} | {_f(b['max_roll_deg'], '.1f')} |")  # fmt: skip
    med = float(np.median([a["speed_error_m_s"] for a in short]))
    worst = max(a["speed_error_m_s"] for a in short)
    print(f"\nmedian RMS error after 5 s {med:.3f} m/s ({med / 0.2:.2f} of the 0.2 bar), worst "
          f"{worst:.3f} ({worst / 0.2:.2f}); 60 s rides fell: {sum(b['fell'] for b in long)} of {len(vs)}\n")  # fmt: skip


def heading(workers: int) -> None:
    print("## 3. Heading steps (commanded at 1 s; settled = within 5 degrees for good)\n")
    cases = [
        (5.0, 30.0),
        (5.0, -30.0),
        (5.0, 90.0),
        (5.0, -90.0),
        (3.0, 90.0),
        (8.0, 90.0),
        (10.0, 90.0),
    ]
    reps = _map(
        [{"speed": v, "seconds": 8.0, "heading": math.radians(h)} for v, h in cases], workers
    )
    print(
        "| speed m/s | step deg | settle s | overshoot deg | max roll deg | speed error m/s | fell |"
    )
    print("|---|---|---|---|---|---|---|")
    for (v, h), r in zip(cases, reps):
        print(f"| {v:g} | {h:+g} | {_f(r.get('settle_time_s'))} | {_f(r.get('overshoot_deg'), '.1f')} | "
              f"{_f(r['max_roll_deg'], '.1f')} | {_f(r['speed_error_m_s'], '.3f')} | {r['fell']} |")  # fmt: skip
    at5 = [r for (v, _), r in zip(cases, reps) if v == 5.0]
    st = [r["settle_time_s"] for r in at5 if r["settle_time_s"] is not None]
    print(f"\nat 5 m/s: median settle {np.median(st):.2f} s ({np.median(st) / 3:.2f} of the 3 s bar), "
          f"worst overshoot {max(r['overshoot_deg'] for r in at5):.1f} deg (bar 10)\n")  # fmt: skip


def hills(workers: int) -> None:
    print("## 4. Hills at 5 m/s, 20 s (speed error from 5 s on)\n")
    cases = [(0.05, 2.8), (0.10, 2.8), (0.10, 2.0)]
    reps = _map(
        [{"speed": 5.0, "seconds": 20.0, "grade": g, "gear": gear} for g, gear in cases], workers
    )
    print(
        "| grade | gear | fell | mean speed m/s | RMS error m/s | max error m/s | crank torque N m | at torque limit |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for (g, gear), r in zip(cases, reps):
        print(f"| {100 * g:g}% | {gear:g} | {r['fell']} | {_f(r['mean_speed_m_s'], '.3f')} | "
              f"{_f(r['speed_error_m_s'], '.3f')} | {r['_max_speed_dev']:.3f} | {_f(r['_torque_mean'], '.0f')} | "
              f"{100 * (r['_torque_saturated'] or 0):.0f}% |")  # fmt: skip
    print()


def group(sizes: list[int], seconds: float | None) -> None:
    print("## 5. Group around the corner on a hill with five obstacles\n")
    course = load_course(COURSE)
    print(
        "| riders | seconds | collisions | fell | min separation m (when) | finished | finish s (median) | real time (wall) | real time (CPU) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for n in sizes:
        res = group_ride(course, n, seconds=seconds)
        r = res.report
        done = [t for t in r["finish_times_s"] if t is not None]
        print(f"| {n} | {r['seconds']:g} | {r['collisions']} | {r['fell']} | {_f(r['min_separation_m'], '.3f')} at {_f(r['min_separation_at_s'], '.1f')} s | "
              f"{len(done)}/{n} | {_f(float(np.median(done)) if done else None, '.1f')} | "
              f"{r['realtime_factor']:.2f}x | {r['cpu_realtime_factor']:.2f}x |")  # fmt: skip
        if r["collisions"]:
            print(f"  collisions: {r['collision_log'][:6]}")
        sys.stdout.flush()
    print()


def realtime() -> None:
    print("## 6. Speed: one rider, 10 s at 5 m/s\n")
    rows = [_ride({"speed": 5.0, "seconds": 10.0}) for _ in range(3)]
    wall = float(np.median([r["realtime_factor"] for r in rows]))
    cpu = float(np.median([r["cpu_realtime_factor"] for r in rows]))
    print(f"real-time factor (median of 3): {wall:.2f}x by the wall clock, {cpu:.2f}x by CPU time "
          f"(goal >= 2x; Hodgins et al.: 10x slower than real time)\n")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=SECTIONS, help="run only these sections")
    ap.add_argument("--workers", type=int, default=1, help="processes for independent rides")
    ap.add_argument("--group-sizes", type=int, nargs="+", default=[8, 16])
    ap.add_argument("--group-seconds", type=float, help="default: the course's (60 s)")
    args = ap.parse_args()
    run = set(args.only or SECTIONS)
    print(f"# bench_athletics_bicycle {datetime.date.today()} ({platform.machine()}, "
          f"{platform.python_version()}): {' '.join(sys.argv[1:]) or '(all sections)'}\n")  # fmt: skip
    t0 = time.perf_counter()
    if "stability" in run:
        stability()
    if "speed" in run:
        speed(args.workers)
    if "heading" in run:
        heading(args.workers)
    if "hills" in run:
        hills(args.workers)
    if "realtime" in run:
        realtime()
    if "group" in run:
        group(args.group_sizes, args.group_seconds)
    print(f"total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
