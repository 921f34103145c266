"""The simulation engine: the one stepping loop behind tracking, pushes, both passes of the
response pipeline and the athletic controllers.

Each step: the controllers that tick (every ``control_every`` steps, ``t`` seconds since the
rollout started), the impacts (:class:`~reactmocap.sim.impacts.ImpactSchedule`), the physics
step. States are recorded at exact output frame times (frame ``k`` of a rate ``fps`` is the
state after ``round(k / (fps dt))`` steps; frame 0 is the initial state), contacts between
characters are logged, and instability (NaN, runaway kinetic energy) either raises or ends the
rollout with a partial result. MuJoCo steps in chunks (``mj_step(nstep=k)``) between the steps
where something happens, each event at the same step as one step at a time. MuJoCo is
deterministic on one thread and nothing here draws random numbers: same inputs, same outputs.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError
from reactmocap.library.motion import Motion
from reactmocap.sim.character import SIM_BODIES
from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.impacts import ContactReport, Impact, ImpactSchedule, contact_report
from reactmocap.sim.world import World

__all__ = ["ContactLog", "RolloutResult", "StopCondition", "rollout"]

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
Status = Literal["ok", "unstable", "stopped"]
#: ``stop(world, t)``: a reason to end the rollout early (e.g. "fell"), or None to go on
StopCondition = Callable[[World, float], str | None]


@dataclass(frozen=True)
class ContactLog:
    """Contacts between characters while any exist, sampled at every step (the engine looks
    for them every ``period`` seconds and samples every step from the first it finds until
    they part): ``times`` ``(n,)`` seconds from the rollout's start, ``normal`` ``(n,)`` the
    summed normal force between characters (N), ``force`` ``(n, 3)`` the world force on
    character 0 from the others (N), ``depth`` ``(n,)`` the deepest interpenetration between
    characters (m), ``point`` ``(n, 3)`` the contacts' centre, weighted by normal force."""

    times: F64
    normal: F64
    force: F64
    depth: F64
    period: float
    dt: float  # seconds per sample (the physics step)
    point: F64 = field(default_factory=lambda: np.zeros((0, 3)))

    @property
    def empty(self) -> bool:
        return self.times.size == 0

    @property
    def impulse(self) -> F64:
        """``(3,)`` world impulse on character 0 from the others (N s), by the rectangle rule
        over the sampled steps."""
        return self.force.sum(axis=0) * self.dt

    @property
    def peak_force(self) -> float:
        return float(self.normal.max()) if self.normal.size else 0.0


@dataclass
class RolloutResult:
    """What a rollout recorded: ``qpos`` ``(R, nq)`` after each of ``record_steps`` ``(R,)``
    step counts, for the frame rates ``fps`` (the first is the primary rate); ``status``
    ``"ok"``, ``"unstable"`` or ``"stopped"`` by a stop condition (with ``reason``; the
    records end there); ``seconds`` simulated; ``contacts``: a report per primary frame when asked for;
    ``references``: per character the motion its non-simulated joints come from, sampled at
    ``reference_starts + t``."""

    world: World
    fps: tuple[float, ...]
    qpos: F64
    record_steps: I64
    duration: float
    steps: int
    seconds: float
    wall_s: float
    status: Status = "ok"
    reason: str | None = None
    contacts: list[ContactReport] = field(default_factory=list)
    contact_log: ContactLog | None = None
    final_state: F64 | None = None
    references: tuple[Motion | None, ...] = ()
    reference_starts: tuple[float, ...] = ()
    #: MuJoCo's warnings during the rollout (caught, not printed)
    warnings: tuple[str, ...] = ()

    def frames(self, fps: float | None = None) -> tuple[F64, F64]:
        """Frame times ``(T,)`` (seconds from the start) and qpos rows ``(T, nq)`` at ``fps``
        (default: the primary rate; it must be one of the recorded rates)."""
        rate = self.fps[0] if fps is None else float(fps)
        if rate not in self.fps:
            raise ConfigError(f"rate {rate} fps was not recorded (recorded: {self.fps})")
        steps = _frame_steps(self.duration, rate, self.world.timestep)
        steps = steps[np.isin(steps, self.record_steps)]  # a prefix: records stop, never skip
        rows = np.searchsorted(self.record_steps, steps)
        return np.arange(steps.size) / rate, self.qpos[rows]

    @property
    def times(self) -> F64:
        return self.frames()[0]

    def body_transforms(self, character: int, fps: float | None = None) -> tuple[F64, F64]:
        """World positions ``(T, 16, 3)`` and rotations ``(T, 16, 4)`` of a character's bodies."""
        wc = self.world.characters[character]
        _, q = self.frames(fps)
        return wc.character.body_transforms_from_qpos(q[:, wc.qpos_slice])

    def motion(self, character: int, fps: float | None = None, name: str | None = None) -> Motion:
        """A character's recorded states as a Motion on its own skeleton; joints that are not
        simulated come from its reference motion (given to :func:`rollout`), if any."""
        wc = self.world.characters[character]
        times, q = self.frames(fps)
        rate = self.fps[0] if fps is None else float(fps)
        ref = self.references[character] if character < len(self.references) else None
        start = self.reference_starts[character] if ref is not None else 0.0
        return wc.character.motion_from_qpos(
            q[:, wc.qpos_slice], rate, ref, times + start if ref is not None else None,
            name=name or f"sim_{wc.prefix.rstrip('/')}",
        )  # fmt: skip

    @property
    def motions(self) -> list[Motion]:
        return [self.motion(c) for c in range(len(self.world.characters))]


