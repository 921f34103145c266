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
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator
from scipy.ndimage import gaussian_filter1d, maximum_filter1d
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
Pose = dict[str, ArrayLike]  # channel name -> key value

# ----------------------------------------------------------------------------------- skeleton
# (name, parent, rest offset in the parent's frame: Z-up metres, x forward, y left). Arms hang
# at the sides in the rest pose; every leg and arm bone points straight down (-Z), which the IK
# below relies on.
_Row = tuple[str, str | None, tuple[float, float, float]]
_LEFT_ARM: tuple[_Row, ...] = (
    ("LeftShoulder", "Spine1", (0.0, 0.03, 0.17)),
    ("LeftArm", "LeftShoulder", (0.0, 0.17, 0.0)),  # shoulders 0.40 m apart
    ("LeftForeArm", "LeftArm", (0.0, 0.0, -0.29)),
    ("LeftHand", "LeftForeArm", (0.0, 0.0, -0.26)),
)
_LEFT_LEG: tuple[_Row, ...] = (
    ("LeftUpLeg", "Hips", (0.0, 0.09, -0.05)),
    ("LeftLeg", "LeftUpLeg", (0.0, 0.0, -0.42)),
    ("LeftFoot", "LeftLeg", (0.0, 0.0, -0.40)),
    ("LeftToeBase", "LeftFoot", (0.13, 0.0, -0.06)),  # ball of the foot
)


def _right(rows: tuple[_Row, ...]) -> tuple[_Row, ...]:
    return tuple(
        (n.replace("Left", "Right"), str(p).replace("Left", "Right"), (x, -y, z))
        for n, p, (x, y, z) in rows
    )


_JOINTS: tuple[_Row, ...] = (
    ("Hips", None, (0.0, 0.0, 0.0)),  # rest height 0.95 m: hip joints 0.90, ankles 0.08
    ("Spine", "Hips", (0.0, 0.0, 0.09)),
    ("Spine1", "Spine", (0.0, 0.0, 0.19)),
    ("Neck", "Spine1", (0.0, 0.0, 0.22)),
    ("Head", "Neck", (0.0, 0.0, 0.12)),
    *_LEFT_ARM,
    *_right(_LEFT_ARM),
    *_LEFT_LEG,
    *_right(_LEFT_LEG),
)
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
# relative to the shoulder joint and elbow poles (where the elbow points), in the heading
# (root-yaw) frame so the arms turn with the body. lball/rball: world position of the ball of
# the foot; knee poles: world direction the knee points (planted feet and knees are world-fixed).
# lfree/rfree (first value, 0..1): how far a foot in the air relaxes to the neutral ankle.
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
    "lfree": (0.0, 0.0, 0.0),
    "rfree": (0.0, 0.0, 0.0),
}


_EULER_CHANNELS = ("rootrot", "lfoot", "rfoot")


