"""The stages of a response (Zordan et al. 2005), each a function returning a dataclass: the cast
(clips placed, characters built), the contact estimate, the naive simulation (Simulation 1), the
continuation search, the transition simulation (Simulation 2) and the blend. Scenario time 0 is
the recipient clip at ``recipient.start``; outputs are at the recipient clip's frame rate."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, ReactMocapError, SearchError
from reactmocap.library.bodyparts import BodyPartMap, parts_for
from reactmocap.library.bvh import read_bvh
from reactmocap.library.clip_library import ClipLibrary
from reactmocap.library.motion import Motion
from reactmocap.library.placement import ground_root, place
from reactmocap.metrics import WARN_ROOT_TURN_RAD
from reactmocap.response.blend import blend_poses, smoothstep, transition_weights
from reactmocap.response.library_cache import LibraryCache
from reactmocap.response.reaction import AssistUntilHit, YieldOnImpact, yield_schedule
from reactmocap.response.scenario import CharacterSpec, ImpactSpec, ResponseConfig, Scenario
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.search import MotionIndex, SearchResult
from reactmocap.sim.bodies import SIM_BODIES
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
from reactmocap.sim.controllers.wholebody import WholeBodyTracker
from reactmocap.sim.impacts import Impact, first_contact, overlap_depths
from reactmocap.sim.reference import reference_path
from reactmocap.sim.rollout import ContactLog, rollout
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "CONTACT_EVERY",
    "PHYSICAL_TRACKERS",
    "REPLANS",
    "REPLAN_EASE_S",
    "SCAN_FPS",
    "UNSTABLE_TRIM_S",
    "Actor",
    "Cast",
    "ContactEstimate",
    "Continuation",
    "NaiveSimulation",
    "TransitionSimulation",
    "cast",
    "desired_motion",
    "estimate_contact",
    "naive_simulation",
    "replan_continuation",
    "search_continuation",
    "transition_simulation",
    "yields_to",
]

F64 = NDArray[np.float64]
#: kinematic contact scan rate (Hz), as in the paper
SCAN_FPS = 30.0
#: steps between samples of the contacts between characters (200 Hz at dt = 0.5 ms)
CONTACT_EVERY = 10
#: seconds of Simulation 1 dropped before an instability (the body is already running away)
UNSTABLE_TRIM_S = 0.1


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

    @cached_property
    def pair(self) -> World:
        """Both characters in one World for kinematic contact and overlap checks (poses are
        set, it is never stepped); built once, since building a World costs ~10 ms."""
        return World([a.character for a in self.actors])


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
    parts = parts_for(clip.skeleton, scenario.parts)
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
    library, index = cache.search(scenario.library, recipient.clip, scenario.parts)
    return Cast(recipient, attacker, library, index)


#: how far down each start's ranking the search looks for a window that is not the recipient's
#: own clip, when the first 4 of every start are
OWN_CLIP_DEPTH = 16


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
        kc = first_contact(cast.pair, shifted, fps=SCAN_FPS, end=horizon)
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


#: the recipient's bodies on Simulation 2's lower friction: the limbs, which it lets slip into
#: the found clip's pose (the paper lowers it "to allow foot slippage"); the trunk keeps
#: Simulation 1's, so a body lying on the floor stays where Simulation 1's lay, where the search
#: placed the found clip (on the whole body, the heavy push's slid 0.3 m further)
LIMBS = tuple(b for b in SIM_BODIES if b not in ("pelvis", "waist", "chest", "head"))


def _world(cast: Cast, cfg: ResponseConfig, limb_friction: float) -> World:
    """The simulations' world on ``friction_sim1``, the recipient's :data:`LIMBS` on
    ``limb_friction`` (the attacker's strike should not depend on the pass)."""
    world = World([a.character for a in cast.actors],
                  WorldConfig(friction=cfg.friction_sim1, timestep=cfg.timestep))  # fmt: skip
    world.set_friction(limb_friction, character=0, bodies=LIMBS)
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
    options: dict[str, Any] | None = None,
) -> Controller:
    """A registered controller with the scenario's ``[response]`` gains (``None``: its own)
    and ``options``."""
    path = reference_path(world, c, ref, fps=fps) if isinstance(ref, np.ndarray) else ref
    spec = controller_spec(name)
    gains = {k: v for k, v in (("kp", cfg.kp), ("kv", cfg.kv), ("torque_limit", cfg.torque_limit))
             if k in spec.defaults or k in spec.options}  # fmt: skip
    return build(name, world, path, {**gains, **(options or {})}, character=c, start=start)


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
    #: why Simulation 1 stopped early (it went unstable), else None: ``motion`` then ends
    #: :data:`UNSTABLE_TRIM_S` before that, and the search uses what is left
    unstable: str | None = None


