"""Balance geometry for the whole-body tracker: the support polygon of the feet on the floor,
a point kept inside it, and capture-point steps (where a foot must land for the body to come to
rest over it). Pure functions of positions; the tracker decides when to use them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Step", "clamp_to_support", "convex_hull", "outside_distance", "step_target"]

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