class _Clip:
    """Per-channel keyframes; a channel holds its last key (and starts at the guard pose)."""

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.keys: dict[str, list[tuple[float, F64]]] = {
            k: [(0.0, np.array(v, dtype=float))] for k, v in GUARD.items()
        }

    def now(self, ch: str) -> F64:
        """The channel's latest key."""
        return self.keys[ch][-1][1].copy()

    def at(self, t: float, **chans: ArrayLike) -> _Clip:
        """Key ``chans`` at time ``t`` (replacing a key at the same time)."""
        for ch, v in chans.items():
            keys = [k for k in self.keys[ch] if abs(k[0] - t) > 1e-9]
            keys.append((t, np.asarray(v, dtype=float)))
            self.keys[ch] = sorted(keys, key=lambda k: k[0])
        return self

    def hold(self, t: float, *chans: str) -> _Clip:
        """Pin ``chans`` at their current value until ``t`` (motion starts after)."""
        return self.at(t, **{ch: self.now(ch) for ch in chans})

    def guard(self, t: float, *chans: str, home: bool = False) -> _Clip:
        """Return ``chans`` (default: every non-foot channel) to the guard pose at ``t``; the
        root keeps its ground position (x, y) unless ``home`` and takes the guard height."""
        names = chans or tuple(k for k in GUARD if k[1:] not in ("ball", "foot"))
        vals = {ch: np.array(GUARD[ch]) for ch in names}
        if "root" in vals and not home:
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
        limp: float = 0.0,
    ) -> _Clip:
        """Swing foot ``side`` ('l'/'r') so its ball lands at ``to`` (x, y[, z]).

        The foot rises before it moves and stops before it lands (no sliding near the ground);
        ``foot`` is its new yaw/pitch/roll. A firm foot (``limp`` 0) turns only in the air; a
        flying foot (falls) turns at once and its ankle relaxes by ``limp`` (0..1) mid-swing.
        """
        ball, fch, free = side + "ball", side + "foot", side + "free"
        a, b = self.now(ball), np.asarray(to, float)
        b = np.append(b, a[2]) if b.size == 2 else b
        f0 = self.now(fch)
        f1 = f0 if foot is None else np.asarray(foot, float)
        d, up = t1 - t0, np.array([0.0, 0.0, h])
        self.at(t0, **{ball: a, fch: f0}).at(t0 + 0.2 * d, **{ball: a + 0.5 * up})
        if not limp:
            self.at(t0 + 0.2 * d, **{fch: f0})
        else:
            loose, firm = (limp, 0.0, 0.0), (0.0, 0.0, 0.0)
            self.at(t0 + 0.2 * d, **{free: firm}).at(t0 + 0.45 * d, **{free: loose})
            self.at(t1 - 0.4 * d, **{free: loose}).at(t1 - 0.15 * d, **{free: firm})
        self.at(t0 + 0.5 * d, **{ball: 0.5 * (a + b) + up})
        self.at(t1 - 0.2 * d, **{ball: b + 0.5 * up, fch: f1})
        return self.at(t1, **{ball: b, fch: f1})

    def sample(self, ch: str, t: F64) -> F64:
        keys = self.keys[ch]
        kt = np.array([k for k, _ in keys])
        kv = np.stack([v for _, v in keys])
        if len(keys) == 1:
            return np.broadcast_to(kv[0], (t.size, 3)).copy()
        if ch not in _EULER_CHANNELS:
            return PchipInterpolator(kt, kv, axis=0)(np.clip(t, kt[0], kt[-1]))
        # Euler keys can wrap or pass near gimbal lock: interpolate sign-continuous quaternions
        q = Rotation.from_euler("ZYX", kv, degrees=True).as_quat()
        for i in range(1, len(q)):
            q[i] *= np.sign(q[i] @ q[i - 1]) or 1.0
        qt = PchipInterpolator(kt, q, axis=0)(np.clip(t, kt[0], kt[-1]))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # gimbal lock: still a valid triple
            return Rotation.from_quat(qt).as_euler("ZYX", degrees=True)


# ---------------------------------------------------------------------------------- solving
def _euler(a: F64) -> F64:
    return Rotation.from_euler("ZYX", a, degrees=True).as_matrix()


def _rotvec(v: F64) -> F64:
    return Rotation.from_rotvec(v, degrees=True).as_matrix()


def _unit(v: F64) -> F64:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _mv(m: F64, v: ArrayLike) -> F64:
    """Matrices ``(..., 3, 3)`` times vectors ``(..., 3)``, broadcasting."""
    return (m @ np.asarray(v, dtype=float)[..., None])[..., 0]


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
    u = np.stack([-sign * b * np.sin(flex), np.zeros_like(flex), -a - b * np.cos(flex)], axis=-1)
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
        up, hinge = _two_bone(pos[:, thigh], ankle, c[s + "knee"], *_LEG, 1.0)
        loc[:, thigh] = np.swapaxes(loc[:, 0], -1, -2) @ up
        loc[:, shin] = hinge
        loc[:, foot] = np.swapaxes(up @ hinge, -1, -2) @ rf
        free = np.clip(c[s + "free"][:, 0], 0.0, 1.0)
        if free.any():  # a flying foot relaxes toward the neutral ankle (keeps ankles in range)
            rv = Rotation.from_matrix(loc[:, foot]).as_rotvec()
            loc[:, foot] = Rotation.from_rotvec(rv * (1.0 - free)[:, None]).as_matrix()
        # toes stay flat on the floor when the heel is raised
        loc[:, toe] = _rotvec(np.outer(-np.maximum(c[s + "foot"][:, 1], 0.0), _Y))
    return loc


def _envelope(d: F64, radius: int) -> F64:
    """A smooth curve >= ``d``: a running max over +-radius frames, then a Gaussian whose support
    fits inside that window (so a correction never kinks the root trajectory)."""
    if radius < 1 or not d.any():
        return d
    wide = maximum_filter1d(d, 2 * radius + 1, mode="nearest")
    return gaussian_filter1d(wide, radius / 3.0, mode="nearest", truncate=3.0)