def _attacker(world: World, cast: Cast, cfg: ResponseConfig, rewind: float) -> list[Controller]:
    """The attacker's controllers: ``attacker_controller`` on its clip, and the root assist
    until the hit when ``attacker_assist`` asks for it."""
    att = cast.attacker
    assert att is not None
    out = [_controller(cfg.attacker_controller, cfg, world, 1, att.motion, rewind + att.clock0,
                       att.motion.fps)]  # fmt: skip
    if cfg.attacker_assist > 0:
        assist = build("root_assist", world, att.motion, {"kp": cfg.attacker_assist},
                       character=1, start=rewind + att.clock0)  # fmt: skip
        out.append(AssistUntilHit(assist, int(world.characters[1].body_ids[0])))
    return out


def _impulse_of(impact: ImpactSpec) -> float:
    return float(np.linalg.norm(impact.force)) * impact.duration


def yields_to(cfg: ResponseConfig, impulse: float) -> bool:
    """Whether the recipient gives way to a hit of ``impulse`` N s (``yielding`` mode)."""
    return cfg.sim1_mode == "yielding" and impulse >= cfg.react_impulse


def _start(world: World, cast: Cast, rewind: float) -> None:
    for k, a in enumerate(cast.actors):
        world.set_from_motion(k, a.motion, a.frame_at(rewind))


def desired_motion(cast: Cast, cfg: ResponseConfig, times: F64, impact: float, yields: bool,
                   target: Continuation) -> Motion:  # fmt: skip
    """What Simulation 2 asks of the recipient at scenario ``times``: the old clip until
    ``impact``; from there (``yields``) its pose at the impact, held through the reaction delay
    while moving on with the body's velocity (or the old clip on); eased (smoothstep) into the
    found clip by the match time, where it is exactly the found clip."""
    rec = cast.recipient
    times = np.asarray(times, dtype=np.float64)
    if target.via is not None:  # a re-plan: the first path, eased into the new clip by its match
        first = desired_motion(cast, cfg, times, impact, yields, target.via)
        found = ground_root(target.found.sample(target.best.time + (times - target.time)),
                            rec.parts, turn=False)  # fmt: skip
        return blend_poses(first, found, smoothstep((times - target.time) / REPLAN_EASE_S + 1.0))
    prev = rec.motion.sample((np.minimum(times, impact) if yields else times) + rec.clock0)
    prev = ground_root(prev, rec.parts, turn=False)
    if yields:
        pelvis = rec.parts.joint_of("pelvis")
        ends = rec.motion.sample(impact + rec.clock0 + np.array([-0.5, 0.5]) / rec.motion.fps)
        g = ends.global_positions()[:, pelvis]
        velocity = (g[1] - g[0]) * rec.motion.fps
        coast = np.maximum(times - impact, 0.0)[:, None] * velocity
        prev = prev.replace(root_positions=prev.root_positions + coast)
    found = ground_root(target.found.sample(target.best.time + (times - target.time)), rec.parts,
                        turn=False)  # fmt: skip
    return blend_poses(prev, found, transition_weights(times, impact, cfg.reaction_delay,
                                                       target.time))  # fmt: skip


