"""Synthetic keyframed clip library: a fighting guard, four attacks, steps and reactions.

These clips are **synthetic** (hand-set keyframes, not motion capture). They exist so the
package, its tests and its examples run without any mocap download. Regenerate them with
``reactmocap synth data/synthetic_clips`` or ``python -m reactmocap.library.synth OUT_DIR``.

Internal frame (the package's): Z up, metres. At facing 0 the character's **forward is +X and
its left is +Y**; every clip starts at the origin facing +X.

Each clip is per-channel keyframes (root position and yaw/pitch/roll, spine/neck/head and wrist
rotation vectors, hand targets, foot placements by the ball of the foot, knee/elbow poles) turned
into a Motion by :mod:`reactmocap.library.keyframes`.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from reactmocap.errors import ConfigError
from reactmocap.library.keyframes import (
    GUARD,
    JOINT_INDEX,
    REST_OFFSETS,
    Clip,
    Pose,
    clip_motion,
    euler,
    mv,
    rotvec,
    synthetic_skeleton,
)
from reactmocap.library.motion import Motion

__all__ = [
    "ATTACK_CLIPS",
    "CLIP_INFO",
    "STRIKERS",
    "synthetic_clips",
    "synthetic_skeleton",
    "write_synthetic_library",
]

F64 = NDArray[np.float64]


# ------------------------------------------------------------------------------------ clips
def _breathing(c: Clip, t0: float, t1: float, cycles: int) -> Clip:
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


def _guard() -> Clip:
    return _breathing(Clip(4.0), 0.0, 4.0, 2)


def _heading(v: ArrayLike, yaw: float) -> F64:
    """World vector ``v`` in the heading frame of a root turned ``yaw`` degrees."""
    return mv(euler(np.array([-yaw, 0.0, 0.0])), np.asarray(v, float))


def _leg(
    root: ArrayLike, rootrot: ArrayLike, side: str, hip: ArrayLike, knee: float,
    ankle: ArrayLike = (0.0, 0.0, 0.0),
) -> dict[str, F64]:  # fmt: skip
    """Foot keys (ball, foot, knee pole) that reproduce a leg given by joint angles (degrees):
    lying and kneeling poses are easier to set that way than by foot placement."""
    s, name = side[0].lower(), "Left" if side[0].lower() == "l" else "Right"
    rr = euler(np.asarray(rootrot, float))
    ru = rr @ rotvec(np.asarray(hip, float))
    rs = ru @ rotvec(np.array([0.0, knee, 0.0]))
    rf = rs @ rotvec(np.asarray(ankle, float))
    ankle_p = np.asarray(root, float) + rr @ REST_OFFSETS[JOINT_INDEX[name + "UpLeg"]]
    ankle_p = (
        ankle_p
        + ru @ REST_OFFSETS[JOINT_INDEX[name + "Leg"]]
        + rs @ REST_OFFSETS[JOINT_INDEX[name + "Foot"]]
    )
    return {
        s + "ball": ankle_p + rf @ REST_OFFSETS[JOINT_INDEX[name + "ToeBase"]],
        s + "foot": Rotation.from_matrix(rf).as_euler("ZYX", degrees=True),
        s + "knee": ru @ (1.0, 0.0, 0.0),
    }


def _punch() -> Clip:
    c = Clip(2.0).hold(0.15, "root", "rootrot", "Spine", "Spine1", "rhand", "lhand")
    c.at(0.3, root=(0.0, 0.0, 0.90), rootrot=(-5.0, 3.0, 0.0), rhand=(0.14, 0.10, -0.03))
    # the cross lands 0.1 s after it starts: the fist near 7 m/s, as in measured punches
    c.at(
        0.40,
        root=(0.06, 0.0, 0.89), rootrot=(25.0, 6.0, 0.0), Spine=(0.0, 5.0, 8.0),
        Spine1=(0.0, 5.0, 8.0), Neck=(0.0, -3.0, -20.0), Head=(0.0, -3.0, -16.0),
        RightShoulder=(0.0, 0.0, 15.0), rhand=_heading((0.535, 0.09, 0.02), 25.0),
        relbow=(0.0, -0.3, -1.0), lhand=(0.16, -0.05, 0.02), rfoot=(-30.0, 25.0, 0.0),
    )  # fmt: skip
    c.hold(0.48, "root", "rootrot", "Spine", "Spine1", "rhand", "RightShoulder", "Neck", "Head")
    c.at(0.70, rhand=(0.22, 0.08, -0.05), RightShoulder=(0.0, 0.0, 0.0))
    return c.guard(1.05, home=True).at(1.05, rfoot=GUARD["rfoot"]).hold(2.0, "root")


def _push() -> Clip:
    c = Clip(2.4).step("l", 0.1, 0.45, (0.62, 0.15))
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


def _front_kick() -> Clip:
    c = Clip(2.4)
    lean: Pose = dict(root=(0.10, 0.05, 0.90), rootrot=(0.0, -3.0, 0.0), Spine=(0.0, 0.0, -8.0))
    c.at(0.3, **lean).at(0.3, lhand=(0.22, -0.06, 0.0), rhand=(0.16, 0.08, 0.0))
    # a high chamber: the snap then travels at the height of the target's abdomen
    chamber: Pose = dict(rball=(0.40, -0.10, 0.58), rfoot=(0.0, 20.0, 0.0), rknee=(1.0, 0.0, 0.3))
    c.at(0.35, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.04)), rfoot=(-30.0, 20.0, 0.0))
    c.at(0.58, **chamber).at(0.58, rootrot=(0.0, -6.0, 0.0), root=(0.12, 0.05, 0.90))
    # the snap: ~0.5 m in 0.1 s, the foot near 9 m/s mid-way, as in measured front kicks
    c.at(
        0.68,
        rball=(0.93, -0.08, 0.95), rfoot=(0.0, -50.0, 0.0), root=(0.15, 0.05, 0.90),
        rootrot=(0.0, -15.0, 0.0), Spine=(0.0, -4.0, -8.0), Spine1=(0.0, -2.0, -8.0),
        Neck=(0.0, 8.0, 8.0), Head=(0.0, 5.0, 8.0), rhand=(0.0, 0.15, -0.25),
    )  # fmt: skip
    c.hold(0.74, "rball", "rfoot", "root", "rootrot", "Spine", "Spine1", "Neck", "Head")
    c.at(0.95, **chamber).at(0.95, root=(0.12, 0.05, 0.90), rootrot=(0.0, -4.0, 0.0))
    c.at(0.95, Spine=GUARD["Spine"], Spine1=GUARD["Spine1"], Neck=GUARD["Neck"])
    c.at(0.95, Head=GUARD["Head"], rhand=(0.16, 0.08, 0.0))
    c.at(1.3, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.05)), rfoot=GUARD["rfoot"])
    c.at(1.3, rknee=GUARD["rknee"]).at(1.45, rball=GUARD["rball"])
    return c.guard(1.75, home=True).hold(2.4, "root")


def _side_kick() -> Clip:
    # The support foot turns out first (a small lifted pivot step) so the hips can turn side-on;
    # the kicking foot is off the floor whenever the hips are turned far from it.
    yaw, c = 80.0, Clip(2.8)
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
    c.at(0.84, **ext).hold(0.90, *ext)  # a fast thrust: 0.12 s from the chamber
    c.at(1.12, **chamber).at(1.12, **turn)
    c.at(1.35, rootrot=(50.0, 0.0, -4.0), rknee=(0.6, 0.6, 0.4), rfoot=lift["rfoot"])
    c.at(1.5, **half, rknee=(0.87, -0.5, 0.0))
    c.at(1.5, rball=np.add(GUARD["rball"], (0.0, 0.0, 0.06)), rfoot=GUARD["rfoot"])
    c.at(1.65, rball=GUARD["rball"]).at(1.7, lknee=(0.35, 1.0, 0.0), rknee=GUARD["rknee"])
    c.step("l", 1.7, 2.0, GUARD["lball"], foot=GUARD["lfoot"], h=0.045)
    return c.guard(2.1, home=True)


def _sway() -> Clip:
    c = Clip(2.5)
    c.at(
        0.25,
        root=(-0.05, 0.0, 0.90), rootrot=(0.0, -6.0, 0.0), Spine=(0.0, -5.0, -8.0),
        Spine1=(0.0, -5.0, -8.0), Neck=(0.0, 6.0, 8.0), Head=(0.0, 4.0, 8.0),
        lhand=(0.24, -0.02, 0.03), rhand=(0.15, 0.12, 0.03),
    )  # fmt: skip
    c.at(0.75, root=(0.01, 0.0, 0.91), rootrot=(0.0, 4.0, 0.0), Spine=(0.0, 5.0, -8.0))
    c.at(0.75, Spine1=GUARD["Spine1"], Neck=GUARD["Neck"], Head=GUARD["Head"])
    return c.guard(1.3, home=True).hold(2.5, "root")


def _shuffle(c: Clip, t: float, d: tuple[float, float], lead: str, dur: float = 0.35) -> float:
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


def _step_forward() -> Clip:
    c = Clip(2.0)
    return c.guard(_shuffle(c, 0.15, (0.3, 0.0), "l") + 0.3).hold(2.0, "root")


def _step_back() -> Clip:
    c = Clip(2.0)
    return c.guard(_shuffle(c, 0.15, (-0.3, 0.0), "r") + 0.3).hold(2.0, "root")


def _back_steps(n: int) -> Clip:
    """Knocked back ``n`` shuffle steps (rear foot first), then recover the guard."""
    c = Clip(2.5 + (n - 1) * 0.85)
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


def _side_steps(side: str) -> Clip:
    """Pushed sideways: the near foot steps out toward ``side``, the other follows."""
    sg = 1.0 if side == "l" else -1.0
    c = Clip(2.5)
    c.at(
        0.12,
        root=(0.0, 0.04 * sg, 0.90), rootrot=(0.0, 3.0, -8.0 * sg), Spine=(-6.0 * sg, 4.0, -8.0),
        Spine1=(-4.0 * sg, 4.0, -8.0), Neck=(8.0 * sg, -3.0, 8.0),
    )  # fmt: skip
    t = _shuffle(c, 0.12, (0.0, 0.3 * sg), side, dur=0.3)
    return c.at(t - 0.2, rootrot=(0.0, 3.0, 0.0)).guard(t + 0.35).hold(2.5, "root")


def _stumble_forward() -> Clip:
    c = Clip(2.5)
    c.at(
        0.12,
        root=(0.06, 0.0, 0.89), rootrot=(0.0, 15.0, 0.0), Spine=(0.0, 8.0, -8.0),
        Spine1=(0.0, 6.0, -8.0), Neck=(0.0, -12.0, 8.0), Head=(0.0, -8.0, 8.0),
        lhand=(0.2, 0.15, -0.15), rhand=(0.15, -0.05, -0.15), rfoot=(-30.0, 25.0, 0.0),
    )  # fmt: skip
    t = _shuffle(c, 0.12, (0.4, 0.0), "l", dur=0.3)
    return c.at(t - 0.2, rootrot=(0.0, 5.0, 0.0)).guard(t + 0.35).hold(2.5, "root")


def _fall_backward() -> Clip:
    # stagger back on the right foot, sit down behind it, roll onto the back (knees up)
    c = Clip(4.5)
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


def _fall_forward() -> Clip:
    # stumble two steps, drop to the knees, catch with the hands, end prone
    c = Clip(4.5)
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


def _fall_sideways() -> Clip:
    # pushed from the right: stagger left, buckle onto the left hip, lie on the left side
    c = Clip(4.5)
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


def _fall_forward_topple() -> Clip:
    # knocked off balance forward: one catching step, then the body pivots over the planted
    # feet like a plank (no kneeling), the hands reach for the floor, prone 0.9 s in
    c = Clip(3.0)
    c.at(
        0.08,
        root=(0.06, 0.0, 0.89), rootrot=(0.0, 12.0, 0.0), Spine=(0.0, 8.0, -8.0),
        Spine1=(0.0, 6.0, -8.0), Neck=(0.0, -10.0, 8.0), Head=(0.0, -8.0, 8.0),
        lhand=(0.30, 0.10, -0.10), rhand=(0.30, -0.10, -0.10),
    )  # fmt: skip
    c.step("r", 0.05, 0.3, (0.40, -0.13), foot=(-5.0, 0.0, 0.0), h=0.07)
    c.hold(0.3, "lfoot", "rfoot")
    c.at(0.3, root=(0.30, 0.0, 0.86), rootrot=(0.0, 25.0, 0.0))
    c.at(0.3, lhand=(0.40, 0.08, -0.15), rhand=(0.40, -0.08, -0.15))
    c.at(0.5, root=(0.62, 0.0, 0.68), rootrot=(0.0, 50.0, 0.0), Neck=(0.0, -25.0, 0.0))
    c.at(0.5, lhand=(0.40, 0.05, -0.35), rhand=(0.40, -0.05, -0.35), Head=(0.0, -15.0, 0.0))
    c.at(0.6, lfoot=(10.0, 40.0, 0.0), rfoot=(-5.0, 40.0, 0.0))
    c.at(0.7, root=(0.95, 0.0, 0.38), rootrot=(0.0, 72.0, 0.0))
    prone: Pose = dict(
        root=(1.25, 0.0, 0.13), rootrot=(0.0, 88.0, 0.0), Spine=(0.0, -3.0, 0.0),
        Spine1=(0.0, -3.0, 0.0), Neck=(0.0, -30.0, 0.0), Head=(0.0, -10.0, 0.0),
        lhand=(0.10, 0.25, -0.05), rhand=(0.10, -0.25, -0.05), lelbow=(-0.3, 1.0, -0.5),
        relbow=(-0.3, -1.0, -0.5), lknee=(0.0, 0.2, -1.0), rknee=(0.0, -0.2, -1.0),
        lfoot=(10.0, 65.0, 0.0), rfoot=(-5.0, 65.0, 0.0),
    )  # fmt: skip
    return c.at(0.9, **prone).hold(3.0, *prone)


def _faster(build: Callable[[], Clip], speed: float, duration: float) -> Clip:
    """Clip ``build`` played ``speed`` times as fast (every key sooner), lasting ``duration``.
    The simulated bodies the real recipients' pushes knock down reach the floor 0.4-0.7 s after
    they start to go (the head 1.2-1.4 m -> 0.1-0.2 m); the falls above take 1.4-2.3 s, so a
    falling body had no fall to match but their lying hold (``docs/benchmarks.md``)."""
    src, c = build(), Clip(duration)
    c.keys = {ch: [(t / speed, v) for t, v in keys] for ch, keys in src.keys.items()}
    return c


CLIP_BUILDERS: dict[str, tuple[Callable[[], Clip], str]] = {
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
    "fall_forward_topple": (
        _fall_forward_topple,
        "heavy reaction: one step, then topples forward over the feet, prone 0.9 s in",
    ),
    "fall_forward_fast": (
        lambda: _faster(_fall_forward, 2.0, 3.0),
        "heavy reaction: fall_forward twice as fast, prone 1.15 s in",
    ),
    "fall_backward_fast": (
        lambda: _faster(_fall_backward, 2.0, 3.0),
        "heavy reaction: fall_backward twice as fast, on the back 1.15 s in",
    ),
    "fall_sideways_fast": (
        lambda: _faster(_fall_sideways, 2.0, 3.0),
        "heavy reaction: fall_sideways twice as fast, on the left side 0.95 s in",
    ),
}
#: clips mirrored left/right from another (name -> (source, meaning)): the one sideways fall
#: lies on the left side, where bodies pushed from the left in simulation lie on the right
MIRRORED: dict[str, tuple[str, str]] = {
    "fall_sideways_fast_right": (
        "fall_sideways_fast",
        "heavy reaction: fall_sideways_fast mirrored, on the right side 0.95 s in",
    ),
}
CLIP_INFO = {k: v[1] for k, v in CLIP_BUILDERS.items()} | {k: v[1] for k, v in MIRRORED.items()}
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
    if not (np.isfinite(fps) and fps > 0):  # NaN reached np.arange as a ValueError
        raise ConfigError(f"fps must be a positive frame rate, got {fps!r}")
    clips = {name: clip_motion(build(), fps, name) for name, (build, _) in CLIP_BUILDERS.items()}
    for name, (src, _) in MIRRORED.items():
        # the skeleton is symmetric, so the mirror's swapped offsets are its own
        m = clips[src].mirror("y")
        clips[name] = m.replace(skeleton=clips[src].skeleton, name=name)
    return clips


def write_synthetic_library(out_dir: str | Path, fps: float = 60.0) -> list[Path]:
    """Write every clip as ``out_dir/<name>.bvh``; returns the paths written."""
    from reactmocap.library.bvh import write_bvh

    clips = synthetic_clips(fps)  # before the folder: a bad fps leaves none behind
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, motion in clips.items():
        path = out / f"{name}.bvh"
        write_bvh(motion, path)
        paths.append(path)
    return paths


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python -m reactmocap.library.synth OUT_DIR")
    written = write_synthetic_library(sys.argv[1])
    print(f"wrote {len(written)} synthetic clips to {sys.argv[1]}")
