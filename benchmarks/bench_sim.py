"""Physics benchmarks (prints figures; run ``.venv/bin/python benchmarks/bench_sim.py``).

1. us per step and real-time factor, each next to the bare ``mj_step`` of the same model and
   state measured in the same run: one character standing under PD, the same passive
   (ragdoll), two characters in contact under PD.
2. MuJoCo options (integrator x solver x cone) for the standing PD character.
3. Tracking robustness: 1 s windows every 0.5 s through each shared walk/run/kick clip (a clip
   shorter than 1 s is one window): % of windows in which the character stays upright with
   the pelvis within 10 cm and 15 deg of the mocap at every recorded frame; medians of the
   errors. Physical (no root help) and, separately labelled, with the non-physical root assist.
   Windows run in ``--jobs`` processes (the predictive tracker takes ~8 s per window).
4. The guard stance clip tracked for 10 s.
5. Whole clips: every shared clip tracked from start to end by ``--whole-controllers``: upright
   to the end (a fall just after a ``support_feasibility``-flagged span is excused and counted
   apart), PHC's criterion (Luo et al. 2023: a clip fails when the mean body position error
   exceeds 0.5 m at any frame), no ``unstable`` status, real-time factors (wall and CPU);
   ``--whole-params`` (JSON) sets options over ``WHOLE_CLIP`` (e.g. ``'{"centre_speed": 1.0}'``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips
from reactmocap.sim import (
    PDServo,
    SupportFeasibility,
    World,
    WorldConfig,
    build_character,
    rollout,
    support_feasibility,
    track_clip,
)
from reactmocap.sim.controllers.registry import WHOLE_CLIP

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT / ".." / "shared" / "mocap"


def _read_bvh(path: Path) -> Motion:
    from reactmocap.library.bvh import read_bvh

    return read_bvh(path)


def _time_steps(world: World, servo: PDServo | None, n: int) -> float:
    """Seconds per step: the servo's chunked stepping (refreshes included), or bare
    ``mj_step(nstep=n)``, one C call as the servo's chunks are."""
    m, d = world.model, world.data
    t = time.perf_counter()
    if servo is None:
        mujoco.mj_step(m, d, nstep=n)
    else:
        servo.step(n)
    return (time.perf_counter() - t) / n


def _paired(world: World, servo: PDServo | None, n: int, reps: int = 5) -> tuple[float, float]:
    """Median us/step with the servo and bare mj_step from the same saved state. Bare runs the
    same model with the servo's actuators as linearised at the start state (one untimed
    refresh): MuJoCo's own actuator cost is in both columns, the refreshes only in the first."""
    state = world.get_state()
    with_pd, bare = [], []
    for _ in range(reps):
        world.set_state(state)
        with_pd.append(_time_steps(world, servo, n))
        world.set_state(state)
        if servo is not None:
            servo.refresh()
        bare.append(_time_steps(world, None, n))
    return float(np.median(with_pd)) * 1e6, float(np.median(bare)) * 1e6


def bench_steps(n: int) -> None:
    clips = synthetic_clips(30.0)
    guard = clips["guard"]
    ch = build_character(guard)
    dt = WorldConfig().timestep
    print(f"\n## us per step (dt = {dt} s; medians of 5 runs of {n} steps)")
    print(f"{'case':<34} {'us/step':>8} {'bare':>8} {'overhead':>9} {'RT factor':>9}")

    world = World(ch)
    world.set_from_motion(0, guard, 0, velocity=False)
    servo = PDServo(world, kp=4000.0)
    rollout(world, 0.1)  # settle on the feet
    pd, bare = _paired(world, servo, n)
    print(
        f"{'1 char standing, PD':<34} {pd:8.1f} {bare:8.1f} {100 * (pd / bare - 1):8.1f}% "
        f"{dt * 1e6 / pd:8.1f}x"
    )

    world = World(ch)
    world.set_from_motion(0, guard, 0, velocity=False)
    t_rag, _ = _paired(world, None, n)
    print(
        f"{'1 char passive (ragdoll)':<34} {t_rag:8.1f} {t_rag:8.1f} {0.0:8.1f}% "
        f"{dt * 1e6 / t_rag:8.1f}x"
    )

    world = World([ch, ch])
    b = guard.transformed(yaw=np.pi, translation=(0.42, 0.0, 0.0))
    world.set_from_motion(0, guard, 0, velocity=False)
    world.set_from_motion(1, b, 0, velocity=False)
    servo = PDServo(world, kp=4000.0)
    rollout(world, 0.05)
    from reactmocap.sim import contact_report

    ncc = len(contact_report(world).between)
    pd, bare = _paired(world, servo, n)
    print(
        f"{'2 chars in contact, PD':<34} {pd:8.1f} {bare:8.1f} {100 * (pd / bare - 1):8.1f}% "
        f"{dt * 1e6 / pd:8.1f}x   ({ncc} char-char contacts at start)"
    )


