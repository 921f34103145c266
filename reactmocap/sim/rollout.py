"""Rollouts: run a World for a duration with a controller callback, record body transforms at
an output rate as Motions on the original skeletons, detect instability; plus the two
high-level operations behind the CLI, :func:`track_clip` and :func:`push_clip`.

Determinism: MuJoCo is deterministic on one thread and nothing here draws random numbers or
depends on wall-clock time, so the same inputs give bit-identical outputs.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.balance import StanceBalance
from reactmocap.sim.character import BALL_JOINTS, SIM_BODIES, SIM_PARENTS, build_character
from reactmocap.sim.impacts import ContactReport, Impact, ImpactSchedule, _t3, contact_report
from reactmocap.sim.pd import PDServo, critical_kv
from reactmocap.sim.predictive import PredictiveTracker
from reactmocap.sim.wholebody import WholeBodyTracker, hemisphere_continuous
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "TRACKING_CONTROLLERS",
    "WHOLEBODY_SERVO_KV",
    "MotionTracker",
    "RolloutResult",
    "RootAssist",
    "TrackReport",
    "TrackingController",
    "push_clip",
    "rollout",
    "track_clip",
    "tracking_controller",
]

F64 = NDArray[np.float64]
Controller = Callable[[World, float], None]
NJ = len(BALL_JOINTS)


@dataclass
class RolloutResult:
    """What a rollout recorded. ``times`` are seconds from the rollout's start; ``body_pos``
    ``(C, T, 16, 3)`` and ``body_quat`` ``(C, T, 16, 4)`` world transforms per character;
    ``motions`` the same as Motions on each character's original skeleton."""

    times: F64
    body_pos: F64
    body_quat: F64
    motions: list[Motion]
    steps: int
    wall_s: float
    contacts: list[ContactReport] = field(default_factory=list)
    final_state: F64 | None = None


class MotionTracker:
    """Controller that makes a servo follow a Motion: at rollout time ``t`` the targets are the
    motion's ball-joint rotations at ``start + t`` (normalised linear blend of the two
    neighbouring frames, hemisphere-aligned: within 0.2% of slerp at 30 fps)."""

    def __init__(self, servo: PDServo, character: int, motion: Motion, start: float = 0.0) -> None:
        self.servo = servo
        self.character = character
        self.motion = motion
        self.start = float(start)
        ch = servo.world.characters[character].character
        q = ch.qpos_from_motion(motion)[:, 7:].reshape(motion.num_frames, NJ, 4)
        # hemisphere continuity in time so the blend takes the short way
        self.quats = hemisphere_continuous(q)
        self._buf = np.empty((NJ, 4))

    def targets_at(self, t: float) -> F64:
        x = min(max((self.start + t) * self.motion.fps, 0.0), self.motion.num_frames - 1.0)
        i0 = int(x)
        i1 = min(i0 + 1, self.motion.num_frames - 1)
        a = x - i0
        np.multiply(self.quats[i0], 1.0 - a, out=self._buf)
        self._buf += a * self.quats[i1]
        return self._buf

    def __call__(self, world: World, t: float) -> None:
        self.servo.set_targets(self.character, self.targets_at(t))


class RootAssist:
    """Optional, NON-PHYSICAL root stabilisation ("hand of god"): an external PD wrench on the
    pelvis toward the mocap pelvis, ``F = M (kp (p_d - p) - kv (v - v_d))``,
    ``tau = I_c (kp e - kv w)``
    with ``M`` the character's mass and ``I_c`` its composite inertia about the pelvis.
    Off unless asked for; reports must say when it was used."""

    def __init__(
        self,
        world: World,
        character: int,
        motion: Motion,
        start: float = 0.0,
        kp: float = 100.0,
        kv: float | None = None,
    ) -> None:
        wc = world.characters[character]
        self.world = world
        self.bid = int(wc.body_ids[0])
        self.start = float(start)
        self.motion = motion
        q = wc.character.qpos_from_motion(motion)
        self.pos = q[:, :3]
        self.rot = q[:, 3:7]
        # velocity feed-forward: without it a PD lags a walking pelvis by kv v / kp
        self.vel = (
            np.gradient(self.pos, 1.0 / motion.fps, axis=0)
            if motion.num_frames > 1
            else np.zeros_like(self.pos)
        )
        self.kp = float(kp)
        self.kv = 2.0 * np.sqrt(kp) if kv is None else float(kv)
        self.mass = float(world.model.body_subtreemass[self.bid])
        self.dof = wc.dof_adr

    def __call__(self, world: World, t: float) -> None:
        d = world.data
        x = min(max((self.start + t) * self.motion.fps, 0.0), self.motion.num_frames - 1.0)
        i = round(x)
        p_d, q_d = self.pos[i], self.rot[i]
        v = d.qvel[self.dof : self.dof + 3]
        w_local = d.qvel[self.dof + 3 : self.dof + 6]
        q = d.xquat[self.bid]
        e = quat_log(quat_mul(quat_conj(q), q_d))  # body frame
        inertia = 0.1 * self.mass  # ~ composite inertia about the pelvis (kg m^2), scale only
        tau_local = inertia * (self.kp * e - self.kv * w_local)
        rot = d.xmat[self.bid].reshape(3, 3)
        d.xfrc_applied[self.bid, :3] = self.mass * (
            self.kp * (p_d - d.xpos[self.bid]) - self.kv * (v - self.vel[i])
        )
        d.xfrc_applied[self.bid, 3:] = rot @ tau_local