def _reach_clamp(c: dict[str, F64], root: F64, radius: int) -> F64:
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
    return root - np.outer(_envelope(root[:, 2] - z, radius), (0.0, 0.0, 1.0))


def _motion(clip: _Clip, fps: float, name: str) -> Motion:
    skel = synthetic_skeleton()
    t = np.arange(round(clip.duration * fps) + 1) / fps
    c = {k: clip.sample(k, t) for k in clip.keys}
    radius = round(0.1 * fps)  # corrections blend in over 0.1 s
    root = _reach_clamp(c, c["root"], radius)

    def build(root: F64) -> Motion:
        return Motion(
            skel, fps, root, quat_canonical(quat_from_matrix(_locals(c, root))), name=name
        )

    for _ in range(8):  # lift the body onto the floor; re-solving the legs can move the lowest
        motion = build(root)
        pos = np.concatenate([motion.global_positions(), motion.end_site_positions()], axis=1)
        lift = np.maximum(-pos[..., 2].min(axis=1), 0.0)
        if lift.max() < 1e-5:
            return motion
        root = root + np.outer(_envelope(lift, radius), (0.0, 0.0, 1.0))
    return build(root)


# ------------------------------------------------------------------------------------ clips
def _breathing(c: _Clip, t0: float, t1: float, cycles: int) -> _Clip:
    """Subtle idle sway: weight shift, breathing in the chest, hands bobbing (loops at ends)."""
    g = {k: np.array(v) for k, v in GUARD.items()}
    for t in np.linspace(t0, t1, 8 * cycles + 1)[1:]:
        ph = 2 * np.pi * cycles * (t - t0) / (t1 - t0)
        s, b = np.sin(ph), np.sin(2 * ph)
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


def _heading(v: ArrayLike, yaw: float) -> F64:
    """World vector ``v`` in the heading frame of a root turned ``yaw`` degrees."""
    return _mv(_euler(np.array([-yaw, 0.0, 0.0])), np.asarray(v, float))


def _leg(
    root: ArrayLike, rootrot: ArrayLike, side: str, hip: ArrayLike, knee: float,
    ankle: ArrayLike = (0.0, 0.0, 0.0),
) -> dict[str, F64]:  # fmt: skip
    """Foot keys (ball, foot, knee pole) that reproduce a leg given by joint angles (degrees):
    lying and kneeling poses are easier to set that way than by foot placement."""
    s, name = side[0].lower(), "Left" if side[0].lower() == "l" else "Right"
    rr = _euler(np.asarray(rootrot, float))
    ru = rr @ _rotvec(np.asarray(hip, float))
    rs = ru @ _rotvec(np.array([0.0, knee, 0.0]))
    rf = rs @ _rotvec(np.asarray(ankle, float))
    ankle_p = np.asarray(root, float) + rr @ _OFF[_IDX[name + "UpLeg"]]
    ankle_p = ankle_p + ru @ _OFF[_IDX[name + "Leg"]] + rs @ _OFF[_IDX[name + "Foot"]]
    return {
        s + "ball": ankle_p + rf @ _OFF[_IDX[name + "ToeBase"]],
        s + "foot": Rotation.from_matrix(rf).as_euler("ZYX", degrees=True),
        s + "knee": ru @ (1.0, 0.0, 0.0),
    }


def _punch() -> _Clip:
    c = _Clip(2.0).hold(0.15, "root", "rootrot", "Spine", "Spine1", "rhand", "lhand")
    c.at(0.3, root=(0.0, 0.0, 0.90), rootrot=(-5.0, 3.0, 0.0), rhand=(0.14, 0.10, -0.03))
    c.at(
        0.48,
        root=(0.06, 0.0, 0.89), rootrot=(25.0, 6.0, 0.0), Spine=(0.0, 5.0, 8.0),
        Spine1=(0.0, 5.0, 8.0), Neck=(0.0, -3.0, -20.0), Head=(0.0, -3.0, -16.0),
        RightShoulder=(0.0, 0.0, 15.0), rhand=_heading((0.535, 0.09, 0.02), 25.0),
        relbow=(0.0, -0.3, -1.0), lhand=(0.16, -0.05, 0.02), rfoot=(-30.0, 25.0, 0.0),
    )  # fmt: skip
    c.hold(0.56, "root", "rootrot", "Spine", "Spine1", "rhand", "RightShoulder", "Neck", "Head")
    c.at(0.75, rhand=(0.22, 0.08, -0.05), RightShoulder=(0.0, 0.0, 0.0))
    return c.guard(1.05, home=True).at(1.05, rfoot=GUARD["rfoot"]).hold(2.0, "root")