def _recipient_path(cast: Cast, cfg: ResponseConfig, rewind: float, seconds: float, every: int,
                    impact: float, yields: bool, target: Continuation) -> tuple[F64, float]:  # fmt: skip
    """Simulation 2's desired qpos (:func:`desired_motion`) at each control tick from the rewind,
    and its rate."""
    n = int(np.ceil(seconds / cfg.timestep / every)) + 1
    ticks = np.arange(n, dtype=np.float64) * every * cfg.timestep + rewind
    motion = desired_motion(cast, cfg, ticks, impact, yields, target)
    return cast.recipient.character.qpos_from_motion(motion), 1.0 / (every * cfg.timestep)


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
    imp = scenario.impact
    if (imp is None and cfg.sim1_mode == "yielding") or (imp and yields_to(cfg, _impulse_of(imp))):
        hold = YieldOnImpact(hold, cfg, imp.at - rewind if imp is not None else None)
    elif cfg.sim1_mode == "passive":
        hold = StateMachine(
            [State("holding", hold, exits=((after(contact.time - rewind), "passive"),)),
             State("passive", on_enter=lambda w, _t: w.servo.enable(0, on=False))],
            "holding", control_every=hold.control_every,
        )  # fmt: skip
    ctrls = [hold]
    if cast.attacker is not None:
        ctrls += _attacker(world, cast, cfg, rewind)
    res = rollout(
        world, end - rewind, controllers=ctrls, impacts=_impacts(scenario, rewind),
        record_fps=fps, references=[a.motion for a in cast.actors],
        reference_start=[rewind + a.clock0 for a in cast.actors],
        contact_every=CONTACT_EVERY, on_unstable="stop",
    )  # fmt: skip
    motion = res.motion(0, name="sim1")
    unstable = res.reason if res.status == "unstable" else None
    if unstable is not None:  # the frames just before the blow-up are already running away
        motion = motion.slice(0, max(1, motion.num_frames - round(UNSTABLE_TRIM_S * fps)))
    log = res.contact_log
    assert log is not None
    if not log.empty:
        t_impact, contact_end = rewind + log.times[0], rewind + log.times[-1]
        peak, impulse = log.peak_force, float(np.linalg.norm(log.impulse))
    elif scenario.impact is not None:
        t_impact = scenario.impact.at
        contact_end = t_impact + scenario.impact.duration
        peak = float(np.linalg.norm(scenario.impact.force))
        impulse = _impulse_of(scenario.impact)
    else:
        t_impact, contact_end, peak, impulse = contact.time, contact.time, 0.0, 0.0
    return NaiveSimulation(motion, state, t_impact, contact_end, peak, log, res.steps, impulse,
                           unstable)  # fmt: skip


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
    #: builds :attr:`alternatives` (on first use: most responses never need them)
    others: Callable[[], tuple[Continuation, ...]] | None = field(default=None, repr=False,
                                                                   compare=False)  # fmt: skip
    #: a re-plan (``land_replan``): the continuation whose path the body follows until it eases
    #: into this one over :data:`REPLAN_EASE_S` before ``time``
    via: Continuation | None = field(default=None, repr=False, compare=False)

    @property
    def first_match(self) -> float:
        """The first continuation's match time (this one's without a re-plan)."""
        return self.via.first_match if self.via is not None else self.time

    @cached_property
    def alternatives(self) -> tuple[Continuation, ...]:
        """The next-best continuations on other clips, best first (``land_tries - 1`` at
        most; in the blend mode, where fewer clips matched, then the found clip's at earlier
        starts)."""
        return self.others() if self.others is not None else ()


def search_continuation(
    scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation
) -> Continuation:
    """Windows of Simulation 1 starting 0.1-1.0 s after the impact (later while contact lasts),
    each searched; the best over all starts wins."""
    cfg = scenario.response
    t_impact = naive.impact_time
    first = t_impact + float(np.clip(naive.contact_end - t_impact, cfg.search_start,
                                     cfg.contact_shift_max))  # fmt: skip
    if naive.impulse >= cfg.react_impulse:
        # a real hit: the active response after the reaction delay needs time to show, so the
        # recipient's own clip right after the hit cannot win by being closest
        first = max(first, t_impact + cfg.reaction_delay + cfg.active_min)
    return _search(scenario, cast, contact, naive, naive.motion, first, t_impact + cfg.search_end)


def replan_continuation(scenario: Scenario, cast: Cast, contact: ContactEstimate,
                        naive: NaiveSimulation, cont: Continuation,
                        sim2: TransitionSimulation) -> Continuation:  # fmt: skip
    """The physical mode's re-plan (``land_replan``): the search again, on Simulation 2's body
    (``sim2``, which did not land on ``cont``) in windows starting from ``cont``'s match to
    ``land_replan`` s after it: a continuation for the body as the hit and the first clip left
    it (its speed too, where Simulation 1's found a clip it could not stop on). The path
    follows ``cont``'s until it eases into the new clip by its match."""
    first = cont.time
    found = _search(scenario, cast, contact, naive, sim2.motion, first,
                    first + scenario.response.land_replan, alternatives=False)  # fmt: skip
    return replace(found, via=cont)


