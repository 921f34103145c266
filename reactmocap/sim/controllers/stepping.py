"""Balance geometry for the whole-body tracker: the support polygon of the feet on the floor,
a point kept inside it, and capture-point steps (where a foot must land for the body to come to
rest over it). Pure functions of positions; the tracker decides when to use them."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "LegFrames", "Step", "clamp_to_support", "convex_hull", "outside_distance", "reach_leg",
    "step_target",
]  # fmt: skip

F64 = NDArray[np.float64]


def convex_hull(points: F64) -> F64:
    """The convex hull of a few 2-D points ``(k, 2)``, counter-clockwise (Andrew's monotone
    chain); fewer than 3 distinct points come back as they are."""
    pts = sorted(set(map(tuple, np.round(points, 9).tolist())))
    if len(pts) < 3:
        return np.array(pts, dtype=np.float64).reshape(-1, 2)

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for q in seq:  # a handful of sole corners per control tick
            while (
                len(out) >= 2
                and (
                    (out[-1][0] - out[-2][0]) * (q[1] - out[-2][1])
                    - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])
                )
                <= 0
            ):
                out.pop()
            out.append(q)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _edges(hull: F64) -> tuple[F64, F64]:
    """Edge vectors and unit outward normals of a counter-clockwise hull."""
    edges = np.roll(hull, -1, axis=0) - hull
    normal = np.column_stack([edges[:, 1], -edges[:, 0]])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    return edges, normal


def outside_distance(p: F64, points: F64) -> float:
    """How far ``p`` (2,) lies outside the convex hull of ``points`` (k, 2) (m; negative
    inside: the distance to the nearest edge line). Hulls of fewer than 3 points are a
    segment or a point: the distance to it."""
    hull = convex_hull(points)
    if len(hull) == 0:
        return float("inf")
    if len(hull) < 3:
        return float(np.linalg.norm(p - _nearest_on_segment(p, hull)))
    _, normal = _edges(hull)
    return float(((p - hull) * normal).sum(axis=1).max())


def _nearest_on_segment(p: F64, seg: F64) -> F64:
    if len(seg) == 1:
        return seg[0]
    a, b = seg
    u = b - a
    s = float(np.clip((p - a) @ u / max(float(u @ u), 1e-12), 0.0, 1.0))
    return a + s * u


def clamp_to_support(p: F64, points: F64, margin: float) -> F64:
    """``p`` (2,) moved into the convex hull of ``points`` (k, 2), at least ``margin`` inside
    (toward its centroid; the centroid itself when the hull is thinner than that)."""
    hull = convex_hull(points)
    centre = hull.mean(axis=0)
    if len(hull) < 3:
        q = _nearest_on_segment(p, hull)
    else:
        edges, normal = _edges(hull)
        dist = ((p - hull) * normal).sum(axis=1)
        if dist.max() <= -margin:
            return p
        q = p
        if dist.max() > 0:  # outside: the nearest point of the boundary
            s = np.clip(((p - hull) * edges).sum(axis=1) / (edges * edges).sum(axis=1), 0, 1)
            near = hull + s[:, None] * edges
            q = near[np.argmin(np.linalg.norm(near - p, axis=1))]
        else:
            margin += float(dist.max())  # already that far inside
    gap = centre - q
    n = float(np.linalg.norm(gap))
    return centre if n <= margin else q + gap * (margin / n)


@dataclass(frozen=True)
class Step:
    """A balance step of ``foot`` (0 left, 1 right) starting at rollout time ``t0``: its sole
    centre goes from ``start`` to ``target`` (world, (3,)) in ``duration`` s, lifted
    ``height`` m at mid-swing."""

    foot: int
    t0: float
    duration: float
    start: F64
    target: F64
    height: float

    def phase(self, t: float) -> float:
        return float(np.clip((t - self.t0) / self.duration, 0.0, 1.0))

    def at(self, t: float) -> tuple[F64, F64, F64]:
        """Position, velocity and acceleration of the sole centre at ``t``: a smoothstep
        across, a bump ``16 h s^2 (1 - s)^2`` up (both at rest at the ends)."""
        s = self.phase(t)
        T = self.duration
        moving = 0.0 < (t - self.t0) < T
        span = self.target - self.start
        p = self.start + (3 * s**2 - 2 * s**3) * span
        p[2] += 16.0 * self.height * s**2 * (1 - s) ** 2
        if not moving:
            return p, np.zeros(3), np.zeros(3)
        v = (6 * s * (1 - s) / T) * span
        a = ((6 - 12 * s) / T**2) * span
        v[2] += 32.0 * self.height * s * (1 - s) * (1 - 2 * s) / T
        a[2] += 32.0 * self.height * (1 - 6 * s + 6 * s**2) / T**2
        return p, v, a


def step_target(
    xi: F64, stance: F64, swing: F64, omega: float, duration: float, *, beyond: float,
    max_length: float, min_width: float, lateral: F64,
) -> F64:  # fmt: skip
    """Where a swing foot (sole centre ``swing`` (2,)) should land so that the body can come
    to rest over it: the capture point ``xi`` (2,) predicted ``duration`` s ahead while
    pivoting over the ``stance`` foot (linear inverted pendulum, natural frequency ``omega``),
    ``beyond`` m further along the fall, at most ``max_length`` m from the stance foot and at
    least ``min_width`` m to the swing foot's side of it (``lateral`` (2,): unit vector from
    the stance foot toward the swing foot's side), so the legs do not cross."""
    pred = stance + (xi - stance) * np.exp(omega * duration)
    fall = pred - stance
    n = float(np.linalg.norm(fall))
    target = pred + (fall / n) * beyond if n > 1e-9 else pred.copy()
    rel = target - stance
    side = float(rel @ lateral)
    if side < min_width:
        target = target + (min_width - side) * lateral
    rel = target - stance
    n = float(np.linalg.norm(rel))
    if n > max_length:
        target = stance + rel * (max_length / n)
    del swing
    return target