def _push() -> _Clip:
    c = _Clip(2.4).step("l", 0.1, 0.45, (0.62, 0.15))
    c.at(0.25, lhand=(0.2, -0.02, -0.1), rhand=(0.2, 0.02, -0.1), lwrist=(0.0, -30.0, 0.0))
    c.at(0.25, rwrist=(0.0, -30.0, 0.0))
    peak: Pose = dict(
        root=(0.30, 0.0, 0.87), rootrot=(0.0, 12.0, 0.0), Spine=(0.0, 6.0, 0.0),
        Spine1=(0.0, 6.0, 0.0), Neck=(0.0, -8.0, 0.0), Head=(0.0, -8.0, 0.0),
        lhand=(0.52, -0.10, -0.10), rhand=(0.52, 0.10, -0.10), lwrist=(0.0, -70.0, 0.0),
        rwrist=(0.0, -70.0, 0.0), lelbow=(0.0, 0.3, -1.0), relbow=(0.0, -0.3, -1.0),
        rfoot=(-30.0, 30.0, 0.0), LeftShoulder=(0.0, 0.0, -10.0), RightShoulder=(0.0, 0.0, 10.0),
    )  # fmt: skip
    c.at(0.6, **peak).hold(0.68, *peak)
    c.at(0.95, root=(0.15, 0.0, 0.89), lhand=(0.25, -0.06, -0.04), rhand=(0.2, 0.08, -0.04))
    c.at(0.95, rootrot=(0.0, 3.0, 0.0), lwrist=(0.0, 0.0, 0.0), rwrist=(0.0, 0.0, 0.0))
    c.step("l", 1.0, 1.35, GUARD["lball"]).at(1.4, root=(0.0, 0.0, 0.90))
    return c.guard(1.7, home=True).at(1.7, rfoot=GUARD["rfoot"]).hold(2.4, "root")


def _front_kick() -> _Clip:
    c = _Clip(2.4)
    lean: Pose = dict(root=(0.10, 0.05, 0.90), rootrot=(0.0, -3.0, 0.0), Spine=(0.0, 0.0, -8.0))
    c.at(0.3, **lean).at(0.3, lhand=(0.22, -0.06, 0.0), rhand=(0.16, 0.08, 0.0))
    chamber: Pose = dict(rball=(0.45, -0.10, 0.42), rfoot=(0.0, 30.0, 0.0), rknee=(0.4, 0.0, 1.0))
    c.at(0.35, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.04)), rfoot=(-30.0, 20.0, 0.0))
    c.at(0.58, **chamber).at(0.58, rootrot=(0.0, -6.0, 0.0), root=(0.12, 0.05, 0.90))
    c.at(
        0.8,
        rball=(0.93, -0.08, 0.93), rfoot=(0.0, -50.0, 0.0), root=(0.15, 0.05, 0.90),
        rootrot=(0.0, -15.0, 0.0), Spine=(0.0, -4.0, -8.0), Spine1=(0.0, -2.0, -8.0),
        Neck=(0.0, 8.0, 8.0), Head=(0.0, 5.0, 8.0), rhand=(0.0, 0.15, -0.25),
    )  # fmt: skip
    c.hold(0.86, "rball", "rfoot", "root", "rootrot", "Spine", "Spine1", "Neck", "Head")
    c.at(1.05, **chamber).at(1.05, root=(0.12, 0.05, 0.90), rootrot=(0.0, -4.0, 0.0))
    c.at(1.05, Spine=GUARD["Spine"], Spine1=GUARD["Spine1"], Neck=GUARD["Neck"])
    c.at(1.05, Head=GUARD["Head"], rhand=(0.16, 0.08, 0.0))
    c.at(1.3, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.05)), rfoot=GUARD["rfoot"])
    c.at(1.3, rknee=GUARD["rknee"]).at(1.45, rball=GUARD["rball"])
    return c.guard(1.75, home=True).hold(2.4, "root")


