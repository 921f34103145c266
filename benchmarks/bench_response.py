"""Response pipeline timing per stage for the example scenarios, next to bare mj_step cost of
the same number of steps measured in the same run.

    python benchmarks/bench_response.py [--repeats 3]

Targets (issue 5): total <= 0.5 s per response with an attacker (1 s of Simulation 1 and 1 s of
Simulation 2); pipeline overhead over bare stepping <= 1.3x.

Bare stepping is one ``mj_step(nstep)`` call on Simulation 2's model from the pre-impact state,
with its servo actuators holding the start pose: MuJoCo's share of the servo (actuator forces,
implicit damping) is in both columns, and the ratio measures what the pipeline adds in Python.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import mujoco
import numpy as np

from reactmocap.response.pipeline import LibraryCache, run_response
from reactmocap.response.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
STAGES = ("scan", "sim1", "search", "sim2", "blend", "total")


def bare_step_seconds(model: mujoco.MjModel, state: np.ndarray, steps: int) -> float:
    """One ``mj_step(nstep=steps)`` call on Simulation 2's model from the pre-impact state.
    The model's servo actuators keep the gears and gains of the last refresh; ``ctrl`` is set
    to their current lengths, so they hold the start pose (the character stands, with
    contacts, as in the pipeline) instead of pulling toward a stale linearisation."""
    d = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    mujoco.mj_setState(model, d, state, spec)
    mujoco.mj_forward(model, d)
    d.ctrl[:] = d.actuator_length
    t0 = time.perf_counter()
    mujoco.mj_step(model, d, nstep=steps)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("scenarios", nargs="*", type=Path)
    args = ap.parse_args()
    paths = args.scenarios or sorted(
        p for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep")
    )
    print(
        f"{'scenario':18s} " + " ".join(f"{s:>7s}" for s in STAGES) + "   steps  bare_s  sim/bare"
    )
    cache = LibraryCache()
    for path in paths:
        sc = load_scenario(path)
        run_response(sc, cache)  # warm: index and library caches
        rows = []
        ratio = []
        for _ in range(args.repeats):
            res = run_response(sc, cache)
            t = res.report["timings_s"]
            rows.append([t[s] for s in STAGES])
            steps = res.report["steps"]["sim1"] + res.report["steps"]["sim2"]
            assert res.model is not None and res.start_state is not None
            bare = bare_step_seconds(res.model, res.start_state, steps)
            ratio.append((t["sim1"] + t["sim2"]) / bare)
        med = np.median(np.array(rows), axis=0)
        print(f"{path.stem:18s} " + " ".join(f"{v:7.3f}" for v in med)
              + f"   {steps:5d}  {bare:6.3f}  {statistics.median(ratio):6.2f}x")  # fmt: skip


if __name__ == "__main__":
    main()
