"""The stages of a response (Zordan et al. 2005), each a function returning a dataclass: the cast
(clips placed, characters built), the contact estimate, the naive simulation (Simulation 1), the
continuation search, the transition simulation (Simulation 2) and the blend. Scenario time 0 is
the recipient clip at ``recipient.start``; outputs are at the recipient clip's frame rate."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, ReactMocapError, SearchError
from reactmocap.library.bodyparts import BodyPartMap, map_body_parts
from reactmocap.library.bvh import read_bvh
from reactmocap.library.clip_library import ClipLibrary
from reactmocap.library.motion import Motion
from reactmocap.library.placement import place
from reactmocap.response.blend import blend_poses, final_blend, transition_weights
from reactmocap.response.footlock import lock_feet
from reactmocap.response.library_cache import LibraryCache
from reactmocap.response.reaction import YieldOnImpact, yield_schedule
from reactmocap.response.scenario import CharacterSpec, ResponseConfig, Scenario
from reactmocap.rotations import quat_slerp
from reactmocap.search import MotionIndex, SearchResult
from reactmocap.sim.character import Character, build_character
from reactmocap.sim.controllers import (
    Controller,
    GainScalable,
    Scheduled,
    State,
    StateMachine,
    after,
    build,
)
from reactmocap.sim.controllers.registry import controller_spec
from reactmocap.sim.impacts import Impact, first_contact
from reactmocap.sim.reference import reference_path
from reactmocap.sim.rollout import ContactLog, rollout
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "CONTACT_EVERY",
    "SCAN_FPS",
    "Actor",
    "Blend",
    "Cast",
    "ContactEstimate",
    "Continuation",
    "NaiveSimulation",
    "TransitionSimulation",
    "blend",
    "cast",
    "estimate_contact",
    "naive_simulation",
    "search_continuation",
    "transition_simulation",
]

F64 = NDArray[np.float64]
#: kinematic contact scan rate (Hz), as in the paper
SCAN_FPS = 30.0
#: steps between samples of the contacts between characters (200 Hz at dt = 0.5 ms)
CONTACT_EVERY = 10


@dataclass(frozen=True)
class Actor:
    """A character of the scenario: its ``clip`` as loaded, ``motion`` placed in the world,
    ``clock0`` the clip time at scenario time 0, its body parts and simulated character."""

    clip: Motion
    motion: Motion
    clock0: float
    parts: BodyPartMap
    character: Character

    def frame_at(self, t: float) -> int:
        """The placed clip's frame at scenario time ``t``."""
        return min(round((t + self.clock0) * self.motion.fps), self.motion.num_frames - 1)


@dataclass(frozen=True)
class Cast:
    recipient: Actor
    attacker: Actor | None
    library: ClipLibrary  # continuations on the recipient's skeleton
    index: MotionIndex

    @property
    def actors(self) -> list[Actor]:
        return [self.recipient] + ([self.attacker] if self.attacker is not None else [])


def _clip(scenario: Scenario, spec: CharacterSpec, cache: LibraryCache) -> Motion:
    """A clip by file (``x.bvh``: the scenario's folder first, then the working folder) or by
    name in the library."""
    p = Path(spec.clip)
    if p.suffix.lower() != ".bvh":
        return cache.library(scenario.library)[spec.clip]
    base = scenario.source.parent if scenario.source is not None else Path.cwd()
    cands = [p] if p.is_absolute() else [base / p, Path.cwd() / p]
    for cand in cands:
        if cand.is_file():
            return read_bvh(cand)
    raise ConfigError(f"{scenario.source}: clip {spec.clip!r} not found "
                      f"(looked in {[str(c) for c in cands]})")  # fmt: skip