def _side_kick() -> _Clip:
    # The support foot turns out first (a small lifted pivot step) so the hips can turn side-on;
    # the kicking foot is off the floor whenever the hips are turned far from it.
    yaw, c = 80.0, _Clip(2.8)
    c.step("l", 0.05, 0.3, GUARD["lball"], foot=(70.0, 0.0, 0.0), h=0.045)
    half: Pose = dict(root=(0.0, 0.03, 0.90), rootrot=(25.0, 0.0, -3.0), Spine=(0.0, 2.0, -10.0))
    c.at(0.3, **half, lknee=(0.35, 1.0, 0.0), rknee=(0.87, -0.5, 0.0))
    c.hold(0.3, "rball", "rfoot").at(0.4, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.06)))
    turn: Pose = dict(
        root=(0.0, 0.04, 0.89), rootrot=(yaw, 0.0, -5.0), Spine=(0.0, 0.0, -10.0),
        Spine1=(0.0, 0.0, -10.0), Neck=(0.0, 0.0, -30.0), Head=(0.0, 0.0, -25.0),
        lhand=_heading((0.22, 0.05, 0.0), yaw), rhand=_heading((0.20, 0.15, 0.0), yaw),
        lknee=(0.35, 1.0, 0.0),
    )  # fmt: skip
    lift: Pose = dict(rknee=(0.5, 0.8, 0.3), rfoot=(40.0, 30.0, 0.0))
    c.at(0.55, **turn).at(0.58, **lift)
    chamber = _leg(
        turn["root"], turn["rootrot"], "r", (-20.0, -60.0, 0.0), 120.0, (0.0, -10.0, 0.0)
    )
    c.at(0.72, **chamber)
    ext_root, ext_rot = (0.0, 0.10, 0.88), (yaw, 0.0, -25.0)
    ext: Pose = dict(
        _leg(ext_root, ext_rot, "r", (-62.0, 0.0, 0.0), 4.0, (0.0, -15.0, 0.0)),
        root=ext_root, rootrot=ext_rot, Spine=(-8.0, 0.0, -10.0), Spine1=(-6.0, 0.0, -10.0),
        Neck=(10.0, 0.0, -30.0), Head=(8.0, 0.0, -25.0),
    )  # fmt: skip
    c.at(0.92, **ext).hold(0.98, *ext)
    c.at(1.18, **chamber).at(1.18, **turn)
    c.at(1.35, rootrot=(50.0, 0.0, -4.0), rknee=(0.6, 0.6, 0.4), rfoot=lift["rfoot"])
    c.at(1.5, **half, rknee=(0.87, -0.5, 0.0))
    c.at(1.5, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.06)), rfoot=GUARD["rfoot"])
    c.at(1.65, rball=GUARD["rball"]).at(1.7, lknee=(0.35, 1.0, 0.0), rknee=GUARD["rknee"])
    c.step("l", 1.7, 2.0, GUARD["lball"], foot=GUARD["lfoot"], h=0.045)
    return c.guard(2.1, home=True)


def _sway() -> _Clip:
    c = _Clip(2.5)
    c.at(
        0.25,
        root=(-0.05, 0.0, 0.90), rootrot=(0.0, -6.0, 0.0), Spine=(0.0, -5.0, -8.0),
        Spine1=(0.0, -5.0, -8.0), Neck=(0.0, 6.0, 8.0), Head=(0.0, 4.0, 8.0),
        lhand=(0.24, -0.02, 0.03), rhand=(0.15, 0.12, 0.03),
    )  # fmt: skip
    c.at(0.75, root=(0.01, 0.0, 0.91), rootrot=(0.0, 4.0, 0.0), Spine=(0.0, 5.0, -8.0))
    c.at(0.75, Spine1=GUARD["Spine1"], Neck=GUARD["Neck"], Head=GUARD["Head"])
    return c.guard(1.3, home=True).hold(2.5, "root")


def _shuffle(c: _Clip, t: float, d: tuple[float, float], lead: str, dur: float = 0.35) -> float:
    """Guard shuffle step by ``d`` (x, y): ``lead`` foot first, the pelvis moves over the new
    base while both feet are down, the other foot follows. Returns the time it ends."""
    trail = "r" if lead == "l" else "l"
    start = c.now("root")[:2]
    c.hold(t, "root")
    c.step(lead, t, t + dur, c.now(lead + "ball")[:2] + d, foot=GUARD[lead + "foot"])
    # the pelvis ends where the guard puts it over the new feet
    end = np.add(GUARD["root"][:2], c.now(lead + "ball")[:2] - GUARD[lead + "ball"][:2])
    c.at(t + dur + 0.05, root=(*(start + 0.55 * (end - start)), 0.89))
    t1 = t + 2 * dur + 0.05
    c.step(trail, t + dur + 0.05, t1, c.now(trail + "ball")[:2] + d, foot=GUARD[trail + "foot"])
    c.at(t + 2 * dur + 0.15, root=(*end, 0.90))
    return t + 2 * dur + 0.15


