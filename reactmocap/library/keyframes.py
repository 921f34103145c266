"""The machinery behind the synthetic clips: their skeleton, per-channel keyframes interpolated
with monotone PCHIP splines (two equal keys give an exactly constant channel, which keeps a
planted foot still), analytic two-bone IK for arms and legs, and the clamps that keep feet
reachable and every joint above the floor. The clips themselves: :mod:`reactmocap.library.synth`.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator
from scipy.ndimage import gaussian_filter1d, maximum_filter1d
from scipy.spatial.transform import Rotation

from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import BVHLayout, Skeleton
from reactmocap.rotations import quat_canonical, quat_from_matrix

__all__ = [
    "GUARD",
    "JOINT_INDEX",
    "REST_OFFSETS",
    "Clip",
    "Pose",
    "clip_motion",
    "euler",
    "mv",
    "rotvec",
    "synthetic_skeleton",
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
JOINT_INDEX = {n: i for i, n in enumerate(_NAMES)}
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
        end_sites={JOINT_INDEX[n]: o for n, o in _END_SITES.items()},
    )
    parents = [-1 if p is None else JOINT_INDEX[p] for _, p, _ in _JOINTS]
    return Skeleton(_NAMES, np.array(parents), np.array([o for *_, o in _JOINTS]), layout)


REST_OFFSETS = np.array([o for *_, o in _JOINTS])
_PARENT = [-1 if p is None else JOINT_INDEX[p] for _, p, _ in _JOINTS]
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


class Clip:
    """Per-channel keyframes; a channel holds its last key (and starts at the guard pose)."""

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.keys: dict[str, list[tuple[float, F64]]] = {
            k: [(0.0, np.array(v, dtype=float))] for k, v in GUARD.items()
        }

    def now(self, ch: str) -> F64:
        """The channel's latest key."""
        return self.keys[ch][-1][1].copy()

    def at(self, t: float, **chans: ArrayLike) -> Clip:
        """Key ``chans`` at time ``t`` (replacing a key at the same time)."""
        for ch, v in chans.items():
            keys = [k for k in self.keys[ch] if abs(k[0] - t) > 1e-9]
            keys.append((t, np.asarray(v, dtype=float)))
            self.keys[ch] = sorted(keys, key=lambda k: k[0])
        return self

    def hold(self, t: float, *chans: str) -> Clip:
        """Pin ``chans`` at their current value until ``t`` (motion starts after)."""
        return self.at(t, **{ch: self.now(ch) for ch in chans})

    def guard(self, t: float, *chans: str, home: bool = False) -> Clip:
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
    ) -> Clip:
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
def euler(a: F64) -> F64:
    return Rotation.from_euler("ZYX", a, degrees=True).as_matrix()


def rotvec(v: F64) -> F64:
    return Rotation.from_rotvec(v, degrees=True).as_matrix()


def _unit(v: F64) -> F64:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def mv(m: F64, v: ArrayLike) -> F64:
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
    heading = euler(c["rootrot"] * (1.0, 0.0, 0.0))

    def fk(j: int) -> None:
        p = _PARENT[j]
        glob[:, j] = glob[:, p] @ loc[:, j] if p >= 0 else loc[:, j]
        pos[:, j] = pos[:, p] + mv(glob[:, p], REST_OFFSETS[j]) if p >= 0 else root

    loc[:, 0] = euler(c["rootrot"])
    fk(0)
    for name in ("Spine", "Spine1", "Neck", "Head", "LeftShoulder", "RightShoulder"):
        loc[:, JOINT_INDEX[name]] = rotvec(c[name])
        fk(JOINT_INDEX[name])
    for s, side in (("l", "Left"), ("r", "Right")):
        arm, fore, hand = (JOINT_INDEX[side + n] for n in ("Arm", "ForeArm", "Hand"))
        fk(arm)
        target = pos[:, arm] + mv(heading, c[s + "hand"])
        up, hinge = _two_bone(pos[:, arm], target, mv(heading, c[s + "elbow"]), *_ARM, -1.0)
        loc[:, arm] = np.swapaxes(glob[:, _PARENT[arm]], -1, -2) @ up
        loc[:, fore] = hinge
        loc[:, hand] = rotvec(c[s + "wrist"])

        thigh, shin, foot, toe = (
            JOINT_INDEX[side + n] for n in ("UpLeg", "Leg", "Foot", "ToeBase")
        )
        fk(thigh)
        rf = euler(c[s + "foot"])
        ankle = c[s + "ball"] - mv(rf, REST_OFFSETS[toe])
        up, hinge = _two_bone(pos[:, thigh], ankle, c[s + "knee"], *_LEG, 1.0)
        loc[:, thigh] = np.swapaxes(loc[:, 0], -1, -2) @ up
        loc[:, shin] = hinge
        loc[:, foot] = np.swapaxes(up @ hinge, -1, -2) @ rf
        free = np.clip(c[s + "free"][:, 0], 0.0, 1.0)
        if free.any():  # a flying foot relaxes toward the neutral ankle (keeps ankles in range)
            rv = Rotation.from_matrix(loc[:, foot]).as_rotvec()
            loc[:, foot] = Rotation.from_rotvec(rv * (1.0 - free)[:, None]).as_matrix()
        # toes stay flat on the floor when the heel is raised
        loc[:, toe] = rotvec(np.outer(-np.maximum(c[s + "foot"][:, 1], 0.0), _Y))
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
    rr = euler(c["rootrot"])
    z = root[:, 2].copy()
    for s, side in (("l", "Left"), ("r", "Right")):
        hip = root + mv(rr, REST_OFFSETS[JOINT_INDEX[side + "UpLeg"]])
        ankle = c[s + "ball"] - mv(
            euler(c[s + "foot"]), REST_OFFSETS[JOINT_INDEX[side + "ToeBase"]]
        )
        reach = 0.985 * sum(_LEG)
        horiz = np.linalg.norm((ankle - hip)[:, :2], axis=-1)
        top = ankle[:, 2] + np.sqrt(np.maximum(reach**2 - horiz**2, 0.0))
        z = np.minimum(z, z - (hip[:, 2] - top))
    return root - np.outer(_envelope(root[:, 2] - z, radius), (0.0, 0.0, 1.0))


def clip_motion(clip: Clip, fps: float, name: str) -> Motion:
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
