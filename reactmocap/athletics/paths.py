"""Where a runner goes: a facing direction (optionally changed at given times) or a path on the
ground (a polyline, a circle, a figure eight) followed by pure pursuit: the desired facing
points at the path point a look-ahead distance beyond the closest one. Each course answers
:meth:`Course.steer` with the desired facing (rad), the path's signed curvature there (1/m,
> 0 turning left: the runner leans into it) and the signed cross-track error (m, > 0: the
runner is left of the path; NaN without a path)."""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from reactmocap.errors import ConfigError
from reactmocap.rotations import einsum

__all__ = [
    "LOOKAHEAD",
    "TURN_RATE",
    "Circle",
    "Course",
    "EntryPath",
    "Facing",
    "Polyline",
    "Straight",
    "clothoid",
    "figure_eight",
    "loop_with_entry",
    "parse_course",
]

F64 = NDArray[np.float64]
#: pure-pursuit look-ahead distance (m)
LOOKAHEAD = 3.0
#: largest |x| or |y| of a path file's point (m)
MAX_COORD = 1e6
#: how fast a commanded facing is turned toward (rad/s)
TURN_RATE = 0.2
#: the longest entry onto a loop (m)
MAX_ENTRY = 100.0
#: spacing of an entry's points (m)
ENTRY_STEP = 0.25
#: how long a loop with an entry is laid out (m): its laps repeated, as Straight's 10 km
ENTRY_PATH_LENGTH = 1e4


class Course(Protocol):
    def steer(self, pos: F64, t: float) -> tuple[float, float, float]:
        """Desired facing, curvature and cross-track error at ground position ``pos (2,)``."""
        ...


class Facing:
    """A facing direction without a path: ``schedule`` is ``(time, heading)`` pairs, the
    heading in force being the last one whose time has come. The desired facing turns toward
    it at no more than ``rate`` rad/s (an abrupt change of facing throws a runner down, as
    Hodgins et al. note); its curvature for the lean is the turn rate over ``speed``."""

    def __init__(self, schedule: Sequence[tuple[float, float]] | float = 0.0,
                 rate: float = TURN_RATE) -> None:  # fmt: skip
        sched = [(0.0, float(schedule))] if isinstance(schedule, (int, float)) else list(schedule)
        if not sched or not all(math.isfinite(a) and math.isfinite(b) for a, b in sched):
            raise ConfigError(f"facing schedule must be finite (time, heading) pairs: {sched}")
        if not (math.isfinite(rate) and rate > 0):
            raise ConfigError(f"turn rate must be > 0 rad/s, got {rate!r}")
        self.schedule = sorted((float(a), float(b)) for a, b in sched)
        self.rate = float(rate)
        self.speed = 1.0
        self.reset()

    def reset(self) -> None:
        self.heading = self.schedule[0][1]
        self.time = self.schedule[0][0]

    def steer(self, pos: F64, t: float) -> tuple[float, float, float]:
        del pos
        goal = self.schedule[0][1]
        for when, heading in self.schedule:
            if t >= when:
                goal = heading
        dt = max(t - self.time, 0.0)
        self.time = t
        step = float(np.clip(goal - self.heading, -self.rate * dt, self.rate * dt))
        self.heading += step
        turning = dt > 0 and abs(step) > 1e-9
        curvature = (step / dt) / max(self.speed, 0.1) if turning else 0.0
        return self.heading, curvature, math.nan


class Circle:
    """A circle of ``radius`` m about ``centre``, run anticlockwise (``ccw``) or clockwise."""

    def __init__(self, centre: ArrayLike, radius: float, ccw: bool = True,
                 lookahead: float = LOOKAHEAD) -> None:  # fmt: skip
        if not (math.isfinite(radius) and radius > 0):
            raise ConfigError(f"circle radius must be > 0 m, got {radius!r}")
        self.centre = np.asarray(centre, dtype=np.float64)[:2]
        self.radius = float(radius)
        self.sign = 1.0 if ccw else -1.0
        self.lookahead = float(lookahead)

    def steer(self, pos: F64, t: float) -> tuple[float, float, float]:
        del t
        r = np.asarray(pos[:2], dtype=np.float64) - self.centre
        dist = max(float(np.hypot(*r)), 1e-6)
        ang = math.atan2(r[1], r[0]) + self.sign * self.lookahead / self.radius
        target = self.centre + self.radius * np.array([math.cos(ang), math.sin(ang)])
        d = target - pos[:2]
        # left of the path: inside an anticlockwise circle, outside a clockwise one
        cross = self.sign * (self.radius - dist)
        return math.atan2(d[1], d[0]), self.sign / self.radius, cross