def _step_forward() -> _Clip:
    c = _Clip(2.0)
    return c.guard(_shuffle(c, 0.15, (0.3, 0.0), "l") + 0.3).hold(2.0, "root")


def _step_back() -> _Clip:
    c = _Clip(2.0)
    return c.guard(_shuffle(c, 0.15, (-0.3, 0.0), "r") + 0.3).hold(2.0, "root")


def _back_steps(n: int) -> _Clip:
    """Knocked back ``n`` shuffle steps (rear foot first), then recover the guard."""
    c = _Clip(2.5 + (n - 1) * 0.85)
    c.at(
        0.12,
        root=(-0.04, 0.0, 0.90), rootrot=(0.0, -8.0, 0.0), Spine=(0.0, -5.0, -8.0),
        Spine1=(0.0, -5.0, -8.0), Neck=(0.0, 6.0, 8.0), lhand=(0.26, 0.02, 0.02),
        rhand=(0.16, 0.14, 0.02),
    )  # fmt: skip
    t = 0.12
    for _ in range(n):
        t = _shuffle(c, t, (-0.3, 0.0), "r", dur=0.3)
    c.at(t, rootrot=(0.0, 0.0, 0.0))
    return c.guard(t + 0.4).hold(c.duration, "root")


def _side_steps(side: str) -> _Clip:
    """Pushed sideways: the near foot steps out toward ``side``, the other follows."""
    sg = 1.0 if side == "l" else -1.0
    c = _Clip(2.5)
    c.at(
        0.12,
        root=(0.0, 0.04 * sg, 0.90), rootrot=(0.0, 3.0, -8.0 * sg), Spine=(-6.0 * sg, 4.0, -8.0),
        Spine1=(-4.0 * sg, 4.0, -8.0), Neck=(8.0 * sg, -3.0, 8.0),
    )  # fmt: skip
    t = _shuffle(c, 0.12, (0.0, 0.3 * sg), side, dur=0.3)
    return c.at(t - 0.2, rootrot=(0.0, 3.0, 0.0)).guard(t + 0.35).hold(2.5, "root")


def _stumble_forward() -> _Clip:
    c = _Clip(2.5)
    c.at(
        0.12,
        root=(0.06, 0.0, 0.89), rootrot=(0.0, 15.0, 0.0), Spine=(0.0, 8.0, -8.0),
        Spine1=(0.0, 6.0, -8.0), Neck=(0.0, -12.0, 8.0), Head=(0.0, -8.0, 8.0),
        lhand=(0.2, 0.15, -0.15), rhand=(0.15, -0.05, -0.15), rfoot=(-30.0, 25.0, 0.0),
    )  # fmt: skip
    t = _shuffle(c, 0.12, (0.4, 0.0), "l", dur=0.3)
    return c.at(t - 0.2, rootrot=(0.0, 5.0, 0.0)).guard(t + 0.35).hold(2.5, "root")


def _fall_backward() -> _Clip:
    # stagger back on the right foot, sit down behind it, roll onto the back (knees up)
    c = _Clip(4.5)
    c.at(
        0.12,
        root=(-0.06, 0.0, 0.90), rootrot=(0.0, -12.0, 0.0), Spine=(0.0, -8.0, -8.0),
        Spine1=(0.0, -8.0, -8.0), Neck=(0.0, 12.0, 8.0), Head=(0.0, 8.0, 8.0),
        lhand=(0.30, 0.05, -0.05), rhand=(0.30, -0.05, -0.05),
    )  # fmt: skip
    c.step("r", 0.1, 0.42, (-0.30, -0.22), h=0.06)
    c.at(0.55, root=(-0.28, -0.02, 0.84), rootrot=(0.0, -15.0, 0.0))
    c.step("l", 0.6, 1.1, (-0.06, 0.16), foot=(10.0, 0.0, 0.0), h=0.2)
    c.at(1.05, root=(-0.62, 0.0, 0.42), rootrot=(0.0, -25.0, 0.0), Spine=(0.0, 5.0, 0.0))
    c.at(1.05, Spine1=(0.0, 5.0, 0.0), Neck=(0.0, 15.0, 0.0), Head=(0.0, 10.0, 0.0))
    c.at(1.05, lknee=(1.0, 0.2, 0.6), rknee=(0.8, -0.4, 0.6))
    c.at(
        1.3,
        root=(-0.83, 0.0, 0.15), rootrot=(0.0, -45.0, 0.0), lhand=(-0.22, 0.15, -0.30),
        rhand=(-0.22, -0.15, -0.30), lelbow=(-1.0, 0.3, 0.0), relbow=(-1.0, -0.3, 0.0),
        lknee=(0.4, 0.2, 1.0), rknee=(0.4, -0.3, 1.0),
    )  # fmt: skip
    c.at(1.75, root=(-0.84, 0.0, 0.13), rootrot=(0.0, -70.0, 0.0), Neck=(0.0, 25.0, 0.0))
    c.at(1.75, lhand=(0.0, 0.35, -0.05), rhand=(0.0, -0.35, -0.05))
    lying: Pose = dict(
        root=(-0.85, 0.0, 0.12), rootrot=(0.0, -86.0, 0.0), Spine=(0.0, -2.0, 0.0),
        Spine1=(0.0, -2.0, 0.0), Neck=(0.0, 12.0, 0.0), Head=(0.0, 5.0, 0.0),
        lhand=(0.45, 0.15, 0.0), rhand=(0.45, -0.15, 0.0), lelbow=(0.0, 1.0, 0.3),
        relbow=(0.0, -1.0, 0.3), lknee=(0.2, 0.3, 1.0), rknee=(0.2, -0.3, 1.0),
    )  # fmt: skip
    return c.at(2.3, **lying).hold(4.5, *lying)