def _actor(scenario: Scenario, spec: CharacterSpec, cache: LibraryCache) -> Actor:
    clip = _clip(scenario, spec, cache)
    parts = map_body_parts(clip.skeleton)
    frame = int(round(spec.start * clip.fps))
    if not 0 <= frame < clip.num_frames:
        raise ConfigError(
            f"start {spec.start} s is outside clip {clip.name!r} ({clip.duration:.2f} s)"
        )
    motion = place(clip, parts, frame, np.radians(spec.facing_deg), spec.position)
    character = build_character(motion, parts, total_mass=scenario.response.total_mass, frame=frame)
    return Actor(clip, motion, frame / clip.fps, parts, character)


def cast(scenario: Scenario, cache: LibraryCache) -> Cast:
    """Load and place the clips, build the characters, prepare the search library."""
    recipient = _actor(scenario, scenario.recipient, cache)
    attacker = _actor(scenario, scenario.attacker, cache) if scenario.attacker else None
    library, index = cache.search(scenario.library, recipient.clip)
    return Cast(recipient, attacker, library, index)


@dataclass(frozen=True)
class ContactEstimate:
    """When the hit lands (scenario seconds), which bodies, and the last mocap frame before it,
    where the simulations start (``rewind``)."""

    time: float
    rewind: float
    body: str


def estimate_contact(scenario: Scenario, cast: Cast) -> ContactEstimate:
    """The explicit impact's time, or the first kinematic contact of the two clips scanned at
    :data:`SCAN_FPS`; then rewind to the last recipient frame before it."""
    rec, att = cast.recipient, cast.attacker
    fps = rec.motion.fps
    if att is not None:
        horizon = min(rec.motion.duration - rec.clock0, att.motion.duration - att.clock0)
        shifted = [a.motion.sample(np.arange(0, horizon, 1 / a.motion.fps) + a.clock0)
                   .replace(fps=a.motion.fps) for a in (rec, att)]  # fmt: skip
        world = World([rec.character, att.character])
        kc = first_contact(world, shifted, fps=SCAN_FPS, end=horizon)
        if kc is None:  # never touching: the scan runs to the end and the clip plays on
            return ContactEstimate(horizon, max(0.0, np.floor(horizon * fps - 1e-9) / fps),
                                   "contact")  # fmt: skip
        # the last scanned frame without contact, on the recipient's frames: apart at the start
        rewind = np.floor(kc.rewind_time * fps + 1e-9) / fps
        return ContactEstimate(kc.time, max(0.0, float(rewind)), "/".join(kc.pairs[0]))
    assert scenario.impact is not None
    t = scenario.impact.at
    return ContactEstimate(t, max(0.0, float(np.floor(t * fps - 1e-9) / fps)),
                           scenario.impact.body)  # fmt: skip


def _world(cast: Cast, cfg: ResponseConfig, recipient_friction: float) -> World:
    """The simulations' world: the attacker always on ``friction_sim1`` (its strike should not
    depend on the pass), the recipient on ``recipient_friction``."""
    world = World([a.character for a in cast.actors],
                  WorldConfig(friction=cfg.friction_sim1, timestep=cfg.timestep))  # fmt: skip
    world.set_friction(recipient_friction, character=0)
    return world


def _impacts(scenario: Scenario, rewind: float) -> list[Impact]:
    spec = scenario.impact
    if spec is None:
        return []
    try:
        return [Impact(spec.body, force=spec.force, point=spec.point, start=spec.at - rewind,
                       duration=spec.duration)]  # fmt: skip
    except ReactMocapError as exc:
        raise ConfigError(f"{scenario.source}: [impact]: {exc}") from None


def _controller(
    name: str,
    cfg: ResponseConfig,
    world: World,
    c: int,
    ref: Motion | F64,
    start: float,
    fps: float,
) -> Controller:
    """A registered controller with the scenario's ``[response]`` gains (``None``: its own)."""
    path = reference_path(world, c, ref, fps=fps) if isinstance(ref, np.ndarray) else ref
    gains = {k: v for k, v in (("kp", cfg.kp), ("kv", cfg.kv))
             if k in controller_spec(name).defaults}  # fmt: skip
    return build(name, world, path, gains, character=c, start=start)


