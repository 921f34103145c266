"""The physical response mode against the paper's blend, on the facing sweep (prints figures).

    python benchmarks/bench_physical.py [--directions 36] [--degs 0,90] [--sweep ...toml]

Every direction of the sweep runs in both modes in the same process, alternating, so the time
ratio is measured under the same load. Per direction: whether the run finished, whether the
body landed on the found clip within the tolerances, the final blend's root offset, largest
joint correction (the skeleton's joints) and root turn, the impulse the recipient took, and the
time per response. The targets
(issue 16): 100% finish, median root offset <= 0.02 m, 95th-percentile joint correction
<= 0.1 rad, median time <= 3x the blend's.
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from reactmocap.batch import load_sweep
from reactmocap.errors import ReactMocapError
from reactmocap.response.pipeline import LibraryCache, run_response

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--directions", type=int, default=36)
    ap.add_argument("--degs", help="facing directions to run (comma list, degrees) instead of "
                    "--directions evenly spaced ones")  # fmt: skip
    ap.add_argument("--sweep", type=Path, default=ROOT / "examples" / "sweep_facing.toml")
    args = ap.parse_args()
    if args.degs:
        degs = [float(d) for d in args.degs.split(",")]
    else:
        degs = [360.0 * k / args.directions for k in range(args.directions)]
    base = load_sweep(args.sweep).points()[0].scenario
    cache = LibraryCache()
    run_response(base, cache)  # warm the library cache outside the timings
    rows: dict[str, list[dict]] = {"blend": [], "physical": []}
    for deg in degs:
        for mode in ("blend", "physical"):
            sc = replace(base, recipient=replace(base.recipient, facing_deg=deg),
                         response=replace(base.response, mode=mode))  # fmt: skip
            t = time.perf_counter()
            try:
                rep = run_response(sc, cache).report
            except ReactMocapError as exc:  # a failure is a figure too
                print(f"facing {deg:5.1f} {mode:8s} FAILED: {exc}")
                rows[mode].append({"failed": True})
                continue
            wall = time.perf_counter() - t
            q, tr = rep["quality"], rep["transition"]
            rows[mode].append({"failed": False, "wall": wall, **q, **tr})
            print(f"facing {deg:5.1f} {mode:8s} {rep['matched']['clip'][:14]:14s} "
                  f"landed {tr['landed_on_clip']!s:5s} root {q['blend_root_offset_max_m']:.3f} m "
                  f"joint {q['blend_joint_correction_max_rad']:.3f} rad "
                  f"root turn {q['blend_root_turn_max_rad']:.3f} rad "
                  f"disp {q['reaction_displacement_m']:.2f} m "
                  f"imp {q['contact_impulse_Ns']:.0f} N s tr {q['transition_s']:.2f} s "
                  f"fell {q['fell']!s:5s} {wall:.2f} s")  # fmt: skip
    for mode, rs in rows.items():
        done = [r for r in rs if not r["failed"]]
        if not done:
            print(f"{mode.upper()}: nothing finished")
            continue
        root = [r["blend_root_offset_max_m"] for r in done]
        joint = [r["blend_joint_correction_max_rad"] for r in done]
        turn = [r["blend_root_turn_max_rad"] for r in done]
        print(f"{mode.upper()}: finished {len(done)}/{len(rs)}; landed on the clip "
              f"{sum(r['landed_on_clip'] for r in done)}/{len(rs)}; median root offset "
              f"{statistics.median(root):.3f} m; p95 joint correction "
              f"{float(np.percentile(joint, 95)):.3f} rad; p95 root turn "
              f"{float(np.percentile(turn, 95)):.3f} rad; median time "
              f"{statistics.median(r['wall'] for r in done):.2f} s")  # fmt: skip
    pairs = [(b["wall"], p["wall"]) for b, p in zip(rows["blend"], rows["physical"], strict=True)
             if not b["failed"] and not p["failed"]]  # fmt: skip
    if pairs:
        print(f"TIME: physical / blend, median of per-direction ratios "
              f"{statistics.median(p / b for b, p in pairs):.2f}x")  # fmt: skip


if __name__ == "__main__":
    main()