def _fall_forward() -> _Clip:
    # stumble two steps, drop to the knees, catch with the hands, end prone
    c = _Clip(4.5)
    c.at(
        0.12,
        root=(0.08, 0.0, 0.88), rootrot=(0.0, 18.0, 0.0), Spine=(0.0, 10.0, -8.0),
        Spine1=(0.0, 8.0, -8.0), Neck=(0.0, -15.0, 8.0), Head=(0.0, -10.0, 8.0),
        lhand=(0.25, 0.10, -0.20), rhand=(0.25, -0.10, -0.20),
    )  # fmt: skip
    c.step("l", 0.1, 0.4, (0.70, 0.15), h=0.07)
    c.at(0.5, root=(0.40, 0.0, 0.84), rootrot=(0.0, 25.0, 0.0))
    c.at(0.5, lhand=(0.35, 0.05, -0.25), rhand=(0.35, -0.05, -0.25))
    c.step("r", 0.45, 0.8, (0.70, -0.13), foot=(-5.0, 0.0, 0.0), h=0.14, limp=0.5)
    c.hold(0.85, "lfoot", "rfoot").at(1.08, lfoot=(10.0, 40.0, 0.0), rfoot=(-5.0, 40.0, 0.0))
    kneel: Pose = dict(
        root=(0.98, 0.0, 0.52), rootrot=(0.0, 15.0, 0.0), lfoot=(10.0, 65.0, 0.0),
        rfoot=(-5.0, 65.0, 0.0), lknee=(1.0, 0.1, -0.4), rknee=(1.0, -0.1, -0.4),
        lhand=(0.30, 0.05, -0.45), rhand=(0.30, -0.05, -0.45),
    )  # fmt: skip
    c.at(1.35, **kneel)
    c.at(
        1.65,
        root=(1.12, 0.0, 0.42), rootrot=(0.0, 55.0, 0.0), lhand=(0.30, 0.02, -0.50),
        rhand=(0.30, -0.02, -0.50), Neck=(0.0, -25.0, 0.0), Head=(0.0, -10.0, 0.0),
    )  # fmt: skip
    prone: Pose = dict(
        root=(1.56, 0.0, 0.13), rootrot=(0.0, 88.0, 0.0), Spine=(0.0, -3.0, 0.0),
        Spine1=(0.0, -3.0, 0.0), Neck=(0.0, -30.0, 0.0), Head=(0.0, -10.0, 0.0),
        lhand=(0.10, 0.25, -0.05), rhand=(0.10, -0.25, -0.05), lelbow=(-0.3, 1.0, -0.5),
        relbow=(-0.3, -1.0, -0.5), lknee=(0.0, 0.2, -1.0), rknee=(0.0, -0.2, -1.0),
    )  # fmt: skip
    return c.at(2.3, **prone).hold(4.5, *prone)


