"""The response pipeline (Zordan et al. 2005) as named stages (:mod:`reactmocap.response.stages`):
cast, contact estimate, naive simulation, continuation search, transition simulation, blend,
report. :func:`run_response` returns everything in memory; :func:`run_scenario` also writes the
outputs."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, TypeVar

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap import __version__
from reactmocap import metrics as qm
from reactmocap.errors import SearchError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.response import final, stages
from reactmocap.response.library_cache import LibraryCache, prepare_library
from reactmocap.response.scenario import Scenario
from reactmocap.search import SearchResult
from reactmocap.sim.bodies import SIM_BODIES
from reactmocap.sim.character import Character
from reactmocap.sim.impacts import overlap_depths

__all__ = ["LibraryCache", "ResponseResult", "prepare_library", "run_response", "run_scenario"]

F64 = NDArray[np.float64]
T = TypeVar("T")


@dataclass
class ResponseResult:
    """Everything a response produced, in scenario time."""

    recipient: Motion
    attacker: Motion | None
    matched: SearchResult
    candidates: list[SearchResult]
    impact_time: float
    #: the match time: the scenario time at which ``found`` is at ``matched.time`` (the
    #: physical mode lands later, at the report's ``transition.end``)
    transition_end: float
    sim1: Motion
    sim2: Motion
    blended: Motion
    found: Motion
    before: Motion
    report: dict[str, Any] = field(default_factory=dict)
    #: the simulated world and its pre-impact state (to measure bare stepping of the same model)
    model: mujoco.MjModel | None = None
    start_state: F64 | None = None
    #: the recipient's body parts
    parts: BodyPartMap | None = None
    #: the hit over time, for the video: scenario times ``(n,)``, contact points and the world
    #: forces on the recipient ``(n, 3)``
    hit: tuple[F64, F64, F64] | None = None
    #: the recipient's own clip over the output's frames, as if nothing had happened
    undisturbed: Motion | None = None


def run_response(scenario: Scenario, cache: LibraryCache | None = None) -> ResponseResult:
    """Run the whole pipeline and return motions and the report (no files written). ``cache``
    keeps libraries and indexes between calls (a fresh one per call if omitted)."""
    cache = LibraryCache() if cache is None else cache
    timings: dict[str, float] = {}
    t_all = time.perf_counter()

    def timed(name: str, fn: Callable[..., T], *args: Any) -> T:
        t = time.perf_counter()
        out = fn(*args)
        timings[name] = timings.get(name, 0.0) + time.perf_counter() - t
        return out

    cast = timed("cast", stages.cast, scenario, cache)
    contact = timed("scan", stages.estimate_contact, scenario, cast)
    naive = timed("sim1", stages.naive_simulation, scenario, cast, contact)
    cont = timed("search", stages.search_continuation, scenario, cast, contact, naive)
    cfg = scenario.response
    # the blend mode's later landing (``blend_settle``) only where the blend at the match
    # would warn: the others run Simulation 2 to the match alone and cost nothing more
    settles = cfg.mode == "blend" and cfg.blend_settle > 0.0
    at_match = replace(scenario, response=replace(cfg, blend_settle=0.0)) if settles else scenario
    sim2 = timed("sim2", stages.transition_simulation, at_match, cast, contact, naive, cont)
    # the body did not land: a re-plan from where it is (``land_replan``), the same clip with
    # balance steps (``land_step_time``), then the search's next-best clips (``land_tries``);
    # the one it comes closest to wins; if none lands, the one the final blend corrects least
    first = cont
    physical = cfg.mode == "physical"
    retries: list[tuple[stages.Continuation, bool]] = []
    tried = [(cont, sim2)]
    for _ in range(stages.REPLANS if physical and cfg.land_replan > 0 else 0):
        if sim2.on_clip or sim2.unstable is not None:
            break
        try:
            plan = timed("search", stages.replan_continuation, scenario, cast, contact, naive,
                         cont, sim2)  # fmt: skip
        except SearchError:  # Simulation 2 too short for a window past the match
            break
        other = timed("sim2", stages.transition_simulation, scenario, cast, contact, naive, plan)
        tried.append((plan, other))
        if _landing_score(other) >= _landing_score(sim2):
            break
        cont, sim2 = plan, other
    if not sim2.on_clip:
        retries += [(first, True)] * (physical and cfg.land_step_time > 0)
        retries += [(alt, False) for alt in first.alternatives]
    for alt, steps in retries:
        other = timed("sim2", stages.transition_simulation, scenario, cast, contact, naive, alt,
                      steps)  # fmt: skip
        tried.append((alt, other))
        if _landing_score(other) < _landing_score(sim2):
            cont, sim2 = alt, other
        if sim2.on_clip:
            break
    if physical and not sim2.on_clip:
        cont, sim2 = min(tried, key=lambda c: _handoff_score(c[1]))
    out = timed("blend", final.blend, scenario, cast, contact, naive, cont, sim2)
    tries = cfg.mode == "blend" and cfg.land_tries > 1
    score = _blend_score(cast, out) if tries or settles else (False, 0.0)
    if settles and score > (False, 1.0):
        # Simulation 2 runs again, on past the match (a rollout cannot be resumed: its
        # controllers restart), and the landing that corrects least wins, the match included
        later = timed("sim2", stages.transition_simulation, scenario, cast, contact, naive, cont)
        later = timed("blend", final.settle, scenario, cast, contact, naive, cont, later)
        blended = timed("blend", final.blend, scenario, cast, contact, naive, cont, later)
        if (s := _blend_score(cast, blended)) < score:
            sim2, out, score = later, blended, s
    for alt in cont.alternatives if tries and score > (False, 1.0) else ():
        # the blend mode's land_tries: a continuation whose final blend corrects less wins
        # (the alternatives are searched only here, where the final blend would warn)
        if score <= (False, 1.0):
            break
        other = timed("sim2", stages.transition_simulation, scenario, cast, contact, naive, alt)
        other = timed("blend", final.settle, scenario, cast, contact, naive, alt, other)
        blended = timed("blend", final.blend, scenario, cast, contact, naive, alt, other)
        if (s := _blend_score(cast, blended)) < score:
            cont, sim2, out, score = alt, other, blended, s
    timings["total"] = time.perf_counter() - t_all
    report = _report(scenario, cast, contact, naive, cont, sim2, out, timings)
    rec = cast.recipient
    fps = rec.motion.fps
    return ResponseResult(
        recipient=out.recipient,
        attacker=out.attacker,
        matched=cont.best,
        candidates=cont.candidates,
        impact_time=naive.impact_time,
        transition_end=cont.time,
        sim1=naive.motion,
        sim2=sim2.motion,
        blended=out.blended,
        found=out.found,
        before=rec.motion.sample(np.arange(0, int(cont.time * fps) + 1) / fps + rec.clock0),
        report=report,
        model=sim2.world.model,
        start_state=naive.start_state,
        parts=rec.parts,
        hit=_hit_marks(scenario, cast, contact, sim2, out),
        undisturbed=rec.motion.sample(out.recipient.times + rec.clock0).replace(fps=fps),
    )


def _handoff_score(sim2: stages.TransitionSimulation) -> float:
    """What the final blend corrects at the hand-off of a body that never landed, over its
    budgets (``stages._Landing.handoff``; a simulation that went unstable is worst)."""
    return np.inf if sim2.unstable is not None else sim2.handoff_score


def _landing_score(sim2: stages.TransitionSimulation) -> float:
    """How close Simulation 2's body came to its found clip: its closest landing check's
    largest gap over the tolerance (<= 1: landed; a simulation that went unstable is worst)."""
    return np.inf if sim2.unstable is not None else sim2.landing_score


def _blend_score(cast: stages.Cast, out: final.Blend) -> tuple[bool, float]:
    """How much the final blend corrects Simulation 2: whether the output overlaps the
    attacker beyond its warning threshold (first: a continuation that overlaps never wins over
    one that does not), then its largest joint turn and root offset over their warning
    thresholds (<= 1: within both)."""
    parts = cast.recipient.parts
    overlap = False
    if out.attacker is not None:
        rec = out.recipient
        att = out.attacker.sample(rec.times).replace(fps=rec.fps)
        overlap = bool(overlap_depths(cast.pair, [rec, att]).max() > qm.WARN_OVERLAP_M)
    return overlap, qm.blend_correction_over_warning(out.simulated, out.blended, parts)


def _report(
    scenario: Scenario,
    cast: stages.Cast,
    contact: stages.ContactEstimate,
    naive: stages.NaiveSimulation,
    cont: stages.Continuation,
    sim2: stages.TransitionSimulation,
    out: final.Blend,
    timings: dict[str, float],
) -> dict[str, Any]:
    cfg = scenario.response
    rec = cast.recipient
    parts = rec.parts
    best = cont.best
    fps = rec.motion.fps
    undisturbed = rec.motion.sample(out.recipient.times + rec.clock0).replace(fps=fps)
    impact_frame = int(np.ceil(naive.impact_time * fps - 1e-9))
    shift = qm.reaction_displacement(out.recipient, undisturbed, parts, impact_frame)
    impulse = _impulse(scenario, sim2)
    overlap = 0.0
    if cast.attacker is not None and out.attacker is not None:
        att = out.attacker.sample(out.recipient.times).replace(fps=fps)
        world = cast.pair
        overlap = float(overlap_depths(world, [out.recipient, att]).max())
    quality = {
        "match_distance": qm.match_distance(best.distance),
        "blend_root_offset_max_m": qm.blend_root_offset_max_m(out.simulated, out.blended, parts),
        "blend_joint_correction_max_rad": qm.blend_joint_correction_max_rad(
            out.simulated, out.blended
        ),
        "blend_root_turn_max_rad": qm.blend_root_turn_max_rad(out.simulated, out.blended),
        "stitch_velocity_jump_rad_s": qm.stitch_velocity_jump_rad_s(out.recipient, out.seams),
        "foot_skate_m": qm.foot_skate_m(out.recipient, parts),
        "penetration_max_m": qm.penetration_max_m(out.recipient),
        "fell": qm.fell(out.recipient, parts),
        "intended_fall": qm.intended_fall(cont.found_clip, parts, best.frame),
        "reaction_displacement_m": float(np.linalg.norm(shift)),
        "reaction_direction_error_deg": qm.direction_error_deg(shift, impulse),
        "transition_s": sim2.landed - naive.impact_time,
        "contact_impulse_Ns": float(np.linalg.norm(impulse)),
        "character_overlap_max_m": overlap,
        **_attacker_quality(cast, out),
    }
    warnings = _warnings(scenario, cast, contact, naive, cont, quality)
    if naive.unstable is not None:
        warnings.append(f"Simulation 1 stopped early ({naive.unstable}): the search used its "
                        f"first {naive.motion.duration:.2f} s")  # fmt: skip
    if sim2.unstable is not None:
        warnings.append(f"Simulation 2 stopped early ({sim2.unstable}): the final blend "
                        "starts from its last stable frame")  # fmt: skip
    elif not sim2.on_clip:
        gap = sim2.landing_gap
        warnings.append(
            f"physical mode: the body did not reach the found clip within {cfg.land_within} s "
            f"(pelvis {gap[0]:.2f} m, root {gap[1]:.2f} rad, a joint {gap[2]:.2f} rad off; "
            f"tolerances {cfg.land_position} m, {cfg.land_angle} rad, {cfg.land_joint} rad, "
            "where the blend corrects least): the blend closed the rest"
        )
    return {
        "scenario": scenario.name,
        "warnings": warnings,
        "reactmocap_version": __version__,
        "mujoco_version": mujoco.__version__,
        "matched": {
            "clip": best.clip,
            "frame": best.frame,
            "time": cont.time,
            "clip_time": best.time,
            "distance": best.distance,
            "yaw_deg": best.yaw_deg,
            "translation": list(best.translation),
            "breakdown": best.breakdown.to_dict(),
        },
        "candidates": [c.to_dict() for c in cont.candidates],
        "library_skipped": [
            {"clip": str(f.path), "reason": f.reason} for f in cast.library.failures
        ],
        "impact": {
            "time": naive.impact_time,
            "body": contact.body,
            "peak_force_N": naive.peak_force,
            "rewind_time": contact.rewind,
            "contact_end": naive.contact_end,
            "impulse_Ns": impulse.tolist(),
        },
        "transition": {
            "start": naive.impact_time,
            "end": sim2.landed,
            "match": cont.time,
            "reaction_delay": cfg.reaction_delay,
            "mode": cfg.mode,
            "landed_on_clip": sim2.on_clip,
            "landing_gap": dict(zip(("pelvis_m", "root_rad", "joint_rad"), sim2.landing_gap)),
            "landing_phase_s": sim2.landing_phase,
            "found_shift_m": list(out.found_shift),
            "balance_steps": sim2.balance_steps,
            "replanned": cont.via is not None,
        },
        "timings_s": timings,
        "steps": {"sim1": naive.steps, "sim2": sim2.steps},
        "quality": quality,
        "config": asdict(cfg),
        "outputs": {},
    }


def _attacker_quality(cast: stages.Cast, out: final.Blend) -> dict[str, float | None]:
    """The attacker's output against its clip (None without an attacker)."""
    att = cast.attacker
    if out.attacker is None or att is None:
        return dict.fromkeys(("attacker_speed_ratio", "attacker_foot_skate_m", "attacker_lift_m"))
    return {
        "attacker_speed_ratio": qm.speed_ratio(out.attacker, att.motion),
        "attacker_foot_skate_m": qm.foot_skate_m(out.attacker, att.parts),
        "attacker_lift_m": qm.lift_above_source_m(out.attacker, att.motion, att.parts),
    }