def _frame_steps(duration: float, fps: float, dt: float) -> I64:
    """Step counts of the frames ``k / fps`` within ``duration``."""
    n = int(np.floor(duration * fps + 1e-9)) + 1
    return np.round(np.arange(n) / (fps * dt)).astype(np.int64)


class _Guard:
    """Instability detection: non-finite state, or kinetic energy per kg above a limit."""

    def __init__(self, world: World, energy_limit_per_kg: float) -> None:
        m = world.model
        self.world = world
        self.limit = np.array(
            [energy_limit_per_kg * float(m.body_subtreemass[wc.body_ids[0]])
             for wc in world.characters]
        )  # fmt: skip

    def problem(self, t: float) -> str | None:
        w, d = self.world, self.world.data
        # the reductions themselves: ndarray.all adds a Python call each, every check
        finite = np.logical_and.reduce
        if not (finite(np.isfinite(d.qvel)) and finite(np.isfinite(d.qpos))):
            bad = "unknown"
            for wc in w.characters:
                if not (np.isfinite(d.xpos[wc.body_ids]).all() and
                        np.isfinite(d.qvel[wc.qvel_slice]).all()):  # fmt: skip
                    rows = np.flatnonzero(~np.all(np.isfinite(d.cvel[wc.body_ids]), axis=1))
                    bad = wc.prefix + (SIM_BODIES[int(rows[0])] if rows.size else "pelvis")
                    break
            return f"simulation went unstable at t = {t:.4f} s: NaN/inf at body {bad}"
        for wc in w.characters:
            ke = w.kinetic_energy(wc.index)
            if ke > self.limit[wc.index]:
                speeds = np.linalg.norm(d.cvel[wc.body_ids, 3:], axis=1)
                body = SIM_BODIES[int(np.argmax(speeds))]
                return (
                    f"simulation went unstable at t = {t:.4f} s: kinetic energy of character "
                    f"{wc.index} is {ke:.0f} J (limit {self.limit[wc.index]:.0f} J); fastest "
                    f"body {wc.prefix}{body} at {speeds.max():.1f} m/s"
                )
        return None


class _ContactLogger:
    def __init__(self, world: World) -> None:
        self.world = world
        self.rows: list[tuple[float, float, F64, float, F64]] = []
        self._f6 = np.zeros(6)

    def log(self, t: float) -> bool:
        """Log the contacts between characters now; whether there are any."""
        w = self.world
        m, d = w.model, w.data
        n = d.ncon
        if n == 0:
            return False
        geoms = d.contact.geom[:n]
        own = w.geom_character[geoms]
        between = np.flatnonzero((own[:, 0] >= 0) & (own[:, 1] >= 0) & (own[:, 0] != own[:, 1]))
        if not between.size:
            return False
        total = 0.0
        force = np.zeros(3)
        point = np.zeros(3)
        for i in between:  # a handful of contacts, only while the characters touch
            mujoco.mj_contactForce(m, d, int(i), self._f6)
            total += abs(self._f6[0])
            point += abs(self._f6[0]) * d.contact.pos[i]
            fw = d.contact.frame[i].reshape(3, 3).T @ self._f6[:3]  # on geom2 from geom1
            if own[i, 1] == 0:
                force += fw
            elif own[i, 0] == 0:
                force -= fw
        depth = float(max(0.0, -d.contact.dist[between].min()))
        point = point / total if total > 0 else d.contact.pos[between].mean(axis=0)
        self.rows.append((t, total, force, depth, point))
        return True

    def result(self, period: float) -> ContactLog:
        dt = self.world.timestep
        if not self.rows:
            z = np.zeros(0)
            return ContactLog(z, z, np.zeros((0, 3)), z, period, dt)
        t, f, v, dep, pt = zip(*self.rows)
        return ContactLog(np.array(t), np.array(f), np.array(v), np.array(dep), period, dt,
                          np.array(pt))  # fmt: skip