def _record(world: World, pos: F64, quat: F64, k: int) -> None:
    d = world.data
    for c, wc in enumerate(world.characters):
        pos[c, k] = d.xpos[wc.body_ids]
        quat[c, k] = d.xquat[wc.body_ids]


def _impact_steps(impacts: Sequence[Impact], dt: float) -> list[int]:
    """Sorted steps at which ImpactSchedule.apply changes xfrc_applied: the ends of each window
    (a force at the centre of mass, or ``point=None``, is constant within it), and every step
    of a window whose point moves with the body (its torque arm turns with the body)."""
    steps: set[int] = set()
    for imp in impacts:
        k0, n = imp.steps(dt)
        steps.update((k0, k0 + n) if imp.point is None else range(k0, k0 + n + 1))
    return sorted(steps)


def _check(world: World, t: float, ke_limit: F64) -> None:
    d, m = world.model, world.data
    del d
    qv = m.qvel
    if not (np.all(np.isfinite(qv)) and np.all(np.isfinite(m.qpos))):
        bad = "unknown"
        for wc in world.characters:
            xp = m.xpos[wc.body_ids]
            v = qv[wc.qvel_slice]
            if not np.all(np.isfinite(xp)) or not np.all(np.isfinite(v)):
                rows = np.flatnonzero(~np.all(np.isfinite(m.cvel[wc.body_ids]), axis=1))
                body = SIM_BODIES[int(rows[0])] if rows.size else "pelvis"
                bad = f"{wc.prefix}{body}"
                break
        raise SimulationError(f"simulation went unstable at t = {t:.4f} s: NaN/inf at body {bad}")
    for wc in world.characters:
        ke = world.kinetic_energy(wc.index)
        if ke > ke_limit[wc.index]:
            speeds = np.linalg.norm(m.cvel[wc.body_ids, 3:], axis=1)
            body = SIM_BODIES[int(np.argmax(speeds))]
            raise SimulationError(
                f"simulation went unstable at t = {t:.4f} s: kinetic energy of character "
                f"{wc.index} is {ke:.0f} J (limit {ke_limit[wc.index]:.0f} J); fastest body "
                f"{wc.prefix}{body} at {speeds.max():.1f} m/s"
            )