def _search(scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation,
            motion: Motion, first: float, last: float,
            alternatives: bool = True) -> Continuation:  # fmt: skip
    """The best continuation of the simulated ``motion`` (frame 0 at the rewind) over windows
    starting from scenario time ``first`` to ``last`` (with the next-best clips for
    ``land_tries`` when ``alternatives``)."""
    cfg = scenario.response
    index = cast.index
    q_fps = index.window.fps
    query = motion.resample(q_fps)
    starts = np.arange(int(np.ceil((first - contact.rewind) * q_fps - 1e-9)),
                       int(np.floor((last - contact.rewind) * q_fps + 1e-9)) + 1)  # fmt: skip
    starts = starts[starts + index.length <= query.num_frames]
    if starts.size == 0:
        raise SearchError("the simulated trajectory is too short for one search window")
    parts = cast.recipient.parts
    rec = cast.recipient
    hit = naive.impulse >= cfg.react_impulse

    def allowed(r: SearchResult, start: float) -> bool:
        # after a real hit the recipient's own clip around its undisturbed time is no reaction
        own = rec.clock0 + contact.rewind + start / q_fps
        return not (hit and r.clip == rec.clip.name and abs(r.time - own) < cfg.own_clip_margin)

    nearest: list[tuple[SearchResult | None, int]] = [
        (index.query(query, s, parts=parts), s) for s in starts.tolist()
    ]

    def search(deeper: int) -> list[tuple[SearchResult, int]]:
        found = []
        for first, s in nearest:
            r = first
            if r is not None and not allowed(r, s):
                r = next((c for c in index.top_k(query, s, n=deeper, parts=parts)
                          if allowed(c, s)), None)  # fmt: skip
            if r is not None:
                found.append((r, s))
        return found

    # the runners-up of each start, further down when the nearest are all the own clip (the
    # real bow pushed from behind matched only its own bow in the first 4)
    results = search(4) or search(OWN_CLIP_DEPTH)
    if not results:
        raise SearchError("no library window continues the response (only the recipient's own "
                          "clip matched, and a real hit rules it out)")  # fmt: skip
    results.sort(key=lambda r: r[0].distance)
    # a continuation that walks into the attacker (back on its own clip) is no continuation
    best, best_start = next((r for r in results
                             if not _runs_into(cast, cfg, r[0], contact.rewind + r[1] / q_fps)),
                            results[0])  # fmt: skip

    def continuation(r: SearchResult, start: int) -> Continuation:
        found_clip = cast.library[r.clip]
        found = found_clip.transformed(r.yaw, r.translation).replace(name=r.clip)
        return Continuation(r, index.top_k(query, start, n=cfg.top_k, parts=parts),
                            contact.rewind + start / q_fps, found, found_clip)  # fmt: skip

    def others() -> tuple[Continuation, ...]:
        # the next-best window of each other clip, for land_tries; in the blend mode, where
        # fewer other clips matched, then the found clip's next-best windows at earlier
        # starts: a fall's still frames match a lying body at any start about equally, and
        # how far the final blend must correct Simulation 2 there is not in the distance
        # (later landings are blend_settle's; the physical mode re-plans, land_replan)
        alts: list[Continuation] = []
        seen = {best.clip}
        for r, s in results:
            if len(alts) >= cfg.land_tries - 1:
                break
            if r.clip in seen or _runs_into(cast, cfg, r, contact.rewind + s / q_fps):
                continue
            seen.add(r.clip)
            alts.append(continuation(r, s))
        for r, s in results if cfg.mode == "blend" else ():
            if len(alts) >= cfg.land_tries - 1:
                break
            if (
                r.clip != best.clip
                or s >= best_start
                or _runs_into(cast, cfg, r, contact.rewind + s / q_fps)
            ):
                continue
            alts.append(continuation(r, s))
        return tuple(alts)

    return replace(continuation(best, best_start),
                   others=others if alternatives and cfg.land_tries > 1 else None)  # fmt: skip