class Polyline:
    """A path through ``points (N, 2)`` (m); progress along it only moves forward, so a path
    that crosses itself (a figure eight) is followed in order. ``closed`` joins the last
    point to the first and laps."""

    def __init__(self, points: F64 | Sequence[Sequence[float]], closed: bool = False,
                 lookahead: float = LOOKAHEAD) -> None:  # fmt: skip
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[0] < 2 or pts.shape[1] < 2 or not np.isfinite(pts).all():
            raise ConfigError(f"a path needs at least 2 finite (x, y) points, got {pts.shape}")
        pts = pts[:, :2]
        if closed:
            pts = np.vstack([pts, pts[:1]])
        seg = np.diff(pts, axis=0)
        length = np.hypot(seg[:, 0], seg[:, 1])
        keep = length > 1e-9
        if not keep.any():
            raise ConfigError("a path needs points that are not all the same")
        self.points = np.vstack([pts[:1], pts[1:][keep]])
        self.seg = np.diff(self.points, axis=0)
        self.len = np.hypot(self.seg[:, 0], self.seg[:, 1])
        self.cum = np.concatenate([[0.0], np.cumsum(self.len)])
        # as lists for point_at's one point (bisect for np.searchsorted, floats for numpy's
        # scalars: the same comparisons and roundings at a tenth of the cost)
        self._cum, self._len = self.cum.tolist(), self.len.tolist()
        self._points, self._seg = self.points.tolist(), self.seg.tolist()
        #: the search window of _closest for the segment it was made at
        self._window: tuple[int, NDArray[np.intp], F64, F64, F64] | None = None
        self.closed = closed
        self.lookahead = float(lookahead)
        self.total = float(self.cum[-1])
        self.reset()

    def reset(self) -> None:
        self.index = 0
        #: how far along the path the runner has got (m), laps of a closed path counted
        self.progress = 0.0
        self._laps = 0

    def _closest(self, p: F64) -> tuple[int, float, float]:
        """Segment, arc length and signed distance of the closest point, searched a window
        ahead of the current segment."""
        if self._window is None or self._window[0] != self.index:
            # the window's segments change only when the runner passes on to the next one
            n = len(self.len)
            end = bisect.bisect_left(self._cum, self._cum[self.index] + 2 * self.lookahead)
            idx = np.arange(self.index, self.index + max(4, end - self.index) + 1)
            idx = idx % n if self.closed else idx[idx < n]
            self._window = (self.index, idx, self.points[idx], self.seg[idx], self.len[idx] ** 2)
        _, idx, a, sv, len2 = self._window
        if len(idx) == 1:  # one segment (a straight line): the same search in floats
            return self._closest1(int(idx[0]), p.tolist(), float(len2[0]))
        u = np.minimum(np.maximum(einsum("ij,ij->i", p - a, sv) / len2, 0.0), 1.0)  # clip
        q = a + u[:, None] * sv
        dist = np.hypot(*(p - q).T)
        j = int(dist.argmin())  # the method: np.argmin wraps it
        i = int(idx[j])
        # the closest point's side and distance in floats (numpy's scalars: the same values)
        (sx, sy), (qx, qy), (px, py) = sv[j].tolist(), q[j].tolist(), p.tolist()
        side = float(np.sign(sx * (py - qy) - sy * (px - qx)))
        return i, self._cum[i] + float(u[j]) * self._len[i], side * float(dist[j])

    def _closest1(self, i: int, p: list[float], len2: float) -> tuple[int, float, float]:
        """:meth:`_closest` over a window of the one segment ``i`` (``len2`` its squared
        length), in floats: the einsum's two products summed as numpy's sum makes them (its
        sum starts from +0.0: ``+ 0.0`` turns a -0.0 into +0.0 as it does; equal on 300000
        random cases, zeros' signs included), numpy's own ``hypot`` and ``sign``."""
        (ax, ay), (sx, sy), (px, py) = self._points[i], self._seg[i], p
        dot = ((px - ax) * sx + (py - ay) * sy) + 0.0
        u = min(max(dot / len2, 0.0), 1.0)  # np.clip's value: NaN stays NaN
        qx, qy = ax + u * sx, ay + u * sy
        dist = float(np.hypot(px - qx, py - qy))
        side = float(np.sign(sx * (py - qy) - sy * (px - qx)))
        return i, self._cum[i] + u * self._len[i], side * dist

    def point_at(self, s: float) -> F64:
        return np.array(self._point(s))

    def _point(self, s: float) -> tuple[float, float]:
        """:meth:`point_at` as floats."""
        if self.closed:
            s = s % self.total
        # builtin min/max: np.clip on one number cost 20 us, four times a tick
        s = float(min(max(s, 0.0), self.total))
        i = min(max(bisect.bisect_right(self._cum, s) - 1, 0), len(self._len) - 1)
        u = (s - self._cum[i]) / self._len[i]
        (px, py), (sx, sy) = self._points[i], self._seg[i]
        return px + u * sx, py + u * sy

    def steer(self, pos: F64, t: float) -> tuple[float, float, float]:
        del t
        p = np.asarray(pos[:2], dtype=np.float64)
        i, s, cross = self._closest(p)
        if self.closed and i < self.index - len(self.len) // 2:
            self._laps += 1  # past the closing point into the next lap
        self.index = i
        self.progress = s + self._laps * self.total
        # in floats from here (the same roundings as the arrays' without their calls)
        ahead = self._point(s + self.lookahead)
        tx, ty = ahead
        if not self.closed and s + self.lookahead > self.total:  # past the end: straight on
            d = self.points[-1] - self.points[-2]
            tx, ty = (p + d / max(float(np.hypot(*d)), 1e-9) * self.lookahead).tolist()
        px, py = p.tolist()
        # the curvature over the look-ahead: the turn between its two halves' chords (the
        # segments' own directions turn in steps, and the lean read from them jumped); the
        # far end is the look-ahead point (2 (L / 2) = L and s + 0 = s exactly)
        half = 0.5 * self.lookahead
        (x0, y0), (x1, y1), (x2, y2) = self._point(s), self._point(s + half), ahead
        ax, ay, bx, by = x1 - x0, y1 - y0, x2 - x1, y2 - y1
        turn = math.atan2(ax * by - ay * bx, ax * bx + ay * by)
        turn = 0.0 if abs(turn) < 1e-12 else turn  # a straight stretch: no rounding's lean
        return math.atan2(ty - py, tx - px), turn / half, cross


