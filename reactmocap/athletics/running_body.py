"""The runner's body (:mod:`reactmocap.athletics.running`): the indices of the joints and
bodies its laws read, the single-quaternion math they use at every tick, and the pose a run
starts from (:func:`running_start`)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.rig import joint_index
from reactmocap.rotations import quat_from_yaw, quat_mul
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODY_INDEX

__all__ = [
    "ANKLE",
    "ELBOW",
    "FOOT",
    "HIP",
    "KNEE",
    "LEG_JOINTS",
    "NECK",
    "NJ",
    "SHIN",
    "SHOULDER",
    "SPINE",
    "THIGH",
    "CONJ",
    "clamp",
    "norm",
    "euler_yxz",
    "pitch_yxz",
    "qconj1",
    "qmul1",
    "quat_yxz",
    "YawMemo",
    "qyaw",
    "running_start",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
#: ball-joint indices (left, right) of the joints the laws set
HIP = (joint_index("l_hip"), joint_index("r_hip"))
KNEE = (joint_index("l_knee"), joint_index("r_knee"))
ANKLE = (joint_index("l_ankle"), joint_index("r_ankle"))
SHOULDER = (joint_index("l_shoulder"), joint_index("r_shoulder"))
ELBOW = (joint_index("l_elbow"), joint_index("r_elbow"))
SPINE = (joint_index("waist"), joint_index("back"))
NECK = joint_index("neck")
LEG_JOINTS = (*HIP, *KNEE, *ANKLE)
#: body indices (left, right) of the leg segments
THIGH = (SIM_BODY_INDEX["l_thigh"], SIM_BODY_INDEX["r_thigh"])
SHIN = (SIM_BODY_INDEX["l_shin"], SIM_BODY_INDEX["r_shin"])
FOOT = (SIM_BODY_INDEX["l_foot"], SIM_BODY_INDEX["r_foot"])


# ---------------------------------------------------------------------------------- small math
# single quaternions at every tick: MuJoCo's C routines and closed forms instead of the
# vectorised numpy helpers of reactmocap.rotations, whose per-call overhead on one quaternion
# dominated the tick (quat_mul 37 us against mju_mulQuat's 2.3 us, 2026-12-03 12:44 UTC)
def qmul1(a: F64, b: F64) -> F64:
    """Hamilton product of two ``(4,)`` quaternions."""
    out = np.empty(4)
    mujoco.mju_mulQuat(out, a, b)
    return out


def norm(v: F64) -> float:
    """Length of a vector: ``np.linalg.norm``'s own sum (``v.dot(v)``) and square root, to the
    bit, without its checks (a third of a tick's vector lengths' cost)."""
    return math.sqrt(v.dot(v))


def clamp(x: float, lo: float, hi: float) -> float:
    """``x`` within ``[lo, hi]``."""
    return float(min(max(x, lo), hi))


#: a quaternion's conjugate as a product (the same sign flips as negation)
CONJ = np.array([1.0, -1.0, -1.0, -1.0])


def qconj1(q: F64) -> F64:
    """Conjugate of a ``(4,)`` quaternion (one product: each entry's own four reads and
    negations cost eight numpy calls)."""
    return np.multiply(q, CONJ)


def qyaw(yaw: float) -> F64:
    """Rotation by ``yaw`` (rad) about +Z."""
    return np.array([math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw)])


class YawMemo:
    """:func:`qyaw`, made again only when the angle changes (a zero of the other sign is
    another quaternion): the laws' yaws stay the same over a straight stretch's ticks. The
    array returned is kept: not to be written."""

    def __init__(self) -> None:
        self._key = math.nan
        self._q = qyaw(0.0)

    def __call__(self, yaw: float) -> F64:
        if yaw != self._key or math.copysign(1.0, yaw) != math.copysign(1.0, self._key):
            self._q = qyaw(yaw)
            self._key = yaw
        return self._q


#: qyaw(0.0), the laws' yaw in quat_yxz
_QYAW_ZERO = qyaw(0.0)


def quat_yxz(pitch: float, roll: float, yaw: float) -> F64:
    """Quaternion of intrinsic Y-X-Z Euler angles (:data:`~reactmocap.athletics.bodies.
    EULER_ORDER`)."""
    qy = np.array([math.cos(0.5 * pitch), 0.0, math.sin(0.5 * pitch), 0.0])
    qx = np.array([math.cos(0.5 * roll), math.sin(0.5 * roll), 0.0, 0.0])
    plus_zero = yaw == 0.0 and math.copysign(1.0, yaw) > 0.0
    return qmul1(qmul1(qy, qx), _QYAW_ZERO if plus_zero else qyaw(yaw))


def pitch_yxz(q: F64) -> float:
    """The pitch of :func:`euler_yxz` alone (what the leg joints' laws read)."""
    w, x, y, z = q.tolist()  # floats: numpy scalars' arithmetic is 3x slower, same rounding
    return math.atan2(2.0 * (x * z + w * y), 1.0 - 2.0 * (x * x + y * y))


def euler_yxz(q: F64) -> tuple[float, float, float]:
    """Intrinsic Y-X-Z Euler angles (pitch, roll, yaw) of a quaternion: with
    ``R = Ry Rx Rz``, pitch = atan2(R02, R22), roll = asin(-R12), yaw = atan2(R10, R11)."""
    w, x, y, z = q.tolist()
    r12 = 2.0 * (y * z - w * x)
    r10 = 2.0 * (x * y + w * z)
    r11 = 1.0 - 2.0 * (x * x + z * z)
    return (pitch_yxz(q), math.asin(max(-1.0, min(1.0, -r12))), math.atan2(r10, r11))


def running_start(athlete: Athlete, speed: float, heading: float = 0.0) -> tuple[F64, F64]:
    """qpos ``(67,)`` and qvel ``(51,)`` of the runner in flight at ``speed`` along
    ``heading``, its soles 5 cm up: the left leg reaching forward for touchdown, the right
    trailing with its knee bent."""
    angles = np.zeros((NJ, 3))
    angles[HIP[0]] = (-0.45, 0.0, 0.0)
    angles[KNEE[0]] = (0.25, 0.0, 0.0)
    angles[ANKLE[0]] = (-0.05, 0.0, 0.0)
    angles[HIP[1]] = (0.25, 0.0, 0.0)
    angles[KNEE[1]] = (1.2, 0.0, 0.0)
    angles[ANKLE[1]] = (0.2, 0.0, 0.0)
    for k in range(2):
        angles[SHOULDER[k]] = (0.9 * angles[HIP[1 - k], 0] + 0.05, 0.15 * (1 - 2 * k), 0.0)
        angles[ELBOW[k]] = (-1.4, 0.0, 0.0)
    q = athlete.standing_qpos(angles, pitch=0.08, clearance=0.05)
    if heading:
        q[3:7] = quat_mul(quat_from_yaw(heading), q[3:7])
        c, s = math.cos(heading), math.sin(heading)
        q[0], q[1] = c * q[0] - s * q[1], s * q[0] + c * q[1]
    v = np.zeros(6 + 3 * NJ)
    v[0] = speed * math.cos(heading)
    v[1] = speed * math.sin(heading)
    return q, v
