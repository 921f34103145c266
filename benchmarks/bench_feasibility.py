"""Dynamic feasibility of the shared clips for our character (prints figures; run
``.venv/bin/python benchmarks/bench_feasibility.py [--check]``).

Why: a tracker can only follow a clip whose whole-body momentum the ground can produce. In
single support all external force but gravity comes through one foot, so the rate of angular
momentum about the centre of mass must equal ``(p - c) x f`` (``f = m (a_c + g)``, ``p`` the
centre of pressure) up to the foot's free moment. For every single-support frame (one foot
planted in the mocap, as the whole-body tracker decides it) this computes, on the character
built from the clip, the horizontal moment left over with ``p`` at the centre of the sole,

    r = | (dL/dt - (p - c) x f)_xy |

and compares it with the most a centre of pressure anywhere on the sole could add,
``cap = f_z * half-diagonal of the sole box`` (a generous bound). Frames with ``r > 2 cap``
need a moment the foot cannot give: no physical tracker can follow them for long.
``c``, ``L`` come from MuJoCo (``subtree_com``, ``subtree_angmom``) at the clip's poses and
finite-difference velocities; their rates are central differences at the clip's frame rate.

``--check`` runs the same analysis on a physically simulated walk (the whole-body tracker's
output, recorded at the clip's frame rate): there every single-support frame must be within
the bound, which checks the analysis itself.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mujoco
import numpy as np

from reactmocap.library.bvh import read_bvh
from reactmocap.library.motion import Motion
from reactmocap.sim import PDServo, World, build_character, track_clip
from reactmocap.sim.wholebody import WholeBodyTracker

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT / ".." / "shared" / "mocap"


def residuals(motion: Motion, character_frame: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: the residual ``r`` (N m; NaN unless exactly one foot is planted) and the
    bound ``cap`` (N m)."""
    world = World(build_character(motion, frame=character_frame))
    wb = WholeBodyTracker(PDServo(world, kp=0.0), 0, motion)
    m = world.model
    d = mujoco.MjData(m)
    wc = world.characters[0]
    root = wc.body_ids[0]
    mass = float(m.body_subtreemass[root])
    sole = np.asarray(wc.sole_ids)
    half_diag = np.hypot(m.geom_size[sole, 0], m.geom_size[sole, 1])
    n = motion.num_frames
    com = np.empty((n, 3))
    mom = np.empty((n, 3))
    cop = np.empty((n, 2, 3))
    for i in range(n):  # one pose per frame: an offline analysis, not a step loop
        d.qpos[wc.qpos_slice] = wb.q[i]
        d.qvel[wc.qvel_slice] = wb.v[i]
        mujoco.mj_forward(m, d)
        mujoco.mj_subtreeVel(m, d)
        com[i] = d.subtree_com[root]
        mom[i] = d.subtree_angmom[root]
        rot = d.geom_xmat[sole].reshape(2, 3, 3)
        cop[i] = d.geom_xpos[sole] - rot[:, :, 2] * m.geom_size[sole, 2][:, None]
    dt = 1.0 / motion.fps
    acc = np.gradient(np.gradient(com, dt, axis=0), dt, axis=0)
    dmom = np.gradient(mom, dt, axis=0)
    force = mass * (acc - m.opt.gravity)
    single = wb.planted.sum(axis=1) == 1
    foot = np.argmax(wb.planted, axis=1)
    lever = cop[np.arange(n), foot] - com
    res = np.linalg.norm((dmom - np.cross(lever, force))[:, :2], axis=1)
    cap = np.maximum(force[:, 2], 0.0) * half_diag[foot]
    res[~single] = np.nan
    return res, cap


def _runs(mask: np.ndarray, fps: float, min_len: float) -> list[tuple[float, float]]:
    """Time intervals (s) where ``mask`` holds for at least ``min_len`` s."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    runs = [(a / fps, b / fps) for a, b in zip(edges[::2], edges[1::2])]
    return [(a, b) for a, b in runs if b - a >= min_len]


def _windows(motion: Motion) -> list[float]:
    """The tracking benchmark's windows (``bench_sim.py``): 1 s every 0.5 s."""
    if motion.duration <= 1.0:
        return [0.0]
    return list(np.arange(0.0, motion.duration - 1.0 + 1e-9, 0.5))


def report(motion: Motion, name: str) -> list[float]:
    """Print the clip's figures; return the infeasible seconds inside each benchmark window."""
    res, cap = residuals(motion)
    single = np.isfinite(res)
    bad = single & (res > 2 * cap)
    runs = _runs(bad, motion.fps, 0.1)
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
    fps = motion.fps
    return [
        float(bad[round(s * fps) : round((s + 1.0) * fps)].sum() / fps) for s in _windows(motion)
    ]


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
        f"\nbenchmark windows (1 s every 0.5 s): {len(over)}; with >= 0.3 s of frames r > 2 cap: "
        f"{int((over >= 0.3).sum())}; with any: {int((over > 0).sum())}"
    )
    if args.check:
        walk = read_bvh(next(p for p in clips if "walk_normal_001" in p.name))
        sim, _, _ = track_clip(walk, start=2.5, seconds=2.0, record_fps=walk.fps)
        print("\n## check: the same analysis on the simulated walk (2.5-4.5 s, whole-body tracker)")
        report(sim, "walk_normal_001 simulated")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
