"""The response pipeline (Zordan et al. 2005): contact scan, Simulation 1, search, Simulation 2,
final blend, attacker handling, outputs.

Scenario time 0 is the recipient clip at ``recipient.start``. Every stage works in scenario
time; the outputs are sampled at the recipient clip's frame rate.

Simulation 1 ("naive") modes, measured with ``benchmarks/bench_response.py``:

* ``passive``: the recipient is a ragdoll (joint damping and limits only) from the impact on.
  It shows the impact's full effect, but a ragdoll buckles under gravity within a few hundred
  milliseconds, so every search ends up favouring falls.
* ``holding`` (default): the recipient keeps tracking its pre-impact clip with the same servo
  as Simulation 2. The trajectory then carries the impact's dynamics on a character that stays
  "alive", which is what the library's reactions were recorded from.

The PD servo runs inside MuJoCo (actuators, see :mod:`reactmocap.sim.pd`), so the simulation
loop only acts at events: control ticks (new targets, contact logging), the impact's first and
last steps, and the steps whose qpos the outputs sample; MuJoCo steps in chunks in between.
Desired poses are precomputed for all control ticks at once.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap import __version__
from reactmocap import metrics as qm
from reactmocap.errors import ConfigError, ReactMocapError, SearchError, SimulationError
from reactmocap.io import atomic_write_text
from reactmocap.library.bodyparts import BodyPartMap, map_body_parts
from reactmocap.library.bvh import read_bvh, write_bvh
from reactmocap.library.clip_library import (
    ClipLibrary,
    default_cache_dir,
    find_bvh_files,
    load_library,
)
from reactmocap.library.motion import Motion
from reactmocap.library.placement import place
from reactmocap.response.blend import blend_poses, final_blend, transition_weights
from reactmocap.response.footlock import lock_feet
from reactmocap.response.scenario import CharacterSpec, Scenario
from reactmocap.rotations import quat_slerp
from reactmocap.search import MotionIndex, SearchResult, SearchWeights, WindowConfig
from reactmocap.search.index import FORMAT_VERSION as INDEX_FORMAT_VERSION
from reactmocap.sim.character import BALL_JOINTS, Character, build_character
from reactmocap.sim.impacts import Impact, first_contact
from reactmocap.sim.pd import PDServo
from reactmocap.sim.world import World, WorldConfig

__all__ = ["ResponseResult", "prepare_library", "run_response", "run_scenario"]

F64 = NDArray[np.float64]
#: servo targets are refreshed every this many physics steps (200 Hz at dt = 0.5 ms): the
#: desired poses are smooth blends of 30-60 Hz clips, so a faster refresh only costs time
CONTROL_EVERY = 10
#: kinematic contact scan rate (Hz), as in the paper
SCAN_FPS = 30.0


@dataclass
class ResponseResult:
    """Everything a response produced, in scenario time."""

    recipient: Motion
    attacker: Motion | None
    matched: SearchResult
    candidates: list[SearchResult]
    impact_time: float
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


# ----------------------------------------------------------------------------- library
_INDEX_MEMO: dict[tuple[str, ...], tuple[ClipLibrary, MotionIndex]] = {}


def prepare_library(
    path: Path, skeleton_of: Motion | None = None, lib: ClipLibrary | None = None
) -> tuple[ClipLibrary, MotionIndex]:
    """Load a clip library (unless given) and its search index (cached on disk, keyed by
    content and by ``skeleton_of``'s skeleton). With ``skeleton_of``, clips on other skeletons
    are retargeted onto it (:mod:`reactmocap.sim.retarget`; each side's reference pose is
    frame 0 of its alphabetically first clip), so every clip can be the continuation."""
    lib = load_library(path) if lib is None else lib
    clips = dict(lib.clips)
    target = ""
    if skeleton_of is not None:
        clips = _retargeted(clips, skeleton_of)
        sk = skeleton_of.skeleton
        target = hashlib.sha256(
            ("\0".join(sk.names) + repr(np.round(sk.offsets, 6).tolist())).encode()
        ).hexdigest()[:12]
    # the code versions are part of the key: an index written by older search code is not reused
    key = (str(Path(path).resolve()), ",".join(sorted(clips)) + lib.fingerprint(),
           f"{__version__}/{INDEX_FORMAT_VERSION}/retarget{RETARGET_VERSION}/{target}")  # fmt: skip
    if key in _INDEX_MEMO:
        return _INDEX_MEMO[key]
    digest = hashlib.sha256("\0".join(key).encode()).hexdigest()[:16]  # stable across processes
    index_path = default_cache_dir().parent / "indexes" / f"{digest}.npz"
    index = MotionIndex.load_or_build(index_path, clips, SearchWeights(), WindowConfig())
    sub = ClipLibrary(lib.root, clips, lib.paths, lib.hashes, lib.failures)
    _INDEX_MEMO[key] = (sub, index)
    return sub, index


RETARGET_VERSION = 1


def _retargeted(clips: dict[str, Motion], recipient: Motion) -> dict[str, Motion]:
    """Every clip on ``recipient``'s skeleton: same-structure clips as they are, the rest
    retargeted (one Retargeter per source skeleton)."""
    from reactmocap.sim.retarget import Retargeter

    target_char = None
    by_skeleton: dict[int, Retargeter] = {}
    out: dict[str, Motion] = {}
    for name in sorted(clips):
        m = clips[name]
        if m.skeleton.same_structure(recipient.skeleton):
            out[name] = m
            continue
        if target_char is None:
            target_char = build_character(recipient, frame=0)
        key = next((k for k, r in by_skeleton.items()
                    if r.source.skeleton.same_structure(m.skeleton)), None)  # fmt: skip
        if key is None:
            key = len(by_skeleton)
            by_skeleton[key] = Retargeter(build_character(m, frame=0), target_char)
        out[name] = by_skeleton[key](m)
    return out


_LIBRARY_MEMO: dict[tuple[str, tuple[tuple[str, int, int], ...]], ClipLibrary] = {}


def _library(path: Path) -> ClipLibrary:
    """The clip library, memoised in-process by file names, sizes and mtimes (a batch runs many
    responses over one library; re-hashing every file costs ~45 ms per response)."""
    files = find_bvh_files(path)
    key = (
        str(Path(path).resolve()),
        tuple((str(f), (st := f.stat()).st_size, st.st_mtime_ns) for f in files),
    )
    if key not in _LIBRARY_MEMO:
        _LIBRARY_MEMO.clear()
        _LIBRARY_MEMO[key] = load_library(path)
    return _LIBRARY_MEMO[key]


def _clip(lib_path: Path, spec: CharacterSpec, lib: ClipLibrary | None) -> Motion:
    p = Path(spec.clip)
    if p.suffix.lower() == ".bvh" and p.exists():
        return read_bvh(p)
    if lib is None:
        lib = _library(lib_path)
    return lib[spec.clip]


def _placed(motion: Motion, parts: BodyPartMap, spec: CharacterSpec) -> tuple[Motion, float]:
    """The clip turned and shifted for the scenario; returns it and the clip time at t=0."""
    frame = int(round(spec.start * motion.fps))
    if not 0 <= frame < motion.num_frames:
        raise ConfigError(
            f"start {spec.start} s is outside clip {motion.name!r} ({motion.duration:.2f} s)"
        )
    return place(
        motion, parts, frame, np.radians(spec.facing_deg), spec.position
    ), frame / motion.fps


# ----------------------------------------------------------------------------- simulation
class _Sim:
    """One or two characters in a World with a PD servo, stepped in lean segments."""

    def __init__(self, chars: list[Character], friction: float, dt: float, kp: float, kv: float):
        self.world = World(chars, WorldConfig(friction=friction, timestep=dt))
        # the servo re-linearises at the control ticks, where the targets change anyway
        self.servo = PDServo(self.world, kp=kp, kv=kv, refresh_every=CONTROL_EVERY)
        m = self.world.model
        owner = np.full(m.ngeom, -1)
        for wc in self.world.characters:
            owner[wc.geom_ids] = wc.index
        self.owner = owner
        self._force = np.zeros(6)

    def run(
        self,
        steps: int,
        targets: list[F64 | None],
        record: _Recording,
        start: int,
        impact: tuple[int, int, int, F64] | None = None,
        contact_log: list[tuple[int, float]] | None = None,
    ) -> None:
        """Step ``steps`` times from step ``start``, recording qpos after the steps ``record``
        samples. ``targets[c]`` is ``(ticks, 15, 4)`` per control tick (None: passive).
        ``impact`` = (body id, first step, last step, 6-vector xfrc). Contacts between
        characters are logged every ``CONTROL_EVERY`` steps. MuJoCo steps in chunks between
        those events (``PDServo.step``), each event at the same step as one step at a time."""
        d = self.world.data
        servo = self.servo
        for c, tg in enumerate(targets):
            servo.enable(c, on=tg is not None)
        rows = record.steps
        ri = int(np.searchsorted(rows, start))
        end = start + steps
        k = start
        while k < end:
            i = k - start
            if i % CONTROL_EVERY == 0:
                tick = i // CONTROL_EVERY
                for c, tg in enumerate(targets):
                    if tg is not None:
                        servo.set_targets(c, tg[min(tick, len(tg) - 1)])
                if contact_log is not None and d.ncon:
                    self._log_contacts(k, contact_log)
            nxt = min(end, k + CONTROL_EVERY - i % CONTROL_EVERY)
            if impact is not None:
                if k == impact[1]:
                    d.xfrc_applied[impact[0]] = impact[3]
                elif k == impact[2]:
                    d.xfrc_applied[impact[0]] = 0.0
                for s in impact[1:3]:
                    if k < s < nxt:
                        nxt = s
            if ri < rows.size:
                nxt = min(nxt, int(rows[ri]) + 1)
            servo.step(nxt - k)
            k = nxt
            while ri < rows.size and rows[ri] < k:  # qpos after step k - 1
                record.qpos[ri] = d.qpos
                ri += 1
        if not np.all(np.isfinite(d.qpos)):
            raise SimulationError(f"simulation diverged by t={d.time:.3f} s (non-finite state)")

    def _log_contacts(self, step: int, log: list[tuple[int, float]]) -> None:
        d = self.world.data
        geoms = d.contact.geom[: d.ncon]
        own = self.owner[geoms]
        between = np.flatnonzero((own[:, 0] >= 0) & (own[:, 1] >= 0) & (own[:, 0] != own[:, 1]))
        if between.size:
            f6 = np.zeros(6)
            total = 0.0
            for c in between:
                mujoco.mj_contactForce(self.world.model, d, int(c), f6)
                total += abs(f6[0])
            log.append((step, total))


def _sample_rows(n: int, dt: float, fps: float) -> tuple[F64, NDArray[np.intp]]:
    """Output frame times (from 0, at ``fps``) over ``n`` steps and, for each, the step whose
    post-step qpos is the frame (step ``j`` ends at ``(j + 1) dt``; frame 0 uses step 0)."""
    times = np.arange(0, int(np.floor(n * dt * fps)) + 1) / fps
    return times, np.clip(np.round(times / dt).astype(int) - 1, 0, n - 1)


class _Recording:
    """qpos after the steps that the outputs sample at the given frame rates: the readers
    (:func:`_to_motion`) only look at those, so the stepping loop records nothing else."""

    def __init__(self, n: int, nq: int, dt: float, fps: list[float]):
        self.n = n
        self.steps = np.unique(np.concatenate([_sample_rows(n, dt, f)[1] for f in fps]))
        self.qpos = np.empty((self.steps.size, nq))

    def at(self, rows: NDArray[np.intp]) -> F64:
        """Recorded qpos after each of ``rows`` (steps that were asked for)."""
        i = np.searchsorted(self.steps, rows)
        if not np.array_equal(self.steps[np.minimum(i, self.steps.size - 1)], rows):
            raise SimulationError("internal error: a step that was not recorded was read")
        return self.qpos[i]


def _ball_targets(ch: Character, motion: Motion, times: NDArray[np.floating]) -> F64:
    """``(n, 15, 4)`` ball-joint quaternions of ``motion`` at ``times`` (its own clock)."""
    return ch.qpos_from_motion(motion.sample(times))[:, 7:].reshape(-1, len(BALL_JOINTS), 4)


# ----------------------------------------------------------------------------- pipeline
def run_response(scenario: Scenario) -> ResponseResult:
    """Run the whole pipeline and return motions and the report (no files written)."""
    cfg = scenario.response
    timings: dict[str, float] = {}
    t_all = time.perf_counter()

    lib = _library(scenario.library)
    rec_clip = _clip(scenario.library, scenario.recipient, lib)
    rec_parts = map_body_parts(rec_clip.skeleton)
    rec_motion, rec_t0 = _placed(rec_clip, rec_parts, scenario.recipient)
    # continuations on the recipient's skeleton (others retargeted); the attacker keeps its own
    search_lib, index = prepare_library(scenario.library, rec_clip, lib)
    fps = rec_clip.fps
    # scenario clock -> clip clock: the placed clip is sampled at rec_t0 + t
    rec_char = build_character(rec_motion, rec_parts, total_mass=cfg.total_mass,
                               frame=int(round(rec_t0 * fps)))  # fmt: skip
    chars = [rec_char]
    att_motion: Motion | None = None
    att_t0 = 0.0
    if scenario.attacker is not None:
        att_clip = _clip(scenario.library, scenario.attacker, lib)
        att_parts = map_body_parts(att_clip.skeleton)
        att_motion, att_t0 = _placed(att_clip, att_parts, scenario.attacker)
        chars.append(build_character(att_motion, att_parts, total_mass=cfg.total_mass,
                                     frame=int(round(att_t0 * att_clip.fps))))  # fmt: skip
    clocks = [rec_t0] + ([att_t0] if att_motion is not None else [])
    motions = [rec_motion] + ([att_motion] if att_motion is not None else [])

    # 1. contact scan / impact time, then rewind to the last mocap frame before it
    t = time.perf_counter()
    horizon = rec_motion.duration - rec_t0
    if att_motion is not None:
        horizon = min(horizon, att_motion.duration - att_t0)
        shifted = [mo.sample(np.arange(0, horizon, 1 / mo.fps) + c0).replace(fps=mo.fps)
                   for mo, c0 in zip(motions, clocks)]  # fmt: skip
        kc = first_contact(World(chars), shifted, fps=SCAN_FPS, end=horizon)
        # never touching: the scan runs to the end and the clip plays on
        t_contact = horizon if kc is None else kc.time
        impact_body = "contact" if kc is None else "/".join(kc.pairs[0])
    else:
        assert scenario.impact is not None
        t_contact = scenario.impact.at
        impact_body = scenario.impact.body
    # rewind to the last mocap frame before the contact
    t_rewind = max(0.0, float(np.floor(t_contact * fps - 1e-9) / fps))
    timings["scan"] = time.perf_counter() - t

    dt = cfg.timestep
    sim1_end = t_contact + cfg.sim1_duration + index.window.length / index.window.fps
    n1 = int(round((sim1_end - t_rewind) / dt))
    ticks = np.arange(0, n1 + CONTROL_EVERY, CONTROL_EVERY) * dt + t_rewind
    hold = [_ball_targets(ch, mo, ticks + c0) for ch, mo, c0 in zip(chars, motions, clocks)]

    def start_state(sim: _Sim) -> None:
        for k, (mo, c0) in enumerate(zip(motions, clocks)):
            f = int(round((t_rewind + c0) * mo.fps))
            sim.world.set_from_motion(k, mo, min(f, mo.num_frames - 1))

    impact = None
    if scenario.impact is not None:
        spec = scenario.impact
        try:
            imp = Impact(spec.body, force=spec.force, point=spec.point,
                         start=spec.at - t_rewind, duration=spec.duration)  # fmt: skip
        except ReactMocapError as exc:
            raise ConfigError(f"{scenario.source}: [impact]: {exc}") from None
        s0, n_imp = imp.steps(dt)
        impact_spec = (imp.body, s0, s0 + n_imp, imp.force_vector(dt), np.array(spec.point))
    else:
        impact_spec = None

    # 2. Simulation 1
    t = time.perf_counter()
    sim = _Sim(chars, cfg.friction_sim1, dt, cfg.kp, cfg.kv)
    start_state(sim)
    if impact_spec is not None:
        impact = _with_body_id(sim, impact_spec)
    saved = sim.world.get_state()
    rec1 = _Recording(n1, sim.world.model.nq, dt, [fps])
    contacts: list[tuple[int, float]] = []
    if cfg.sim1_mode == "passive":
        pre = max(0, int(round((t_contact - t_rewind) / dt)))
        sim.run(pre, list(hold), rec1, 0, impact, contacts)
        rest: list[F64 | None] = [None, *(h[pre // CONTROL_EVERY :] for h in hold[1:])]
        sim.run(n1 - pre, rest, rec1, pre, impact, contacts)
    else:
        sim.run(n1, list[F64 | None](hold), rec1, 0, impact, contacts)
    timings["sim1"] = time.perf_counter() - t
    sim1_motion = _to_motion(sim, 0, rec_char, rec1, t_rewind, dt, fps, rec_motion, rec_t0, "sim1")

    # contact duration and impact time from the physics
    if contacts:
        t_impact = t_rewind + contacts[0][0] * dt
        contact_end = t_rewind + contacts[-1][0] * dt
        peak = max(f for _, f in contacts)
    elif scenario.impact is not None:
        t_impact = scenario.impact.at
        contact_end = t_impact + scenario.impact.duration
        peak = float(np.linalg.norm(scenario.impact.force))
    else:
        t_impact, contact_end, peak = t_contact, t_contact, 0.0

    # 3. search over windows starting 0.1-1.0 s after the impact (later while contact lasts)
    t = time.perf_counter()
    first = t_impact + float(
        np.clip(contact_end - t_impact, cfg.search_start, cfg.contact_shift_max)
    )
    first = max(first, t_impact + cfg.search_start)
    last = t_impact + cfg.search_end
    q_fps = index.window.fps
    query = sim1_motion.resample(q_fps)
    q0 = t_rewind  # sim1_motion starts at t_rewind
    starts = np.arange(
        int(np.ceil((first - q0) * q_fps - 1e-9)),
        int(np.floor((last - q0) * q_fps + 1e-9)) + 1,
    )
    starts = starts[starts + index.length <= query.num_frames]
    if starts.size == 0:
        raise SearchError("the simulated trajectory is too short for one search window")
    best: SearchResult | None = None
    best_start = 0
    for s in starts:
        r = index.query(query, int(s), parts=rec_parts)
        if best is None or r.distance < best.distance:
            best, best_start = r, int(s)
    assert best is not None
    candidates = index.top_k(query, best_start, n=cfg.top_k, parts=rec_parts)
    t_match = q0 + best_start / q_fps
    timings["search"] = time.perf_counter() - t

    found_clip = search_lib[best.clip]
    found = found_clip.transformed(best.yaw, best.translation).replace(name=best.clip)

    # 4. Simulation 2: same start, same impact, friction 0.5, track slerp(prev, found)
    t = time.perf_counter()
    att_end = t_impact + cfg.attacker_follow + cfg.attacker_blend
    sim2_end = max(t_match, att_end if att_motion is not None else t_match)
    n2 = max(1, int(round((sim2_end - t_rewind) / dt)))
    ticks2 = np.arange(0, n2 + CONTROL_EVERY, CONTROL_EVERY) * dt + t_rewind
    prev_q = _ball_targets(rec_char, rec_motion, ticks2 + rec_t0)
    found_q = _ball_targets(rec_char, found, best.time + (ticks2 - t_match))
    w = transition_weights(ticks2, t_impact, cfg.reaction_delay, t_match)
    desired = quat_slerp(prev_q, found_q, w[:, None])
    targets2: list[F64 | None] = [desired]
    targets2 += [
        _ball_targets(ch, mo, ticks2 + c0) for ch, mo, c0 in zip(chars[1:], motions[1:], clocks[1:])
    ]
    sim2 = _Sim(chars, cfg.friction_sim2, dt, cfg.kp, cfg.kv)
    sim2.world.set_state(saved)
    impact2 = _with_body_id(sim2, impact_spec) if impact_spec is not None else None
    rec2 = _Recording(
        n2, sim2.world.model.nq, dt, [fps] + ([att_motion.fps] if att_motion is not None else [])
    )
    sim2.run(n2, targets2, rec2, 0, impact2)
    timings["sim2"] = time.perf_counter() - t
    sim2_motion = _to_motion(sim2, 0, rec_char, rec2, t_rewind, dt, fps, rec_motion, rec_t0, "sim2")

    # 5. final blend over [impact, match], then the found clip plays on
    t = time.perf_counter()
    i_imp = int(np.ceil(t_impact * fps - 1e-9))
    i_end = int(round(t_match * fps))
    before = rec_motion.sample(np.arange(0, i_imp) / fps + rec_t0) if i_imp > 0 else None
    trans_times = np.arange(i_imp, i_end + 1) / fps
    sim_part = sim2_motion.sample(trans_times - t_rewind)
    found_part = found.sample(best.time + (trans_times - t_match))
    blended = final_blend(sim_part, found_part)
    if cfg.foot_lock:
        blended = lock_feet(blended, rec_parts)
    tail_n = int(np.floor(min(cfg.tail, found.duration - best.time) * fps))
    tail = found.sample(best.time + np.arange(1, tail_n + 1) / fps) if tail_n > 0 else None
    pieces = [p for p in (before, blended, tail) if p is not None]
    recipient_out = Motion.concatenate([p.replace(fps=fps) for p in pieces], name="recipient")
    attacker_out = None
    if att_motion is not None:
        attacker_out = _attacker_output(
            chars[1], sim2, rec2, att_motion, att_t0, t_rewind, t_impact, dt, cfg,
            recipient_out.duration,
        )  # fmt: skip
    timings["blend"] = time.perf_counter() - t
    timings["total"] = time.perf_counter() - t_all

    seams = [i_imp, i_end + 1] if before is not None else [i_end + 1]
    quality = {
        "match_distance": qm.match_distance(best.distance),
        "blend_root_offset_max_m": qm.blend_root_offset_max_m(sim_part, blended),
        "blend_joint_correction_max_rad": qm.blend_joint_correction_max_rad(sim_part, blended),
        "stitch_velocity_jump_rad_s": qm.stitch_velocity_jump_rad_s(recipient_out, seams),
        "foot_skate_m": qm.foot_skate_m(recipient_out, rec_parts),
        "penetration_max_m": qm.penetration_max_m(recipient_out),
        "fell": qm.fell(recipient_out, rec_parts),
        "intended_fall": qm.intended_fall(found_clip, rec_parts, best.frame),
    }
    report: dict[str, Any] = {
        "scenario": scenario.name,
        "reactmocap_version": __version__,
        "mujoco_version": mujoco.__version__,
        "matched": {
            "clip": best.clip,
            "frame": best.frame,
            "time": t_match,
            "clip_time": best.time,
            "distance": best.distance,
            "yaw_deg": best.yaw_deg,
            "translation": list(best.translation),
            "breakdown": best.breakdown.to_dict(),
        },
        "candidates": [c.to_dict() for c in candidates],
        "impact": {
            "time": t_impact,
            "body": impact_body,
            "peak_force_N": peak,
            "rewind_time": t_rewind,
            "contact_end": contact_end,
        },
        "transition": {"start": t_impact, "end": t_match, "reaction_delay": cfg.reaction_delay},
        "timings_s": timings,
        "steps": {"sim1": n1, "sim2": n2},
        "quality": quality,
        "config": asdict(cfg),
        "outputs": {},
    }
    return ResponseResult(
        recipient=recipient_out,
        attacker=attacker_out,
        matched=best,
        candidates=candidates,
        impact_time=t_impact,
        transition_end=t_match,
        sim1=sim1_motion,
        sim2=sim2_motion,
        blended=blended,
        found=found,
        before=rec_motion.sample(np.arange(0, int(t_match * fps) + 1) / fps + rec_t0),
        report=report,
        model=sim2.world.model,
        start_state=saved,
    )


def _with_body_id(sim: _Sim, spec: tuple[str, int, int, F64, F64]) -> tuple[int, int, int, F64]:
    """Resolve the impact body in this world; the force acts at ``point`` (body frame), turned
    into a wrench about the body's centre of mass in the start pose."""
    body, s0, s1, force, point = spec
    bid = sim.world.characters[0].body_id(body)
    d = sim.world.data
    rot = d.xmat[bid].reshape(3, 3)
    arm = d.xpos[bid] + rot @ point - d.xipos[bid]
    return bid, s0, s1, np.concatenate([force, np.cross(arm, force)])


def _to_motion(sim: _Sim, k: int, ch: Character, rec: _Recording, t0: float, dt: float,
               fps: float, reference: Motion, ref_t0: float, name: str) -> Motion:  # fmt: skip
    """Recorded qpos (after steps starting at scenario time t0, step j ending at
    t0 + (j + 1) dt) as a Motion at ``fps`` on the character's original skeleton; its frame 0
    is scenario time t0."""
    wc = sim.world.characters[k]
    times, rows = _sample_rows(rec.n, dt, fps)
    q = rec.at(rows)[:, wc.qpos_slice]
    return ch.motion_from_qpos(q, fps, reference=reference, times=times + t0 + ref_t0, name=name)


def _attacker_output(ch: Character, sim: _Sim, rec: _Recording, motion: Motion, clock0: float,
                     t_rewind: float, t_impact: float, dt: float, cfg: Any,
                     duration: float) -> Motion:  # fmt: skip
    """The attacker follows its simulation for ``attacker_follow`` s after the impact, then
    blends linearly back to its own clip over ``attacker_blend`` s."""
    fps = motion.fps
    sim_m = _to_motion(sim, 1, ch, rec, t_rewind, dt, fps, motion, clock0, "attacker_sim")
    times = np.arange(0, int(np.floor(duration * fps)) + 1) / fps
    orig = motion.sample(times + clock0).replace(fps=fps)
    simulated = sim_m.sample(np.clip(times - t_rewind, 0, sim_m.duration))
    t1 = t_impact + cfg.attacker_follow
    w = np.where(times < t_impact, 1.0, np.clip((times - t1) / max(cfg.attacker_blend, 1e-9), 0, 1))
    return blend_poses(simulated, orig, w).replace(name="attacker")


# ----------------------------------------------------------------------------- outputs
def run_scenario(
    scenario: Scenario,
    out_dir: str | Path | None = None,
    *,
    plot: bool = False,
    video: bool = False,
) -> dict[str, Any]:
    """Run a scenario; with ``out_dir`` write ``recipient.bvh``, ``attacker.bvh``,
    ``report.json`` (and ``plot.png``, a video) atomically. Returns the report."""
    result = run_response(scenario)
    report = result.report
    if out_dir is None:
        return report
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    outputs: dict[str, str] = {}
    write_bvh(result.recipient, out / "recipient.bvh")
    outputs["recipient"] = str(out / "recipient.bvh")
    if result.attacker is not None:
        write_bvh(result.attacker, out / "attacker.bvh")
        outputs["attacker"] = str(out / "attacker.bvh")
    if plot:
        outputs["plot"] = str(_plot(result, out / "plot.png", scenario))
    if video:
        outputs.update(_video(result, out))
    outputs["report"] = str(out / "report.json")
    report["outputs"] = outputs
    atomic_write_text(out / "report.json", json.dumps(_jsonable(report), indent=2))
    return report


def _video(result: ResponseResult, out: Path) -> dict[str, str]:
    """MuJoCo-rendered MP4 with a translucent ghost of the found clip; the matplotlib stick
    figure GIF where no GL context can be made (the report says which)."""
    from reactmocap.response.render import RenderUnavailable, render_video

    fps = result.recipient.fps
    t = result.recipient.times
    # the found clip on the scenario clock: its matched frame falls on the transition's end
    ghost = result.found.sample(np.clip(result.matched.time + t - result.transition_end, 0, None))
    try:
        path = render_video(
            [(result.recipient, (0.25, 0.45, 0.85, 1.0))]
            + ([(result.attacker, (0.85, 0.3, 0.25, 1.0))] if result.attacker is not None else []),
            out / "video.mp4",
            fps=min(fps, 30.0),
            ghost=(ghost.replace(fps=fps), (0.3, 0.8, 0.35, 0.3)),
        )
        return {"video": str(path), "video_renderer": "mujoco"}
    except RenderUnavailable as exc:
        from reactmocap.response.plots import stick_figure_video

        motions = [(result.recipient, "tab:blue")]
        if result.attacker is not None:
            motions.append((result.attacker, "tab:red"))
        path = stick_figure_video(motions, out / "video.gif")
        return {"video": str(path), "video_renderer": f"matplotlib stick figure ({exc})"}


def _plot(result: ResponseResult, path: Path, scenario: Scenario) -> Path:
    from reactmocap.response.plots import pelvis_height_plot

    parts = map_body_parts(result.recipient.skeleton)
    pj = parts.joint_of("pelvis")

    def curve(m: Motion, t0: float) -> tuple[F64, F64]:
        return m.times + t0, m.global_positions()[:, pj, 2]

    t_imp = result.impact_time
    t_end = result.transition_end
    fps = result.recipient.fps
    found_t = result.matched.time + (np.arange(0, int((t_end + 1.0) * fps)) / fps - t_end)
    found_m = result.found.sample(np.clip(found_t, 0, None))
    curves = {
        "mocap before": curve(result.before, 0.0),
        "simulation 1": curve(result.sim1, result.report["impact"]["rewind_time"]),
        "simulation 2": curve(result.sim2, result.report["impact"]["rewind_time"]),
        "final blend": curve(result.blended, np.ceil(t_imp * fps - 1e-9) / fps),
        "found clip": (np.arange(found_m.num_frames) / fps, found_m.global_positions()[:, pj, 2]),
    }
    return pelvis_height_plot(curves, path, impact_time=t_imp, transition=(t_imp, t_end),
                              title=f"{scenario.name}: matched {result.matched.clip}")  # fmt: skip


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, Path):
        return str(x)
    return x