@dataclass(frozen=True)
class LegFrames:
    """One leg of a character's model for :func:`reach_leg`: the qpos addresses (within the
    character's qpos) of the pelvis's free-joint quaternion and the hip, knee and ankle ball
    joints; the thigh's, shin's and foot's body quaternions ``(3, 4)``; the knee in the
    thigh's frame and the ankle in the shin's ``(3,)`` (m); the pelvis's left axis in its own
    frame ``(3,)``."""

    root: int
    hip: int
    knee: int
    ankle: int
    body_quat: F64
    knee_pos: F64
    ankle_pos: F64
    left: F64


def _mul(a: F64, b: F64) -> F64:
    out = np.empty(4)
    mujoco.mju_mulQuat(out, a, b)
    return out


def _conj(a: F64) -> F64:
    out = np.empty(4)
    mujoco.mju_negQuat(out, a)
    return out


def _rot(q: F64, v: F64) -> F64:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, v, q)
    return out


def _axis_angle(axis: F64, angle: float) -> F64:
    out = np.empty(4)
    mujoco.mju_axisAngle2Quat(out, axis, angle)
    return out


def reach_leg(q: F64, leg: LegFrames, move: F64, cut: bool = True) -> F64:
    """Turn the hip and knee of ``leg`` in the pose ``q`` (a character's qpos, changed in
    place) so that its ankle moves by ``move`` (world, (3,)), the foot's orientation kept (the
    ankle turned back). A target past the leg's reach is, with ``cut``, moved back along
    ``move`` to what the straight leg reaches, else the straight leg points at it. Returns the
    ankle's move made (world, (3,)). A closed-form two-link solve (law of cosines at the
    knee, then the hip turned onto the target): MuJoCo and scipy have no analytic leg IK,
    and an iterative solve each control tick costs more."""
    bt, bs, bf = leg.body_quat
    qh, qk, qa = q[leg.hip : leg.hip + 4], q[leg.knee : leg.knee + 4], q[leg.ankle : leg.ankle + 4]
    m = _rot(_conj(q[leg.root : leg.root + 4]), move)  # the move in the pelvis's frame
    thigh = _mul(bt, qh)
    shin_base = _mul(thigh, bs)  # the shin's frame before the knee's turn
    shin = _mul(shin_base, qk)
    kp, wp = _rot(thigh, leg.knee_pos), _rot(shin, leg.ankle_pos)
    a = kp + wp
    reach = 0.995 * (float(np.linalg.norm(leg.knee_pos)) + float(np.linalg.norm(leg.ankle_pos)))
    mm, am, aa = float(m @ m), float(a @ m), float(a @ a)
    if mm < 1e-12 or (cut and aa >= reach * reach):
        return np.zeros(3)
    target = a + m
    out = float(target @ target) - reach * reach
    if out > 0 and cut:  # |a + x m| = reach, the root in (0, 1)
        target = a + m * (-am + float(np.sqrt(am * am - mm * (aa - reach * reach)))) / mm
    elif out > 0:
        target *= reach / float(np.linalg.norm(target))
    # the knee: turned about the hip's flexion axis (the pelvis's left, off the thigh) so
    # the hip-ankle distance is the target's
    n = leg.left - (leg.left @ kp) / (kp @ kp) * kp
    n /= np.linalg.norm(n)
    kn, wn = float(kp @ n), float(wp @ n)
    k_perp, w_perp = kp - kn * n, wp - wn * n
    lk, lw = float(np.linalg.norm(k_perp)), float(np.linalg.norm(w_perp))
    phi = float(np.arctan2(n @ np.cross(k_perp, w_perp), k_perp @ w_perp))
    c = (float(target @ target) - float(kp @ kp) - float(wp @ wp) - 2.0 * kn * wn) / (2.0 * lk * lw)
    turn = np.copysign(float(np.arccos(min(1.0, max(-1.0, c)))), phi) - phi
    knee_turn = _axis_angle(n, turn)  # in the pelvis's frame
    shin_new = _mul(knee_turn, shin)
    q[leg.knee : leg.knee + 4] = _mul(_conj(shin_base), shin_new)
    # the hip: the shortest turn of the new ankle onto the target
    a2 = kp + _rot(shin_new, leg.ankle_pos)
    axis = np.cross(a2, target)
    s = float(np.linalg.norm(axis))
    hip_turn = _axis_angle(axis / s, float(np.arctan2(s, a2 @ target))) if s > 1e-12 else None
    if hip_turn is not None:
        q[leg.hip : leg.hip + 4] = _mul(_conj(bt), _mul(hip_turn, thigh))
        shin_new = _mul(hip_turn, shin_new)
    # the ankle: the foot as it was, (shin' bf qa') = (shin bf qa)
    foot = _mul(_mul(shin, bf), qa)
    q[leg.ankle : leg.ankle + 4] = _mul(_conj(_mul(shin_new, bf)), foot)
    return _rot(q[leg.root : leg.root + 4], target - a)