class EntryPath(Polyline):
    """A loop entered along a clothoid (see :func:`loop_with_entry`): an open path whose
    first ``entry`` m ramp the curvature; ``entered_at`` is the time (s) the runner's progress
    first reached the loop (None before), from which the run's cross-track error is scored."""

    def __init__(self, points: F64, entry: float) -> None:
        self.entry = float(entry)
        self.entered_at: float | None = None
        super().__init__(points)

    def reset(self) -> None:
        super().reset()
        self.entered_at = None

    def steer(self, pos: F64, t: float) -> tuple[float, float, float]:
        out = super().steer(pos, t)
        if self.entered_at is None and self.progress >= self.entry:
            self.entered_at = t
        return out


def clothoid(length: float, radius: float, step: float = ENTRY_STEP) -> F64:
    """Points ``(N, 2)`` of a clothoid from the origin along +X, its curvature ramped
    linearly from 0 to ``1 / radius`` (left) over ``length`` m: heading ``s^2 / (2 L R)``,
    the position from the Fresnel integrals."""
    from scipy.special import fresnel

    a = math.sqrt(math.pi * length * radius)
    s = np.linspace(0.0, length, max(int(math.ceil(length / step)), 2) + 1)
    fs, fc = fresnel(s / a)
    return np.column_stack([a * fc, a * fs])