@dataclass(frozen=True)
class NaiveSimulation:
    """Simulation 1 from the rewind: the recipient's ``motion`` (frame 0 at ``rewind``), the
    start state (Simulation 2 restarts from it), what the physics says of the hit."""

    motion: Motion
    start_state: F64
    impact_time: float
    contact_end: float
    peak_force: float
    contacts: ContactLog
    steps: int
    impulse: float  # |impulse| on the recipient (N s)


def _start(world: World, cast: Cast, rewind: float) -> None:
    for k, a in enumerate(cast.actors):
        world.set_from_motion(k, a.motion, a.frame_at(rewind))


def _recipient_path(cast: Cast, cfg: ResponseConfig, rewind: float, seconds: float, every: int,
                    impact: float, target: Continuation) -> tuple[F64, float]:  # fmt: skip
    """Simulation 2's desired qpos for the recipient at each control tick from the rewind, and
    its rate: the old clip until ``impact``; from there (``yielding``) its pose at the impact,
    held through the reaction delay (or, ``holding``/``passive``: the old clip on), eased
    (smoothstep) into the found clip by the match time."""
    rec = cast.recipient
    ch = rec.character
    n = int(np.ceil(seconds / cfg.timestep / every)) + 1
    ticks = np.arange(n) * every * cfg.timestep + rewind
    clock = np.minimum(ticks, impact) if cfg.sim1_mode == "yielding" else ticks
    prev = ch.qpos_from_motion(rec.motion.sample(clock + rec.clock0))
    found = ch.qpos_from_motion(target.found.sample(target.best.time + (ticks - target.time)))
    w = transition_weights(ticks, impact, cfg.reaction_delay, target.time)
    q = np.empty_like(prev)
    q[:, :3] = prev[:, :3] + w[:, None] * (found[:, :3] - prev[:, :3])
    quats = quat_slerp(prev[:, 3:].reshape(n, -1, 4), found[:, 3:].reshape(n, -1, 4), w[:, None])
    q[:, 3:] = quats.reshape(n, -1)
    return q, 1.0 / (every * cfg.timestep)


def naive_simulation(scenario: Scenario, cast: Cast, contact: ContactEstimate) -> NaiveSimulation:
    """Simulation 1 (friction ``friction_sim1``) with ``sim1_controller``: the recipient
    ``yielding`` to the hit (the default), ``holding`` its old clip or ``passive`` from the
    contact (see :class:`~reactmocap.response.scenario.ResponseConfig`)."""
    cfg = scenario.response
    rewind = contact.rewind
    end = contact.time + cfg.sim1_duration + cast.index.window.length / cast.index.window.fps
    world = _world(cast, cfg, cfg.friction_sim1)
    _start(world, cast, rewind)
    state = world.get_state()
    fps = cast.recipient.motion.fps
    rec = cast.recipient
    hold = _controller(cfg.sim1_controller, cfg, world, 0, rec.motion, rewind + rec.clock0, fps)
    if cfg.sim1_mode == "yielding":
        explicit = scenario.impact.at - rewind if scenario.impact is not None else None
        hold = YieldOnImpact(hold, cfg, explicit)
    elif cfg.sim1_mode == "passive":
        hold = StateMachine(
            [State("holding", hold, exits=((after(contact.time - rewind), "passive"),)),
             State("passive", on_enter=lambda w, _t: w.servo.enable(0, on=False))],
            "holding", control_every=hold.control_every,
        )  # fmt: skip
    ctrls = [hold]
    if cast.attacker is not None:
        att = cast.attacker
        ctrls.append(_controller(cfg.attacker_controller, cfg, world, 1, att.motion,
                                 rewind + att.clock0, fps))  # fmt: skip
    res = rollout(
        world, end - rewind, controllers=ctrls, impacts=_impacts(scenario, rewind),
        record_fps=fps, references=[a.motion for a in cast.actors],
        reference_start=[rewind + a.clock0 for a in cast.actors],
        contact_every=CONTACT_EVERY,
    )  # fmt: skip
    log = res.contact_log
    assert log is not None
    if not log.empty:
        t_impact, contact_end = rewind + log.times[0], rewind + log.times[-1]
        peak, impulse = log.peak_force, float(np.linalg.norm(log.impulse))
    elif scenario.impact is not None:
        t_impact = scenario.impact.at
        contact_end = t_impact + scenario.impact.duration
        peak = float(np.linalg.norm(scenario.impact.force))
        impulse = peak * scenario.impact.duration
    else:
        t_impact, contact_end, peak, impulse = contact.time, contact.time, 0.0, 0.0
    return NaiveSimulation(res.motion(0, name="sim1"), state, t_impact, contact_end, peak, log,
                           res.steps, impulse)  # fmt: skip


