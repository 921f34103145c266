"""The blend mode's landing: ``blend_settle`` lands the final blend where it corrects least
(Simulation 2 runs on along the found clip past the match), and ``land_tries`` tries the
search's next-best windows of other clips (then the found clip's at earlier starts) when the
final blend would warn."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from reactmocap import metrics as qm
from reactmocap.library.motion import Motion
from reactmocap.library.placement import ground_root
from reactmocap.response import final, stages
from reactmocap.response.pipeline import LibraryCache, ResponseResult, run_response
from reactmocap.response.scenario import (
    CharacterSpec,
    ImpactSpec,
    ResponseConfig,
    Scenario,
    load_scenario,
)
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from tests.conftest import BEFORE_RIGHT_FALL, REPO, SYNTHETIC, linked_library

EXAMPLES = REPO / "examples"
CACHE = LibraryCache()


def _blend(name: str, **kw: object) -> Scenario:
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    return replace(sc, response=replace(sc.response, mode="blend", **kw))


def _score(report: dict) -> float:
    """The final blend's correction over the warning thresholds (<= 1: no warning)."""
    q = report["quality"]
    return max(q["blend_joint_correction_max_rad"] / qm.WARN_JOINT_CORRECTION_RAD,
               q["blend_root_turn_max_rad"] / qm.WARN_ROOT_TURN_RAD,
               q["blend_root_offset_max_m"] / qm.WARN_ROOT_OFFSET_M)  # fmt: skip


def _simulated(res: ResponseResult) -> Motion:
    """Simulation 2 over the final blend's frames, as the blend takes it."""
    rep = res.report
    fps = res.recipient.fps
    first = int(np.ceil(rep["impact"]["time"] * fps - 1e-9))
    times = (first + np.arange(res.blended.num_frames)) / fps - rep["impact"]["rewind_time"]
    assert res.parts is not None
    return ground_root(res.sim2.sample(times), res.parts, turn=False)


def _turns(res: ResponseResult) -> NDArray[np.float64]:
    """``(T, J)`` each joint's turn (rad) by the final blend, per frame."""
    sim = _simulated(res)
    rel = quat_mul(quat_conj(sim.rotations), res.blended.rotations)
    return np.linalg.norm(quat_log(rel), axis=-1)


def test_the_blend_mode_corrects_only_the_gap_left_at_the_landing() -> None:
    # the front kick in the blend mode, the foot lock off (it pins planted feet on its own):
    # each joint's turn grows to its gap at the landing and no further; slerped toward the
    # path frame by frame (``blend_end_gap`` off) the blend also corrects Simulation 2's
    # tracking error on the way, up to 0.4 rad more than at the landing
    gap = run_response(_blend("front_kick", foot_lock=False), CACHE)
    path = run_response(_blend("front_kick", foot_lock=False, blend_end_gap=False), CACHE)
    assert gap.report["matched"] == path.report["matched"]  # the same continuation
    turns = _turns(gap)
    assert (turns <= turns[-1] + 1e-6).all(), (turns.max(axis=0) - turns[-1]).max()
    on_path = _turns(path)
    assert (on_path.max(axis=0) - on_path[-1]).max() > 0.2
    q, p = gap.report["quality"], path.report["quality"]
    assert q["blend_joint_correction_max_rad"] < p["blend_joint_correction_max_rad"] - 0.05
    assert q["blend_root_turn_max_rad"] < p["blend_root_turn_max_rad"] - 0.05
    assert q["reaction_displacement_m"] > 0.1  # still a reaction