def loop_with_entry(kind: str, radius: float, entry: float, start: ArrayLike = (0.0, 0.0),
                    heading: float = 0.0, per_circle: int = 120,
                    reversal: float = 0.0) -> EntryPath:  # fmt: skip
    """A ``kind`` (``"circle"`` or ``"eight"``) loop of ``radius`` m entered from ``start``
    along ``heading`` over a clothoid of ``entry`` m (> 0) whose curvature ramps from 0 to the
    loop's first circle's (left); the loop leaves the clothoid's end tangent to it, and its
    laps are laid out to :data:`ENTRY_PATH_LENGTH`. An eight's ``reversal`` (m) is as
    :func:`figure_eight`'s; its lap then starts where its first lobe's arc does."""
    if not (math.isfinite(radius) and radius > 0):
        raise ConfigError(f"{kind} radius must be > 0 m, got {radius!r}")
    if not (math.isfinite(entry) and 0 < entry <= MAX_ENTRY):
        raise ConfigError(f"entry must be within (0, {MAX_ENTRY:g}] m, got {entry!r}")
    ramp = clothoid(entry, radius)
    turn = entry / (2 * radius)  # the clothoid's end heading
    th = np.linspace(0.0, 2 * np.pi, per_circle, endpoint=False)
    lap = np.column_stack([radius * np.sin(th), radius * (1 - np.cos(th))])
    if kind == "eight" and reversal != 0:
        lap = _reversal_lap(radius, reversal, per_circle)
    elif kind == "eight":
        lap = np.vstack([lap, lap * [1.0, -1.0]])
    elif kind != "circle":
        raise ConfigError(f"an entry is for 'circle' or 'eight' loops, got {kind!r}")
    elif reversal != 0:
        raise ConfigError(f"reversal is for 'eight' loops, got {kind!r}")
    if reversal != 0:
        seg = np.diff(np.vstack([lap, lap[:1]]), axis=0)
        lap_length = float(np.hypot(seg[:, 0], seg[:, 1]).sum())
    else:
        lap_length = 2 * np.pi * radius * (2 if kind == "eight" else 1)
    laps = int(math.ceil(ENTRY_PATH_LENGTH / lap_length))
    c, s = math.cos(turn), math.sin(turn)
    loop = np.tile(lap, (laps, 1)) @ np.array([[c, -s], [s, c]]).T + ramp[-1]
    pts = np.vstack([ramp, loop, loop[:1]])
    c, s = math.cos(heading), math.sin(heading)
    pts = pts @ np.array([[c, -s], [s, c]]).T + np.asarray(start, dtype=np.float64)[:2]
    return EntryPath(pts, entry)


def Straight(heading: float = 0.0, start: ArrayLike = (0.0, 0.0)) -> Polyline:
    """A straight line from ``start`` along ``heading`` (rad), 10 km long."""
    p0 = np.asarray(start, dtype=np.float64)[:2]
    return Polyline(np.stack([p0, p0 + 1e4 * np.array([math.cos(heading), math.sin(heading)])]))


def figure_eight(radius: float, start: ArrayLike = (0.0, 0.0), heading: float = 0.0,
                 per_circle: int = 120, reversal: float = 0.0) -> Polyline:  # fmt: skip
    """Two circles of ``radius`` m meeting at ``start``: the first anticlockwise, the second
    clockwise, leaving ``start`` along ``heading``; closed (it laps). With a ``reversal`` of L m
    (within (0, 2R]) each change of loop is a clothoid pair, the curvature ramped linearly
    +-1/R -> 0 -> -+1/R over L (:func:`_eight_lobe`; the lobes then cross at an angle); the
    runner still starts on the first circle (curvature 1/R), where its arc begins
    (:func:`_reversal_lap`), so only the reversals differ."""
    if not (math.isfinite(radius) and radius > 0):
        raise ConfigError(f"figure-eight radius must be > 0 m, got {radius!r}")
    if reversal != 0:
        pts = _reversal_lap(radius, reversal, per_circle)
    else:
        th = np.linspace(0.0, 2 * np.pi, per_circle, endpoint=False)
        left = np.column_stack([radius * np.sin(th), radius * (1 - np.cos(th))])
        right = np.column_stack([radius * np.sin(th), -radius * (1 - np.cos(th))])
        pts = np.vstack([left, right])
    c, s = math.cos(heading), math.sin(heading)
    rot = np.array([[c, -s], [s, c]])
    return Polyline(pts @ rot.T + np.asarray(start, dtype=np.float64)[:2], closed=True)