def bench_options(n: int) -> None:
    guard = synthetic_clips(30.0)["guard"]
    ch = build_character(guard)
    print(f"\n## MuJoCo options, 1 char standing under PD (us/step, median of 3 x {n})")
    for integ in ("euler", "implicitfast", "rk4"):
        for solver in ("newton", "cg", "pgs"):
            for cone in ("pyramidal", "elliptic"):
                if integ == "rk4" and solver != "newton":
                    continue
                world = World(ch, WorldConfig(integrator=integ, solver=solver, cone=cone))
                world.set_from_motion(0, guard, 0, velocity=False)
                kp = 400.0 if integ == "rk4" else 4000.0  # RK4 damping is explicit
                servo = PDServo(world, kp=kp)
                try:
                    rollout(world, 0.05)
                    pd, bare = _paired(world, servo, n, reps=3)
                    print(
                        f"{integ:<13} {solver:<7} {cone:<10} PD {pd:7.1f}  bare {bare:7.1f}"
                        f"  ncon {world.data.ncon}"
                    )
                except Exception as exc:
                    print(f"{integ:<13} {solver:<7} {cone:<10} failed: {exc}")


def _windows(motion: Motion) -> list[float]:
    if motion.duration <= 1.0:
        return [0.0]
    return list(np.arange(0.0, motion.duration - 1.0 + 1e-9, 0.5))


#: a window whose clip has this many seconds of single-support frames needing more than twice
#: the moment the foot can give (``support_feasibility``) asks the impossible of a physical
#: tracker for a while (``bench_feasibility.py``)
INFEASIBLE_SECONDS = 0.3


def infeasible_seconds(motion: Motion, check: SupportFeasibility | None = None) -> list[float]:
    """Seconds of single support needing more than twice the foot's moment inside each of
    :func:`_windows` (``check``: the clip's :func:`support_feasibility`, computed if absent)."""
    check = support_feasibility(motion) if check is None else check
    return [check.infeasible_seconds(s, 1.0) for s in _windows(motion)]


def _track_window(
    job: tuple[Path, float, str, float, dict[str, float]],
) -> tuple[bool, bool, float, float, float, float] | str:
    """One window: (ok, upright, max root error m, max angle rad, mean joint error rad,
    wall seconds per simulated second), or the error message."""
    path, s, controller, assist, params = job
    motion = _read_bvh(path)
    secs = min(1.0, motion.duration - s)
    try:
        res = track_clip(
            motion, start=float(s), seconds=secs, root_assist=assist, controller=controller,
            params=params,
        )  # fmt: skip
    except Exception as exc:
        return f"{path.name} @ {s:.1f}s failed: {exc}"
    rep = res.report
    ang = float(np.max(res.errors.angle))
    ok = (not rep.fell) and rep.max_root_error_m <= 0.10 and ang <= np.radians(15.0)
    return ok, not rep.fell, rep.max_root_error_m, ang, rep.mean_joint_error_rad, rep.wall_s / secs