def test_the_blend_mode_places_the_found_clip_where_simulation_2_lies(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk backwards pushed from its left (bench_reactions' push, blend mode): the
    # body falls on past where the search placed fall_backward (over Simulation 1's pelvis at
    # the match), and the blend dragged it 0.34 m back (a root warning); the fall clip moved
    # on the ground to Simulation 2's pelvis at the landing leaves no such gap
    # without the right-lying fall, which wins this run now (clean too) and takes the
    # standing clip's place among the next-best
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC, without=BEFORE_RIGHT_FALL)
    cfg = ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                         torque_limit=1000.0)  # fmt: skip
    sc = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_walk-back_normal_001", start=0.1),
        impact=ImpactSpec("chest", (4.5018606020314085, -249.959463215778, 0.0), 0.35, 0.2),
        response=cfg,
        name="walk-back-push-left",
    )  # fmt: skip
    cache = LibraryCache()
    cast = stages.cast(sc, cache)
    contact = stages.estimate_contact(sc, cast)
    naive = stages.naive_simulation(sc, cast, contact)
    first = stages.search_continuation(sc, cast, contact, naive)
    fall = next(c for c in (first, *first.alternatives) if c.best.clip == "fall_backward")
    sim2 = stages.transition_simulation(sc, cast, contact, naive, fall)
    sim2 = final.settle(sc, cast, contact, naive, fall, sim2)
    out = final.blend(sc, cast, contact, naive, fall, sim2)
    unplaced = replace(sc, response=replace(cfg, blend_place=False))
    old = final.blend(unplaced, cast, contact, naive, fall, sim2)  # the same landing
    parts = cast.recipient.parts
    moved = qm.blend_root_offset_max_m(out.simulated, out.blended, parts)
    dragged = qm.blend_root_offset_max_m(old.simulated, old.blended, parts)
    assert dragged > qm.WARN_ROOT_OFFSET_M and moved < 0.05, (dragged, moved)
    assert np.hypot(*out.found_shift) > qm.WARN_ROOT_OFFSET_M and old.found_shift == (0.0, 0.0)
    assert np.allclose(out.found.root_positions[:, :2] - fall.found.root_positions[:, :2],
                       out.found_shift, atol=1e-9)  # fmt: skip
    # a standing clip (the next-best guide) keeps the search's place: the body reaches it on
    # its planted legs
    standing = next(c for c in first.alternatives
                    if not qm.intended_fall(c.found_clip, parts, c.best.frame))  # fmt: skip
    assert final.placed(cast, contact, standing, sim2, sim2.landed) == (standing, (0.0, 0.0))
    # the whole response: this landing wins, without warnings, the shift reported; the
    # output's pelvis at the landing is Simulation 2's on the ground plane
    res = run_response(sc, cache)
    rep = res.report
    assert rep["matched"]["clip"] == "fall_backward" and not rep["warnings"], rep["warnings"]
    assert rep["transition"]["found_shift_m"] == list(out.found_shift)
    pelvis = parts.joint_of("pelvis")
    end = _simulated(res).global_positions()[-1, pelvis]
    landing = int(round(rep["transition"]["end"] * res.recipient.fps))
    assert np.linalg.norm((res.recipient.global_positions()[landing, pelvis] - end)[:2]) < 0.01


def test_the_blend_mode_settles_where_the_final_blend_corrects_least() -> None:
    # the heavy push's blend at the match, slerping each frame toward the path
    # (``blend_end_gap`` off, the found clip where the search put it), turns the root 0.67 rad
    # (over the warning threshold); Simulation 2 runs on, and the blend lands later, where it
    # corrects less (one try: with land_tries the blend at the match switches to
    # fall_backward_fast, which does not warn; by default the blend at the match corrects 0.16
    # rad and settles nothing)
    old = {"land_tries": 1, "blend_end_gap": False, "blend_place": False}
    at_match = run_response(_blend("heavy_push_fall", blend_settle=0.0, **old), CACHE).report
    settled = run_response(_blend("heavy_push_fall", blend_settle=0.5, **old), CACHE).report
    tr = settled["transition"]
    assert tr["match"] == at_match["transition"]["match"]  # the same search, the same match
    assert at_match["transition"]["end"] == at_match["transition"]["match"]  # the paper
    assert _score(at_match) > 1.0, at_match["quality"]  # the case: the match's blend warns
    assert tr["match"] < tr["end"] <= tr["match"] + 0.5 + 1e-9
    assert _score(settled) < _score(at_match) - 0.05, (settled["quality"], at_match["quality"])
    assert settled["quality"]["transition_s"] > at_match["quality"]["transition_s"]
    # a settle too short to reach the next candidate frame keeps the match
    short = run_response(_blend("heavy_push_fall", blend_settle=0.01, **old), CACHE).report
    assert short["transition"]["end"] == short["transition"]["match"]
    assert _score(short) == _score(at_match)