@dataclass
class _Plan:
    """What one rollout does at which step (built once, read by the loop)."""

    nsteps: int
    controllers: Sequence[Controller]
    schedule: ImpactSchedule | None
    events: I64  # steps where impacts change, records are taken or checks made
    periods: list[int]  # control, contact-log and progress periods (steps)
    rec_steps: I64
    primary: set[int]
    check_every: int
    logger: _ContactLogger | None
    contact_every: int
    on_tick: Callable[[float], None] | None
    tick_every: int
    record_contacts: bool
    stop: StopCondition | None = None


def rollout(
    world: World,
    duration: float,
    *,
    controllers: Sequence[Controller] = (),
    impacts: Sequence[Impact] = (),
    record_fps: float | Sequence[float] = 60.0,
    references: Sequence[Motion | None] = (),
    reference_start: float | Sequence[float] = 0.0,
    record_contacts: bool = False,
    contact_every: int | None = None,
    energy_limit_per_kg: float = 100.0,
    check_every: int = 20,
    on_unstable: Literal["raise", "stop"] = "raise",
    on_tick: Callable[[float], None] | None = None,
    tick_every: int = 100,
    stop: StopCondition | None = None,
) -> RolloutResult:
    """Run ``duration`` seconds from the world's current state (see the module docstring).

    Args:
        controllers: reset once, then ticked every ``control_every`` steps each, in order.
        impacts: pushes, their ``start`` relative to the rollout's start.
        record_fps: output frame rate(s); the first is the primary one.
        references: per character, the motion whose non-simulated joints the recorded
            Motions take, sampled at ``reference_start + t``.
        record_contacts: a :class:`ContactReport` per primary frame.
        contact_every: log contacts between characters every this many steps.
        energy_limit_per_kg: kinetic energy (J/kg) taken as unstable (100: the whole body at
            14 m/s); checked with finiteness every ``check_every`` steps and at every frame.
        on_unstable: ``"raise"`` a SimulationError, or ``"stop"`` and return what was recorded
            with ``status = "unstable"``. MuJoCo's own warnings join the reason.
        on_tick: called with ``t`` every ``tick_every`` steps (a progress bar).
        stop: checked at every primary frame; a reason it returns ends the rollout there
            with ``status = "stopped"``.
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ConfigError(f"duration must be > 0 s, got {duration!r}")
    rates = (record_fps,) if isinstance(record_fps, int | float) else tuple(record_fps)
    if not rates or not all(np.isfinite(r) and r > 0 for r in rates):
        raise ConfigError(f"record_fps must be > 0, got {record_fps!r}")
    if check_every < 1 or tick_every < 1 or (contact_every is not None and contact_every < 1):
        raise ConfigError("check_every, tick_every and contact_every must be >= 1")
    if on_unstable not in ("raise", "stop"):
        raise ConfigError(f"on_unstable must be 'raise' or 'stop', got {on_unstable!r}")
    for c in controllers:
        if not (isinstance(c.control_every, int) and c.control_every >= 1):
            raise ConfigError(f"{type(c).__name__}.control_every must be an int >= 1")
    nchar = len(world.characters)
    starts = (
        (float(reference_start),) * nchar
        if isinstance(reference_start, int | float)
        else tuple(float(s) for s in reference_start)
    )
    dt = world.timestep
    nsteps = round(duration / dt)
    rec_steps = np.unique(np.concatenate([_frame_steps(duration, r, dt) for r in rates]))
    rec_steps = rec_steps[rec_steps <= nsteps]
    schedule = ImpactSchedule(world, impacts) if impacts else None
    events = sorted(set(schedule.event_steps() if schedule else []) | set(rec_steps.tolist())
                    | {nsteps})  # fmt: skip
    periods = {check_every} | {c.control_every for c in controllers}
    periods |= ({contact_every} if contact_every else set()) | ({tick_every} if on_tick else set())
    plan = _Plan(
        nsteps, controllers, schedule, np.array(events, dtype=np.int64), sorted(periods),
        rec_steps, set(_frame_steps(duration, rates[0], dt).tolist()), check_every,
        _ContactLogger(world) if contact_every else None, contact_every or 0, on_tick,
        tick_every, record_contacts, stop,
    )  # fmt: skip
    qpos = np.empty((rec_steps.size, world.model.nq))
    contacts: list[ContactReport] = []
    guard = _Guard(world, energy_limit_per_kg)
    warnings: list[str] = []
    handler = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda msg: warnings.append(str(msg).strip()))
    wall = _time.perf_counter()
    try:
        reason, ri, k, stopped = _loop(world, plan, guard, qpos, contacts)
    finally:
        mujoco.set_mju_user_warning(handler)
        if schedule is not None:
            schedule.clear()
    wall = _time.perf_counter() - wall
    status: Status = "ok"
    if stopped:
        status = "stopped"
    elif reason is not None:
        if warnings:
            reason += f" (MuJoCo: {warnings[0]})"
        if on_unstable == "raise":
            raise SimulationError(reason)
        status = "unstable"
    return RolloutResult(
        world=world,
        fps=rates,
        qpos=qpos[:ri],
        record_steps=rec_steps[:ri],
        duration=float(duration),
        steps=k,
        seconds=k * dt,
        wall_s=wall,
        status=status,
        reason=reason,
        contacts=contacts,
        contact_log=plan.logger.result(plan.contact_every * dt) if plan.logger else None,
        final_state=world.get_state(),
        references=tuple(references) + (None,) * (nchar - len(references)),
        reference_starts=starts + (0.0,) * (nchar - len(starts)),
        warnings=tuple(warnings),
    )


def _loop(
    world: World, plan: _Plan, guard: _Guard, qpos: F64, contacts: list[ContactReport]
) -> tuple[str | None, int, int, bool]:
    """The stepping loop; returns the instability or stop reason (or None), the records made,
    the steps, and whether a stop condition ended it."""
    d = world.data
    t0 = float(d.time)
    for c in plan.controllers:
        c.reset(world)
    rec, events, nsteps = plan.rec_steps, plan.events, plan.nsteps
    ri = 0  # next record
    ei = 0  # next event
    k = 0
    touching = False  # contacts between characters: logged every step while they last
    while True:
        is_record = ri < rec.size and rec[ri] == k
        if is_record or k % plan.check_every == 0 or k >= nsteps:
            reason = guard.problem(float(d.time) - t0)
            if reason is not None:
                return reason, ri, k, False
        if is_record:
            qpos[ri] = d.qpos
            primary = k in plan.primary
            if plan.record_contacts and primary:
                contacts.append(contact_report(world))
            ri += 1
            if primary and plan.stop is not None:
                why = plan.stop(world, float(d.time) - t0)
                if why is not None:
                    return why, ri, k, True
        if k >= nsteps:
            return None, ri, k, False
        t = float(d.time) - t0
        for c in plan.controllers:
            if k % c.control_every == 0:
                c.control(world, t)
        if plan.logger is not None and (touching or k % plan.contact_every == 0):
            touching = plan.logger.log(t)
        if plan.on_tick is not None and k % plan.tick_every == 0:
            plan.on_tick(t)
        if plan.schedule is not None:
            plan.schedule.apply(k)
        # the next step where something happens
        while ei < events.size and events[ei] <= k:
            ei += 1
        nxt = int(events[ei]) if ei < events.size else nsteps
        for p in plan.periods:
            nxt = min(nxt, (k // p + 1) * p)
        if touching:
            nxt = k + 1
        try:
            world.step(nxt - k)
        except SimulationError as exc:  # met by the servo between the guard's checks
            return guard.problem(float(d.time) - t0) or str(exc), ri, k, False
        k = nxt