@dataclass(frozen=True)
class Continuation:
    """The best library window after the impact (``best``, its runners-up ``candidates``),
    the scenario time ``time`` where the transition lands on it, and the found clip moved into
    place (``found``)."""

    best: SearchResult
    candidates: list[SearchResult]
    time: float
    found: Motion
    found_clip: Motion


def search_continuation(
    scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation
) -> Continuation:
    """Windows of Simulation 1 starting 0.1-1.0 s after the impact (later while contact lasts),
    each searched; the best over all starts wins."""
    cfg = scenario.response
    index = cast.index
    t_impact = naive.impact_time
    first = t_impact + float(np.clip(naive.contact_end - t_impact, cfg.search_start,
                                     cfg.contact_shift_max))  # fmt: skip
    if naive.impulse >= cfg.react_impulse:
        # a real hit: the active response after the reaction delay needs time to show, so the
        # recipient's own clip right after the hit cannot win by being closest
        first = max(first, t_impact + cfg.reaction_delay + cfg.active_min)
    last = t_impact + cfg.search_end
    q_fps = index.window.fps
    query = naive.motion.resample(q_fps)
    starts = np.arange(int(np.ceil((first - contact.rewind) * q_fps - 1e-9)),
                       int(np.floor((last - contact.rewind) * q_fps + 1e-9)) + 1)  # fmt: skip
    starts = starts[starts + index.length <= query.num_frames]
    if starts.size == 0:
        raise SearchError("the simulated trajectory is too short for one search window")
    parts = cast.recipient.parts
    results = [(index.query(query, int(s), parts=parts), int(s)) for s in starts]
    best, best_start = min(results, key=lambda r: r[0].distance)
    candidates = index.top_k(query, best_start, n=cfg.top_k, parts=parts)
    found_clip = cast.library[best.clip]
    found = found_clip.transformed(best.yaw, best.translation).replace(name=best.clip)
    return Continuation(best, candidates, contact.rewind + best_start / q_fps, found, found_clip)


@dataclass(frozen=True)
class TransitionSimulation:
    """Simulation 2 from the rewind: the recipient ``motion`` (frame 0 at the rewind) and the
    attacker's (at its own clip rate), with the world it ran in."""

    motion: Motion
    attacker: Motion | None
    steps: int
    world: World
    contacts: ContactLog