def _runs_into(cast: Cast, cfg: ResponseConfig, r: SearchResult, at: float) -> bool:
    """Whether window ``r``'s clip, matched at scenario time ``at`` and played for ``tail``
    seconds, runs into the attacker's own clip (scanned at :data:`SCAN_FPS`)."""
    att = cast.attacker
    if att is None:
        return False
    clip = cast.library[r.clip]
    t = np.arange(0.0, min(cfg.tail, clip.duration - r.time), 1.0 / SCAN_FPS)
    if t.size == 0:
        return False
    found = clip.transformed(r.yaw, r.translation).sample(r.time + t).replace(fps=SCAN_FPS)
    own = att.motion.sample(at + t + att.clock0).replace(fps=SCAN_FPS)
    return bool(overlap_depths(cast.pair, [found, own]).max() > 0.02)


#: Simulation 2's controllers in the physical mode: trackers that keep a free-rooted body
#: balanced while it follows the found clip (the joint-only ``pd`` servo cannot)
PHYSICAL_TRACKERS = ("wholebody", "predictive")


class _Landing:
    """The physical mode's stop condition: from ``after`` s into the rollout, the recipient is
    within the landing tolerances of the desired path ``q`` (qpos per control tick, ``rate``
    Hz from the rollout's start); ``at`` is then that time (None until it is). Until then it
    keeps the check where the body came closest (``best``: the largest gap over its
    tolerance smallest; the give-up and the retries go by it) and the check where the final
    blend corrects least (``handoff``: the pelvis's gap beyond the ground shift the clip's
    placement takes up, over ``land_position``; the root's turn over its warning; the largest
    joint over ``land_joint``; the largest of the three smallest): a body that never lands
    hands off there, not wherever it has drifted (or fallen) to when the time is up.

    ``clip`` (the found clip's qpos per tick, ``pad`` ticks before the rollout's start and
    after its end) and ``offsets`` (ticks) time-warp the check: the body is compared with the
    found clip ``offsets`` ticks ahead of (or behind) the path too, and lands on the nearest
    (``phase``, s; the smallest shift among equals). A hit body that follows the clip late or
    early is on it, at another frame; the blend then lands on that frame.

    A body :data:`LAND_GIVE_UP` times further off than at its closest, :data:`LAND_GIVE_UP_S`
    after it and after ``keep`` s, stops the rollout (a body fallen away hands off at an earlier check)."""

    def __init__(self, cfg: ResponseConfig, q: F64, rate: float, after: float,
                 clip: F64 | None = None, offsets: NDArray[np.int64] | None = None,
                 pad: int = 0, keep: float = 0.0) -> None:  # fmt: skip
        self.cfg, self.q, self.rate, self.after, self.keep = cfg, q, rate, after, keep
        self.tol = np.array([cfg.land_position, cfg.land_angle, cfg.land_joint])
        self.clip, self.pad = clip, pad
        # the path itself first, then the shifts by size: argmin keeps the smallest among equals
        offs = np.zeros(1, np.int64) if offsets is None else np.asarray(offsets, np.int64)
        self.offsets = offs[np.argsort(np.abs(offs), kind="stable")]
        self.at: float | None = None
        self.gap = np.full(3, np.inf)  # the last check's pelvis (m), root and joint (rad) gaps
        self.phase = 0.0  # the last check's time shift onto the found clip (s)
        self.best = (np.inf, after, self.gap, 0.0)  # (largest gap / tolerance, time, gaps, phase)
        # where a body that never lands hands off: the check the final blend corrects least
        self.handoff = self.best

    def __call__(self, world: World, t: float) -> str | None:
        if t < self.after - 1e-9:
            return None
        i = min(int(round(t * self.rate)), len(self.q) - 1)
        if self.clip is None or self.offsets.size == 1:
            want, offs = self.q[i][None], self.offsets[:1]
        else:  # shifts that stay within the found clip's frames (``clip``'s non-NaN rows)
            rows = i + self.pad + self.offsets
            ok = (rows >= 0) & (rows < len(self.clip))
            rows, offs = rows[ok], self.offsets[ok]
            ok = np.isfinite(self.clip[rows, 0])
            rows, offs = rows[ok], offs[ok]
            want = np.concatenate([self.q[i][None], self.clip[rows[offs != 0]]])
            offs = np.concatenate([[0], offs[offs != 0]])
        cur = world.data.qpos[world.characters[0].qpos_slice]
        m = len(want)
        rel = quat_mul(quat_conj(want[:, 3:].reshape(m, -1, 4)), cur[3:].reshape(1, -1, 4))
        turn = np.linalg.norm(quat_log(rel), axis=-1)
        gaps = np.stack([np.linalg.norm(want[:, :3] - cur[:3], axis=1), turn[:, 0],
                         turn[:, 1:].max(axis=1)], axis=1)  # fmt: skip
        scores = (gaps / self.tol).max(axis=1)
        k = int(np.argmin(scores))
        score, self.gap, self.phase = float(scores[k]), gaps[k], float(offs[k]) / self.rate
        if score < self.best[0]:
            self.best = (score, t, self.gap, self.phase)
        # the final blend's correction: the pelvis's gap less the ground shift the clip's
        # placement takes up (``final.placed``), the joints, the root's turn (its warning)
        d = cur[:3] - want[:, :3]
        ground = np.maximum(np.hypot(d[:, 0], d[:, 1]) - self.tol[0], 0.0)
        left = np.maximum(np.maximum(np.hypot(ground, d[:, 2]) / self.tol[0],
                                     turn[:, 0] / WARN_ROOT_TURN_RAD), gaps[:, 2] / self.tol[2])  # fmt: skip
        h = int(np.argmin(left))
        if left[h] < self.handoff[0]:
            self.handoff = (float(left[h]), t, gaps[h], float(offs[h]) / self.rate)
        if score <= 1.0:
            self.at = t
            return "landed on the found clip"
        # long past its closest and far from it, the body has fallen away: the rest of
        # ``land_within`` would only cost time (it hands off at an earlier check)
        late = t > max(self.best[1] + LAND_GIVE_UP_S, self.keep)
        if late and score > LAND_GIVE_UP * max(self.best[0], 1.0):
            return "fell away from the found clip"
        return None