def rollout(
    world: World,
    duration: float,
    *,
    servo: PDServo | None = None,
    controllers: Sequence[Controller] = (),
    control_every: int = 4,
    impacts: Sequence[Impact] = (),
    record_fps: float = 60.0,
    references: Sequence[Motion | None] | None = None,
    reference_start: float = 0.0,
    record_contacts: bool = False,
    energy_limit_per_kg: float = 100.0,
    check_every: int = 20,
) -> RolloutResult:
    """Run ``duration`` seconds from the world's current state.

    Each step: controllers (every ``control_every`` steps, called as ``f(world, t)`` with
    ``t`` seconds since the rollout started), impacts into ``xfrc_applied``, the servo, the
    physics step. Body transforms are recorded at ``record_fps`` (frame 0 = the initial state).
    ``references[c]`` supplies character c's non-simulated joints, sampled at
    ``reference_start + t``. Raises SimulationError on NaN/inf or kinetic energy above
    ``energy_limit_per_kg`` J/kg (100 J/kg = the whole body at 14 m/s).

    MuJoCo steps in chunks (``mj_step(nstep=k)``, through :meth:`PDServo.step` with a servo)
    between the steps where something happens: control ticks, impact windows (every step of
    a window whose force point moves with the body, its ends otherwise), records and energy
    checks, each at the same step as one step at a time.
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ConfigError(f"duration must be > 0 s, got {duration!r}")
    if not (np.isfinite(record_fps) and record_fps > 0):
        raise ConfigError(f"record_fps must be > 0, got {record_fps!r}")
    if control_every < 1 or check_every < 1:
        raise ConfigError("control_every and check_every must be >= 1")
    m, d = world.model, world.data
    dt = world.timestep
    nsteps = round(duration / dt)
    every = max(1, round(1.0 / (record_fps * dt)))
    nrec = nsteps // every + 1
    nchar = len(world.characters)
    pos = np.empty((nchar, nrec, len(SIM_BODIES), 3))
    quat = np.empty((nchar, nrec, len(SIM_BODIES), 4))
    schedule = ImpactSchedule(world, impacts) if impacts else None
    impact_steps = _impact_steps(impacts, dt)
    ke_limit = np.array(
        [energy_limit_per_kg * float(m.body_subtreemass[wc.body_ids[0]]) for wc in world.characters]
    )
    contacts: list[ContactReport] = []
    t0 = float(d.time)
    _record(world, pos, quat, 0)
    if record_contacts:
        contacts.append(contact_report(world))
    wall = _time.perf_counter()
    rec = 1
    tick = control_every if controllers else nsteps + 1  # no controllers: no ticks
    ie = 0
    k = 0
    while k < nsteps:
        if controllers and k % control_every == 0:
            t = float(d.time) - t0
            for f in controllers:
                f(world, t)
        if schedule is not None:
            schedule.apply(k)
        # next step where something happens
        nxt = min(nsteps, (k // every + 1) * every, (k // check_every + 1) * check_every)
        nxt = min(nxt, (k // tick + 1) * tick)
        while ie < len(impact_steps) and impact_steps[ie] <= k:
            ie += 1
        if ie < len(impact_steps):
            nxt = min(nxt, impact_steps[ie])
        if servo is not None:
            servo.step(nxt - k)
        else:
            mujoco.mj_step(m, d, nstep=nxt - k)
        k = nxt
        if k % every == 0 and rec < nrec:
            _record(world, pos, quat, rec)
            rec += 1
            if record_contacts:
                contacts.append(contact_report(world))
        if k % check_every == 0:
            _check(world, float(d.time) - t0, ke_limit)
    _check(world, float(d.time) - t0, ke_limit)
    if schedule is not None:
        schedule.clear()
    wall = _time.perf_counter() - wall
    times = (np.arange(nrec) * (every * dt)).astype(np.float64)
    fps = 1.0 / (every * dt)
    refs = list(references) if references is not None else [None] * nchar
    motions = [
        wc.character.motion_from_body_transforms(
            pos[c],
            quat[c],
            fps,
            refs[c],
            times + reference_start if refs[c] is not None else None,
            name=f"sim_{wc.prefix.rstrip('/')}",
        )
        for c, wc in enumerate(world.characters)
    ]
    return RolloutResult(times, pos, quat, motions, nsteps, wall, contacts, world.get_state())


# ---------------------------------------------------------------------------------- tracking
@dataclass(frozen=True)
class TrackReport:
    """Summary of a tracking run (what ``reactmocap track`` writes as JSON)."""

    clip: str
    start: float
    seconds: float
    fell: bool
    fall_time: float | None
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
        from dataclasses import asdict

        return asdict(self)


def _kv(kp: float, kv: float | None) -> float:
    return critical_kv(kp) if kv is None else float(kv)


def _errors(world: World, result: RolloutResult, motion: Motion, start: float) -> dict[str, object]:
    """Compare the simulated character 0 with the mocap at the recorded times."""
    ch = world.characters[0].character
    times = result.times + start
    ref = motion.sample(times)
    q_ref = ch.qpos_from_motion(ref)
    ref_pos, ref_rot = ch.body_transforms_from_qpos(q_ref)
    sim_pos, sim_rot = result.body_pos[0], result.body_quat[0]
    # joint error: angle between simulated and mocap local rotations of the 15 ball joints
    par = SIM_PARENTS[1:]

    def local(rot: F64) -> F64:
        return quat_mul(quat_conj(rot[:, par]), rot[:, 1:])

    rel = quat_mul(quat_conj(local(sim_rot)), local(ref_rot))
    jerr = np.linalg.norm(quat_log(rel), axis=-1)
    root_err = np.linalg.norm(sim_pos[:, 0] - ref_pos[:, 0], axis=-1)
    ang = np.linalg.norm(quat_log(quat_mul(quat_conj(sim_rot[:, 0]), ref_rot[:, 0])), axis=-1)
    z0 = sim_pos[0, 0, 2]
    fallen = np.flatnonzero(sim_pos[:, 0, 2] < 0.5 * z0)
    return {
        "fell": bool(fallen.size),
        "fall_time": float(result.times[fallen[0]]) if fallen.size else None,
        "mean_joint_error_rad": float(jerr.mean()),
        "root_error_m": float(root_err.mean()),
        "max_root_error_m": float(root_err.max()),
        "root_angle_error_rad": float(ang.mean()),
        "root_err_series": root_err,
        "root_ang_series": ang,
        "upright_series": sim_pos[:, 0, 2] >= 0.5 * z0,
    }


@dataclass(frozen=True)
class TrackingController:
    """A registered way to track a clip: ``build(world, motion, start, kp, kv, every)`` returns
    the servo and the controllers for character 0; ``kp``/``kv`` ``None`` mean the defaults,
    ``every`` is the rollout's steps between control ticks."""

    description: str
    default_kp: float
    control_every: int
    physical: bool
    build: Callable[
        [World, Motion, float, float, float | None, int], tuple[PDServo, list[Controller]]
    ]