def transition_simulation(scenario: Scenario, cast: Cast, contact: ContactEstimate,
                          naive: NaiveSimulation, cont: Continuation) -> TransitionSimulation:  # fmt: skip
    """Simulation 2 (friction ``friction_sim2``) from the same start and impact: the recipient
    follows the desired path to the found clip with ``sim2_controller``, yielding through the
    reaction delay as in Simulation 1 (the passive response), then recovering (the active)."""
    cfg = scenario.response
    rewind = contact.rewind
    end = cont.time
    if cast.attacker is not None:
        end = max(end, naive.impact_time + cfg.attacker_follow + cfg.attacker_blend)
    seconds = max(end - rewind, cfg.timestep)
    world = _world(cast, cfg, cfg.friction_sim2)
    world.set_state(naive.start_state)
    name = cfg.sim2_controller
    every = int(controller_spec(name).defaults["control_every"] or 1)
    q, rate = _recipient_path(cast, cfg, rewind, seconds, every, naive.impact_time, cont)
    recipient = _controller(name, cfg, world, 0, q, 0.0, rate)
    if cfg.sim1_mode == "yielding" and isinstance(recipient, GainScalable):
        recipient = Scheduled(recipient, yield_schedule(cfg, naive.impact_time - rewind))
    ctrls = [recipient]
    fps = [cast.recipient.motion.fps]
    if cast.attacker is not None:
        att = cast.attacker
        ctrls.append(_controller(cfg.attacker_controller, cfg, world, 1, att.motion,
                                 rewind + att.clock0, att.motion.fps))  # fmt: skip
        fps.append(att.motion.fps)
    res = rollout(
        world, seconds, controllers=ctrls, impacts=_impacts(scenario, rewind), record_fps=fps,
        references=[a.motion for a in cast.actors],
        reference_start=[rewind + a.clock0 for a in cast.actors], contact_every=CONTACT_EVERY,
    )  # fmt: skip
    attacker = res.motion(1, fps[-1], name="attacker_sim") if cast.attacker is not None else None
    assert res.contact_log is not None
    return TransitionSimulation(res.motion(0, name="sim2"), attacker, res.steps, world,
                                res.contact_log)  # fmt: skip


@dataclass(frozen=True)
class Blend:
    """The outputs: the ``recipient`` animation (mocap before the impact, the blended
    transition, the found clip after), the ``attacker``'s, the ``blended`` transition alone,
    Simulation 2 over the same frames (``simulated``), and the ``seams`` between pieces."""

    recipient: Motion
    attacker: Motion | None
    blended: Motion
    simulated: Motion
    seams: list[int]


def blend(scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation,
          cont: Continuation, sim2: TransitionSimulation) -> Blend:  # fmt: skip
    """The paper's final blend over [impact, match], then the found clip plays on; the attacker
    follows its simulation briefly, then blends back to its clip."""
    cfg = scenario.response
    rec = cast.recipient
    fps = rec.motion.fps
    i_imp = int(np.ceil(naive.impact_time * fps - 1e-9))
    i_end = int(round(cont.time * fps))
    before = rec.motion.sample(np.arange(0, i_imp) / fps + rec.clock0) if i_imp > 0 else None
    times = np.arange(i_imp, i_end + 1) / fps
    simulated = sim2.motion.sample(times - contact.rewind)
    blended = final_blend(simulated, cont.found.sample(cont.best.time + (times - cont.time)))
    if cfg.foot_lock:
        blended = lock_feet(blended, rec.parts)
    tail_n = int(np.floor(min(cfg.tail, cont.found.duration - cont.best.time) * fps))
    tail = (cont.found.sample(cont.best.time + np.arange(1, tail_n + 1) / fps)
            if tail_n > 0 else None)  # fmt: skip
    pieces = [p.replace(fps=fps) for p in (before, blended, tail) if p is not None]
    recipient = Motion.concatenate(pieces, name="recipient")
    attacker = None
    if cast.attacker is not None and sim2.attacker is not None:
        att = cast.attacker
        afps = att.motion.fps
        t = np.arange(0, int(np.floor(recipient.duration * afps)) + 1) / afps
        own = att.motion.sample(t + att.clock0).replace(fps=afps)
        simulated_att = sim2.attacker.sample(np.clip(t - contact.rewind, 0, sim2.attacker.duration))
        t1 = naive.impact_time + cfg.attacker_follow
        w = np.where(t < naive.impact_time, 1.0,
                     np.clip((t - t1) / max(cfg.attacker_blend, 1e-9), 0, 1))  # fmt: skip
        attacker = blend_poses(simulated_att, own, w).replace(name="attacker")
    seams = [i_imp, i_end + 1] if before is not None else [i_end + 1]
    return Blend(recipient, attacker, blended, simulated, seams)