@dataclass(frozen=True)
class TransitionSimulation:
    """Simulation 2 from the rewind: the recipient ``motion`` (frame 0 at the rewind) and the
    attacker's (at its own clip rate), with the world it ran in."""

    motion: Motion
    attacker: Motion | None
    steps: int
    world: World
    contacts: ContactLog
    #: scenario time from which the attacker's own clip no longer runs into the recipient: its
    #: output follows the simulation until then (or the end of ``attacker_follow``)
    attacker_release: float = 0.0
    #: scenario time the blend lands on the found clip: the match time in the ``blend`` mode;
    #: in the ``physical`` mode when the body got there (or the simulation's end)
    landed: float = 0.0
    #: physical mode: the body reached the found clip within the landing tolerances
    on_clip: bool = True
    #: physical mode: the pelvis (m), root and largest joint (rad) gaps to the found clip at
    #: the landing (or the simulation's end)
    landing_gap: tuple[float, float, float] = (0.0, 0.0, 0.0)
    #: why Simulation 2 stopped early (it went unstable), else None; it ends at
    #: its last stable frame and the blend closes the rest
    unstable: str | None = None
    #: physical mode: the time shift (s) onto the found clip at the landing (``land_warp``):
    #: the blend lands on the found clip's frame that much later than the path's
    landing_phase: float = 0.0
    #: physical mode: the tracker took at least one capture-point balance step (``land_step_time``)
    balance_steps: bool = False
    #: physical mode: the closest landing check's largest gap over its tolerance (<= 1: landed;
    #: how the retries compare rollouts; a body that never lands hands off elsewhere)
    landing_score: float = 0.0
    #: physical mode, a body that never landed: what the final blend corrects at the hand-off
    #: (``_Landing.handoff``'s score); how such rollouts compare
    handoff_score: float = 0.0


