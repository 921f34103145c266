"""Dynamic feasibility of the shared clips for our character (prints figures; run
``.venv/bin/python benchmarks/bench_feasibility.py [--check]``).

For every single-support frame, :func:`reactmocap.sim.support_feasibility` gives the horizontal
moment about the centre of mass a single ground force at the sole's centre leaves unexplained
(``r``) and the most the centre of pressure could add (``cap``); frames with ``r > 2 cap`` need
a moment the foot cannot give (see that module). Printed per clip: the share of such frames,
their runs of 0.1 s or more, and how many of the tracking benchmark's windows
(``bench_sim.py``) overlap them.

``--check`` runs the same analysis on a physically simulated walk (the whole-body tracker's
output, recorded at the clip's frame rate): there no frame should be above the bound's 2x,
which checks the analysis itself.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

# the tracking benchmark's windows (this script's folder)
from bench_sim import INFEASIBLE_SECONDS, infeasible_seconds

from reactmocap.library.bvh import read_bvh
from reactmocap.library.motion import Motion
from reactmocap.sim import support_feasibility, track_clip

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT / ".." / "shared" / "mocap"


def report(motion: Motion, name: str) -> list[float]:
    """Print the clip's figures; return the infeasible seconds inside each benchmark window."""
    check = support_feasibility(motion)
    res, cap = check.residual, check.bound
    single = check.single_support
    bad = check.infeasible(2.0)
    runs = check.stretches(2.0, 0.1)
    ratio = res[single] / np.maximum(cap[single], 1e-9)
    print(
        f"{name:<32} single support {single.mean():4.0%}  median r/cap "
        f"{np.median(ratio) if ratio.size else 0.0:5.2f}  frames r > 2 cap "
        f"{bad.sum() / max(single.sum(), 1):4.0%}  max r {res[single].max(initial=0.0):6.0f} N m"
    )
    for a, b in runs:
        seg = slice(round(a * motion.fps), round(b * motion.fps))
        print(
            f"    {a:5.2f}-{b:5.2f} s: r {np.nanmin(res[seg]):4.0f}-{np.nanmax(res[seg]):4.0f} "
            f"N m against cap {np.nanmin(cap[seg]):3.0f}-{np.nanmax(cap[seg]):3.0f} N m"
        )
    return infeasible_seconds(motion, check)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="also analyse a simulated walk")
    args = ap.parse_args(argv)
    clips = sorted(
        p for p in SHARED.glob("*/*.bvh") if any(k in p.name for k in ("walk", "run", "kick"))
    )
    if not clips:
        print(f"(no shared clips under {SHARED.resolve()})")
        return 0
    print("## single-support moment residual (r) against the sole's bound (cap); runs >= 0.1 s")
    inside: list[float] = []
    for path in clips:
        inside += report(read_bvh(path), path.stem)
    over = np.array(inside)
    print(
        f"\nbenchmark windows (1 s every 0.5 s): {len(over)}; with >= {INFEASIBLE_SECONDS} s of "
        f"frames r > 2 cap: {int((over >= INFEASIBLE_SECONDS).sum())}; with any: "
        f"{int((over > 0).sum())}"
    )
    if args.check:
        walk = read_bvh(next(p for p in clips if "walk_normal_001" in p.name))
        sim = track_clip(walk, start=2.5, seconds=2.0, record_fps=walk.fps).motion
        print("\n## check: the same analysis on the simulated walk (2.5-4.5 s, whole-body tracker)")
        report(sim, "walk_normal_001 simulated")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
