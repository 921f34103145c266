"""The physical response mode: Simulation 2 runs on until the body is back on the found clip,
so the final blend corrects only a small gap; when the body does not get there, the report
says so."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from reactmocap.errors import ConfigError
from reactmocap.response.pipeline import LibraryCache, run_response
from reactmocap.response.scenario import Scenario, load_scenario, parse_scenario
from tests.conftest import REPO

EXAMPLES = REPO / "examples"
CACHE = LibraryCache()


def _physical(name: str) -> Scenario:
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    return replace(sc, response=replace(sc.response, mode="physical"))


def test_a_push_lands_physically_and_the_blend_corrects_only_the_small_gap() -> None:
    sc = _physical("light_push")
    physical = run_response(sc, CACHE).report
    blend = run_response(replace(sc, response=replace(sc.response, mode="blend")), CACHE).report
    tr, q = physical["transition"], physical["quality"]
    assert tr["mode"] == "physical" and tr["landed_on_clip"], tr
    assert tr["end"] >= tr["match"] - 1e-9
    gap = tr["landing_gap"]
    assert gap["pelvis_m"] <= sc.response.land_position
    assert gap["joint_rad"] <= sc.response.land_joint
    assert q["blend_root_offset_max_m"] <= 0.02, q
    assert q["blend_joint_correction_max_rad"] <= 0.1 + 1e-9, q
    assert q["reaction_displacement_m"] >= 0.10  # a reaction, not the own clip played on
    assert abs(tr["landing_phase_s"]) <= sc.response.land_warp + 1e-9
    assert not physical["warnings"]
    # the same fields as the blend mode, so regress can compare the two
    assert set(q) == set(blend["quality"])
    assert blend["transition"]["landing_gap"] == {"pelvis_m": 0, "root_rad": 0, "joint_rad": 0}


def test_a_body_that_does_not_land_is_reported_not_hidden() -> None:
    # the tracker cannot follow the found sway clip after the facing sweep's kick from 0 deg,
    # nor any re-planned or next-best one (the front kick example now lands on a re-plan):
    # the report must say so
    rep = run_response(_facing(0.0, "physical"), CACHE).report
    tr = rep["transition"]
    if tr["landed_on_clip"]:
        pytest.skip("the kick now lands physically: nothing left to report")
    assert any("physical mode" in w for w in rep["warnings"]), rep["warnings"]
    assert tr["end"] > tr["match"]  # it kept trying past the match


def test_an_unknown_mode_is_a_clear_error() -> None:
    data = {"library": str(REPO / "data" / "synthetic_clips"), "recipient": {"clip": "guard"},
            "impact": {}, "response": {"mode": "ragdoll"}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"\[response\]\.mode: expected one of"):
        parse_scenario(data, source="s.toml")


def test_a_body_that_never_lands_lands_where_it_came_closest() -> None:
    # a real World on the light push's recipient, its qpos set off the desired path by a turn
    # of one joint at each check: far, near (still outside the 0.1 rad tolerance), far again
    from reactmocap.response import stages
    from reactmocap.rotations import quat_mul
    from reactmocap.sim.world import World

    sc = _physical("light_push")
    cast = stages.cast(sc, CACHE)
    rec = cast.recipient
    q = rec.character.qpos_from_motion(rec.motion)
    world = World([rec.character])
    span = world.characters[0].qpos_slice
    landing = stages._Landing(sc.response, q, rec.motion.fps, after=0.1)
    for t, angle in ((0.05, 0.01), (0.2, 0.8), (0.3, 0.15), (0.4, 0.6)):
        want = q[int(round(t * rec.motion.fps))].copy()
        turn = np.array([np.cos(angle / 2), np.sin(angle / 2), 0.0, 0.0])
        want[7:11] = quat_mul(want[7:11], turn)  # the first joint after the free root
        world.data.qpos[span] = want
        assert landing(world, t) is None  # never within the tolerances
    assert landing.at is None
    score, at, gap, phase = landing.best
    assert at == 0.3  # not the last check (0.4 s), nor the one before ``after``
    assert gap[2] == pytest.approx(0.15, abs=1e-6) and score == pytest.approx(1.5, abs=1e-5)
    assert phase == 0.0  # no time warp asked


def test_a_body_on_the_clip_but_late_lands_on_its_frame_with_the_time_warp() -> None:
    # a real World with the body posed on a stepping clip 0.1 s behind the path: off the path's
    # own frame by more than the tolerances, on the clip's earlier frame exactly
    from reactmocap.response import stages
    from reactmocap.sim.world import World

    sc = _physical("light_push")
    cfg = sc.response
    cast = stages.cast(sc, CACHE)
    rec = cast.recipient
    clip = cast.library["step_right"]
    q = rec.character.qpos_from_motion(clip)
    rate = clip.fps
    world = World([rec.character])
    lag = int(round(0.1 * rate))
    t = 0.6
    i = int(round(t * rate))
    world.data.qpos[world.characters[0].qpos_slice] = q[i - lag]
    plain = stages._Landing(cfg, q, rate, after=0.0)
    assert plain(world, t) is None and plain.at is None  # the path's own frame: not landed
    assert plain.best[0] > 1.0
    pad = int(round(cfg.land_warp * rate))
    assert lag < pad
    padded = np.vstack([np.full((pad, q.shape[1]), np.nan), q, np.full((pad, q.shape[1]), np.nan)])
    warped = stages._Landing(cfg, q, rate, after=0.0, clip=padded,
                             offsets=np.arange(-pad, pad + 1), pad=pad)  # fmt: skip
    assert warped(world, t) == "landed on the found clip"
    assert warped.at == t and warped.phase == pytest.approx(-lag / rate)
    assert np.all(warped.gap < 1e-6), warped.gap


def _score(report: dict, sc: Scenario) -> float:
    gap = report["transition"]["landing_gap"]
    cfg = sc.response
    return max(gap["pelvis_m"] / cfg.land_position, gap["root_rad"] / cfg.land_angle,
               gap["joint_rad"] / cfg.land_joint)  # fmt: skip


def test_a_body_that_does_not_land_tries_other_clips_and_keeps_the_closest() -> None:
    from reactmocap.response import stages

    sc = _physical("front_kick")
    sc = replace(sc, response=replace(sc.response, land_tries=1, land_replan=0.0))
    one = run_response(sc, CACHE).report
    if one["transition"]["landed_on_clip"]:
        pytest.skip("the kick now lands physically on the nearest window")
    tries = replace(sc, response=replace(sc.response, land_tries=3))
    cast = stages.cast(tries, CACHE)
    contact = stages.estimate_contact(tries, cast)
    cont = stages.search_continuation(tries, cast, contact, stages.naive_simulation(tries, cast,
                                                                                    contact))  # fmt: skip
    others = [c.best.clip for c in cont.alternatives]
    assert cont.best.clip == one["matched"]["clip"]  # the nearest window still comes first
    assert 1 <= len(others) <= 2 and len({cont.best.clip, *others}) == len(others) + 1, others
    three = run_response(tries, CACHE).report
    assert three["matched"]["clip"] in {cont.best.clip, *others}
    assert _score(three, tries) <= _score(one, sc) + 1e-12
    if three["matched"]["clip"] != one["matched"]["clip"]:  # it switched: it landed closer
        assert _score(three, tries) < _score(one, sc)


def test_stiffening_from_the_match_lands_a_kick_that_does_not_land_without_it() -> None:
    # the facing sweep's kick from 240 deg (the found clip `step_right`): with the joints as
    # built the body comes within 1.5 tolerances 0.15 s after the match and drifts off;
    # held stiffer from the match on (`land_stiffness`), it settles onto the clip
    from reactmocap.batch import load_sweep

    base = load_sweep(EXAMPLES / "sweep_facing.toml").points()[0].scenario
    sc = replace(base, recipient=replace(base.recipient, facing_deg=240.0),
                 response=replace(base.response, mode="physical", land_replan=0.0))  # fmt: skip
    assert sc.response.land_stiffness > 1.0
    stiff = run_response(sc, CACHE).report
    built = run_response(replace(sc, response=replace(sc.response, land_stiffness=1.0)),
                         CACHE).report  # fmt: skip
    assert stiff["matched"]["clip"] == built["matched"]["clip"]  # the same search
    assert not built["transition"]["landed_on_clip"]
    assert stiff["transition"]["landed_on_clip"], stiff["transition"]
    assert _score(stiff, sc) <= 1.0 < _score(built, sc)


def test_a_land_stiffness_that_is_not_positive_is_a_clear_error() -> None:
    data = {"library": str(REPO / "data" / "synthetic_clips"), "recipient": {"clip": "guard"},
            "impact": {}, "response": {"mode": "physical", "land_stiffness": 0.0}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"\[response\]\.land_stiffness"):
        parse_scenario(data, source="s.toml")


def _facing(deg: float, mode: str) -> Scenario:
    from reactmocap.batch import load_sweep

    base = load_sweep(EXAMPLES / "sweep_facing.toml").points()[0].scenario
    return replace(base, recipient=replace(base.recipient, facing_deg=deg),
                   response=replace(base.response, mode=mode))  # fmt: skip


def test_a_landed_kick_reports_the_roots_turn_apart_from_the_joints() -> None:
    # the sweep's kick from 240 deg lands with the root turned 0.15 rad off the clip (within
    # land_angle) and every joint within land_joint: the final blend turns no joint of the
    # skeleton by more than 0.1 rad, and the root's turn is its own field
    sc = _facing(240.0, "physical")
    rep = run_response(sc, CACHE).report
    tr, q = rep["transition"], rep["quality"]
    assert tr["landed_on_clip"], tr
    gap = tr["landing_gap"]
    assert q["blend_joint_correction_max_rad"] <= sc.response.land_joint + 1e-9, q
    assert q["blend_root_turn_max_rad"] == pytest.approx(gap["root_rad"], abs=0.02), (q, gap)
    assert 0.1 < q["blend_root_turn_max_rad"] <= sc.response.land_angle + 1e-9, q
    assert q["blend_root_offset_max_m"] <= sc.response.land_position + 1e-9, q
    assert not rep["warnings"], rep["warnings"]


def test_a_kick_lands_physically_with_at_most_2_cm_of_root_correction() -> None:
    # issue 16's test: the sweep's kick from 80 deg (found clip `step_left`) lands, and the
    # final blend moves the root at most 2 cm and turns no joint more than 0.1 rad
    rep = run_response(_facing(80.0, "physical"), CACHE).report
    tr, q = rep["transition"], rep["quality"]
    assert tr["landed_on_clip"], tr
    assert q["contact_impulse_Ns"] > 20.0  # a real kick, not a graze
    assert q["blend_root_offset_max_m"] <= 0.02, q
    assert q["blend_joint_correction_max_rad"] <= 0.1, q
    assert q["blend_root_turn_max_rad"] <= 0.17, q


def test_a_large_root_turn_still_warns() -> None:
    # the blend mode on the sweep's kick from 300 deg: the final blend turns the root by more
    # than the warning threshold, and the report says so in its own words
    from reactmocap import metrics as qm

    rep = run_response(_facing(300.0, "blend"), CACHE).report
    q = rep["quality"]
    assert q["blend_root_turn_max_rad"] > qm.WARN_ROOT_TURN_RAD, q
    assert any("turns the root" in w for w in rep["warnings"]), rep["warnings"]


def test_a_kick_that_does_not_land_lands_when_simulated_again_with_balance_steps() -> None:
    # the sweep's kick from 210 deg (found clip `step_right`): the body leaves its feet's
    # support at 0.6-0.8 m/s and falls off the clip after the match; simulated again with
    # capture-point balance steps (`land_step_time`), it catches itself and lands
    sc = _facing(210.0, "physical")
    # the same clip only, no re-plan before the stepped retry
    sc = replace(sc, response=replace(sc.response, land_tries=1, land_replan=0.0))
    assert sc.response.land_step_time > 0.0
    stepped = run_response(sc, CACHE).report
    flat = run_response(replace(sc, response=replace(sc.response, land_step_time=0.0)),
                        CACHE).report  # fmt: skip
    assert stepped["matched"]["clip"] == flat["matched"]["clip"]  # the same search
    assert not flat["transition"]["landed_on_clip"] and not flat["transition"]["balance_steps"]
    tr, q = stepped["transition"], stepped["quality"]
    assert tr["landed_on_clip"] and tr["balance_steps"], tr
    assert _score(stepped, sc) <= 1.0 < _score(flat, sc)
    assert q["blend_joint_correction_max_rad"] <= sc.response.land_joint + 1e-9, q
    assert q["blend_root_offset_max_m"] <= sc.response.land_position + 1e-9, q


def test_a_negative_land_step_time_is_a_clear_error() -> None:
    data = {"library": str(REPO / "data" / "synthetic_clips"), "recipient": {"clip": "guard"},
            "impact": {}, "response": {"mode": "physical", "land_step_time": -0.1}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"\[response\]\.land_step_time"):
        parse_scenario(data, source="s.toml")


def test_a_kick_that_does_not_land_lands_on_a_clip_searched_again_from_where_the_body_is() -> None:
    # the sweep's kick from 100 deg (found clip `fall_sideways`, searched on Simulation 1's
    # body): Simulation 2's body does not land on it; searched again on Simulation 2's own body
    # from the match (`land_replan`), its path eased into the window so found, it lands
    sc = _facing(100.0, "physical")
    sc = replace(sc, response=replace(sc.response, land_tries=1, land_step_time=0.0))
    assert sc.response.land_replan > 0.0
    replanned = run_response(sc, CACHE).report
    once = run_response(replace(sc, response=replace(sc.response, land_replan=0.0)),
                        CACHE).report  # fmt: skip
    assert not once["transition"]["landed_on_clip"] and not once["transition"]["replanned"]
    tr, q = replanned["transition"], replanned["quality"]
    assert tr["landed_on_clip"] and tr["replanned"], tr
    assert tr["match"] >= once["transition"]["match"]  # a window from the first match on
    assert _score(replanned, sc) <= 1.0 < _score(once, sc)
    assert q["blend_joint_correction_max_rad"] <= sc.response.land_joint + 1e-9, q
    assert q["blend_root_offset_max_m"] <= sc.response.land_position + 1e-9, q


def test_a_body_that_falls_away_from_the_clip_stops_early_and_lands_where_it_came_closest(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # the sweep's kick from 0 deg does not land on `sway`: Simulation 2 stops once the body is
    # 3x further off than at its closest, 0.3 s after it, with the same landing as the whole
    # `land_within` gives, in fewer steps
    from reactmocap.response import stages

    sc = _facing(0.0, "physical")
    sc = replace(sc, response=replace(sc.response, land_tries=1, land_step_time=0.0,
                                      land_replan=0.0))  # fmt: skip
    early = run_response(sc, CACHE).report
    monkeypatch.setattr(stages, "LAND_GIVE_UP", np.inf)
    whole = run_response(sc, CACHE).report
    assert not early["transition"]["landed_on_clip"]
    assert early["transition"] == whole["transition"]
    key = "blend_root_offset_max_m"
    assert early["quality"][key] == whole["quality"][key]
    assert early["steps"]["sim2"] < 0.75 * whole["steps"]["sim2"], (early["steps"], whole["steps"])


def test_a_negative_land_replan_is_a_clear_error() -> None:
    data = {"library": str(REPO / "data" / "synthetic_clips"), "recipient": {"clip": "guard"},
            "impact": {}, "response": {"mode": "physical", "land_replan": -0.1}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"\[response\]\.land_replan"):
        parse_scenario(data, source="s.toml")


def test_a_landed_kick_is_placed_under_the_body_and_the_blend_corrects_only_the_rest() -> None:
    # the sweep's kick from 60 deg lands on `step_left` 4 cm (ground plane) from where the
    # search placed it: the clip is moved on the ground under the body's pelvis at the landing
    # (`blend_place`, reported as `found_shift_m`), so the final blend moves the root only by
    # what is left (the height); unplaced, it moves it the whole 4 cm
    from reactmocap import metrics as qm
    from reactmocap.response import final, stages

    sc = _facing(60.0, "physical")
    cfg = sc.response
    cast = stages.cast(sc, CACHE)
    contact = stages.estimate_contact(sc, cast)
    naive = stages.naive_simulation(sc, cast, contact)
    cont = stages.search_continuation(sc, cast, contact, naive)
    sim2 = stages.transition_simulation(sc, cast, contact, naive, cont)
    assert sim2.on_clip and sim2.landing_gap[0] > 0.03, sim2.landing_gap
    parts = cast.recipient.parts
    out = final.blend(sc, cast, contact, naive, cont, sim2)
    old = final.blend(replace(sc, response=replace(cfg, blend_place=False)), cast, contact,
                      naive, cont, sim2)  # fmt: skip
    placed = qm.blend_root_offset_max_m(out.simulated, out.blended, parts)
    dragged = qm.blend_root_offset_max_m(old.simulated, old.blended, parts)
    assert dragged == pytest.approx(sim2.landing_gap[0], abs=0.005)
    assert placed <= 0.02 < dragged, (placed, dragged)
    shift = np.hypot(*out.found_shift)
    assert 0.02 < shift <= cfg.land_position + 1e-9 and old.found_shift == (0.0, 0.0)
    # what is left is the height: the found clip's pelvis over the body's on the ground plane
    pelvis = parts.joint_of("pelvis")
    body = out.simulated.global_positions()[-1, pelvis]
    clip = out.blended.global_positions()[-1, pelvis]
    assert np.allclose(body[:2], clip[:2], atol=1e-3), (body, clip)
    assert placed == pytest.approx(abs(body[2] - clip[2]), abs=1e-3)
    # the joints are not the placement's to correct: the same blend
    same = qm.blend_joint_correction_max_rad(old.simulated, old.blended)
    assert qm.blend_joint_correction_max_rad(out.simulated, out.blended) == pytest.approx(same)
    # the shift is bounded by the landing tolerance, whatever the body's distance
    near = final.placed(cast, contact, cont, sim2, sim2.landed, within=0.01)[1]
    assert np.hypot(*near) == pytest.approx(0.01)
    assert np.allclose(np.asarray(near) / 0.01, np.asarray(out.found_shift) / shift)


def test_a_body_that_never_lands_hands_off_where_the_blend_corrects_least() -> None:
    # a real World on the light push's recipient, never within the tolerances: at 0.2 s a joint
    # 0.15 rad off (the closest check: 1.5 tolerances), at 0.3 s the joints within 0.05 rad but
    # the root turned 0.3 rad (1.8 tolerances of `land_angle`, half the root-turn warning) and
    # the pelvis 6 cm off on the ground (what the clip's placement takes up, but 1 cm): the
    # hand-off is the second, where the final blend turns no joint past `land_joint`
    from reactmocap import metrics as qm
    from reactmocap.response import stages
    from reactmocap.rotations import quat_mul
    from reactmocap.sim.world import World

    sc = _physical("light_push")
    cfg = sc.response
    cast = stages.cast(sc, CACHE)
    rec = cast.recipient
    q = rec.character.qpos_from_motion(rec.motion)
    world = World([rec.character])
    span = world.characters[0].qpos_slice
    landing = stages._Landing(cfg, q, rec.motion.fps, after=0.1)

    def turned(a: float) -> np.ndarray:
        return np.array([np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)])

    for t, joint, root, shift in ((0.2, 0.15, 0.0, 0.0), (0.3, 0.05, 0.3, 0.06)):
        want = q[int(round(t * rec.motion.fps))].copy()
        want[7:11] = quat_mul(want[7:11], turned(joint))  # the first joint after the free root
        want[3:7] = quat_mul(turned(root), want[3:7])
        want[0] += shift
        world.data.qpos[span] = want
        assert landing(world, t) is None  # never within the tolerances
    assert landing.at is None
    score, at, gap, _ = landing.best
    assert at == 0.2 and score == pytest.approx(1.5, abs=1e-5)  # the closest check
    left, at, gap, _ = landing.handoff
    assert at == 0.3, landing.handoff
    assert gap[2] == pytest.approx(0.05, abs=1e-6) and gap[1] == pytest.approx(0.3, abs=1e-6)
    assert left == pytest.approx(max(0.01 / cfg.land_position, 0.3 / qm.WARN_ROOT_TURN_RAD,
                                     0.5), abs=1e-5)  # fmt: skip


@pytest.mark.parametrize("deg", [270.0, 340.0])
def test_a_kick_that_does_not_land_hands_off_with_no_joint_past_the_tolerance(deg: float) -> None:
    # the sweep's kicks from 270 and 340 deg never land (re-plans, steps and other clips
    # included): at the closest check a joint is 0.115 and 0.134 rad off; each hands off where
    # the final blend turns no joint past `land_joint` (the root's turn within its warning):
    # 270 within its closest rollout, 340 on another rollout (a re-plan or the next-best clip:
    # in its closest one no check has every joint within 0.1 rad); the report still says it
    # did not land
    from reactmocap import metrics as qm

    sc = _facing(deg, "physical")
    rep = run_response(sc, CACHE).report
    tr, q = rep["transition"], rep["quality"]
    assert not tr["landed_on_clip"], tr
    assert _score(rep, sc) > 1.0
    assert q["blend_joint_correction_max_rad"] <= sc.response.land_joint + 1e-9, q
    assert q["blend_root_turn_max_rad"] <= qm.WARN_ROOT_TURN_RAD, q
    assert q["blend_root_offset_max_m"] <= sc.response.land_position, q
    assert any("physical mode" in w for w in rep["warnings"]), rep["warnings"]
