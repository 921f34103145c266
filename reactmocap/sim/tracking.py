"""Physical tracking of a clip (``reactmocap track``) and pushes while tracking
(``reactmocap push``): a character built from the clip, a registered controller, the engine,
and a report of how closely the simulation followed the clip."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.metrics import FALL_FRACTION
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.character import SIM_PARENTS, build_character
from reactmocap.sim.controllers.registry import (
    WHOLE_CLIP,
    build,
    controller_spec,
)
from reactmocap.sim.controllers.stepping import outside_distance
from reactmocap.sim.feet import foot_soles, sole_corners_world
from reactmocap.sim.impacts import Impact
from reactmocap.sim.reference import reference_path
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "EndState",
    "TrackErrors",
    "TrackReport",
    "TrackResult",
    "WalkState",
    "end_state",
    "push_clip",
    "recovery",
    "track_clip",
    "tracking_errors",
    "walk_state",
]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class TrackReport:
    """Summary of a tracking run (what ``reactmocap track`` writes as JSON)."""

    clip: str
    start: float
    seconds: float
    #: ``"ok"``, ``"fell"`` (the pelvis below half its start height: the run ends there) or
    #: ``"unstable"`` (the simulation diverged: it ends at the last stable frame)
    status: str
    reason: str | None
    fell: bool
    fell_at_s: float | None
    mean_joint_error_rad: float
    root_error_m: float
    max_root_error_m: float
    root_angle_error_rad: float
    wall_s: float
    realtime_factor: float
    kp: float
    kv: float
    friction: float
    timestep: float
    root_assist: float
    controller: str
    impacts: int

    def to_dict(self) -> dict[str, object]:
        return asdict(self)


@dataclass(frozen=True)
class TrackErrors:
    """How a simulated character 0 followed the clip, per recorded frame: ``root`` ``(T,)``
    pelvis position error (m), ``angle`` ``(T,)`` pelvis orientation error (rad), ``joint``
    ``(T, 15)`` ball-joint rotation errors (rad), ``upright`` ``(T,)`` pelvis above
    :data:`~reactmocap.metrics.FALL_FRACTION` of its start height; ``times`` ``(T,)``."""

    times: F64
    root: F64
    angle: F64
    joint: F64
    upright: NDArray[np.bool_]

    @property
    def fell_at_s(self) -> float | None:
        fallen = np.flatnonzero(~self.upright)
        return float(self.times[fallen[0]]) if fallen.size else None


@dataclass(frozen=True)
class TrackResult:
    """A tracking run: the simulated Motion on the clip's skeleton (joints that are not
    simulated come from the clip), its report, errors and the raw rollout."""

    motion: Motion
    report: TrackReport
    errors: TrackErrors
    rollout: RolloutResult


def tracking_errors(result: RolloutResult, motion: Motion, start: float) -> TrackErrors:
    """Compare the simulated character 0 of ``result`` with ``motion`` (clip time ``start`` at
    rollout time 0) at the recorded frames."""
    ch = result.world.characters[0].character
    times, _ = result.frames()
    ref_pos, ref_rot = ch.body_transforms_from_qpos(
        ch.qpos_from_motion(motion.sample(times + start))
    )
    sim_pos, sim_rot = result.body_transforms(0)
    par = SIM_PARENTS[1:]

    def local(rot: F64) -> F64:
        return quat_mul(quat_conj(rot[:, par]), rot[:, 1:])

    joint = np.linalg.norm(quat_log(quat_mul(quat_conj(local(sim_rot)), local(ref_rot))), axis=-1)
    root = np.linalg.norm(sim_pos[:, 0] - ref_pos[:, 0], axis=-1)
    angle = np.linalg.norm(quat_log(quat_mul(quat_conj(sim_rot[:, 0]), ref_rot[:, 0])), axis=-1)
    upright = sim_pos[:, 0, 2] >= FALL_FRACTION * sim_pos[0, 0, 2]
    return TrackErrors(times, root, angle, joint, upright)


def track_clip(
    motion: Motion,
    *,
    start: float = 0.0,
    seconds: float | None = None,
    controller: str = "wholebody",
    params: dict[str, Any] | None = None,
    kp: float | None = None,
    kv: float | None = None,
    friction: float = 1.0,
    impacts: Sequence[Impact] = (),
    record_fps: float = 60.0,
    root_assist: float = 0.0,
    total_mass: float = 75.0,
    config: WorldConfig | None = None,
    character_kwargs: dict[str, Any] | None = None,
    parts: BodyPartMap | None = None,
    on_tick: Callable[[float, float], None] | None = None,
    stop_on_fall: bool = True,
) -> TrackResult:
    """Track ``motion`` from ``start`` for ``seconds`` (default: to its end) with the registered
    ``controller`` (``params`` over its defaults; ``kp``/``kv`` are shortcuts for those) on a
    character built from the clip, optionally with impacts (their ``start`` relative to
    ``start``). ``root_assist > 0`` adds the NON-PHYSICAL root assist with that kp (only with
    ``"pd"``). ``parts``: the clip's body parts (default: mapped by name). ``on_tick(t,
    seconds)`` reports progress. The whole-body tracker gets the registry's
    :data:`~reactmocap.sim.controllers.registry.WHOLE_CLIP` options under ``params`` (their
    trunk rows give after a push while the clip stands: ``trunk_give``). A failure
    is a result, not an exception: a fall ends the run
    there (``stop_on_fall``), a diverging simulation at its last stable frame, and the report's
    ``status`` says which."""
    if not (np.isfinite(start) and 0 <= start <= motion.duration):
        raise ConfigError(f"start {start!r} s is outside the clip (0..{motion.duration:.3f} s)")
    remaining = motion.duration - start
    seconds = remaining if seconds is None else float(seconds)
    if not (np.isfinite(seconds) and seconds > 0):
        raise ConfigError(f"seconds must be > 0, got {seconds!r}")
    if seconds > remaining + 1e-9:
        raise ConfigError(
            f"cannot track {seconds} s from {start} s: the clip {motion.name!r} lasts "
            f"{motion.duration:.3f} s"
        )
    if not (np.isfinite(root_assist) and root_assist >= 0):  # a negative gain was silently off
        raise ConfigError(f"root_assist must be a finite gain >= 0 (0: off), got {root_assist!r}")
    spec = controller_spec(controller)
    if root_assist > 0 and controller != "pd":
        raise ConfigError(
            f"root_assist cannot be combined with the {controller!r} controller: its ground "
            "forces assume nothing else holds the body up (they went unstable together); "
            "use controller='pd' with root_assist"
        )
    given = {**(params or {}), **{k: v for k, v in (("kp", kp), ("kv", kv)) if v is not None}}
    if set(WHOLE_CLIP) <= set(spec.options):  # a whole clip, not a short window
        given = {**WHOLE_CLIP, **given}
    resolved = spec.params(given)
    frame = round(start * motion.fps)
    character = build_character(motion, parts, total_mass=total_mass, frame=frame,
                                **(character_kwargs or {}))  # fmt: skip
    character.check_fk(motion, frame)
    cfg = config or WorldConfig(friction=friction)
    world = World(character, cfg)
    world.set_from_motion(0, motion, frame)
    # the controller builds its path from the clip: stance detection is its own option
    ctrls = [build(controller, world, motion, given, start=start)]
    if root_assist > 0:
        path = reference_path(world, 0, motion)
        ctrls.append(build("root_assist", world, path, {"kp": root_assist}, start=start))
    pelvis = world.characters[0].qpos_adr + 2
    low = FALL_FRACTION * float(world.data.qpos[pelvis])

    def fallen(w: World, t: float) -> str | None:
        return f"fell at {t:.2f} s" if w.data.qpos[pelvis] < low else None

    result = rollout(
        world,
        seconds,
        controllers=ctrls,
        impacts=impacts,
        record_fps=record_fps,
        references=[motion],
        reference_start=start,
        on_tick=None if on_tick is None else (lambda t: on_tick(t, seconds)),
        on_unstable="stop",
        stop=fallen if stop_on_fall else None,
    )
    err = tracking_errors(result, motion, start)
    status = {"ok": "ok", "stopped": "fell", "unstable": "unstable"}[result.status]
    if status == "ok" and err.fell_at_s is not None:
        status = "fell"
    kp_used = float(resolved.get("kp", 0.0))
    kv_used = resolved.get("kv")
    report = TrackReport(
        clip=motion.name,
        start=float(start),
        seconds=float(seconds),
        status=status,
        reason=result.reason,
        fell=err.fell_at_s is not None,
        fell_at_s=err.fell_at_s,
        mean_joint_error_rad=float(err.joint.mean()),
        root_error_m=float(err.root.mean()),
        max_root_error_m=float(err.root.max()),
        root_angle_error_rad=float(err.angle.mean()),
        wall_s=float(result.wall_s),
        realtime_factor=(
            float(result.seconds / result.wall_s) if result.wall_s > 0 else float("inf")
        ),
        kp=kp_used,
        kv=critical_kv(kp_used) if kv_used is None else float(kv_used),
        friction=cfg.friction,
        timestep=cfg.timestep,
        root_assist=float(root_assist),
        controller=controller,
        impacts=len(impacts),
    )
    name = f"{motion.name}_tracked" if motion.name else "tracked"
    return TrackResult(result.motion(0, name=name), report, err, result)


def push_clip(
    motion: Motion,
    *,
    time: float,
    body: str,
    force: Sequence[float],
    duration: float = 0.1,
    point: Sequence[float] | None = None,
    start: float | None = None,
    seconds: float | None = None,
    **kwargs: Any,
) -> TrackResult:
    """Track ``motion`` and push ``body`` with ``force`` (N, world) at clip time ``time`` for
    ``duration`` s. Tracking starts at ``start`` (default: 0.5 s before the push, or 0) and
    runs ``seconds`` (default: to the clip's end)."""
    if not (np.isfinite(time) and 0 <= time <= motion.duration):
        raise ConfigError(f"push time {time!r} s is outside the clip (0..{motion.duration:.3f} s)")
    s0 = max(0.0, time - 0.5) if start is None else float(start)
    if time < s0:
        raise ConfigError(f"push time {time} s is before the tracking start {s0} s")
    impact = Impact(
        body=body,
        force=tuple(force),  # type: ignore[arg-type]
        point=None if point is None else tuple(point),  # type: ignore[arg-type]
        start=time - s0,
        duration=duration,
    )
    return track_clip(motion, start=s0, seconds=seconds, impacts=[impact], **kwargs)


@dataclass(frozen=True)
class EndState:
    """How character 0 stands when a tracking run ends (:func:`end_state`): ``upright`` (the
    run's status ``ok``), ``com_speed`` the centre of mass's horizontal speed over the last
    ``over`` s (m/s), ``capture_outside`` how far its capture point lies outside the hull of the
    sole corners within ``touch`` of the floor (m; negative inside, inf with none down),
    ``lowest_sole`` the lowest sole corner's height (m), and ``settled``: upright, slower than
    ``speed``, the capture point within ``margin`` of the support, a foot within ``air`` of
    the floor."""

    upright: bool
    com_speed: float
    capture_outside: float
    lowest_sole: float
    settled: bool

    @property
    def why(self) -> str:
        """What keeps it from being settled ("" when it is)."""
        if self.settled:
            return ""
        if not self.upright:
            return "not upright"
        return (
            f"COM {self.com_speed:.2f} m/s, capture point {self.capture_outside:+.2f} m "
            f"outside the support, lowest sole {self.lowest_sole:.2f} m up"
        )


def _com_xyz(m: mujoco.MjModel, d: mujoco.MjData, root: int, qpos: F64) -> F64:
    """Character 0's centre of mass (world) at ``qpos``."""
    d.qpos[:] = qpos
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    return d.subtree_com[root].copy()


def _capture_outside(
    m: mujoco.MjModel, com: F64, vel: F64, pts: F64, floor_z: float, touch: float
) -> float:
    """How far (m) the capture point of a linear inverted pendulum at the COM's height lies
    outside the hull of the sole corners ``pts`` within ``touch`` of the floor (inf: none)."""
    omega = np.sqrt(abs(float(m.opt.gravity[2])) / max(float(com[2]) - floor_z, 1e-3))
    down = pts[:, 2] - floor_z < touch
    if not down.any():
        return float("inf")
    return float(outside_distance(com[:2] + vel / omega, pts[down, :2]))


def end_state(
    result: TrackResult,
    *,
    speed: float = 0.3,
    margin: float = 0.05,
    touch: float = 0.02,
    air: float = 0.05,
    over: float = 0.1,
) -> EndState:
    """Whether ``result``'s body has recovered at its last recorded frame, not merely stayed
    upright: a body still stepping, still falling toward the floor or thrown into the air
    is upright but not settled (see :class:`EndState` for the criteria)."""
    ro = result.rollout
    times, q = ro.frames()
    k = int(np.searchsorted(times, times[-1] - over - 1e-9))
    if k >= times.size - 1:
        raise ConfigError(f"end_state needs more than {over} s of recorded frames")
    world = ro.world
    m = world.model
    d = mujoco.MjData(m)
    root = world.characters[0].body_ids[0]
    # two states of a finished run (d holds the last one for the soles below)
    com = np.stack([_com_xyz(m, d, root, q[row]) for row in (k, times.size - 1)])
    vel = (com[1, :2] - com[0, :2]) / (times[-1] - times[k])
    floor_z = float(d.geom_xpos[m.geom("floor").id, 2])
    _, sole, corners = foot_soles(world, 0, "end_state")
    pts = sole_corners_world(d, sole, corners).reshape(-1, 3)
    height = pts[:, 2] - floor_z
    outside = _capture_outside(m, com[1], vel, pts, floor_z, touch)
    upright = result.report.status == "ok"
    com_speed = float(np.linalg.norm(vel))
    lowest = float(height.min())
    settled = upright and com_speed < speed and outside <= margin and lowest <= air
    return EndState(upright, com_speed, float(outside), lowest, bool(settled))


@dataclass(frozen=True)
class WalkState:
    """How character 0 walks when a tracking run of a walk ends (:func:`walk_state`):
    ``upright`` (the run's status ``ok``); over the last ``over`` s, ``speed_ratio`` the centre
    of mass's mean horizontal speed over the clip's (its own centre of mass over the same clip
    times at rate 1) and ``heading_error`` the angle between the two velocities (rad);
    ``capture_outside`` how far the capture point (from the last 0.1 s) lies outside the hull
    of the sole corners within ``touch`` of the floor at the last frame (m; inf with none
    down); ``feet_down`` how many feet touched the floor in the window; ``walking``: upright,
    the speed ratio within ``1 +- speed``, the heading within ``heading``, the capture point
    within ``reach`` of the support, and both feet down at some time in the window."""

    upright: bool
    speed_ratio: float
    heading_error: float
    capture_outside: float
    feet_down: int
    walking: bool

    @property
    def why(self) -> str:
        """What keeps it from walking as the clip does ("" when it does)."""
        if self.walking:
            return ""
        if not self.upright:
            return "not upright"
        return (
            f"speed {self.speed_ratio:.2f} of the clip's, heading off by "
            f"{np.degrees(self.heading_error):.0f} deg, capture point "
            f"{self.capture_outside:+.2f} m outside the support, {self.feet_down} feet down"
        )


def walk_state(
    result: TrackResult,
    *,
    speed: float = 0.3,
    heading: float = np.radians(30.0),
    reach: float = 0.6,
    touch: float = 0.02,
    over: float = 0.6,
) -> WalkState:
    """Whether ``result``'s walk has recovered at its last recorded frame: upright and walking
    as its clip does again, not merely upright (a walk is never still, so :func:`end_state`'s
    stillness does not apply). Compares the body with its clip over the last ``over`` s (about
    a stride's half: each foot lands in it); see :class:`WalkState` for the criteria."""
    ro = result.rollout
    motion = ro.references[0] if ro.references else None
    if motion is None:
        raise ConfigError("walk_state needs the run's clip (a tracking run records it)")
    times, q = ro.frames()
    k = int(np.searchsorted(times, times[-1] - over - 1e-9))
    j = int(np.searchsorted(times, times[-1] - 0.1 - 1e-9))
    if k >= times.size - 1:
        raise ConfigError(f"walk_state needs more than {over} s of recorded frames")
    world = ro.world
    m = world.model
    d = mujoco.MjData(m)
    root = world.characters[0].body_ids[0]
    floor_z = float(world.data.geom_xpos[m.geom("floor").id, 2])
    _, sole, corners = foot_soles(world, 0, "walk_state")
    down = np.zeros(2, dtype=bool)
    for row in range(k, times.size):  # once per recorded frame of a finished run
        d.qpos[:] = q[row]
        mujoco.mj_kinematics(m, d)
        height = sole_corners_world(d, sole, corners)[..., 2] - floor_z
        down |= height.min(axis=1) < touch
    com_k, com_j = _com_xyz(m, d, root, q[k]), _com_xyz(m, d, root, q[j])
    com = _com_xyz(m, d, root, q[-1])
    vel = (com[:2] - com_k[:2]) / (times[-1] - times[k])
    # the clip's own centre of mass over the same clip times at rate 1
    path = reference_path(world, 0, motion)
    assert path.com is not None
    t0 = ro.reference_starts[0] if ro.reference_starts else 0.0
    rows = np.clip(np.round((t0 + times[[k, -1]]) * path.fps).astype(int), 0, path.num_frames - 1)
    clip_vel = (path.com[rows[1], :2] - path.com[rows[0], :2]) / (times[-1] - times[k])
    clip_speed = float(np.linalg.norm(clip_vel))
    ratio = float(np.linalg.norm(vel)) / max(clip_speed, 1e-6)
    cross = clip_vel[0] * vel[1] - clip_vel[1] * vel[0]
    angle = abs(float(np.arctan2(cross, float(clip_vel @ vel))))
    pts = sole_corners_world(d, sole, corners).reshape(-1, 3)  # d holds the last frame
    vel_end = (com[:2] - com_j[:2]) / (times[-1] - times[j])
    outside = _capture_outside(m, com, vel_end, pts, floor_z, touch)
    upright = result.report.status == "ok"
    walking = (
        upright
        and abs(ratio - 1.0) <= speed
        and angle <= heading
        and outside <= reach
        and bool(down.all())
    )
    return WalkState(upright, ratio, angle, float(outside), int(down.sum()), bool(walking))


#: a clip whose centre of mass moves faster than this (m/s) over :func:`recovery`'s span is
#: judged as a walk
WALKING_CLIP_SPEED = 0.3


def recovery(result: TrackResult, *, over: float = 0.6) -> EndState | WalkState:
    """The verdict that fits ``result``'s clip at the run's end: :func:`walk_state` where the
    clip's own centre of mass moves faster than :data:`WALKING_CLIP_SPEED` over the last
    ``over`` s of clip time, :func:`end_state` (standing still) otherwise."""
    ro = result.rollout
    times, _ = ro.frames()
    motion = ro.references[0] if ro.references else None
    if motion is None or times.size < 2:
        return end_state(result)
    path = reference_path(ro.world, 0, motion)
    assert path.com is not None
    t0 = ro.reference_starts[0] if ro.reference_starts else 0.0
    span = np.array([times[-1] - over, times[-1]]) + t0
    rows = np.clip(np.round(span * path.fps).astype(int), 0, path.num_frames - 1)
    speed = float(np.linalg.norm(path.com[rows[1], :2] - path.com[rows[0], :2])) / over
    return walk_state(result, over=over) if speed > WALKING_CLIP_SPEED else end_state(result)