def _build_pd(
    world: World, motion: Motion, start: float, kp: float, kv: float | None, every: int
) -> tuple[PDServo, list[Controller]]:
    servo = PDServo(world, kp=kp, kv=kv)
    return servo, [MotionTracker(servo, 0, motion, start=start)]


def _build_balance(
    world: World, motion: Motion, start: float, kp: float, kv: float | None, every: int
) -> tuple[PDServo, list[Controller]]:
    servo, ctrls = _build_pd(world, motion, start, kp, kv, every)
    return servo, [*ctrls, StanceBalance(servo, 0, motion, start=start)]


#: damping of the servo under the whole-body tracker (1/s, inertia-scaled): its stiffness is
#: off because, held between ticks against a moving target, it fought the plan
WHOLEBODY_SERVO_KV = 20.0


def _wholebody(
    world: World, motion: Motion, start: float, kp: float, kv: float | None
) -> tuple[PDServo, WholeBodyTracker]:
    servo = PDServo(world, kp=0.0, kv=WHOLEBODY_SERVO_KV)
    return servo, WholeBodyTracker(servo, 0, motion, start=start, kp_joint=kp, kv_joint=kv)


def _build_wholebody(
    world: World, motion: Motion, start: float, kp: float, kv: float | None, every: int
) -> tuple[PDServo, list[Controller]]:
    servo, wb = _wholebody(world, motion, start, kp, kv)
    return servo, [wb]


#: control ticks of the whole-body trackers (steps): every 2 ms at dt = 0.0005
WHOLEBODY_EVERY = 4


def _build_predictive(
    world: World, motion: Motion, start: float, kp: float, kv: float | None, every: int
) -> tuple[PDServo, list[Controller]]:
    servo, wb = _wholebody(world, motion, start, kp, kv)
    # its predictions tick as the rollout will
    return servo, [PredictiveTracker(wb, control_every=every)]


TRACKING_CONTROLLERS: dict[str, TrackingController] = {
    "wholebody": TrackingController(
        "inverse dynamics with optimised ground forces (pelvis tracked through the feet)",
        default_kp=1000.0, control_every=WHOLEBODY_EVERY, physical=True, build=_build_wholebody,
    ),
    "predictive": TrackingController(
        "the whole-body tracker steered by predictive sampling (looks 0.5 s ahead; ~40x slower)",
        default_kp=1000.0, control_every=WHOLEBODY_EVERY, physical=True,
        build=_build_predictive,
    ),
    "balance": TrackingController(
        "inertia-scaled PD servo plus stance-leg balance (StanceBalance)",
        default_kp=4000.0, control_every=10, physical=True, build=_build_balance,
    ),
    "pd": TrackingController(
        "inertia-scaled PD servo only (the paper's tracker; no balance)",
        default_kp=4000.0, control_every=10, physical=True, build=_build_pd,
    ),
}  # fmt: skip


def tracking_controller(name: str) -> TrackingController:
    """The registered tracking controller ``name``; an unknown name lists the valid ones."""
    try:
        return TRACKING_CONTROLLERS[name]
    except KeyError:
        raise UnknownKeyError(
            f"unknown tracking controller {name!r}; valid keys: {sorted(TRACKING_CONTROLLERS)}"
        ) from None