def test_the_blend_mode_lands_at_the_match_when_its_blend_would_not_warn() -> None:
    # the front kick's blend at the match turns 0.43 rad, within the threshold: no later
    # landing is searched, and Simulation 2 stops where it does without blend_settle
    at_match = run_response(_blend("front_kick", blend_settle=0.0), CACHE)
    lazy = run_response(_blend("front_kick", blend_settle=0.5), CACHE)
    assert _score(at_match.report) <= 1.0, at_match.report["quality"]
    tr = lazy.report["transition"]
    assert tr["end"] == tr["match"] == at_match.report["transition"]["end"]
    assert lazy.sim2.num_frames == at_match.sim2.num_frames
    assert _score(lazy.report) == _score(at_match.report)


def test_the_blend_mode_tries_other_clips_when_its_final_blend_would_warn(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk pushed from the front (bench_reactions' push, blend mode, each frame
    # slerped toward the path: ``blend_end_gap`` off; by default the gap at the match is 0.53
    # rad and nothing is tried): Simulation 2 cannot follow the nearest window (the walk
    # itself, later) closely enough, and the final blend turns the left shin 0.9 rad; another
    # clip's window needs less
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    cfg = ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                         torque_limit=1000.0, land_tries=1, blend_end_gap=False,
                         blend_place=False)  # fmt: skip
    sc = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_walk_normal_001", start=0.5),
        impact=ImpactSpec("chest", (-249.73579086797838, 11.49063790854824, 0.0), 1.0, 0.2),
        response=cfg,
        name="walk-push-front",
    )  # fmt: skip
    cache = LibraryCache()
    one = run_response(sc, cache).report
    assert _score(one) > 1.0, one["quality"]  # the case: the nearest window's blend warns
    tries = replace(sc, response=replace(cfg, land_tries=3))
    cast = stages.cast(tries, cache)
    contact = stages.estimate_contact(tries, cast)
    naive = stages.naive_simulation(tries, cast, contact)
    cont = stages.search_continuation(tries, cast, contact, naive)
    others = [c.best.clip for c in cont.alternatives]
    assert cont.best.clip == one["matched"]["clip"]  # the nearest window still comes first
    assert 1 <= len(others) <= 2 and cont.best.clip not in others, others
    three = run_response(tries, cache).report
    assert three["matched"]["clip"] in {cont.best.clip, *others}
    assert _score(three) < _score(one)  # it switched to a continuation it follows closer
    assert three["matched"]["clip"] != one["matched"]["clip"]
    assert three["quality"]["reaction_displacement_m"] > 0.05  # still a reaction


def test_the_blend_mode_tries_the_found_fall_at_an_earlier_start(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk-left pushed from the right (bench_reactions, blend mode): the body lies
    # still at the match, and the fall's still frames match it at every start about equally
    # (fall_sideways at 1.9 s nearest); one other clip matched at all (fall_sideways_fast,
    # settled: a joint 0.90 rad, the body still falling 0.55 m/s onto a still frame), so the
    # third try is the found fall at an earlier start, whose final blend needs no warning
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    cfg = ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                         attacker_assist=100.0, mode="blend", land_position=0.25,
                         land_angle=0.5, land_joint=0.5, land_within=1.0, land_tries=3,
                         torque_limit=1000.0, blend_settle=0.5)  # fmt: skip
    sc = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_walk-left_normal_001", start=0.5),
        impact=ImpactSpec("chest", (-18.946436750860666, 249.28103123672616, 0.0), 1.0, 0.2),
        response=cfg,
        name="walk-left-right",
    )  # fmt: skip
    cache = LibraryCache()
    cast = stages.cast(sc, cache)
    contact = stages.estimate_contact(sc, cast)
    naive = stages.naive_simulation(sc, cast, contact)
    cont = stages.search_continuation(sc, cast, contact, naive)
    again = [c for c in cont.alternatives if c.best.clip == cont.best.clip]
    assert len(cont.alternatives) == 2 and len(again) == 1, cont.alternatives
    assert again[0].time < cont.time  # later landings are blend_settle's
    assert again[0].best.distance >= cont.best.distance  # the next-best window, not a closer
    rep = run_response(sc, cache).report
    assert rep["matched"]["clip"] == cont.best.clip
    assert rep["transition"]["match"] == again[0].time
    assert _score(rep) <= 1.0 and not rep["warnings"], rep["quality"]
    assert rep["quality"]["reaction_displacement_m"] > 0.3  # a fall, not a stand