#: (quality field, name of its threshold in :mod:`reactmocap.metrics`, message) of the
#: attacker's warnings; the threshold is read when warning, as the others are
_ATTACKER_WARNINGS = (
    ("attacker_speed_ratio", "WARN_ATTACKER_SPEED_RATIO",
     "the attacker moves a joint {value:.2f}x faster than its clip ever does (more than {limit}x)"),
    ("attacker_foot_skate_m", "WARN_ATTACKER_FOOT_SKATE_M",
     "the attacker's planted feet slide {value:.2f} m in all (more than {limit} m)"),
    ("attacker_lift_m", "WARN_ATTACKER_LIFT_M",
     "the attacker's body is {value:.2f} m higher off the floor than its clip ever is (more "
     "than {limit} m): held or blended in the air"),
)  # fmt: skip


def _warnings(
    scenario: Scenario,
    cast: stages.Cast,
    contact: stages.ContactEstimate,
    naive: stages.NaiveSimulation,
    cont: stages.Continuation,
    quality: dict[str, Any],
) -> list[str]:
    """What a user should know before trusting the animation (thresholds in
    :mod:`reactmocap.metrics`)."""
    out = []
    q = quality
    if q["character_overlap_max_m"] > qm.WARN_OVERLAP_M:
        out.append(f"the characters overlap by {100 * q['character_overlap_max_m']:.1f} cm in "
                   f"the output (more than {100 * qm.WARN_OVERLAP_M:.0f} cm)")  # fmt: skip
    if q["blend_root_offset_max_m"] > qm.WARN_ROOT_OFFSET_M:
        out.append(f"the final blend moves the root by {q['blend_root_offset_max_m']:.2f} m "
                   f"(more than {qm.WARN_ROOT_OFFSET_M} m): the simulation ended far from the "
                   "found clip")  # fmt: skip
    if q["blend_joint_correction_max_rad"] > qm.WARN_JOINT_CORRECTION_RAD:
        out.append(f"the final blend turns a joint by {q['blend_joint_correction_max_rad']:.2f} "
                   f"rad (more than {qm.WARN_JOINT_CORRECTION_RAD})")  # fmt: skip
    if q["blend_root_turn_max_rad"] > qm.WARN_ROOT_TURN_RAD:
        out.append(f"the final blend turns the root by {q['blend_root_turn_max_rad']:.2f} rad "
                   f"(more than {qm.WARN_ROOT_TURN_RAD})")  # fmt: skip
    # the attacker's fields are None without an attacker
    for key, threshold, text in _ATTACKER_WARNINGS:
        value, limit = q[key], getattr(qm, threshold)
        if value is not None and value > limit:
            out.append(text.format(value=value, limit=limit))
    if cast.attacker is not None and contact.time <= 0.0:
        out.append("the characters already touch when the scenario starts (place them apart)")
    if cast.attacker is not None and naive.contacts.empty:
        out.append("the attacker never touched the recipient: nothing was hit")
    rec = cast.recipient
    if naive.impact_time > rec.motion.duration - rec.clock0:
        out.append(f"the impact ({naive.impact_time:.2f} s) comes after the recipient's clip "
                   f"ends ({rec.motion.duration - rec.clock0:.2f} s into the scenario)")  # fmt: skip
    cfg = scenario.response
    own = rec.clock0 + cont.time  # the recipient's own clip time had nothing happened
    if (naive.impulse >= cfg.react_impulse and cont.best.clip == rec.clip.name
            and abs(cont.best.time - own) < cfg.own_clip_margin):  # fmt: skip
        out.append(f"the recipient carries on with its own clip after an impulse of "
                   f"{naive.impulse:.1f} N s (from {cfg.react_impulse} N s it should react)")  # fmt: skip
    return out