def _eight_lobe(radius: float, reversal: float, per_circle: int) -> tuple[F64, float, int]:
    """An eight's anticlockwise lobe whose ends are halves of a ``reversal`` m clothoid pair:
    points from the crossing at the origin (curvature 0, heading ``alpha``) over a clothoid of
    ``reversal / 2`` (curvature 0 -> 1/R), an arc of ``radius`` and the mirror clothoid back to
    the origin (heading ``-alpha``; the origin itself left off). ``alpha`` puts the arc's centre
    on the Y axis, so the lobe is symmetric about it and closes; the clockwise lobe is its
    mirror in X. Returns the points ``(N, 2)``, the heading where the arc starts (``alpha``
    plus the half's turn, rad) and the ramp's point count (the crossing's and the arc's start)."""
    if not (math.isfinite(reversal) and 0 < reversal <= 2 * radius):
        raise ConfigError(
            f"reversal must be within (0, {2 * radius:g}] m (twice the radius), got {reversal!r}"
        )
    ramp = clothoid(0.5 * reversal, radius)
    tau = 0.25 * reversal / radius  # the half's turn, s^2 / (2 l R) at s = l
    qx, qy = ramp[-1]
    # the centre's x, (qx, qy) rotated by alpha less R sin(alpha + tau), is 0
    alpha = math.atan2(qx - radius * math.sin(tau), qy + radius * math.cos(tau))
    c, s = math.cos(alpha), math.sin(alpha)
    ramp = ramp @ np.array([[c, -s], [s, c]]).T
    beta = alpha + tau  # the heading where the arc starts
    centre = ramp[-1] + radius * np.array([-math.sin(beta), math.cos(beta)])
    sweep = 2 * math.pi - 2 * beta
    n = max(int(math.ceil(sweep / (2 * math.pi) * per_circle)), 2)
    phi = beta - 0.5 * math.pi + np.linspace(0.0, sweep, n + 1)[1:-1]
    arc = centre + radius * np.column_stack([np.cos(phi), np.sin(phi)])
    back = ramp[::-1] * [-1.0, 1.0]
    return np.vstack([ramp, arc, back[:-1]]), beta, len(ramp)


def _reversal_lap(radius: float, reversal: float, per_circle: int) -> F64:
    """One lap of an eight with a ``reversal`` (:func:`_eight_lobe`), starting where its first
    lobe's arc does (curvature 1/R), at the origin heading +X. The arc's points are
    :func:`figure_eight`'s first circle's own, so a run on it is the eight's without a reversal
    to the bit until the path ahead reaches the first reversal."""
    lobe, beta, n = _eight_lobe(radius, reversal, per_circle)
    sweep = 2 * math.pi - 2 * beta
    th = np.linspace(0.0, 2 * np.pi, per_circle, endpoint=False)
    th = th[th < sweep - np.pi / per_circle]  # no step shorter than half the arc's
    arc = np.column_stack([radius * np.sin(th), radius * (1 - np.cos(th))])
    n_arc = len(lobe) - 2 * n + 1  # the lobe's arc points between its two Q's
    rest = np.vstack([lobe[n + n_arc :], lobe * [1.0, -1.0], lobe[1 : n - 1]])
    c, s = math.cos(-beta), math.sin(-beta)
    return np.vstack([arc, (rest - lobe[n - 1]) @ np.array([[c, -s], [s, c]]).T])