def bench_tracking(assist_gain: float, controllers: list[str], jobs: int) -> None:
    clips = sorted(
        p for p in SHARED.glob("*/*.bvh") if any(k in p.name for k in ("walk", "run", "kick"))
    )
    if not clips:
        print(f"\n(no shared clips under {SHARED.resolve()}: tracking robustness skipped)")
        return
    labels = {"pd": "PD only", "balance": "PD + stance balance (physical)",
              "wholebody": "whole-body inverse dynamics (physical, default, WHOLE_CLIP)",
              "predictive": "whole-body + predictive sampling (physical)"}  # fmt: skip
    modes = [(c, 0.0, labels.get(c, c), {}) for c in controllers]
    if "wholebody" in controllers:  # the tracker without the whole-clip options
        window = {k: None for k in WHOLE_CLIP}  # None: the constructor's defaults
        modes.append(("wholebody", 0.0, "whole-body, window settings (no WHOLE_CLIP)", window))
    modes.append(("pd", assist_gain, f"PD WITH non-physical root assist kp={assist_gain:g}", {}))
    motions = {p: _read_bvh(p) for p in clips}
    windows = {p: _windows(m) for p, m in motions.items()}
    feasible = {
        p: [x < INFEASIBLE_SECONDS for x in infeasible_seconds(m)] for p, m in motions.items()
    }
    print(f"\n(windows run in {jobs} processes: real-time factors are per process)")
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for controller, assist, label, params in modes:
            print(f"\n## tracking robustness, {label} (controller's default gains)")
            print(
                f"{'clip':<28} {'windows':>7} {'ok %':>6} {'upright %':>9} {'med root cm':>11} "
                f"{'med ang deg':>11} {'med joint rad':>13}"
            )
            t0 = time.perf_counter()
            work = [(p, s, controller, assist, params) for p in clips for s in windows[p]]
            results = list(pool.map(_track_window, work))
            tot_ok = tot = feas_ok = feas = 0
            walls: list[float] = []
            for path in clips:
                rows = [r for (p, *_), r in zip(work, results) if p == path]
                for r in rows:
                    if isinstance(r, str):
                        print(f"  {r}")
                good = [r for r in rows if not isinstance(r, str)]
                ok = sum(r[0] for r in good)
                up = sum(r[1] for r in good)
                walls += [r[5] for r in good]
                tot_ok += ok
                tot += len(rows)
                for r, clear in zip(rows, feasible[path]):
                    feas += clear
                    feas_ok += clear and not isinstance(r, str) and r[0]
                print(
                    f"{path.stem:<28} {len(rows):>7} {100 * ok / len(rows):6.0f} "
                    f"{100 * up / len(rows):9.0f} {100 * np.median([r[2] for r in good]):11.1f} "
                    f"{np.degrees(np.median([r[3] for r in good])):11.1f} "
                    f"{np.median([r[4] for r in good]):13.3f}"
                )
            print(
                f"{'ALL':<28} {tot:>7} {100 * tot_ok / max(tot, 1):6.0f}   "
                f"(median real-time factor {1.0 / np.median(walls):.2f}x; "
                f"{time.perf_counter() - t0:.0f} s wall)"
            )
            print(
                f"{'FEASIBLE':<28} {feas:>7} {100 * feas_ok / max(feas, 1):6.0f}   (windows with "
                f"< {INFEASIBLE_SECONDS} s of single support needing > 2x the foot's moment)"
            )


#: a fall this soon after a feasibility-flagged span ends is excused (the clip asked for a
#: moment no foot gives; the body needs a moment to come down)
EXCUSE_AFTER_S = 0.5
#: PHC's failure threshold (Luo et al. 2023): mean body position error at any frame (m)
PHC_THRESHOLD_M = 0.5


def _track_whole(job: tuple[Path, str, dict[str, Any]]) -> dict[str, object]:
    """One whole clip: status, fall time, errors, PHC's criterion, feasibility excuse, rates."""
    path, controller, params = job
    motion = _read_bvh(path)
    cpu = time.process_time()
    res = track_clip(motion, controller=controller, params=params or None)
    cpu = time.process_time() - cpu
    rep = res.report
    roll = res.rollout
    ch = roll.world.characters[0].character
    times, _ = roll.frames()
    sim, _ = roll.body_transforms(0)
    ref, _ = ch.body_transforms_from_qpos(ch.qpos_from_motion(motion.sample(times)))
    body_err = np.linalg.norm(sim - ref, axis=-1).mean(axis=1)
    spans = support_feasibility(motion).stretches() if motion.num_frames >= 3 else []
    fell = rep.fell_at_s
    excused = fell is not None and any(a <= fell <= b + EXCUSE_AFTER_S for a, b in spans)
    return {
        "clip": path.stem, "seconds": motion.duration, "status": rep.status, "fell_at_s": fell,
        "excused": excused, "flagged": spans, "max_root_m": rep.max_root_error_m,
        "phc_ok": bool(body_err.max() <= PHC_THRESHOLD_M), "max_body_m": float(body_err.max()),
        "joint_rad": rep.mean_joint_error_rad, "rt_wall": rep.realtime_factor,
        "rt_cpu": roll.seconds / cpu if cpu > 0 else float("inf"),
    }  # fmt: skip