def track_clip(
    motion: Motion,
    *,
    start: float = 0.0,
    seconds: float | None = None,
    kp: float | None = None,
    kv: float | None = None,
    friction: float = 1.0,
    impacts: Sequence[Impact] = (),
    record_fps: float = 60.0,
    root_assist: float = 0.0,
    controller: str = "wholebody",
    control_every: int | None = None,
    total_mass: float = 75.0,
    config: WorldConfig | None = None,
    character_kwargs: dict[str, object] | None = None,
    on_tick: Callable[[float, float], None] | None = None,
) -> tuple[Motion, TrackReport, RolloutResult]:
    """Track ``motion`` from ``start`` for ``seconds`` (default: to its end) with the PD servo
    on a simulated character built from the clip (reference = the start frame), optionally
    with impacts (their ``start`` is relative to ``start``). Returns the simulated Motion on
    the clip's skeleton (non-simulated joints from the clip), the report and the raw result.
    ``controller`` names an entry of :data:`TRACKING_CONTROLLERS`: ``"wholebody"`` (default,
    :class:`~reactmocap.sim.wholebody.WholeBodyTracker`), ``"balance"`` (PD servo plus
    :class:`~reactmocap.sim.balance.StanceBalance`) or ``"pd"`` (the servo alone); ``kp``/``kv``
    are its joint gains (default: the controller's). ``root_assist > 0`` adds the
    non-physical :class:`RootAssist` with that kp (only with ``"pd"``). Targets and
    feed-forward update every ``control_every`` steps (default: the controller's; the servo's
    own stiffness and damping act every step inside MuJoCo). ``on_tick(t, seconds)`` is
    called at every control tick (a progress bar)."""
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
    spec = tracking_controller(controller)
    if root_assist > 0 and controller != "pd":
        raise ConfigError(
            f"root_assist cannot be combined with the {controller!r} controller: its ground "
            "forces assume nothing else holds the body up (they went unstable together); "
            "use controller='pd' with root_assist"
        )
    kp = spec.default_kp if kp is None else float(kp)
    every = spec.control_every if control_every is None else int(control_every)
    if every < 1:
        raise ConfigError(f"control_every must be >= 1, got {control_every!r}")
    frame = round(start * motion.fps)
    character = build_character(
        motion,
        total_mass=total_mass,
        frame=frame,
        **(character_kwargs or {}),  # type: ignore[arg-type]
    )  # type: ignore[arg-type]
    character.check_fk(motion, frame)
    cfg = config or WorldConfig(friction=friction)
    world = World(character, cfg)
    world.set_from_motion(0, motion, frame)
    servo, ctrls = spec.build(world, motion, float(start), kp, kv, every)
    if root_assist > 0:
        ctrls.append(RootAssist(world, 0, motion, start=start, kp=root_assist))
    for f in ctrls:
        f(world, 0.0)
    if on_tick is not None:
        tick = on_tick
        ctrls.append(lambda _w, t: tick(t, seconds))
    result = rollout(
        world,
        seconds,
        servo=servo,
        controllers=ctrls,
        # the assist's explicit whole-body PD acts on the light pelvis: held for several steps
        # it goes unstable, so it runs every step
        control_every=1 if root_assist > 0 else every,
        impacts=impacts,
        record_fps=record_fps,
        references=[motion],
        reference_start=start,
    )
    err = _errors(world, result, motion, start)
    report = TrackReport(
        clip=motion.name,
        start=float(start),
        seconds=float(seconds),
        fell=bool(err["fell"]),
        fall_time=err["fall_time"],  # type: ignore[arg-type]
        mean_joint_error_rad=float(err["mean_joint_error_rad"]),  # type: ignore[arg-type]
        root_error_m=float(err["root_error_m"]),  # type: ignore[arg-type]
        max_root_error_m=float(err["max_root_error_m"]),  # type: ignore[arg-type]
        root_angle_error_rad=float(err["root_angle_error_rad"]),  # type: ignore[arg-type]
        wall_s=float(result.wall_s),
        realtime_factor=float(seconds / result.wall_s) if result.wall_s > 0 else float("inf"),
        kp=kp,
        kv=_kv(kp, kv),
        friction=cfg.friction,
        timestep=cfg.timestep,
        root_assist=float(root_assist),
        controller=controller,
        impacts=len(impacts),
    )
    name = f"{motion.name}_tracked" if motion.name else "tracked"
    return result.motions[0].replace(name=name), report, result


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
    **kwargs: object,
) -> tuple[Motion, TrackReport, RolloutResult]:
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
        force=_t3(force),
        point=None if point is None else _t3(point),
        start=time - s0,
        duration=duration,
    )
    return track_clip(motion, start=s0, seconds=seconds, impacts=[impact], **kwargs)  # type: ignore[arg-type]