def parse_course(spec: str, start: ArrayLike = (0.0, 0.0), heading: float = 0.0,
                 entry: float = 0.0, reversal: float = 0.0) -> Course:  # fmt: skip
    """A course from the CLI's ``--path``: ``line``, ``circle:R`` (anticlockwise, starting
    tangent to the runner's heading, centre on its left), ``eight:R`` (figure eight) or a CSV
    file of ``x,y`` rows in metres (a header line is allowed). A loop's ``entry`` (m, or the
    spec's suffix ``circle:R+entry:L``) starts the runner on a clothoid of that length onto
    it (:func:`loop_with_entry`); 0 (the default) starts on the loop. An eight's ``reversal``
    (m, or the suffix ``eight:R+turn:L``; within [0, 2R]) joins its loops by a clothoid pair
    of that length (:func:`figure_eight`); 0 (the default) joins them at the curvature's
    jump."""
    spec = spec.strip()
    for key in ("entry", "turn"):
        if f"+{key}:" in spec:
            spec, _, tail = spec.partition(f"+{key}:")
            tail, plus, rest = tail.partition("+")
            spec += plus + rest  # another suffix after this one
            try:
                value = float(tail)
            except ValueError:
                raise ConfigError(
                    f"--path ...+{key}:L needs a length in metres, got {tail!r}"
                ) from None
            if key == "entry":
                entry = value
            else:
                reversal = value
    if not (math.isfinite(entry) and 0 <= entry <= MAX_ENTRY):
        raise ConfigError(f"entry must be within [0, {MAX_ENTRY:g}] m, got {entry!r}")
    if not (math.isfinite(reversal) and reversal >= 0):
        raise ConfigError(f"reversal must be within [0, 2R] m (twice the radius), got {reversal!r}")
    if reversal > 0 and not spec.startswith("eight:"):
        raise ConfigError(f"reversal is for 'eight:R' paths, got {spec!r}")
    p0 = np.asarray(start, dtype=np.float64)[:2]
    if entry > 0 and not spec.startswith(("circle:", "eight:")):
        raise ConfigError(f"entry is for 'circle:R' or 'eight:R' paths, got {spec!r}")
    if spec == "line":
        return Straight(heading, p0)
    for kind in ("circle", "eight"):
        if spec.startswith(kind + ":"):
            try:
                r = float(spec.split(":", 1)[1])
            except ValueError:
                raise ConfigError(
                    f"--path {kind}:R needs a radius in metres, got {spec!r}"
                ) from None
            if entry > 0:
                return loop_with_entry(kind, r, entry, p0, heading, reversal=reversal)
            if kind == "eight":
                return figure_eight(r, p0, heading, reversal=reversal)
            left = np.array([-math.sin(heading), math.cos(heading)])
            return Circle(p0 + r * left, r, ccw=True)
    path = Path(spec)
    if path.suffix.lower() == ".csv":
        if not path.is_file():
            raise ConfigError(f"path file {spec!r} does not exist")
        rows: list[tuple[float, float]] = []
        for n, line in enumerate(path.read_text().splitlines()):
            bits = [b.strip() for b in line.replace(";", ",").split(",") if b.strip()]
            if not bits:
                continue
            try:
                x, y = (float(b) for b in bits)  # exactly two: a third column was dropped
            except ValueError:
                if n == 0 and not rows:
                    continue  # a header
                raise ConfigError(
                    f"{spec}:{n + 1}: expected 'x,y' in metres, got {line!r}"
                ) from None
            if not (abs(x) <= MAX_COORD and abs(y) <= MAX_COORD):  # NaN too
                raise ConfigError(f"{spec}:{n + 1}: expected finite x,y within "
                                  f"+-{MAX_COORD:g} m, got {line!r}")  # fmt: skip
            rows.append((x, y))
        if len(rows) < 2:
            raise ConfigError(f"{spec}: a path needs at least 2 'x,y' points, got {len(rows)}")
        return Polyline(np.array(rows))
    raise ConfigError(
        f"unknown path {spec!r}; valid paths are 'line', 'circle:R', 'eight:R' or FILE.csv"
    )