def bench_whole(controllers: list[str], jobs: int, params: dict[str, Any] | None = None) -> None:
    clips = sorted(SHARED.glob("*/*.bvh"))
    if not clips:
        print(f"\n(no shared clips under {SHARED.resolve()}: whole clips skipped)")
        return
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for controller in controllers:
            how = f"params {json.dumps(params)} over the defaults" if params else "default gains"
            print(f"\n## whole clips, {controller} ({how}; {jobs} processes)")
            print(f"{'clip':<30} {'s':>5} {'status':<8} {'fell at':>7} {'excused':>7} "
                  f"{'max root m':>10} {'PHC ok':>6} {'RT wall':>7} {'RT cpu':>6}")  # fmt: skip
            t0 = time.perf_counter()
            rows = list(pool.map(_track_whole, [(p, controller, params or {}) for p in clips]))
            for r in rows:
                fell = "-" if r["fell_at_s"] is None else f"{r['fell_at_s']:.2f}"
                print(
                    f"{r['clip']:<30} {r['seconds']:5.2f} {r['status']:<8} {fell:>7} "
                    f"{'yes' if r['excused'] else '':>7} {r['max_root_m']:10.2f} "
                    f"{'yes' if r['phc_ok'] else 'no':>6} {r['rt_wall']:6.2f}x {r['rt_cpu']:5.2f}x"
                )
            n = len(rows)
            ok = sum(r["status"] == "ok" for r in rows)
            exc = sum(bool(r["excused"]) for r in rows)
            phc = sum(bool(r["phc_ok"]) for r in rows)
            unstable = sum(r["status"] == "unstable" for r in rows)
            print(
                f"WHOLE {controller}: upright to the end {ok}/{n} ({100 * ok / n:.0f}%), with "
                f"{exc} feasibility-excused falls {ok + exc}/{n} ({100 * (ok + exc) / n:.0f}%); "
                f"PHC criterion {phc}/{n} ({100 * phc / n:.0f}%); unstable {unstable}; median "
                f"real-time factor {np.median([r['rt_wall'] for r in rows]):.2f}x wall, "
                f"{np.median([r['rt_cpu'] for r in rows]):.2f}x CPU "
                f"({time.perf_counter() - t0:.0f} s wall)"
            )


def bench_guard(kp: float, assist_gain: float) -> None:
    guard = synthetic_clips(30.0)["guard"]
    loop = Motion.concatenate([guard, guard.slice(1), guard.slice(1)], name="guard_x3")
    runs = [(c, 0.0) for c in ("pd", "balance", "wholebody", "predictive")]
    for controller, assist in [*runs, ("pd", assist_gain)]:
        rep = track_clip(
            loop, seconds=10.0, kp=None if controller in ("wholebody", "predictive") else kp,
            root_assist=assist, controller=controller,
        ).report  # fmt: skip
        label = f"root assist kp={assist:g}" if assist else controller
        print(
            f"\n## guard 10 s ({label}): fell={rep.fell} (at {rep.fell_at_s}), "
            f"mean joint err {rep.mean_joint_error_rad:.3f} rad, root err "
            f"{100 * rep.root_error_m:.1f} cm, RT factor {rep.realtime_factor:.2f}x"
        )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--kp", type=float, default=4000.0)
    ap.add_argument("--assist", type=float, default=100.0)
    ap.add_argument(
        "--skip", nargs="*", default=[],
        choices=["steps", "options", "tracking", "guard", "whole"],
    )  # fmt: skip
    ap.add_argument(
        "--controllers",
        nargs="*",
        default=["pd", "balance", "wholebody", "predictive"],
        help="tracking controllers for the robustness windows (the root-assist run is added)",
    )
    ap.add_argument(
        "--whole-controllers", nargs="*", default=["wholebody"],
        help="controllers tracking the whole shared clips (predictive: ~40x slower)",
    )  # fmt: skip
    ap.add_argument(
        "--whole-params", type=json.loads, default={},
        help="JSON options over the whole clips' (WHOLE_CLIP and the controller's defaults)",
    )  # fmt: skip
    ap.add_argument("--jobs", type=int, default=2, help="processes for the tracking runs")
    args = ap.parse_args(argv)
    print(f"mujoco {mujoco.__version__}, python {sys.version.split()[0]}")
    if "steps" not in args.skip:
        bench_steps(args.steps)
    if "options" not in args.skip:
        bench_options(args.steps // 2)
    if "guard" not in args.skip:
        bench_guard(args.kp, args.assist)
    if "tracking" not in args.skip:
        bench_tracking(args.assist, args.controllers, args.jobs)
    if "whole" not in args.skip:
        bench_whole(args.whole_controllers, args.jobs, args.whole_params)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
