"""What a controller follows: a clip as a path of MuJoCo states (:class:`ReferencePath`) and the
clock that maps rollout time onto it (:class:`ClipClock`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_continuous
from reactmocap.sim.character import BALL_JOINTS, qvel_from_qpos
from reactmocap.sim.feet import foot_soles, sole_corners_world
from reactmocap.sim.world import World

__all__ = ["ClipClock", "ReferencePath", "as_path", "reference_path", "with_soles"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
NQ = 7 + 4 * NJ
NV = 6 + 3 * NJ


@dataclass(frozen=True)
class ClipClock:
    """Rollout time ``t`` -> fractional frame ``(start + min(t, until)) fps`` of a clip of
    ``frames`` frames, clamped to the clip (``until``: the clip stops there, its pose held)."""

    fps: float
    frames: int
    start: float = 0.0
    until: float = float("inf")

    def __post_init__(self) -> None:
        if not (np.isfinite(self.fps) and self.fps > 0) or self.frames < 1:
            raise ConfigError(f"a clip clock needs fps > 0 and frames >= 1, got {self!r}")
        if not np.isfinite(self.start):
            raise ConfigError(f"clip clock start must be finite, got {self.start!r}")

    def frame(self, t: float) -> float:
        return min(max((self.start + min(t, self.until)) * self.fps, 0.0), self.frames - 1.0)

    def held_from(self, t: float) -> ClipClock:
        """This clock with the clip stopped at rollout time ``t``."""
        return replace(self, until=float(t))

    def coast(self, t: float) -> float:
        """Seconds past the hold at rollout time ``t`` (0 before it)."""
        return max(0.0, t - self.until)

    def bracket(self, t: float) -> tuple[int, int, float]:
        """The frames either side of ``t`` and the weight of the later one."""
        x = self.frame(t)
        i0 = int(x)
        return i0, min(i0 + 1, self.frames - 1), x - i0

    def nearest(self, t: float) -> int:
        return round(self.frame(t))


@dataclass(frozen=True)
class ReferencePath:
    """A clip on one character, per frame (read-only arrays): ``q`` ``(T, 67)`` qpos with
    sign-continuous quaternions, ``v`` ``(T, 51)`` qvel and ``a`` ``(T, 51)`` qacc by central
    differences, ``planted`` ``(T, 2)`` the feet (left, right) whose sole is within ``reach`` of
    the floor, ``pivoting`` ``(T, 2)`` the planted feet turning faster than ``pivot_rate``;
    ``fps`` the frame rate; ``sole`` ``(T, 2, 3)`` the centre of each sole's bottom face and
    ``sole_yaw`` ``(T, 2)`` its heading (rad, unwrapped over time) in the world, ``corners``
    ``(T, 2, 4, 3)`` its corners (world; heights above the floor) ``sole_up`` ``(T, 2, 3)`` its normal (``None``
    when built by hand: :func:`with_soles` adds these), ``com`` ``(T, 3)`` the centre of mass."""

    q: F64
    v: F64
    a: F64
    planted: NDArray[np.bool_]
    pivoting: NDArray[np.bool_]
    fps: float
    sole: F64 | None = None
    sole_yaw: F64 | None = None
    corners: F64 | None = None
    com: F64 | None = None
    sole_up: F64 | None = None

    @property
    def num_frames(self) -> int:
        return int(self.q.shape[0])

    def clock(self, start: float = 0.0) -> ClipClock:
        return ClipClock(self.fps, self.num_frames, start)

    def sample(self, x: float, coast: float = 0.0) -> tuple[F64, F64, F64, NDArray[np.bool_]]:
        """``q``, ``v``, ``a`` interpolated linearly at fractional frame ``x`` (clamped to
        the path; quaternions renormalised) and ``planted`` at the nearest frame. ``coast``
        seconds past a held frame: the pose is held but the root keeps its linear velocity
        (a held pose of a walking body moves on with it); joints and root turn no more."""
        x = min(max(x, 0.0), self.num_frames - 1.0)
        i0 = int(x)
        i1 = min(i0 + 1, self.num_frames - 1)
        w = x - i0
        q = (1 - w) * self.q[i0] + w * self.q[i1]
        quats = q[3:].reshape(NJ + 1, 4)
        quats /= np.linalg.norm(quats, axis=1, keepdims=True)
        v = (1 - w) * self.v[i0] + w * self.v[i1]
        acc = (1 - w) * self.a[i0] + w * self.a[i1]
        if coast > 0:
            q[:3] += coast * v[:3]
            v[3:] = 0.0
            acc[:] = 0.0
        return q, v, acc, self.planted[round(x)]

    def sole_at(self, x: float) -> tuple[F64, F64]:
        """The soles' centres ``(2, 3)`` and headings ``(2,)`` at fractional frame ``x``
        (linear; clamped to the path)."""
        if self.sole is None or self.sole_yaw is None:
            raise ConfigError("this path has no sole tracks (build it with reference_path)")
        x = min(max(x, 0.0), self.num_frames - 1.0)
        i0 = int(x)
        i1 = min(i0 + 1, self.num_frames - 1)
        w = x - i0
        return (
            (1 - w) * self.sole[i0] + w * self.sole[i1],
            (1 - w) * self.sole_yaw[i0] + w * self.sole_yaw[i1],
        )


def reference_path(
    world: World,
    character: int,
    source: Motion | F64,
    *,
    fps: float | None = None,
    reach: float = 0.05,
    pivot_rate: float | None = 2.0,
    slide_speed: float | None = None,
    centre_speed: float | None = None,
) -> ReferencePath:
    """``source`` on ``world``'s ``character`` as a :class:`ReferencePath`: a Motion on the
    character's skeleton, or a ``(T, 67)`` qpos path sampled at ``fps``. Foot stance is
    measured on the character's own sole boxes (``pivot_rate`` rad/s; ``None``: no pivots); a
    foot whose lowest corner moves faster than ``slide_speed`` (m/s) is not planted (``None``:
    any foot within ``reach``, the short-window and response trackers' stance); one whose sole
    centre moves horizontally faster than ``centre_speed`` (m/s) is not planted either
    (``None``: off; the lowest corner is slow while a swinging foot rolls over it)."""
    for name, value in (
        ("reach", reach),
        ("pivot_rate", 0.0 if pivot_rate is None else pivot_rate),
        ("slide_speed", 0.0 if slide_speed is None else slide_speed),
        ("centre_speed", 0.0 if centre_speed is None else centre_speed),
    ):
        if not (np.isfinite(value) and value >= 0):
            raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
    wc = world.characters[character]
    if isinstance(source, Motion):
        q = wc.character.qpos_from_motion(source)
        rate = float(source.fps)
    else:
        q = np.array(source, dtype=np.float64)
        if q.ndim != 2 or q.shape[1] != NQ or not np.isfinite(q).all():
            raise ConfigError(f"a qpos path must be (T, {NQ}) finite numbers, got {q.shape}")
        if fps is None or not (np.isfinite(fps) and fps > 0):
            raise ConfigError(f"a qpos path needs its frame rate fps > 0, got {fps!r}")
        rate = float(fps)
    n = q.shape[0]
    q[:, 3:] = quat_continuous(q[:, 3:].reshape(n, NJ + 1, 4)).reshape(n, -1)
    v = qvel_from_qpos(q, rate)
    a = np.gradient(v, 1.0 / rate, axis=0) if n > 2 else np.zeros_like(v)
    corner_z, centre, yaw, com, up = _sole_tracks(world, character, q)
    low = np.argmin(corner_z[..., 2], axis=2)[..., None, None]  # (T, 2, 1, 1)
    planted = np.take_along_axis(corner_z[..., 2], low[..., 0], axis=2)[..., 0] < reach
    rate_yaw = np.zeros((n, 2))
    slide = np.zeros((n, 2))
    if n > 1:
        rate_yaw = np.abs(np.gradient(yaw, 1.0 / rate, axis=0))
        vel = np.gradient(corner_z[..., :2], 1.0 / rate, axis=0)
        slide = np.linalg.norm(np.take_along_axis(vel, low, axis=2)[:, :, 0], axis=-1)
    turning = rate_yaw > (np.inf if pivot_rate is None else float(pivot_rate))
    if slide_speed is not None:
        # a foot skimming the floor (a low step, a slide in the capture) is not a support
        planted &= (slide < slide_speed) | turning
    if centre_speed is not None:
        # a foot rolling over its lowest corner mid-swing: that corner is slow, the sole not
        planted &= sole_speed(centre, rate) < centre_speed
    pivoting = planted & turning
    arrays = (q, v, a, planted, pivoting, centre, yaw, corner_z, com, up)
    for arr in arrays:
        arr.flags.writeable = False
    return ReferencePath(q, v, a, planted, pivoting, rate, centre, yaw, corner_z, com, up)


def sole_speed(sole: F64, fps: float) -> F64:
    """Each sole centre's horizontal speed ``(T, 2)`` (m/s, central differences) from its
    track ``sole`` ``(T, 2, 3)`` at ``fps``; zero for a single frame."""
    if sole.shape[0] < 2:
        return np.zeros(sole.shape[:2])
    return np.linalg.norm(np.gradient(sole[..., :2], 1.0 / fps, axis=0), axis=-1)


def _sole_tracks(world: World, character: int, q: F64) -> tuple[F64, F64, F64, F64, F64]:
    """Per qpos row of ``character``: each sole's corners ``(T, 2, 4, 3)`` (heights above the
    floor), the centre of its bottom face ``(T, 2, 3)`` and its heading ``(T, 2)``
    (unwrapped), the centre of mass ``(T, 3)`` and each sole's normal ``(T, 2, 3)``."""
    m = world.model
    wc = world.characters[character]
    _, sole_ids, corners = foot_soles(world, character, "reference_path")
    floor_z = float(world.data.geom_xpos[m.geom("floor").id, 2])
    half = m.geom_size[sole_ids, 2][:, None]
    d = mujoco.MjData(m)
    n = q.shape[0]
    low = np.empty((n, 2, 4, 3))
    centre = np.empty((n, 2, 3))
    yaw = np.empty((n, 2))
    com = np.empty((n, 3))
    up = np.empty((n, 2, 3))
    bodies = wc.body_ids
    mass = m.body_mass[bodies]
    for i in range(n):  # once per clip, not in the step loop
        d.qpos[wc.qpos_slice] = q[i]
        mujoco.mj_kinematics(m, d)
        low[i] = sole_corners_world(d, sole_ids, corners)
        rot = d.geom_xmat[sole_ids].reshape(2, 3, 3)
        centre[i] = d.geom_xpos[sole_ids] - rot[:, :, 2] * half
        yaw[i] = np.arctan2(rot[:, 1, 0], rot[:, 0, 0])
        com[i] = mass @ d.xipos[bodies] / mass.sum()
        up[i] = rot[:, :, 2]
    low[..., 2] -= floor_z
    return low, centre, np.unwrap(yaw, axis=0), com, up


def with_soles(world: World, character: int, path: ReferencePath) -> ReferencePath:
    """``path`` with its sole tracks (:attr:`ReferencePath.sole`) on ``character``."""
    if not any(a is None for a in (path.sole, path.sole_yaw, path.corners, path.com,
                                   path.sole_up)):  # fmt: skip
        return path
    corner_z, centre, yaw, com, up = _sole_tracks(world, character, path.q)
    for arr in (corner_z, centre, yaw, com, up):
        arr.flags.writeable = False
    return replace(path, sole=centre, sole_yaw=yaw, corners=corner_z, com=com, sole_up=up)


def as_path(world: World, character: int, reference: Motion | ReferencePath) -> ReferencePath:
    """``reference`` as a path on ``character``: a ReferencePath as it is, a Motion converted."""
    if isinstance(reference, ReferencePath):
        return reference
    return reference_path(world, character, reference)