def transition_simulation(scenario: Scenario, cast: Cast, contact: ContactEstimate,
                          naive: NaiveSimulation, cont: Continuation,
                          steps: bool = False) -> TransitionSimulation:  # fmt: skip
    """Simulation 2 (the recipient's limbs on ``friction_sim2``) from the same start and
    impact: the recipient follows the desired path to the found clip with ``sim2_controller``,
    yielding through the reaction delay as in Simulation 1 (the passive response), then
    recovering (the active). In the ``physical`` mode it runs on along the found clip until the body lands on it,
    with ``steps`` taking capture-point balance steps of ``land_step_time`` s."""
    cfg = scenario.response
    rewind = contact.rewind
    end = cont.time
    physical = cfg.mode == "physical"
    left = cont.found.duration - cont.best.time  # no further than the found clip goes
    if physical:
        end += max(0.0, min(cfg.land_within, left))
    else:  # the blend mode's landing may be chosen up to blend_settle s later (final.settle)
        end += max(0.0, min(cfg.blend_settle, left))
    release = 0.0
    if cast.attacker is not None:
        release = max(naive.impact_time + cfg.attacker_follow,
                      _attacker_clear(cast, cfg, naive, cont))  # fmt: skip
        end = max(end, release + cfg.attacker_blend)
    seconds = max(end - rewind, cfg.timestep)
    world = _world(cast, cfg, cfg.friction_sim2)
    world.set_state(naive.start_state)
    name = cfg.sim2_controller
    if physical and name not in PHYSICAL_TRACKERS:
        name = PHYSICAL_TRACKERS[0]
    every = int(controller_spec(name).defaults["control_every"] or 1)
    yields = yields_to(cfg, naive.impulse)
    q, rate = _recipient_path(cast, cfg, rewind, seconds, every, naive.impact_time, yields, cont)
    # the physical mode's body keeps its balance through a hit its ankles cannot take (it gives
    # way above the hips only): yielding whole, it is still off balance when the found clip
    # starts and falls from it (docs/benchmarks.md)
    options: dict[str, Any] | None = {"hold_balance": True} if physical else None
    if options is not None and steps:
        options.update(stepping=True, step_time=cfg.land_step_time)
    recipient = tracker = _controller(name, cfg, world, 0, q, 0.0, rate, options)
    if yields and isinstance(recipient, GainScalable):
        recipient = Scheduled(recipient, yield_schedule(cfg, naive.impact_time - rewind))
    landing = None
    if physical:
        pad = int(round(cfg.land_warp * rate))
        ticks = rewind + np.arange(-pad, len(q) + pad) / rate
        clip = _found_path(cast, cont, ticks) if pad else None
        step = max(1, int(round(rate * LAND_WARP_STEP)))
        offsets = np.arange(-(pad // step), pad // step + 1) * step
        # a re-plan searches Simulation 2's body up to a window past land_replan: kept that long
        keep = cont.time + cfg.land_replan + cast.index.window.duration - rewind
        landing = _Landing(cfg, q, rate, max(cont.time, release) - rewind, clip, offsets, pad,
                           keep)  # fmt: skip
        if cfg.land_stiffness != 1.0 and isinstance(tracker, WholeBodyTracker):
            # from the first match: a re-plan's body is the first try's until its path turns
            stiff = max(cont.first_match, release) - rewind
            recipient = _StiffenFrom(recipient, tracker, stiff, cfg.land_stiffness)
    ctrls = [recipient]
    fps = [cast.recipient.motion.fps]
    if cast.attacker is not None:
        ctrls += _attacker(world, cast, cfg, rewind)
        fps.append(cast.attacker.motion.fps)
    # the joints the body does not simulate (toes, clavicles, the head below a neck body) take
    # what Simulation 2 was asked to do, not the old clip: the final blend then corrects only
    # what the physics did not follow
    rfps = cast.recipient.motion.fps
    asked = desired_motion(cast, cfg, rewind + np.arange(int(np.ceil(seconds * rfps)) + 1) / rfps,
                           naive.impact_time, yields, cont).replace(fps=rfps)  # fmt: skip
    res = rollout(
        world, seconds, controllers=ctrls, impacts=_impacts(scenario, rewind), record_fps=fps,
        references=[asked] + [a.motion for a in cast.actors[1:]],
        reference_start=[0.0] + [rewind + a.clock0 for a in cast.actors[1:]],
        contact_every=CONTACT_EVERY,
        stop=landing, on_unstable="stop",
    )  # fmt: skip
    attacker = res.motion(1, fps[-1], name="attacker_sim") if cast.attacker is not None else None
    assert res.contact_log is not None
    landed, on_clip, gap, phase, score, left = cont.time, True, (0.0, 0.0, 0.0), 0.0, 0.0, 0.0
    if landing is not None:
        on_clip = landing.at is not None
        # not landed: where the final blend corrects least (a simulation that went unstable
        # before the match still lands no earlier than it)
        score, (left, at, last, phase) = landing.best[0], landing.handoff
        if landing.at is not None:
            at, last, phase = landing.at, landing.gap, landing.phase
            score = float(np.max(last / landing.tol))
        elif not np.isfinite(last).all():  # never checked (unstable before the match)
            at, last, phase = res.duration, landing.gap, 0.0
        landed = max(cont.time, rewind + min(at, res.duration))
        gap = (float(last[0]), float(last[1]), float(last[2]))
    unstable = res.reason if res.status == "unstable" else None
    stepped = steps and isinstance(tracker, WholeBodyTracker) and bool(tracker.steps_taken)
    return TransitionSimulation(res.motion(0, name="sim2"), attacker, res.steps, world,
                                res.contact_log, release, landed, on_clip, gap,
                                unstable, phase, stepped, score, left)  # fmt: skip


class _StiffenFrom:
    """``inner`` (driving ``tracker``) with ``tracker``'s joints ``factor`` times stiffer from
    rollout time ``at`` on (the physical mode's ``land_stiffness``, from the match)."""

    def __init__(self, inner: Controller, tracker: WholeBodyTracker, at: float,
                 factor: float) -> None:  # fmt: skip
        self.inner, self.tracker, self.at, self.factor = inner, tracker, at, factor
        self.control_every = inner.control_every
        self._done = False

    def reset(self, world: World) -> None:
        self.inner.reset(world)
        self._done = False

    def control(self, world: World, t: float) -> None:
        if not self._done and t >= self.at - 1e-9:
            self.tracker.stiffen_joints(self.factor)
            self._done = True
        self.inner.control(world, t)


#: the physical mode's landing check gives up on a body this many seconds past its closest
#: check and this many times further off (in tolerances, at least that many)
LAND_GIVE_UP_S = 0.3
LAND_GIVE_UP = 3.0
#: the physical mode re-plans at most this many times, each from the last while each comes closer
REPLANS = 3
#: a re-plan's path eases from the first continuation's into the new one over this many seconds
#: before the new match
REPLAN_EASE_S = 0.1


#: the physical mode's time-warped landing check compares the body with the found clip at
#: shifts this many seconds apart (within ``land_warp``)
LAND_WARP_STEP = 0.01


def _found_path(cast: Cast, cont: Continuation, times: F64) -> F64:
    """The found clip's qpos at scenario ``times`` (played from the match as in
    :func:`desired_motion`); NaN rows where ``times`` fall outside the clip."""
    rec = cast.recipient
    clip_t = cont.best.time + (np.asarray(times, dtype=np.float64) - cont.time)
    found = ground_root(cont.found.sample(clip_t), rec.parts, turn=False)
    q = rec.character.qpos_from_motion(found)
    q[(clip_t < 0.0) | (clip_t > cont.found.duration)] = np.nan
    return q


def _output_end(cfg: ResponseConfig, cont: Continuation, landed: float | None = None) -> float:
    """Scenario time of the recipient output's last frame (the found clip's tail included)
    when the blend lands on the found clip at ``landed`` (the match time if None)."""
    land = cont.time if landed is None else landed
    return land + max(0.0, min(cfg.tail, cont.found.duration - cont.best.time - (land - cont.time)))


def _attacker_clear(cast: Cast, cfg: ResponseConfig, naive: NaiveSimulation,
                    cont: Continuation) -> float:  # fmt: skip
    """The last scenario time at which the attacker's own clip still runs into the recipient's
    planned output (its clip eased into the found clip), scanned at :data:`SCAN_FPS` from the
    impact: until then the attacker's output must stay simulated (physical), not its clip."""
    att, rec = cast.attacker, cast.recipient
    assert att is not None
    t = np.arange(naive.impact_time, _output_end(cfg, cont), 1.0 / SCAN_FPS)
    if t.size == 0:
        return naive.impact_time
    w = transition_weights(t, naive.impact_time, cfg.reaction_delay, cont.time)
    planned = blend_poses(rec.motion.sample(t + rec.clock0),
                          cont.found.sample(cont.best.time + (t - cont.time)), w)  # fmt: skip
    own = att.motion.sample(t + att.clock0)
    world = cast.pair
    depth = overlap_depths(world, [planned.replace(fps=SCAN_FPS), own.replace(fps=SCAN_FPS)])
    hit = np.flatnonzero(depth > 0.0)
    return float(t[hit[-1]] + 1.0 / SCAN_FPS) if hit.size else naive.impact_time