def _hit_marks(scenario: Scenario, cast: stages.Cast, contact: stages.ContactEstimate,
               sim2: stages.TransitionSimulation, out: final.Blend) -> tuple[F64, F64, F64]:  # fmt: skip
    """Where and how hard the recipient was hit, over time (for the video)."""
    if scenario.impact is not None:
        imp = scenario.impact
        fps = out.recipient.fps
        frames = np.arange(
            int(np.ceil(imp.at * fps)), int(np.floor((imp.at + imp.duration) * fps)) + 1
        )
        frames = frames[frames < out.recipient.num_frames]
        joint = cast.recipient.character.anchors[SIM_BODIES.index(Character.body_name(imp.body))]
        points = out.recipient.global_positions()[frames, int(joint)]
        forces = np.tile(np.asarray(imp.force, dtype=np.float64), (frames.size, 1))
        return frames / fps, points, forces
    log = sim2.contacts
    return log.times + contact.rewind, log.point, log.force


def _impulse(scenario: Scenario, sim2: stages.TransitionSimulation) -> F64:
    """``(3,)`` the world impulse on the recipient (N s): the explicit impact's, or what the
    attacker's contacts delivered in Simulation 2."""
    if scenario.impact is not None:
        return np.asarray(scenario.impact.force) * scenario.impact.duration
    return sim2.contacts.impulse


def run_scenario(
    scenario: Scenario,
    out_dir: str | Path | None = None,
    *,
    plot: bool = False,
    video: bool = False,
    cache: LibraryCache | None = None,
) -> dict[str, Any]:
    """Run a scenario; with ``out_dir`` write ``recipient.bvh``, ``attacker.bvh``,
    ``report.json`` (and ``plot.png``, a video), each atomically, and none of them if any
    fails. Returns the report."""
    from reactmocap.response.outputs import write_outputs

    result = run_response(scenario, cache)
    if out_dir is None:
        return result.report
    return write_outputs(result, scenario, Path(out_dir), plot=plot, video=video)