def _fall_sideways() -> _Clip:
    # pushed from the right: stagger left, buckle onto the left hip, lie on the left side
    c = _Clip(4.5)
    c.at(
        0.12,
        root=(0.0, 0.06, 0.89), rootrot=(0.0, 3.0, -15.0), Spine=(-8.0, 3.0, -8.0),
        Spine1=(-6.0, 3.0, -8.0), Neck=(10.0, 0.0, 8.0),
    )  # fmt: skip
    c.at(0.25, lhand=(0.1, 0.3, -0.1), rhand=(0.2, -0.1, 0.05))
    c.step("l", 0.1, 0.4, (0.30, 0.48), h=0.06)
    c.at(0.5, root=(0.02, 0.30, 0.84), rootrot=(0.0, 5.0, -20.0))
    c.step("r", 0.45, 0.8, (0.10, 0.20), foot=(-10.0, 0.0, 0.0), h=0.08)
    c.at(1.0, root=(0.08, 0.62, 0.45), rootrot=(0.0, 10.0, -40.0), lknee=(1.0, 0.3, 0.2))
    c.at(1.0, rknee=(1.0, 0.2, 0.2), lhand=(0.25, 0.15, -0.28), lelbow=(0.0, -0.3, -1.0))
    c.at(1.35, root=(0.12, 0.82, 0.18), rootrot=(0.0, 8.0, -65.0))
    # legs fold up off the floor as the hip lands, and come down on their sides
    lie_root, lie_rot = (0.10, 0.92, 0.16), (0.0, 5.0, -88.0)
    legs = {
        **_leg(lie_root, lie_rot, "l", (-4.0, -45.0, 0.0), 80.0),
        **_leg(lie_root, lie_rot, "r", (0.0, -55.0, 0.0), 90.0),
    }
    c.step("l", 0.85, 1.55, legs["lball"], foot=legs["lfoot"], h=0.12, limp=1.0)
    c.at(0.85, rfoot=(-10.0, 20.0, 0.0))  # heel up while the hips drop
    c.step("r", 0.95, 1.7, legs["rball"], foot=legs["rfoot"], h=0.12, limp=1.0)
    c.at(1.55, lknee=legs["lknee"]).at(1.7, rknee=legs["rknee"]).at(1.15, rfoot=(-70, 25, -75))
    lying: Pose = dict(
        root=lie_root, rootrot=lie_rot, Spine=(4.0, 5.0, 0.0), Spine1=(4.0, 5.0, 0.0),
        Neck=(-12.0, 5.0, 0.0), Head=(-10.0, 0.0, 0.0), lhand=(0.50, 0.05, 0.0),
        rhand=(0.35, 0.0, -0.22), lelbow=(0.0, -1.0, 0.3), relbow=(-0.2, 0.0, 1.0),
    )  # fmt: skip
    return c.at(1.9, **lying).hold(4.5, *lying)


CLIP_BUILDERS: dict[str, tuple[Callable[[], _Clip], str]] = {
    "guard": (_guard, "fighting guard (left foot forward) with a subtle breathing sway; loops"),
    "step_forward": (_step_forward, "guard shuffle step forward 0.3 m (front foot first)"),
    "step_back": (_step_back, "guard shuffle step back 0.3 m (rear foot first)"),
    "front_kick": (_front_kick, "attack: right-leg front kick, ball of the foot ~1 m ahead"),
    "side_kick": (_side_kick, "attack: right-leg side kick, hips turned, foot ~0.9 m ahead"),
    "punch": (_punch, "attack: right cross, fist ~1 m ahead"),
    "push": (_push, "attack: two-hand shove with a step, hands ~1 m ahead"),
    "sway": (_sway, "light reaction: torso sways back and recovers, feet stay planted"),
    "step_back_1": (
        lambda: _back_steps(1),
        "medium reaction: knocked back one shuffle step (0.3 m)",
    ),
    "step_back_2": (
        lambda: _back_steps(2),
        "medium reaction: knocked back two shuffle steps (0.6 m)",
    ),
    "step_left": (lambda: _side_steps("l"), "medium reaction: pushed one step (0.3 m) to the left"),
    "step_right": (
        lambda: _side_steps("r"),
        "medium reaction: pushed one step (0.3 m) to the right",
    ),
    "step_forward_react": (_stumble_forward, "medium reaction: stumbles one step (0.4 m) forward"),
    "fall_backward": (_fall_backward, "heavy reaction: staggers back, sits down, ends on the back"),
    "fall_forward": (_fall_forward, "heavy reaction: stumbles, drops to the knees, ends prone"),
    "fall_sideways": (_fall_sideways, "heavy reaction: staggers left, ends lying on the left side"),
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
