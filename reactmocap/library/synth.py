"""Synthetic keyframed clip library: a fighting guard, four attacks, steps and reactions.

These clips are **synthetic** (hand-set keyframes, not motion capture). They exist so the
package, its tests and its examples run without any mocap download. Regenerate them with
``reactmocap synth data/synthetic_clips`` or ``python -m reactmocap.library.synth OUT_DIR``.

Internal frame (the package's): Z up, metres. At facing 0 the character's **forward is +X and
its left is +Y**; every clip starts at the origin facing +X.

How a clip is made: per-channel keyframes (root position and yaw/pitch/roll, spine/neck/head and
wrist rotation vectors, hand targets, foot placements, knee/elbow pole vectors) are interpolated
with monotone PCHIP splines, so two equal keys give an exactly constant channel (that is what
keeps a planted foot still). Legs and arms are solved with analytic two-bone IK: a foot placed at
a fixed world point stays there while the pelvis moves. Feet are placed by their ball (the
ToeBase joint) and world orientation; a raised heel pivots about the ball and the toes stay flat.
Two clamps run on every frame: the pelvis is lowered if a leg cannot reach its foot, and the
whole body is lifted so no joint or end site is below the ground (falls rotate onto the floor).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator
from scipy.spatial.transform import Rotation

from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import BVHLayout, Skeleton
from reactmocap.rotations import quat_canonical, quat_from_matrix

__all__ = [
    "ATTACK_CLIPS",
    "CLIP_INFO",
    "STRIKERS",
    "synthetic_clips",
    "synthetic_skeleton",
    "write_synthetic_library",
]

F64 = NDArray[np.float64]

# ----------------------------------------------------------------------------------- skeleton
# (name, parent, rest offset in the parent's frame: Z-up metres, x forward, y left). Arms hang
# at the sides in the rest pose; every leg and arm bone points straight down (-Z), which the IK
# below relies on.
_LEFT = (
    ("LeftShoulder", "Spine1", (0.0, 0.03, 0.17)),
    ("LeftArm", "LeftShoulder", (0.0, 0.17, 0.0)),
    ("LeftForeArm", "LeftArm", (0.0, 0.0, -0.29)),
    ("LeftHand", "LeftForeArm", (0.0, 0.0, -0.26)),
    ("LeftUpLeg", "Hips", (0.0, 0.09, -0.05)),
    ("LeftLeg", "LeftUpLeg", (0.0, 0.0, -0.42)),
    ("LeftFoot", "LeftLeg", (0.0, 0.0, -0.40)),
    ("LeftToeBase", "LeftFoot", (0.13, 0.0, -0.06)),
)
_JOINTS: tuple[tuple[str, str | None, tuple[float, float, float]], ...] = (
    ("Hips", None, (0.0, 0.0, 0.0)),  # rest height 0.95 m: hip joints 0.90, ankles 0.08
    ("Spine", "Hips", (0.0, 0.0, 0.09)),
    ("Spine1", "Spine", (0.0, 0.0, 0.19)),
    ("Neck", "Spine1", (0.0, 0.0, 0.22)),
    ("Head", "Neck", (0.0, 0.0, 0.12)),
    *_LEFT[:4],
    *((n.replace("Left", "Right"), p.replace("Left", "Right"), (x, -y, z)) for n, p, (x, y, z) in _LEFT[:4]),
    *_LEFT[4:],
    *((n.replace("Left", "Right"), p.replace("Left", "Right"), (x, -y, z)) for n, p, (x, y, z) in _LEFT[4:]),
)  # fmt: skip
_NAMES = tuple(j[0] for j in _JOINTS)
_IDX = {n: i for i, n in enumerate(_NAMES)}
_END_SITES = {
    "Head": (0.0, 0.0, 0.18),  # head top at 1.75 m in the rest pose
    "LeftHand": (0.0, 0.0, -0.17),
    "RightHand": (0.0, 0.0, -0.17),
    "LeftToeBase": (0.06, 0.0, 0.0),
    "RightToeBase": (0.06, 0.0, 0.0),
}
_ROOT_CH = ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")
_ROT_CH = ("Zrotation", "Xrotation", "Yrotation")


def synthetic_skeleton() -> Skeleton:
    """The adult humanoid (1.75 m head top at rest) all synthetic clips share.

    Joint names follow the CMU/Mixamo style; the BVH layout is Y-up centimetres with ZXY
    rotation channels and end sites at the head top, fingertips and toe tips.
    """
    layout = BVHLayout(
        channels=(_ROOT_CH,) + (_ROT_CH,) * (len(_JOINTS) - 1),
        unit="cm",
        up="y",
        end_sites={_IDX[n]: o for n, o in _END_SITES.items()},
    )
    parents = [-1 if p is None else _IDX[p] for _, p, _ in _JOINTS]
    return Skeleton(_NAMES, np.array(parents), np.array([o for *_, o in _JOINTS]), layout)


_OFF = np.array([o for *_, o in _JOINTS])
_PARENT = [-1 if p is None else _IDX[p] for _, p, _ in _JOINTS]
_Y = np.array([0.0, 1.0, 0.0])

# ----------------------------------------------------------------------------------- channels
# Every channel is a 3-vector. rootrot, lfoot/rfoot: yaw, pitch (+ leans forward / toes down),
# roll (+ tilts to the right) in degrees, R = Rz Ry Rx. Spine..Head, shoulders, wrists: local
# rotation vectors in degrees (+y bends forward, +z turns left). lhand/rhand: wrist target
# relative to the shoulder joint, in the heading (root-yaw) frame. lball/rball: world position
# of the ball of the foot. Poles (elbow/knee): the direction the joint points, heading frame.
GUARD: dict[str, tuple[float, float, float]] = {
    "root": (0.0, 0.0, 0.91),
    "rootrot": (0.0, 3.0, 0.0),
    "Spine": (0.0, 4.0, -8.0),
    "Spine1": (0.0, 4.0, -8.0),
    "Neck": (0.0, -3.0, 8.0),
    "Head": (0.0, -3.0, 8.0),
    "LeftShoulder": (0.0, 0.0, 0.0),
    "RightShoulder": (0.0, 0.0, 0.0),
    "lhand": (0.28, -0.08, -0.02),
    "rhand": (0.18, 0.10, 0.0),
    "lelbow": (-0.2, 0.5, -1.0),
    "relbow": (-0.2, -0.5, -1.0),
    "lwrist": (0.0, 0.0, 0.0),
    "rwrist": (0.0, 0.0, 0.0),
    "lball": (0.30, 0.15, 0.02),
    "rball": (-0.05, -0.20, 0.02),
    "lfoot": (10.0, 0.0, 0.0),
    "rfoot": (-30.0, 12.0, 0.0),
    "lknee": (1.0, 0.2, 0.0),
    "rknee": (0.8, -0.5, 0.0),
}


class _Clip:
    """Per-channel keyframes; a channel holds its last key (and starts at the guard pose)."""

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.keys: dict[str, list[tuple[float, F64]]] = {
            k: [(0.0, np.array(v, dtype=float))] for k, v in GUARD.items()
        }

    def now(self, ch: str) -> F64:
        return self.keys[ch][-1][1].copy()

    def at(self, t: float, **chans: ArrayLike) -> _Clip:
        """Key ``chans`` at time ``t`` (must not precede the channel's last key)."""
        for ch, v in chans.items():
            keys = self.keys[ch]
            if t < keys[-1][0] - 1e-9:
                raise ValueError(f"key {ch}@{t} before {keys[-1][0]}")
            if abs(t - keys[-1][0]) < 1e-9:
                keys.pop()
            keys.append((t, np.asarray(v, dtype=float)))
        return self

    def hold(self, t: float, *chans: str) -> _Clip:
        """Pin ``chans`` at their current value until ``t`` (motion starts after)."""
        return self.at(t, **{ch: self.now(ch) for ch in chans})

    def guard(self, t: float, *chans: str) -> _Clip:
        """Return ``chans`` (default: every non-foot channel) to the guard pose at ``t``; the
        root keeps its ground position (x, y) and takes the guard height."""
        names = chans or tuple(k for k in GUARD if k[1:] not in ("ball", "foot"))
        vals = {ch: np.array(GUARD[ch]) for ch in names}
        if "root" in vals:
            vals["root"][:2] = self.now("root")[:2]
        return self.at(t, **vals)

    def step(
        self,
        side: str,
        t0: float,
        t1: float,
        to: ArrayLike,
        foot: ArrayLike | None = None,
        h: float = 0.08,
    ) -> _Clip:
        """Swing foot ``side`` ('l'/'r') so its ball lands at ``to`` (x, y[, z]).

        The foot rises before it moves and stops before it lands (no sliding near the ground).
        """
        ball, fch = side + "ball", side + "foot"
        a = self.now(ball)
        b = np.array([*np.asarray(to, float)[:2], a[2]]) if np.size(to) == 2 else np.asarray(to, float)
        f0 = self.now(fch)
        f1 = f0 if foot is None else np.asarray(foot, float)
        d, up = t1 - t0, np.array([0.0, 0.0, h])
        self.at(t0, **{ball: a, fch: f0})
        self.at(t0 + 0.2 * d, **{ball: a + 0.5 * up})
        self.at(t0 + 0.5 * d, **{ball: 0.5 * (a + b) + up, fch: 0.5 * (f0 + f1) * (1, 0.3, 1)})
        self.at(t1 - 0.2 * d, **{ball: b + 0.5 * up, fch: f1})
        return self.at(t1, **{ball: b, fch: f1})

    def sample(self, ch: str, t: F64) -> F64:
        keys = self.keys[ch]
        kt = np.array([k for k, _ in keys])
        kv = np.stack([v for _, v in keys])
        if len(keys) == 1:
            return np.broadcast_to(kv[0], (t.size, 3)).copy()
        return PchipInterpolator(kt, kv, axis=0)(np.clip(t, kt[0], kt[-1]))


# ---------------------------------------------------------------------------------- solving
def _euler(a: F64) -> F64:
    return Rotation.from_euler("ZYX", a, degrees=True).as_matrix()


def _rotvec(v: F64) -> F64:
    return Rotation.from_rotvec(v, degrees=True).as_matrix()


def _unit(v: F64) -> F64:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _mv(m: F64, v: ArrayLike) -> F64:
    return np.einsum("...ij,...j->...i", m, v)


def _two_bone(
    start: F64, target: F64, pole: F64, a: float, b: float, sign: float
) -> tuple[F64, F64]:
    """Global rotation of the upper bone and local hinge rotation of the middle joint.

    Both bones point down (-Z) at rest and the hinge is the local Y axis; ``sign`` +1 bends like a
    knee (the joint juts toward local +X), -1 like an elbow. ``pole``: where the joint should jut.
    """
    w = target - start
    d = np.clip(np.linalg.norm(w, axis=-1), abs(a - b) + 1e-3, (a + b) * 0.9995)
    flex = np.pi - np.arccos(np.clip((a * a + b * b - d * d) / (2 * a * b), -1.0, 1.0))
    hinge = Rotation.from_rotvec(np.outer(sign * flex, _Y)).as_matrix()
    # the reach vector and the jut direction, in the upper bone's local frame and in the world
    u = np.stack([-sign * b * np.sin(flex), 0 * flex, -a - b * np.cos(flex)], axis=-1)
    e1, f1 = _unit(u), _unit(w)
    q = np.broadcast_to([sign, 0.0, 0.0], u.shape)
    e2 = _unit(q - np.sum(q * e1, -1, keepdims=True) * e1)
    f2 = _unit(pole - np.sum(pole * f1, -1, keepdims=True) * f1)
    local = np.stack([e1, e2, np.cross(e1, e2)], axis=-1)
    world = np.stack([f1, f2, np.cross(f1, f2)], axis=-1)
    return world @ np.swapaxes(local, -1, -2), hinge


_ARM = (0.29, 0.26)
_LEG = (0.42, 0.40)


def _locals(c: dict[str, F64], root: F64) -> F64:
    """Local rotation matrices ``(T, J, 3, 3)`` for sampled channels ``c`` and root positions."""
    n = root.shape[0]
    loc = np.broadcast_to(np.eye(3), (n, len(_NAMES), 3, 3)).copy()
    glob = loc.copy()
    pos = np.zeros((n, len(_NAMES), 3))
    heading = _euler(c["rootrot"] * (1.0, 0.0, 0.0))

    def fk(j: int) -> None:
        p = _PARENT[j]
        glob[:, j] = glob[:, p] @ loc[:, j] if p >= 0 else loc[:, j]
        pos[:, j] = pos[:, p] + _mv(glob[:, p], _OFF[j]) if p >= 0 else root

    loc[:, 0] = _euler(c["rootrot"])
    fk(0)
    for name in ("Spine", "Spine1", "Neck", "Head", "LeftShoulder", "RightShoulder"):
        loc[:, _IDX[name]] = _rotvec(c[name])
        fk(_IDX[name])
    for s, side in (("l", "Left"), ("r", "Right")):
        arm, fore, hand = (_IDX[side + n] for n in ("Arm", "ForeArm", "Hand"))
        fk(arm)
        target = pos[:, arm] + _mv(heading, c[s + "hand"])
        up, hinge = _two_bone(pos[:, arm], target, _mv(heading, c[s + "elbow"]), *_ARM, -1.0)
        loc[:, arm] = np.swapaxes(glob[:, _PARENT[arm]], -1, -2) @ up
        loc[:, fore] = hinge
        loc[:, hand] = _rotvec(c[s + "wrist"])

        thigh, shin, foot, toe = (_IDX[side + n] for n in ("UpLeg", "Leg", "Foot", "ToeBase"))
        fk(thigh)
        rf = _euler(c[s + "foot"])
        ankle = c[s + "ball"] - _mv(rf, _OFF[toe])
        up, hinge = _two_bone(pos[:, thigh], ankle, _mv(heading, c[s + "knee"]), *_LEG, 1.0)
        loc[:, thigh] = np.swapaxes(loc[:, 0], -1, -2) @ up
        loc[:, shin] = hinge
        loc[:, foot] = np.swapaxes(up @ hinge, -1, -2) @ rf
        # toes stay flat on the floor when the heel is raised
        loc[:, toe] = _rotvec(np.outer(-np.maximum(c[s + "foot"][:, 1], 0.0), _Y))
    return loc


def _reach_clamp(c: dict[str, F64], root: F64) -> F64:
    """Lower the pelvis where a leg could not reach its foot (keeps planted feet planted)."""
    rr = _euler(c["rootrot"])
    z = root[:, 2].copy()
    for s, side in (("l", "Left"), ("r", "Right")):
        hip = root + _mv(rr, _OFF[_IDX[side + "UpLeg"]])
        ankle = c[s + "ball"] - _mv(_euler(c[s + "foot"]), _OFF[_IDX[side + "ToeBase"]])
        reach = 0.985 * sum(_LEG)
        horiz = np.linalg.norm((ankle - hip)[:, :2], axis=-1)
        top = ankle[:, 2] + np.sqrt(np.maximum(reach**2 - horiz**2, 0.0))
        z = np.minimum(z, z - (hip[:, 2] - top))
    return np.stack([root[:, 0], root[:, 1], z], axis=-1)


def _motion(clip: _Clip, fps: float, name: str) -> Motion:
    skel = synthetic_skeleton()
    t = np.arange(int(round(clip.duration * fps)) + 1) / fps
    c = {k: clip.sample(k, t) for k in clip.keys}
    root = _reach_clamp(c, c["root"])
    motion = Motion(skel, fps, root, np.zeros((t.size, len(_NAMES), 4)) + (1, 0, 0, 0), name=name)
    for _ in range(8):  # lift the body onto the floor; re-solving the legs can change the lowest
        quats = quat_canonical(quat_from_matrix(_locals(c, root)))
        motion = motion.replace(root_positions=root, rotations=quats)
        pos = np.concatenate([motion.global_positions(), motion.end_site_positions()], axis=1)
        lift = np.maximum(-pos[..., 2].min(axis=1), 0.0)
        if lift.max() < 1e-6:
            break
        root = root + np.outer(lift, (0.0, 0.0, 1.0))
    return motion


# ------------------------------------------------------------------------------------ clips
def _breathing(c: _Clip, t0: float, t1: float, cycles: int) -> _Clip:
    """Subtle idle sway: weight shift, breathing in the chest, hands bobbing (loops at ends)."""
    for t in np.linspace(t0, t1, 8 * cycles + 1)[1:]:
        ph = 2 * np.pi * cycles * (t - t0) / (t1 - t0)
        s, b = np.sin(ph), np.sin(2 * ph)
        g = {k: np.array(v) for k, v in GUARD.items()}
        c.at(
            float(t),
            root=g["root"] + (0.012 * s, 0.006 * s, -0.003 * (1 - np.cos(2 * ph))),
            Spine1=g["Spine1"] + (0.0, 1.2 * b, 0.0),
            lhand=g["lhand"] + (0.0, 0.0, 0.01 * b),
            rhand=g["rhand"] + (0.0, 0.0, 0.01 * b),
        )
    return c


def _guard() -> _Clip:
    return _breathing(_Clip(4.0), 0.0, 4.0, 2)


def _step_forward() -> _Clip:
    c = _Clip(2.0)
    c.at(0.2, root=(0.03, 0.0, 0.90)).step("l", 0.15, 0.6, (0.65, 0.15))
    c.at(0.75, root=(0.32, 0.0, 0.90)).step("r", 0.7, 1.15, (0.30, -0.20))
    return c.at(1.4, root=(0.35, 0.0, 0.91)).guard(1.6).hold(2.0, "root")


def _step_back() -> _Clip:
    c = _Clip(2.0)
    c.at(0.2, root=(-0.03, 0.0, 0.90)).step("r", 0.15, 0.6, (-0.40, -0.20))
    c.at(0.75, root=(-0.32, 0.0, 0.90)).step("l", 0.7, 1.15, (-0.05, 0.15))
    return c.at(1.4, root=(-0.35, 0.0, 0.91)).guard(1.6).hold(2.0, "root")


CLIP_BUILDERS: dict[str, tuple[Callable[[], _Clip], str]] = {
    "guard": (_guard, "fighting guard (left foot forward) with a subtle breathing sway; loops"),
    "step_forward": (_step_forward, "guard shuffle step forward 0.35 m (front foot first)"),
    "step_back": (_step_back, "guard shuffle step back 0.35 m (rear foot first)"),
}
CLIP_INFO = {k: v[1] for k, v in CLIP_BUILDERS.items()}
ATTACK_CLIPS = ("front_kick", "side_kick", "punch", "push")
#: joints whose position (or end site) strikes, per attack clip
STRIKERS: dict[str, tuple[str, ...]] = {
    "front_kick": ("RightToeBase",),
    "side_kick": ("RightFoot",),
    "punch": ("RightHand",),
    "push": ("LeftHand", "RightHand"),
}


def synthetic_clips(fps: float = 60.0) -> dict[str, Motion]:
    """Every synthetic clip, name -> Motion (deterministic: no randomness)."""
    return {name: _motion(build(), fps, name) for name, (build, _) in CLIP_BUILDERS.items()}


def write_synthetic_library(out_dir: str | Path, fps: float = 60.0) -> list[Path]:
    """Write every clip as ``out_dir/<name>.bvh``; returns the paths written."""
    from reactmocap.library.bvh import write_bvh

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, motion in synthetic_clips(fps).items():
        path = out / f"{name}.bvh"
        write_bvh(motion, path)
        paths.append(path)
    return paths


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python -m reactmocap.library.synth OUT_DIR")
    written = write_synthetic_library(sys.argv[1])
    print(f"wrote {len(written)} synthetic clips to {sys.argv[1]}")
