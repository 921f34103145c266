"""The last stage of a response: the final blend onto the found clip and the attacker's
output around the recipient's (see :mod:`reactmocap.response.stages` for the ones before)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.library.placement import ground_root
from reactmocap.metrics import (
    FALL_FRACTION,
    blend_correction_over_warning,
    intended_fall,
    joint_speed_max_m_s,
    planted,
)
from reactmocap.response.blend import blend_poses, final_blend
from reactmocap.response.footlock import lock_feet, place_ankles
from reactmocap.response.scenario import ResponseConfig, Scenario
from reactmocap.response.stages import (
    Actor,
    Cast,
    ContactEstimate,
    Continuation,
    NaiveSimulation,
    TransitionSimulation,
    desired_motion,
    yields_to,
)
from reactmocap.rotations import quat_conj, quat_mul
from reactmocap.sim.bodies import SIM_BODIES, SIM_PARENTS
from reactmocap.sim.impacts import overlap_depths

__all__ = ["Blend", "blend", "placed", "settle"]

F64 = NDArray[np.float64]
#: the shortest span (s) over which the final blend moves the root (a contact that delays the
#: root's correction cannot squeeze it into fewer frames)
ROOT_BLEND_MIN_S = 0.2
#: MuJoCo's default gravity (m/s^2): the attacker's last simulated pose falls under it
STANDARD_GRAVITY = 9.81
#: how many times the attacker's blend back to its clip may double its length to move no joint
#: faster than its clip's fastest
BLEND_BACK_TRIES = 5
#: the blend mode's ``blend_settle`` tries a landing every this many seconds past the match
SETTLE_STEP_S = 0.05
#: the attacker steps aside until the two overlap by no more than this (m) ...
ASIDE_MARGIN_M = 0.005
#: ... re-measured this many times (each adds the depth still left)
ASIDE_TRIES = 12
#: the step aside is taken in steps: a planted foot steps (lifted ``STEP_LIFT_M``, over
#: ``STEP_S``) once the root will be more than ``STEP_M`` past it by the step's end; the root
#: moves no faster than a step per step time (a person's side step: ~0.25-0.4 m in ~0.3 s)
STEP_M = 0.25
STEP_S = 0.3
STEP_LIFT_M = 0.06
#: ... and the root crouches so that no leg stretches past this share of its length
LEG_REACH = 0.97


def _clear_of(cast: Cast, recipient: Motion, impact: float) -> float:
    """The last time after ``impact`` at which the attacker's own clip runs into the recipient's
    output (``impact`` if never)."""
    att = cast.attacker
    assert att is not None
    fps = recipient.fps
    i0 = int(np.ceil(impact * fps))
    t = np.arange(i0, recipient.num_frames) / fps
    if t.size == 0:
        return impact
    own = att.motion.sample(t + att.clock0).replace(fps=fps)
    world = cast.pair
    depth = overlap_depths(world, [recipient.sample(t).replace(fps=fps), own])
    hit = np.flatnonzero(depth > 0.0)
    return float(t[hit[-1]] + 1.0 / fps) if hit.size else impact


def _attacker_output(cfg: ResponseConfig, att: Actor, contact: ContactEstimate,
                     sim2: TransitionSimulation, duration: float, shift_times: F64,
                     shift: F64, release: float, speed: float) -> Motion:  # fmt: skip
    """The attacker's output: its clip until the rewind, its simulation (moved by the
    recipient's blend ``shift`` at ``shift_times``, held after) until ``release``, then
    blended back to its clip over ``attacker_blend`` or longer: the straight-line gap closed at
    no more than half its clip's fastest joint ``speed`` (m/s), and the blend lengthened until
    no joint moves faster than ``speed``."""
    assert sim2.attacker is not None
    afps = att.motion.fps
    t = np.arange(0, int(np.floor(duration * afps)) + 1) / afps
    own = ground_root(att.motion.sample(t + att.clock0).replace(fps=afps), att.parts, turn=False)
    held = sim2.attacker.sample(np.clip(t - contact.rewind, 0, sim2.attacker.duration))
    sim = ground_root(_falling_when_held(held, t - contact.rewind - sim2.attacker.duration,
                                         sim2.attacker, att.parts), att.parts, turn=False)  # fmt: skip
    if shift_times.size:
        # horizontal only: a blend that lifts a fallen recipient onto a standing clip carried
        # the attacker lying on the floor 0.8-1.2 m up with it (the real walk-left kicked)
        moved = np.zeros((t.size, 3))
        moved[:, :2] = np.stack([np.interp(t, shift_times, shift[:, k]) for k in range(2)], axis=1)
        moved[t < shift_times[0]] = 0.0
        if cfg.mode == "physical":
            # the recipient's per-joint blend can squeeze its correction into a few frames (the
            # run kicked: its hit body 22.9 m/s); the attacker follows it no faster than half
            # its clip's fastest joint speed, as the blend back does
            moved = _rate_limited(moved, 0.5 * speed / afps)
        sim = sim.replace(root_positions=sim.root_positions + moved)
    # back to the clip no faster than the capture moves: the blend adds (gap / duration) to
    # the joints' speed, kept within half the clip's fastest joint speed
    # a kicker its simulation knocked down stays down: blended back to its standing clip it
    # would rise through the air (no get-up exists; the real respond kicked rose 0.36 m clear)
    pelvis = att.parts.joint_of("pelvis")
    standing = float(att.motion.global_positions()[:, pelvis, 2].max())
    if sim.slice(-1).global_positions()[0, pelvis, 2] < FALL_FRACTION * standing:
        release = np.inf
    i = min(int(np.searchsorted(t, release)), t.size - 1)
    gap = float(np.linalg.norm(sim.slice(i, i + 1).global_positions()[0]
                               - own.slice(i, i + 1).global_positions()[0], axis=1).max())  # fmt: skip
    span = max(cfg.attacker_blend, gap / max(0.5 * speed, 1e-9))
    for _ in range(BLEND_BACK_TRIES):
        w = np.where(t < contact.rewind, 1.0, np.clip((t - release) / span, 0, 1))
        out = ground_root(blend_poses(sim, own, w), att.parts).replace(name="attacker")
        # the gap above is a straight line, but the blend turns every joint along its arc, and
        # a clip that spins while the simulation stands turns that arc by whole turns: the
        # blend is lengthened until it moves no joint faster than the capture does
        if joint_speed_max_m_s(out.slice(i)) <= speed:
            break
        span *= 2.0
    # the blend back slides the root under planted feet (0.3-0.4 m in the examples' punch and
    # push from behind): they are pinned as the recipient's are; the clip before the rewind,
    # and the ends, stay exact
    j = int(np.searchsorted(t, contact.rewind))
    if t.size - j >= 3:
        locked = lock_feet(out.slice(j), att.parts)
        out = out.replace(rotations=np.concatenate([out.rotations[:j], locked.rotations]))
    return out


def _falling_when_held(held: Motion, after: F64, sim: Motion, parts: BodyPartMap) -> Motion:
    """``held`` (the attacker's simulation sampled at clip times, its last frame held ``after``
    seconds past its end where positive) with the held frames falling under gravity from the
    last frame's vertical speed until the body's lowest joint reaches the floor: a simulation
    that ends with the attacker knocked off its feet would otherwise leave it hanging in the
    air (the real respond kicked: lying 0.4-0.5 m up from 1.4 s to the end)."""
    late = after > 0.0
    if not late.any() or sim.num_frames < 2:
        return held
    # a dummy top joint above the pelvis stays on the floor: the body is the rest
    body = slice(1, None) if parts.joint_of("pelvis") != 0 else slice(None)
    z = sim.slice(-2).global_positions()[:, body, 2]
    height = max(float(z[-1].min()), 0.0)
    vz = float(z[-1].mean() - z[0].mean()) * sim.fps
    a = after[late]
    drop = np.clip(-vz * a + 0.5 * STANDARD_GRAVITY * a * a, 0.0, height)
    root = np.array(held.root_positions)
    root[late, 2] -= drop
    return held.replace(root_positions=root)


def _rate_limited(path: F64, step: float) -> F64:
    """``path`` ``(n, 3)`` followed by a point that moves at most ``step`` per frame (it keeps
    catching up after ``path`` stops)."""
    out = path.copy()
    for k in range(1, len(out)):  # sequential by nature: each frame starts from the last
        d = path[k] - out[k - 1]
        n = float(np.linalg.norm(d))
        out[k] = out[k - 1] + (d * (step / n) if n > step else d)
    return out


def _step_aside(cast: Cast, recipient: Motion, attacker: Motion, impact: float,
                speed: float) -> Motion:  # fmt: skip
    """``attacker`` moved aside horizontally (away from the recipient's pelvis where they first
    overlap) until the recipient's output no longer runs into it: the offset its root needs at
    each overlapping frame is reached beforehand at no more than a quarter of its clip's
    fastest joint ``speed`` nor a side step's pace (``STEP_M`` per ``STEP_S``) and kept after
    (the recipient stays where it stood); its feet follow in steps (:func:`_side_steps`). The
    recipient's tail (the found clip after the landing or the blend) walks or falls onto an
    attacker that its simulation left standing or lying there (docs/benchmarks.md)."""
    assert cast.attacker is not None
    fps = recipient.fps
    t = recipient.times
    ta = attacker.times
    need = np.zeros(t.size)
    offset = np.zeros(t.size)
    direction: F64 | None = None
    pelvis = cast.recipient.parts.joint_of("pelvis")
    aparts = cast.attacker.parts
    apelvis = aparts.joint_of("pelvis")
    moved = attacker
    v = min(0.25 * speed, STEP_M / STEP_S)
    ahead = np.maximum(t[None, :] - t[:, None], 0.0)  # [this frame i, frame j]: t_j - t_i, >= 0
    for _ in range(ASIDE_TRIES):
        depth = overlap_depths(cast.pair, [recipient, moved.sample(t).replace(fps=fps)])
        depth[t < impact] = 0.0  # before the hit the two are apart by construction
        bad = depth > ASIDE_MARGIN_M
        if not bad.any():
            break
        if direction is None:
            k = int(np.argmax(bad))
            d = (moved.sample([t[k]]).global_positions()[0, apelvis]
                 - recipient.global_positions()[k, pelvis])  # fmt: skip
            d[2] = 0.0
            n = float(np.linalg.norm(d))
            direction = d / n if n > 1e-6 else np.array([1.0, 0.0, 0.0])
        # at least the offset it already has there, plus the depth still left
        need = np.where(bad, np.maximum(need, offset + depth + ASIDE_MARGIN_M), need)
        # the offset at each frame: the largest of every later need reached at the step-aside
        # speed, and of every earlier one (kept)
        reach = need[None, :] - v * ahead
        offset = np.maximum(reach.max(axis=1), 0.0)
        off_a = np.interp(ta, t, offset)
        off_a[ta < impact] = 0.0
        moved = _side_steps(attacker, aparts, off_a, direction, speed)
    return moved


def _side_steps(motion: Motion, parts: BodyPartMap, offset: F64, direction: F64,
                speed: float) -> Motion:  # fmt: skip
    """``motion`` with its root moved by ``offset`` ``(T,)`` (m, nondecreasing) along
    ``direction`` and its feet following in steps, each planted foot (as
    :func:`reactmocap.metrics.planted` finds them in ``motion``) held where it stands: a foot
    in the air in ``motion`` moves on to where the root will be at the end of its next stance
    (two step times ahead at most); a planted foot the root leaves more than ``STEP_M``
    behind steps (lifted ``STEP_LIFT_M``) to where the root will be two step times later, at
    most ``2 * STEP_M``, over ``STEP_S`` or longer: its foot no faster than half the clip's
    fastest joint ``speed`` (m/s), as the attacker's blend back; the foot further along
    ``direction`` first, one foot at a time. The legs bend to their feet
    (:func:`place_ankles`)."""
    fps = motion.fps
    n = motion.num_frames
    feet = [parts.joint_of(f"{s}_foot") for s in ("l", "r")]
    ankles = motion.global_positions()[:, feet]
    pairs = planted(ankles, fps)
    down = np.zeros((n, 2), dtype=bool)  # a frame is planted where a planted pair touches it
    down[:-1] |= pairs
    down[1:] |= pairs
    moved = motion.replace(root_positions=motion.root_positions
                           + offset[:, None] * direction[None])  # fmt: skip
    moving = np.flatnonzero(offset > 0.0)
    if moving.size == 0:
        return moved
    steps = max(2, int(round(STEP_S * fps)))
    foot = np.zeros((n, 2))  # each foot's offset along ``direction``
    lift = np.zeros((n, 2))
    # each frame's next planted frame and the last frame of that plant, per foot
    frame = np.arange(n)[:, None]
    nxt_on = np.minimum.accumulate(np.where(down, frame, n - 1)[::-1])[::-1]
    ends = down & ~np.concatenate([down[1:], np.zeros((1, 2), dtype=bool)])
    nxt_end = np.minimum.accumulate(np.where(ends, frame, n - 1)[::-1])[::-1]
    nxt_off = np.take_along_axis(nxt_end, nxt_on, axis=0)
    first = int(moving[0])
    order = np.argsort(-(ankles[first, :, :2] @ direction[:2]))  # the leading foot first
    left = np.zeros(2, dtype=int)  # frames left of each foot's own step
    span = np.zeros((2, 2))  # each own step's start and end offsets
    length = np.full(2, steps)  # and its frames
    rate = 0.5 * speed / fps  # a foot in the air moves on no faster than the blend back
    for i in range(first, n):  # sequential: each frame starts from the last
        foot[i] = foot[i - 1] if i > 0 else 0.0
        for f in order:
            g = 1 - f
            if left[f] > 0:
                # lift, move (in the middle half, the foot off the ground), plant
                s = 1.0 - (left[f] - 1) / length[f]
                h = min(max(2.0 * s - 0.5, 0.0), 1.0)
                foot[i, f] = span[f, 0] + (span[f, 1] - span[f, 0]) * h * h * (3.0 - 2.0 * h)
                lift[i, f] = STEP_LIFT_M * np.sin(np.pi * s)
                left[f] -= 1
            elif not down[i, f]:  # in the air in the clip: on to its next plant
                land = int(nxt_on[i, f])
                goal = min(offset[min(int(nxt_off[i, f]), land + 2 * steps)],
                           offset[land] + STEP_M)  # fmt: skip
                foot[i, f] += np.clip((goal - foot[i, f]) / max(land - i, 1), -rate, rate)
            elif (offset[min(i + steps, n - 1)] - foot[i, f] > STEP_M and left[g] == 0
                  and down[i, g]):  # fmt: skip
                span[f] = foot[i, f], min(offset[min(i + 2 * steps, n - 1)],
                                          foot[i, f] + 2.0 * STEP_M)  # fmt: skip
                # a smoothstep over half the step peaks at 3x the step's mean speed
                slow = 3.0 * (span[f, 1] - span[f, 0]) / max(0.5 * speed, 1e-9) * fps
                left[f] = length[f] = max(steps, int(np.ceil(slow)))
    rest = np.abs(foot - offset[:, None]) > 1e-6
    goal = ankles + foot[..., None] * direction
    goal[..., 2] += lift
    # a foot the root left further than the leg reaches: the root crouches (a straight leg's
    # knee has no bending plane for the IK)
    pos = moved.global_positions()
    hips, knees = (pos[:, [parts.joint_of(f"{s}_{p}") for s in ("l", "r")]]
                   for p in ("thigh", "shin"))  # fmt: skip
    carried = ankles + offset[:, None, None] * direction  # the feet moved with the root
    legs = np.linalg.norm(knees - hips, axis=-1) + np.linalg.norm(carried - knees, axis=-1)
    # (or its stretch in the clip: a foot left where it was needs no crouch)
    reach = np.maximum(LEG_REACH * legs, np.linalg.norm(carried - hips, axis=-1))
    flat = np.linalg.norm((goal - hips)[..., :2], axis=-1)
    up = np.sqrt(np.maximum(reach**2 - flat**2, 0.0))
    drop = np.where(rest | (lift > 0.0), (hips[..., 2] - goal[..., 2]) - up, 0.0).max(axis=1)
    # each frame's crouch reached beforehand and left afterwards no faster than ``rate``
    span_s = np.abs(frame - frame.T)
    drop = np.maximum((drop[None, :] - rate * span_s).max(axis=1), 0.0)
    moved = moved.replace(root_positions=moved.root_positions
                          - drop[:, None] * np.array([0.0, 0.0, 1.0]))  # fmt: skip
    goals = {}
    for f, side in enumerate(("l", "r")):
        frames = np.flatnonzero(rest[:, f] | (lift[:, f] > 0.0) | (drop > 0.0))
        goals[side] = (frames, goal[frames, f])
    return place_ankles(moved, parts, goals, keep_bend=True)


@dataclass(frozen=True)
class Blend:
    """The outputs: the ``recipient`` animation (mocap before the impact, the blended
    transition, the found clip after), the ``attacker``'s, the ``blended`` transition alone,
    Simulation 2 over the same frames (``simulated``), the ``seams`` between pieces, and the
    ``found`` clip where the blend placed it (moved ``found_shift`` m on the ground from
    where the search placed it: ``blend_place``)."""

    recipient: Motion
    attacker: Motion | None
    blended: Motion
    simulated: Motion
    seams: list[int]
    found: Motion
    found_shift: tuple[float, float] = (0.0, 0.0)


def blend(scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation,
          cont: Continuation, sim2: TransitionSimulation) -> Blend:  # fmt: skip
    """The paper's final blend over [impact, match], then the found clip plays on; the attacker
    follows its simulation from the rewind until its own clip no longer runs into the recipient
    (:attr:`TransitionSimulation.attacker_release`), then blends back to its clip."""
    cfg = scenario.response
    rec = cast.recipient
    fps = rec.motion.fps
    i_imp = int(np.ceil(naive.impact_time * fps - 1e-9))
    i_end = int(round(sim2.landed * fps))
    moved = (0.0, 0.0)
    if cfg.blend_place:
        # the physical mode's body landed within ``land_position`` of the clip: its ground
        # residual is taken up by the clip's placement, the blend corrects the rest
        within = cfg.land_position if cfg.mode == "physical" else None
        cont, moved = placed(cast, contact, cont, sim2, sim2.landed, within)
    # every piece with a dummy top joint on the ground under the pelvis, unturned while blending
    # (ground_root): the blend then moves the body, not meters of offset between the clips'
    # dummy roots; the output is grounded and turned to the heading as a whole
    grounded = lambda m: ground_root(m, rec.parts, turn=False)  # noqa: E731
    before = (grounded(rec.motion.sample(np.arange(0, i_imp) / fps + rec.clock0))
              if i_imp > 0 else None)  # fmt: skip
    times = np.arange(i_imp, i_end + 1) / fps
    simulated = grounded(sim2.motion.sample(times - contact.rewind))
    # the blend corrects the simulation toward what it was asked to do, which ends exactly on
    # the found clip: it then corrects only the tracking error, not the whole way to the clip
    found = desired_motion(cast, cfg, times, naive.impact_time, yields_to(cfg, naive.impulse), cont)
    # the found clip's time at the landing (time-warped by the physical mode's landing phase)
    on = cont.best.time + (sim2.landed - cont.time) + sim2.landing_phase
    if cfg.mode == "physical" or cfg.blend_end_gap:
        # close only the gap left at the landing, spread over the blend
        end = grounded(cont.found.sample([on])) if sim2.landing_phase else found
        found = _with_end_gap(simulated, end)
    tail_n = int(np.floor(max(0.0, min(cfg.tail, cont.found.duration - on)) * fps))
    tail = (grounded(cont.found.sample(on + np.arange(1, tail_n + 1) / fps))
            if tail_n > 0 else None)  # fmt: skip
    start = np.zeros(rec.motion.num_joints)
    pelvis = rec.parts.joint_of("pelvis")  # its delayed start delays the root offset too
    speed = joint_speed_max_m_s(cast.attacker.motion) if cast.attacker is not None else 0.0
    held = 0.0  # the attacker follows its simulation at least until then
    for _ in range(8):  # limbs still touching the attacker keep their simulated pose longer
        # the root's correction is spread over ROOT_BLEND_MIN_S at least, even while the trunk
        # still touches the attacker: held to the last frame, it would jump its whole gap there
        root_last = max(0.0, times.size - 1 - ROOT_BLEND_MIN_S * fps)
        blended = final_blend(simulated, found, start, root_start=min(start[pelvis], root_last))
        if cfg.foot_lock and cfg.mode == "blend":  # the physics holds the feet otherwise
            blended = lock_feet(blended, rec.parts)
        pieces = [p.replace(fps=fps) for p in (before, blended, tail) if p is not None]
        recipient = ground_root(Motion.concatenate(pieces, name="recipient"), rec.parts)
        if cast.attacker is None or sim2.attacker is None:
            return Blend(recipient, None, blended, simulated, _seams(i_imp, i_end, before),
                         cont.found, moved)  # fmt: skip
        # the blend moved the recipient off its simulation: the attacker's simulated part
        # moves with the body it hit, so the two keep the spacing the physics gave them
        hit = int(rec.character.anchors[SIM_BODIES.index(_hit_body(contact))])
        shift = blended.global_positions()[:, hit] - simulated.global_positions()[:, hit]
        release = max(sim2.attacker_release, _clear_of(cast, recipient, naive.impact_time), held)
        attacker = _attacker_output(cfg, cast.attacker, contact, sim2, recipient.duration,
                                    times, shift, release, speed)  # fmt: skip
        depth = overlap_depths(cast.pair, [blended, attacker.sample(times).replace(fps=fps)],
                               per_body=True)  # fmt: skip
        later = _blend_later(cast, depth > 0.005, start)
        if later is not None:
            start = later
            continue
        # nothing left to delay on the recipient's side: if the attacker, blending back to
        # its clip, runs into the recipient's output, it follows its simulation past that
        out_t = recipient.times
        after = out_t >= release
        if not after.any():
            break
        whole = overlap_depths(cast.pair, [recipient.slice(int(np.argmax(after))),
                                           attacker.sample(out_t[after]).replace(fps=fps)])  # fmt: skip
        late = np.flatnonzero(whole > 0.005)
        if late.size == 0:
            break
        held = float(out_t[after][late[-1]]) + 1.0 / fps
    if cast.attacker is not None and attacker is not None:
        attacker = _step_aside(cast, recipient, attacker, naive.impact_time, speed)
    return Blend(recipient, attacker, blended, simulated, _seams(i_imp, i_end, before),
                 cont.found, moved)  # fmt: skip


def settle(scenario: Scenario, cast: Cast, contact: ContactEstimate, naive: NaiveSimulation,
           cont: Continuation, sim2: TransitionSimulation) -> TransitionSimulation:  # fmt: skip
    """The blend mode's landing with ``blend_settle``: Simulation 2 ran on along the found clip
    past the match, and the final blend lands on the frame (from the match on, every
    :data:`SETTLE_STEP_S`) where it corrects least: its largest joint turn and pelvis shift
    (the foot lock's included; not the holds of limbs touching the attacker), each over its
    warning threshold, with the found clip placed (``blend_place``) and the gap spread
    (``blend_end_gap``) for that landing as :func:`blend` does; the smallest of the larger
    wins, the earliest among equals. ``sim2`` unchanged otherwise (the paper: the match
    time)."""
    cfg = scenario.response
    rec = cast.recipient
    fps = rec.motion.fps
    i_imp = int(np.ceil(naive.impact_time * fps - 1e-9))
    i_match = int(round(cont.time * fps))
    i_last = min(int(np.floor((contact.rewind + sim2.motion.duration) * fps + 1e-9)),
                 int(np.floor((cont.time + cfg.blend_settle) * fps + 1e-9)))  # fmt: skip
    if cfg.mode != "blend" or i_last <= i_match or i_match <= i_imp:
        return sim2
    times = np.arange(i_imp, i_last + 1) / fps
    simulated = ground_root(sim2.motion.sample(times - contact.rewind), rec.parts, turn=False)
    # what the blend corrects toward: exactly as in :func:`blend`
    yields = yields_to(cfg, naive.impulse)
    found = desired_motion(cast, cfg, times, naive.impact_time, yields, cont)
    best, landed = np.inf, i_match
    step = max(1, int(round(SETTLE_STEP_S * fps)))
    for end in range(i_match - i_imp, times.size, step):
        if cfg.blend_place:
            at = placed(cast, contact, cont, sim2, (i_imp + end) / fps)[0]
            if at is not cont:  # a falling clip, moved for this landing (else as found)
                found = desired_motion(cast, cfg, times, naive.impact_time, yields, at)
        sim, target = simulated.slice(0, end + 1), found.slice(0, end + 1)
        out = final_blend(sim, _with_end_gap(sim, target) if cfg.blend_end_gap else target)
        if cfg.foot_lock:
            out = lock_feet(out, rec.parts)
        score = blend_correction_over_warning(sim, out, rec.parts)
        if score < best - 1e-9:
            best, landed = score, i_imp + end
    return replace(sim2, landed=landed / fps)


def placed(cast: Cast, contact: ContactEstimate, cont: Continuation, sim2: TransitionSimulation,
           landed: float, within: float | None = None) -> tuple[Continuation, tuple[float, float]]:  # fmt: skip
    """``cont`` with its found clip moved on the ground so that its pelvis is over Simulation
    2's at scenario time ``landed`` (the clip's frame there, time-warped by the landing's
    phase), and that shift (m). ``within`` None (the blend mode's ``blend_place``): only a
    clip that falls (zero shift otherwise): the search placed it over Simulation 1's at the
    match, and a falling body travels on, where a standing one reaches its clip's place on its
    planted legs. ``within`` a distance (the physical mode's): any clip, moved at most that
    far (the body landed within ``land_position`` of the search's placement, and a shift on
    flat ground is as valid a placement as the search's)."""
    parts = cast.recipient.parts
    if within is None and not intended_fall(cont.found_clip, parts, cont.best.frame):
        return cont, (0.0, 0.0)
    pelvis = parts.joint_of("pelvis")
    body = sim2.motion.sample([landed - contact.rewind]).global_positions()[0, pelvis]
    on = cont.best.time + (landed - cont.time) + sim2.landing_phase
    clip = cont.found.sample([on]).global_positions()[0, pelvis]
    d = body[:2] - clip[:2]
    if within is not None:
        d *= min(1.0, within / max(float(np.linalg.norm(d)), 1e-12))
    dx, dy = (float(v) for v in d)
    return replace(cont, found=cont.found.transformed(0.0, (dx, dy))), (dx, dy)


def _with_end_gap(simulated: Motion, target: Motion) -> Motion:
    """``simulated`` carrying the gap of its last frame to ``target``'s last frame on every
    frame (each local rotation turned by the last frame's correction, the root moved by its
    offset): a final blend toward it corrects nothing but that gap and still lands exactly."""
    fix = quat_mul(quat_conj(simulated.rotations[-1]), target.rotations[-1])
    offset = target.root_positions[-1] - simulated.root_positions[-1]
    tr = None
    if simulated.translations is not None or target.translations is not None:
        ts = simulated.local_translations()
        tr = ts + (target.local_translations()[-1] - ts[-1])[None]
    return simulated.replace(rotations=quat_mul(simulated.rotations, fix[None]),
                             root_positions=simulated.root_positions + offset,
                             translations=tr)  # fmt: skip


def _hit_body(contact: ContactEstimate) -> str:
    """The recipient's body the hit landed on (the pelvis when unknown)."""
    body = contact.body.split("/")[0]
    return body if body in SIM_BODIES else "pelvis"


def _seams(i_imp: int, i_end: int, before: Motion | None) -> list[int]:
    return [i_imp, i_end + 1] if before is not None else [i_end + 1]


def _limb_root(body: int) -> int:
    """The first body of the chain whose blend an overlap of ``body`` delays: a leg from its
    thigh; anything above the pelvis from the waist (holding an arm alone still lets the
    blended trunk carry it into the other character). Either also holds the pelvis's turn,
    which swings a held leg as much as the trunk."""
    name = SIM_BODIES[body]
    if name == "pelvis":
        return body
    if name.endswith(("thigh", "shin", "foot")):
        return SIM_BODIES.index(name[:2] + "thigh")
    return SIM_BODIES.index("waist")


def _blend_later(cast: Cast, hit: NDArray[np.bool_], start: F64) -> F64 | None:
    """New per-joint blend starts when limbs of the blended transition run into the attacker's
    output (``hit`` ``(n, 16)``: each recipient body overlapping it, per frame): each such limb (its joints and the folded ones above it) keeps its simulated pose
    until two frames after its last overlap. None when nothing overlaps (or nothing changes)."""
    rec = cast.recipient
    if not hit.any():
        return None
    out = start.copy()
    skel = rec.motion.skeleton
    anchors = rec.character.anchors
    for b in np.flatnonzero(hit.any(axis=0)):
        root = _limb_root(int(b))
        a = int(anchors[root])
        parent = int(anchors[SIM_PARENTS[root]]) if root > 0 else -1
        above = [j for j in skel.chain(a) if parent < 0 or j not in skel.chain(parent)]
        joints = above + [j for j in range(skel.num_joints) if a in skel.chain(j)]
        if SIM_BODIES[root] != "pelvis":  # the pelvis's turn carries the trunk and legs too
            joints += skel.chain(int(anchors[0]))
        last = int(np.flatnonzero(hit[:, b])[-1]) + 2
        out[joints] = np.maximum(out[joints], last)
    return None if np.array_equal(out, start) else out
