"""Tumbling (thesis ch. 5) and the standing back somersault (ch. 8.4), measured on the bodies and
on the simulated motion."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from reactmocap.athletics import athlete
from reactmocap.athletics.backdrop import arm_windmill
from reactmocap.athletics.behaviours import AthleticsResult
from reactmocap.athletics.land import LandingParams
from reactmocap.athletics.leap import LeapParams
from reactmocap.athletics.maneuvers import (
    CONTROLLERS,
    Maneuver,
    Perturbation,
    Phase,
    load_maneuver,
    run_maneuver,
)
from reactmocap.athletics.report import FALL_HEIGHT
from reactmocap.athletics.rig import joint_index
from reactmocap.athletics.routines import (
    DIVE_PIKE_HIP,
    SETTLED_START,
    SETTLED_START_STANDING,
    SOMERSAULT_SECONDS,
    TIMED_START,
    dive_maneuver,
    somersault,
    somersault_maneuver,
)
from reactmocap.athletics.scene import athletics_world
from reactmocap.athletics.senses import Senses
from reactmocap.athletics.tumble import (
    POSITIONS,
    TumbleParams,
    composite_inertia,
    position_angles,
    somersault_inertia,
)
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.bodies import SIM_BODIES
from tests.athletics.test_capture import FULL, full_starts

#: Fig. 5.2: moment of inertia about the somersault axis (kg m^2)
THESIS_FIG_5_2 = {
    "male": {"layout": 18.31, "pike": 5.84, "tuck": 4.84},
    "female": {"layout": 7.43, "pike": 2.52, "tuck": 1.92},
}


@pytest.mark.parametrize("body", ["male", "female"])
def test_somersault_inertia_within_10_percent_of_the_thesis(body: str) -> None:
    a = athlete(body)
    for position, thesis in THESIS_FIG_5_2[body].items():
        measured = somersault_inertia(a, position)
        assert abs(measured - thesis) <= 0.10 * thesis, (position, measured, thesis)
    # the tuck is the tightest: about a third of the layout's (section 5.1)
    assert (
        somersault_inertia(a, "tuck")
        < somersault_inertia(a, "pike")
        < somersault_inertia(a, "layout") / 2.5
    )


def test_positions_and_params_are_checked() -> None:
    assert set(POSITIONS) == {"layout", "pike", "tuck"}
    with pytest.raises(UnknownKeyError, match="valid positions"):
        TumbleParams(position="straddle")
    with pytest.raises(ConfigError, match="> 0"):
        TumbleParams(turns=0.0)
    for bad in (-0.1, math.nan, 5.0):
        with pytest.raises(ConfigError, match=r"open_delay must be in \[0, 5\) s"):
            TumbleParams(open_delay=bad)


@pytest.fixture(scope="module")
def back_tuck():  # type: ignore[no-untyped-def]
    return somersault("tuck", "backward", "male")


def test_a_back_somersault_turns_360_and_lands(back_tuck) -> None:  # type: ignore[no-untyped-def]
    r = back_tuck.report
    assert abs(abs(r["rotation_deg"]) - 360.0) <= 30.0
    assert r["rotation_deg"] < 0  # backward
    assert r["landed"] and not r["fell"] and r["status"] == "ok"
    # the rotation is the log's: the trunk came back upright, one turn round
    assert np.degrees(back_tuck.log["rotation"][-1]) == pytest.approx(r["rotation_deg"])
    assert [t for _, _, t in back_tuck.transitions][3:5] == ["tumble.tumble", "land.reach"]


def test_angular_momentum_is_conserved_in_the_somersault_flight(back_tuck) -> None:  # type: ignore[no-untyped-def]
    r = back_tuck.report
    t, momentum = back_tuck.log["t"], back_tuck.log["momentum"]
    flight = (t > r["time_to_liftoff_s"] + 0.01) & (t < r["touchdown_s"] - 0.01)
    assert flight.sum() > 100
    m = momentum[flight]
    assert np.linalg.norm(m[0]) > 30.0  # a real back somersault's momentum
    assert np.abs(m - m[0]).max() / np.linalg.norm(m[0]) <= 0.01
    # tucking speeds the rotation up (Fig. 5.3): peak rate well above the layout's L / I
    layout = np.linalg.norm(m[0]) / somersault_inertia(athlete("male"), "layout")
    assert r["peak_somersault_rate_rad_s"] > 2.5 * layout


def test_a_4_kg_backpack_still_lands_the_back_somersault_untuned() -> None:
    # thesis 8.5.2 (there on the forward somersault, which needed re-tuning)
    r = somersault("tuck", "backward", "male", backpack=4.0).report
    assert r["backpack_kg"] == 4.0 and r["liftoff_pitch_momentum"] < -50.0  # heavier: more L
    assert r["landed"] and abs(r["rotation_deg"] + 360.0) <= 30.0


def test_the_back_layout_somersault_turns_360_and_lands() -> None:
    # the layout turns slower than the landing's reach: the tumble holds it until the
    # prediction has come down to the turn, well into the flight
    res = somersault("layout", "backward", "male")
    r = res.report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    assert r["tumble_min_inertia_kgm2"] > 14.0  # it was in the layout, not tucked
    start = next(t for t, _, to in res.transitions if to == "tumble.tumble")
    opened = next(t for t, frm, _ in res.transitions if frm == "tumble.tumble")
    assert opened - start > 0.5 * r["flight_s"]
    assert r["flight_momentum_drift"] <= 0.01


def test_the_back_layout_with_one_twist_twists_360_and_lands() -> None:
    # thesis 5.2's tilt twist in the standing back layout (issue 19): the arms' throw twists
    # the body and their return stops it at a full turn; the tumble opens only after that, so
    # the leap takes off with more momentum than the untwisted layout's (-77 kg m^2/s: at -79
    # the body touched down at -275 deg and fell). Refused before 2026-12-02
    res = somersault("layout", "backward", "male", twist=1.0)
    r = res.report
    assert r["status"] == "ok" and r["landed"] and not r["fell"]
    assert abs(r["rotation_deg"] + 360.0) <= 30.0
    assert r["twist_turns"] == 1.0 and abs(r["twist_error_deg"]) <= 45.0
    assert abs(abs(r["twist_at_touchdown_deg"]) - 360.0) <= 45.0
    assert r["twist_stopped"] and r["liftoff_pitch_momentum"] < -85.0
    opened = next(t for t, frm, _ in res.transitions if frm == "tumble.tumble")
    assert r["twist_undone_s"] < opened < r["touchdown_s"]
    # the arms' throw and return within the flight: 1.4% drift measured (the dive's: < 1%)
    assert r["flight_momentum_drift"] <= 0.02


def _layout_flight(arm_tilt: float) -> tuple[float, dict]:  # type: ignore[type-arg]
    """The twist (deg) when the tumble opens (the layout held until then) and the report."""
    m = somersault_maneuver("layout")
    phases = list(m.phases)
    phases[2] = replace(phases[2], params={**phases[2].params, "arm_tilt": arm_tilt})
    res = run_maneuver(replace(m, phases=tuple(phases), seconds=2.3))
    opened = next(t for t, frm, _ in res.transitions if frm == "tumble.tumble")
    i = int(np.searchsorted(res.log["t"], opened))
    return float(np.degrees(res.log["twist"][i])), res.report


def test_the_arm_throw_starts_a_twist_in_the_air() -> None:
    # section 5.2: both arms turned the same way about the front-back axis tilt the body out of
    # the somersault plane; with no throw the layout somersault does not twist. Measured while
    # the layout is held (the landing's reach then pikes and turns the pelvis-to-head line)
    (still, _), (thrown, rep) = _layout_flight(0.0), _layout_flight(1.0)
    assert abs(still) < 5.0
    assert abs(thrown) > 40.0
    assert rep["flight_momentum_drift"] <= 0.01


def test_windmilling_the_arms_with_no_momentum_tilts_the_body_about_20_degrees() -> None:
    # thesis 5.1.1: one clockwise windmill of the arms tilts the male torso ~20 degrees the
    # other way; torque-free, so the angular momentum stays at zero
    one, back = arm_windmill("male", 1.0), arm_windmill("male", -1.0)
    assert one["status"] == "ok" and one["max_momentum"] < 0.1
    assert 15.0 <= one["rotation_per_cycle_deg"] <= 25.0
    assert back["rotation_deg"] == pytest.approx(-one["rotation_deg"], abs=1.0)
    # it adds up cycle by cycle (a somersault by repetition, given the time)
    assert arm_windmill("male", 2.0)["rotation_deg"] == pytest.approx(
        2 * one["rotation_deg"], rel=0.05
    )


def test_the_female_back_somersault_lands_too() -> None:
    r = somersault("tuck", "backward", "female").report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    # her tuck: about a third of the male's momentum, and faster (Fig. 5.2: 1.92 kg m^2)
    assert -30.0 < r["liftoff_pitch_momentum"] < -15.0
    assert r["tumble_min_inertia_kgm2"] < 2.2 and r["peak_somersault_rate_rad_s"] > 10.0


def test_the_forward_tuck_somersault_turns_360_forward_and_lands() -> None:
    res = somersault("tuck", "forward", "male")
    r = res.report
    assert r["status"] == "ok" and r["liftoff_pitch_momentum"] > 35.0  # forward momentum
    # one full turn forward, the trunk upright again at the end (the mirrored back preset
    # turned -635 degrees and fell)
    assert abs(r["rotation_deg"] - 360.0) <= 45.0
    assert r["landed"] and not r["fell"]
    # 1.5%, not 1%: the reach, opened 0.24 s before touchdown, swings the hips from -2.1 to
    # +0.4 rad in 0.15 s, and the momentum moves by 1.2% over those ticks (nothing touches):
    # the integrator's error at 0.5 ms, 0.49% at a 0.25 ms step (docs/athletics.md)
    assert r["flight_momentum_drift"] <= 0.015
    # `fell` is the log's: nothing but the feet touched and the pelvis stayed above half its
    # standing height (this landing's crouch is deep: docs/athletics.md)
    pelvis = res.log["pelvis"]
    assert not res.log["others"].any() and pelvis.min() >= FALL_HEIGHT * pelvis[0]


def test_the_forward_tuck_lands_with_2_and_4_kg_backpacks_untuned() -> None:
    """Thesis 8.5.2: the forward tuck carries a 2 or a 4 kg backpack without re-tuning. Its
    "com" push leaves the floor once (the timed push before it hopped off as it began and left
    at +43 or +34 kg m^2/s; both backpacks fell) with its momentum near the aimed +49."""
    for kg in (2.0, 4.0):
        res = somersault("tuck", "forward", "male", backpack=kg, fps=10.0)
        r = res.report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0, kg
        assert 46.0 < r["liftoff_pitch_momentum"] < 54.0, kg
        times = {to: t for t, _, to in res.transitions}
        t = res.log["t"]
        push = (t >= times["leap.thrust"]) & (t <= times["leap.flight"] + 0.004)
        down = res.log["feet"][push] > 0
        assert int(np.sum(down[:-1] & ~down[1:])) == 1, kg  # the feet leave once


#: the benchmark's perturbations at a tenth of full size (``bench_athletics.capture``)
_TENTH = {"joint_sd": math.radians(0.3), "pitch_sd": math.radians(0.2),
          "velocity_sd": 0.005, "spin_sd": 0.01}  # fmt: skip


def _tenth_start(seed: int, i: int) -> Perturbation:
    """Start ``i`` of ``capture_region``'s draw at a tenth on ``seed``."""
    rng = np.random.default_rng(seed)
    return [Perturbation.sample(rng, **_TENTH) for _ in range(i + 1)][i]


FORWARD_FILE = Path(__file__).parents[2] / "examples/athletics/maneuvers/forward_somersault.toml"


def _without_land_param(m: Maneuver, key: str) -> Maneuver:
    """``m`` with ``key`` taken out of its landing phase's parameters."""
    i = next(k for k, ph in enumerate(m.phases) if ph.controller == "land")
    return _with_land_params(m, {k: v for k, v in m.phases[i].params.items() if k != key})


def _with_land_params(m: Maneuver, params: Mapping[str, Any]) -> Maneuver:
    """``m`` with its landing phase's parameters replaced by ``params``."""
    i = next(k for k, ph in enumerate(m.phases) if ph.controller == "land")
    return replace(
        m, phases=(*m.phases[:i], replace(m.phases[i], params=params), *m.phases[i + 1 :])
    )


def _forward_timed() -> Maneuver:
    """The forward preset leaping 0.3 s into the start (:data:`TIMED_START`, 5.5 s), as
    before 2026-12-05 (since then it settles first, :data:`SETTLED_START_STANDING`): the
    tests of the leap's and the landing's options below were written on starts whose outcome
    the settled start changes."""
    m = somersault_maneuver(direction="forward")
    return replace(m, phases=(TIMED_START, *m.phases[1:]), seconds=SOMERSAULT_SECONDS["after"])


def _forward_hold_015() -> Maneuver:
    """The forward preset with its crouch's hold at 0.15 s, as before 2026-12-03 22:45 UTC
    (since then 0.25), from the timed start (:func:`_forward_timed`): the tests of the push's
    and the landing's options below were written on starts whose outcome the longer hold
    changes."""
    m = _forward_timed()
    leap = replace(m.phases[1], params={**m.phases[1].params, "hold": 0.15})
    return replace(m, phases=(m.phases[0], leap, *m.phases[2:]))


def test_a_perturbed_forward_tuck_settles_onto_both_feet_before_the_crouch() -> None:
    """Start 12 of the capture region at full size (seed 0): leaping 0.3 s into the start
    (:func:`_forward_timed`), it crouched on one foot (fewer than two down 98% of the crouch
    and hold), took off with -12.6 kg m^2/s of roll and fell forward 0.78 s after touchdown.
    The preset's start since 2026-12-05 (:data:`SETTLED_START_STANDING`) settles it onto both
    feet first: it leaps later and lands (docs/athletics.md, "Forward tuck: a census of the
    full-size failures")."""
    start = full_starts(13)[12]
    m = somersault_maneuver(direction="forward")
    assert m.phases[0] == SETTLED_START_STANDING
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    before = run_maneuver(_forward_timed(), perturbation=start, fps=10.0).report
    assert not before["landed"] and before["time_to_liftoff_s"] < r["time_to_liftoff_s"]


def test_the_forward_tuck_files_feet_move_by_the_predicted_touchdown_rotation() -> None:
    """Start 23 of the capture region at full size (seed 0): without the landing's
    ``turn_gain`` it lands 448 deg round, over-rotated, and falls; the file since 2026-12-05
    (``turn_gain`` 0.25 past ``turn_ref`` 5.49 rad) puts the feet ahead by the rotation
    predicted at touchdown and it lands (full size 44 / 44 / 40 of 50 on seeds 0 / 1 / 2,
    from 44 / 41 / 37; docs/athletics.md, "Forward tuck: the short touchdown's class C");
    the over-rotation read with the last balance as it was then (since 2026-12-05 13:50 UTC
    the standing plant and gains)."""
    m = load_maneuver(FORWARD_FILE)
    start = full_starts(24)[23]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    plain = _with_last_balance_params(m, {"settle": 2.0})
    before = run_maneuver(_without_land_param(plain, "turn_gain"), perturbation=start, fps=10.0)
    assert not before.report["landed"] and before.report["rotation_deg"] > 400.0


def _with_last_balance_params(m: Maneuver, params: Mapping[str, Any]) -> Maneuver:
    """``m`` with its last phase (a balance) given ``params``."""
    assert m.phases[-1].controller == "balance"
    return replace(m, phases=(*m.phases[:-1], replace(m.phases[-1], params=params)))


def test_the_forward_tucks_last_balance_puts_down_a_foot_left_hanging() -> None:
    """Start 42 of the capture region at full size (seed 0) lands, then stands up on one
    foot in the last balance (97% of it, the lifted foot cm up) and falls sideways 1.7 s after
    touchdown; the file since 2026-12-05 13:50 UTC (the standing balance's plant of a hung
    foot and its gains, ``standing_step``, its step off) puts the foot down and it stands
    (full size 45 / 46 / 41 of 50 on seeds 0 / 1 / 2 from 44 / 44 / 40; docs/athletics.md,
    "Forward tuck: the standing balance's own step in the last balance")."""
    m = load_maneuver(FORWARD_FILE)
    assert m.phases[-1].params["standing_step"] is True
    start = full_starts(43)[42]
    r = run_maneuver(m, perturbation=start, fps=10.0)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["rotation_deg"] - 360.0) <= 30.0 and int(r.log["feet"][-1]) == 2
    before = run_maneuver(_with_last_balance_params(m, {"settle": 2.0}), perturbation=start,
                          fps=10.0)  # fmt: skip
    assert before.report["fell"] and not before.report["landed"]


def test_the_forward_tucks_hanging_foot_put_down_near_the_support_lands_seed_2s_start_26() -> None:
    """Start 26 of the capture region at full size, seed 2: without ``hang_near`` the last
    balance puts its hung foot down 0.32 s after touchdown with the COM still 11 cm off the
    standing sole, and it stands on one foot for 84% of the balance and falls; the file since
    2026-12-05 16:50 UTC (``hang_near`` 0.085: the plant waits for the COM within 8.5 cm of
    the sole too) never plants it there, both feet take turns down and it lands (full size
    45 / 47 / 43 of 50 on seeds 0 / 1 / 2 from 45 / 46 / 41; docs/athletics.md, "Forward
    tuck: the hung foot put down near the support")."""
    rng = np.random.default_rng(2)
    start = [Perturbation.sample(rng, **FULL) for _ in range(27)][26]
    m = replace(load_maneuver(FORWARD_FILE), seconds=5.5)
    last = dict(m.phases[-1].params)
    assert last.pop("hang_near") == 0.085
    last.pop("plant_settle")  # the file before hang_near (2026-12-05): nor recover_min
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    old = _without_land_param(_with_last_balance_params(m, last), "recover_min")
    before = run_maneuver(old, perturbation=start, fps=10.0)
    assert before.report["fell"] and not before.report["landed"]


def test_the_forward_tucks_stand_up_restarted_at_the_plant_lands_seed_2s_start_18() -> None:
    """Start 18 of the capture region at full size, seed 2: without ``plant_settle`` the last
    balance puts its hung foot down 0.34 s after touchdown in the stand-up's bounce, the foot
    hovers, the COM crosses past it and the body falls toward it; the file since 2026-12-05
    (``plant_settle`` 1.0: the stand-up starts again from rest at the plant and takes 1 s)
    lands (full size 45 / 47 on seeds 0 / 1 as before, held-out seeds 3 / 4 43 / 45 from
    42 / 45; docs/athletics.md, "Forward tuck: the stand-up restarted at the plant")."""
    rng = np.random.default_rng(2)
    start = [Perturbation.sample(rng, **FULL) for _ in range(19)][18]
    m = replace(load_maneuver(FORWARD_FILE), seconds=6.0)
    last = dict(m.phases[-1].params)
    assert last.pop("plant_settle") == 1.0
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    old = _without_land_param(_with_last_balance_params(m, last), "recover_min")  # the file then
    before = run_maneuver(old, perturbation=start, fps=10.0).report
    assert before["fell"] and not before["landed"]


def test_the_forward_tuck_files_4_kg_backpack_lands_with_the_landings_recover_min() -> None:
    """Thesis 8.5.2 on the file: with a 4 kg backpack its landing bounced off both feet 12 ms
    into the recovery, which handed over at its 0.05 s minimum on one foot, and the run fell
    (-305.5 deg); the file since 2026-12-06 (``recover_min`` 0.15 s) lands it
    (docs/athletics.md, "Forward tuck: the file's 4 kg backpack landed"). Cut at 5.5 s."""
    m = replace(load_maneuver(FORWARD_FILE), backpack=4.0, seconds=5.5)
    land = next(p for p in m.phases if p.controller == "land").params
    assert land["recover_min"] == 0.15
    r = run_maneuver(m, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    before = run_maneuver(_without_land_param(m, "recover_min"), fps=10.0).report
    assert before["fell"] and not before["landed"]


def test_the_landing_refuses_a_recover_min_out_of_range() -> None:
    for bad in (0.0, 0.04, 1.5, math.nan, -1.0):
        with pytest.raises(ConfigError, match="recover_min"):
            LandingParams(recover_min=bad)
    m = _with_land_params(load_maneuver(FORWARD_FILE), {"recover_min": 2.0})
    with pytest.raises(ConfigError, match="recover_min"):
        run_maneuver(m, fps=10.0)


def test_a_perturbed_forward_tuck_pushes_off_without_cartwheel_and_lands() -> None:
    """Start 2 of the capture region at full size (seed 0). Its "com" push let the start's
    small roll grow to -5.8 kg m^2/s of cartwheel momentum: the feet touched down 12 cm to
    the side of the COM, it stood up on one foot and fell. With the push's weight moved
    between the feet against the roll (``roll_gain``) and the legs' sideways aim taken from
    the pelvis's whole orientation (``aim_sideways``), the preset since 2026-12-03, it leaves
    with under 1 kg m^2/s of roll and lands (the roll read as the world x momentum, see
    :func:`_liftoff_momentum`)."""
    start = full_starts(3)[2]
    m = _forward_hold_015()
    assert m.phases[1].params["roll_gain"] > 0 and m.phases[3].params["aim_sideways"] is True
    r = run_maneuver(m, perturbation=start, fps=10.0)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["rotation_deg"] - 360.0) <= 30.0
    assert abs(_liftoff_momentum(r)[0]) < 2.0
    leap = replace(m.phases[1], params={**m.phases[1].params, "roll_gain": 0.0})
    land = replace(m.phases[3], params={**m.phases[3].params, "aim_sideways": False})
    before = replace(m, phases=(m.phases[0], leap, m.phases[2], land, *m.phases[4:]))
    r = run_maneuver(before, perturbation=start, fps=10.0)
    assert r.report["fell"] and not r.report["landed"]
    assert abs(_liftoff_momentum(r)[0]) > 4.0


def test_the_leap_refuses_a_roll_gain_out_of_range() -> None:
    for bad in (-1.0, 101.0, math.nan):
        with pytest.raises(ConfigError, match="roll_gain|finite"):
            LeapParams(roll_gain=bad)


def test_the_back_pike_lands_on_more_momentum_than_the_tuck(back_tuck) -> None:  # type: ignore[no-untyped-def]
    r = somersault("pike", "backward", "male").report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    # the pike's larger inertia (Fig. 5.2) needs a larger take-off momentum for the same turn
    assert r["liftoff_pitch_momentum"] < back_tuck.report["liftoff_pitch_momentum"] - 5.0
    assert r["tumble_min_inertia_kgm2"] > back_tuck.report["tumble_min_inertia_kgm2"] + 0.5


def test_perturbed_back_layouts_open_past_inverted_and_land() -> None:
    """Starts 2 and 10 of the capture region at a tenth (seed 0). With the leap at effort 0.8
    and the opening predicted at 7.5 kg m^2 (before 2026-12-02 07:00) both fell: start 2 took
    off with a little less momentum than the nominal, opened short of inverted, and the
    landing's reach folded it into a deep pike that touched down at -514 deg. The higher leap
    opens them past inverted: they touch down near -300 deg and land."""
    rng = np.random.default_rng(0)
    tenth = {"joint_sd": math.radians(0.3), "pitch_sd": math.radians(0.2),
             "velocity_sd": 0.005, "spin_sd": 0.01}  # fmt: skip
    starts = [Perturbation.sample(rng, **tenth) for _ in range(11)]
    # measured with the leap 0.3 s into the start (the preset now settles it first)
    m = somersault_maneuver("layout")
    m = replace(m, phases=(TIMED_START, *m.phases[1:]))
    for i in (2, 10):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert -330.0 < r["rotation_at_touchdown_deg"] < -280.0, (i, r["rotation_at_touchdown_deg"])
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, i


def test_the_back_layout_opens_by_the_reach_s_turn_over_its_time() -> None:
    """Starts 28 and 42 of ``back_layout.toml``'s capture region at a tenth (seed 0). With the
    reach's turn predicted as L / 8.0 kg m^2 over all the time to touchdown (before
    2026-12-03) both opened a tick early, touched down near -305.5 deg still turning backward
    and fell. The reach pikes deeper the longer it has, so its turn grows about four times
    faster with its time than its mean rate: predicted over the time less ``open_delay``
    (the file), both open a tick later, touch down near -303 deg and land."""
    rng = np.random.default_rng(0)
    tenth = {"joint_sd": math.radians(0.3), "pitch_sd": math.radians(0.2),
             "velocity_sd": 0.005, "spin_sd": 0.01}  # fmt: skip
    starts = [Perturbation.sample(rng, **tenth) for _ in range(43)]
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    tumble = m.phases[2]
    assert tumble.controller == "tumble" and tumble.params["open_delay"] > 0.0
    old = replace(tumble, params={**tumble.params, "lead": 0.0, "open_inertia": 8.0,
                                  "open_delay": 0.0})  # fmt: skip
    # the landing as it was then too: its turn_gain (since 2026-12-03 22:00) lands a touchdown
    # at -305.5 (the next test), its recover_spin (since 2026-12-04 11:30) lands start 28 and
    # its lean 0.8 (since 13:12) start 42
    land = replace(m.phases[3], params={**m.phases[3].params, "turn_gain": 0.0,
                                        "recover_spin": 0.0, "lean": 0.5})  # fmt: skip
    before = replace(m, phases=(*m.phases[:2], old, land, *m.phases[4:]))
    for i in (28, 42):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert -305.0 < r["rotation_at_touchdown_deg"] < -301.0, (i, r["rotation_at_touchdown_deg"])
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, i
        r = run_maneuver(before, perturbation=starts[i], fps=10.0).report
        assert r["rotation_at_touchdown_deg"] < -305.0, (i, r["rotation_at_touchdown_deg"])
        assert r["fell"] and not r["landed"], i


def test_perturbed_back_tucks_land_with_the_legs_aimed_sideways() -> None:
    """Starts 0 and 5 of the capture region at full size (seed 0). Both fell with the legs'
    roll from the foot servo alone: start 0 touched down with the pelvis rolled 16 degrees and
    the feet 7 cm to the side of the COM, stood on one foot and fell sideways; start 5 stood on
    one foot and turned on backward. With the hips' roll taken from the pelvis's whole
    orientation (``aim_sideways``, the preset since 2026-12-02) both land on both feet."""
    starts = full_starts(6)
    # measured with the leap 0.3 s into the start (the preset now settles it first)
    m = somersault_maneuver()
    m = replace(m, phases=(TIMED_START, *m.phases[1:]))
    assert m.phases[3].params["aim_sideways"] is True
    for i in (0, 5):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, i
    # the same landing without the sideways aim (and the reach before ``spin_aim``): start 0
    # falls
    land = replace(m.phases[3], params={**m.phases[3].params, "aim_sideways": False,
                                        "spin_aim": False})  # fmt: skip
    off = replace(m, phases=(*m.phases[:3], land, *m.phases[4:]))
    r = run_maneuver(off, perturbation=starts[0], fps=10.0).report
    assert r["fell"] and not r["landed"]


def test_perturbed_back_tucks_land_with_the_legs_holding_their_aim() -> None:
    """Starts 8 and 9 of the capture region at full size (seed 0) fell with the reach's legs
    aimed in the pelvis's forward heading (which flips as the body passes the horizontal) and
    trailing their turning target: the feet swept forward under the body at 3-5 m/s when
    they touched. With ``spin_aim`` (the preset) the legs hold their aim and both land."""
    starts = full_starts(10)
    m = somersault_maneuver()
    assert m.phases[3].params["spin_aim"] is True
    _land_only_with_the_landing_as_is(m, {"spin_aim": False}, [starts[8], starts[9]])


def _land_only_with_the_landing_as_is(
    m: Maneuver, off: dict[str, object], starts: list[Perturbation]
) -> None:
    """Each start lands a back somersault with ``m`` and falls with its landing (phase 3)
    changed by ``off``."""
    land = replace(m.phases[3], params={**m.phases[3].params, **off})
    before = replace(m, phases=(*m.phases[:3], land, *m.phases[4:]))
    for i, start in enumerate(starts):
        r = run_maneuver(m, perturbation=start, fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, i
        r = run_maneuver(before, perturbation=start, fps=10.0).report
        assert r["fell"] and not r["landed"], i


#: the female back tuck's landing before 2026-12-03's arms against the twist
ARMS_OFF = {"twist_arms": 0.0, "stance_push": False}


def test_perturbed_female_back_tucks_land_with_the_legs_aimed_where_the_pelvis_will_be() -> None:
    """Starts 0 and 5 of the capture region at full size (seed 0), on the female body. Her
    take-off's few kg m^2/s of cartwheel momentum twist her opening body about its long axis
    (the pelvis rolling at ~4 rad/s through the reach), and with the legs' sideways aim taken
    from where the pelvis is (``aim_sideways`` alone, or the preset before: ``spin_aim``
    alone) start 0's feet touched down 10-17 cm to the side of the COM, she stood up on one
    foot and fell sideways. With the aim taken from where the pelvis will be once the hips
    get there (``twist_aim``, the preset since 2026-12-03) both land. The ablations push off
    as the preset did then (no ``tilt_gain``: with it start 0 lands without ``twist_aim``
    too)."""
    starts = full_starts(6)
    m = somersault_maneuver(body="female")
    assert m.phases[3].params["twist_aim"] is True
    for i in (0, 5):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, i
    leap = replace(m.phases[1], params={**m.phases[1].params, "tilt_gain": 0.0})
    for off in ({"twist_aim": False}, {"twist_aim": False, "aim_sideways": False}):
        land = replace(m.phases[3], params={**m.phases[3].params, **ARMS_OFF, **off})
        before = replace(m, phases=(m.phases[0], leap, m.phases[2], land, *m.phases[4:]))
        r = run_maneuver(before, perturbation=starts[0], fps=10.0).report
        assert r["fell"] and not r["landed"], off


def _liftoff_momentum(r: AthleticsResult) -> np.ndarray:
    """The whole-body angular momentum (world, kg m^2/s) just after lift-off. Its x is the
    roll only while the heading is the start's (+X): a heading turned by a few degrees mixes
    in part of the pitch momentum (the forward tuck's +50: start 0 reads +7.3 in the world,
    -0.95 in its heading frame; docs/athletics.md, the forward tuck's roll traced)."""
    t = r.log["t"]
    k = min(int(np.searchsorted(t, r.report["time_to_liftoff_s"] + 0.02)), t.size - 1)
    return np.asarray(r.log["momentum"][k])


def test_the_female_back_tuck_pushes_off_with_little_yaw_momentum() -> None:
    """Start 3 of the capture region at full size (seed 0), female. The take-off's yaw
    momentum told her landings apart (above 0.61 kg m^2/s 19% landed, below 90%): it twists
    the opening body. Without the push's tilt feedback (``tilt_gain`` 0, the preset before)
    she left with 1.07 kg m^2/s and fell; with it (the preset since 2026-12-03) with about
    half, and lands. Both with the landing as it was measured then, without the feet placed
    for the spin (``momentum_gain``), with which this start, twisted 31 degrees in the air,
    falls sideways."""
    start = full_starts(4)[3]
    m = somersault_maneuver(body="female")
    assert m.phases[1].params["tilt_gain"] > 0
    land = replace(m.phases[3], params={**m.phases[3].params, "momentum_gain": 0.0})
    m = replace(m, phases=(*m.phases[:3], land, *m.phases[4:]))
    r = run_maneuver(m, perturbation=start, fps=10.0)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["rotation_deg"] + 360.0) <= 30.0
    assert abs(_liftoff_momentum(r)[2]) < 0.6
    leap = replace(m.phases[1], params={**m.phases[1].params, "tilt_gain": 0.0})
    land = replace(m.phases[3], params={**m.phases[3].params, **ARMS_OFF})
    before = replace(m, phases=(m.phases[0], leap, m.phases[2], land, *m.phases[4:]))
    r = run_maneuver(before, perturbation=start, fps=10.0)
    assert r.report["fell"] and not r.report["landed"]
    assert abs(_liftoff_momentum(r)[2]) > 0.9


def _air_twist(r: AthleticsResult) -> float:
    """The twist (deg) from lift-off to touchdown."""
    t, twist = r.log["t"], r.log["twist"]
    k0, k1 = np.searchsorted(t, (r.report["time_to_liftoff_s"], r.report["touchdown_s"]))
    return math.degrees(float(twist[min(k1, t.size - 1)] - twist[k0]))


def test_perturbed_female_back_tucks_land_with_the_arms_out_against_the_twist() -> None:
    """Starts 9 and 16 of the capture region at full size (seed 0), female. Her tuck opens
    with 2-4 kg m^2/s of angular momentum about the long axis, about which the opened body's
    inertia is least: with the arms forward (the preset before) start 9 twisted 105 degrees
    between lift-off and touchdown, touched down on one foot and fell sideways. With the arms
    spread against the twist in the reach (``twist_arms``) it twists about half that, and
    with the absorbing legs pushing from the foot that carries the weight (``stance_push``)
    both starts land (the preset since 2026-12-03); either alone, or neither, and start 9
    falls. The ablations spread the arms at ``twist_arms`` 15, as they were measured (at the
    preset's 25, since 2026-12-03 too, start 9 lands without ``stance_push`` as well)."""
    starts = full_starts(17)
    m = somersault_maneuver(body="female")
    assert m.phases[3].params["twist_arms"] > 0 and m.phases[3].params["stance_push"]
    for i in (9, 16):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0)
        assert r.report["landed"] and not r.report["fell"], i
        assert abs(r.report["rotation_deg"] + 360.0) <= 30.0, i
        assert abs(_air_twist(r)) < 70.0, i
    for off in (ARMS_OFF, {"twist_arms": 0.0}, {"stance_push": False}):
        land = replace(m.phases[3], params={**m.phases[3].params, "twist_arms": 15.0, **off})
        r = run_maneuver(replace(m, phases=(*m.phases[:3], land, *m.phases[4:])),
                         perturbation=starts[9], fps=10.0)  # fmt: skip
        assert r.report["fell"] and not r.report["landed"], off
        if off.get("twist_arms") == 0.0:  # the arms forward: the twist as before
            assert abs(_air_twist(r)) > 90.0, off


def test_a_weak_female_back_tuck_take_off_lands_with_the_feet_placed_for_its_spin() -> None:
    """Starts 14 and 24 of the capture region at full size (seed 0), female. Both push off
    weakly (under 22 of her usual 23 kg m^2/s backward); with the feet placed for the usual
    spin (the preset before) they touched down 4-5 cm behind the COM, stopped the smaller
    spin too hard and fell forward. With the feet moved ahead by the spin measured about the
    pelvis's left-right axis as the reach begins (``momentum_gain`` with ``momentum_side``,
    the preset since 2026-12-03) both land."""
    starts = full_starts(25)
    m = somersault_maneuver(body="female")
    assert m.phases[3].params["momentum_side"] is True
    _land_only_with_the_landing_as_is(m, {"momentum_gain": 0.0}, [starts[14], starts[24]])


def test_female_back_tucks_that_twisted_in_the_air_land_with_the_arms_spread_sooner() -> None:
    """Starts 1 and 29 of the capture region at full size (seed 0), female. With the arms
    spread against the twist at ``twist_arms`` 15 (the preset before; the full spread at 2.8
    kg m^2/s about the long axis) both fell. With 25 (the preset since 2026-12-03; the full
    spread from 1.7 kg m^2/s) both land."""
    starts = full_starts(30)
    m = somersault_maneuver(body="female")
    assert m.phases[3].params["twist_arms"] == 25.0
    _land_only_with_the_landing_as_is(m, {"twist_arms": 15.0}, [starts[1], starts[29]])


def test_a_female_back_tuck_start_settles_with_the_hips_and_arms_against_its_fall() -> None:
    """Start 38 of the capture region at full size (seed 0), female. It stands with the COM
    about 9 cm behind the balance's target over the feet; under the COM servo alone (``gains``
    "balance", the preset before) the ankles do not bring it back, it drifts further back,
    falls while settling and never leaps (``unsettled_s``). With the standing behaviour's hip
    and arm strategies as well (``gains`` "standing", the preset since 2026-12-03) it settles
    and lands."""
    start = full_starts(39)[38]
    m = somersault_maneuver(body="female")
    assert m.phases[0].params["gains"] == "standing"
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert "unsettled_s" not in r
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    first = replace(m.phases[0], params={**m.phases[0].params, "gains": "balance"})
    r = run_maneuver(replace(m, phases=(first, *m.phases[1:])), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["unsettled_s"] == pytest.approx(3.0) and r["time_to_liftoff_s"] is None


def test_the_balance_phase_refuses_an_unknown_gain_set() -> None:
    with pytest.raises(ConfigError, match="balance gains must be one of"):
        CONTROLLERS["balance"].build(Phase("balance", "settled", {"gains": "stiff"}),
                                     athlete("female"))  # fmt: skip


def test_the_leap_refuses_a_tilt_gain_out_of_range() -> None:
    for bad in (-1.0, 101.0, math.nan):
        with pytest.raises(ConfigError, match="tilt_gain|finite"):
            LeapParams(tilt_gain=bad)


def test_the_female_back_somersault_file_is_the_preset() -> None:
    """``back_somersault_female.toml`` (the capture benchmark's) runs the command's preset."""
    path = Path(__file__).parents[2] / "examples/athletics/maneuvers/back_somersault_female.toml"
    m, f = somersault_maneuver(body="female"), load_maneuver(path)
    assert (f.body, f.seconds) == (m.body, m.seconds)
    for built, read in zip(m.phases, f.phases, strict=True):
        params = {k: v for k, v in read.params.items() if (k, v) != ("turns", 1.0)}
        assert replace(read, params=params) == built


def test_the_somersault_command_leaps_from_a_settled_start_as_the_files_do() -> None:
    """The command's presets start as ``back_somersault.toml`` does (since 2026-12-02): the
    start settled onto both feet (:data:`SETTLED_START`) before the leap, not 0.3 s into it.
    The full twist keeps the timed start (:data:`PRESET_STARTS`); the male forward tuck settles
    with the standing gains since 2026-12-05.
    Start 4 of the full-size starts (seed 0) left the timed start moving back at 1.1 m/s and
    fell after touchdown; settled first it lands."""
    maneuvers = Path(__file__).parents[2] / "examples" / "athletics" / "maneuvers"
    for stem in ("vertical_leap", "back_somersault", "broad_jump"):
        first = load_maneuver(maneuvers / f"{stem}.toml").phases[0]
        if stem != "back_somersault":  # their own settled share (test_capture.py)
            first = replace(first, params={"plant": first.params["plant"]})
        assert first == SETTLED_START, stem
    m = somersault_maneuver()
    assert m.seconds == load_maneuver(maneuvers / "back_somersault.toml").seconds
    for built in (m, somersault_maneuver("pike"), somersault_maneuver("layout")):
        assert built.phases[0] == SETTLED_START, built.name
    for built in (somersault_maneuver(body="female"), somersault_maneuver(direction="forward")):
        assert built.phases[0] == SETTLED_START_STANDING, built.name  # with the standing gains
        assert built.seconds == m.seconds, built.name
    assert replace(SETTLED_START_STANDING, params={"plant": True}) == SETTLED_START
    assert somersault_maneuver("layout", twist=1.0).phases[0] == TIMED_START
    start = full_starts(5)[4]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    timed = replace(m, phases=(TIMED_START, *m.phases[1:]))
    assert run_maneuver(timed, perturbation=start, fps=10.0).report["fell"]


def test_the_side_heading_holds_through_a_somersault() -> None:
    """Pitched past the horizontal, the pelvis's forward axis points back: its heading flips
    by half a turn; the heading from the left-right axis (the landing's ``spin_aim``) does
    not."""
    a = athlete("male")
    world = athletics_world(a)
    senses = Senses(world, a)
    for pitch, flipped in ((0.3, False), (2.2, True), (-2.2, True)):
        world.set_pose(0, a.standing_qpos(np.zeros((15, 3)), pitch=pitch))
        turn = abs(math.remainder(senses.heading() - senses.side_heading(), 2.0 * math.pi))
        assert turn == pytest.approx(math.pi if flipped else 0.0, abs=1e-6), pitch
        assert abs(math.remainder(senses.side_heading(), 2.0 * math.pi)) < 1e-6


@pytest.mark.parametrize("body", ["male", "female"])
def test_the_dive_pike_turns_about_its_largest_principal_axis(body: str) -> None:
    """At the pike's own hips (-2.2 rad) the somersault axis is the piked body's intermediate
    principal axis, about which a rotation is unstable; at the dive's hips it is the largest."""
    a = athlete(body)
    model = a.character.model
    data = mujoco.MjData(model)
    bodies = np.array([model.body(b).id for b in SIM_BODIES])
    ranks = []
    for hip in (None, DIVE_PIKE_HIP):
        angles = position_angles("pike")
        if hip is not None:
            angles[[joint_index("l_hip"), joint_index("r_hip")], 0] = hip
        data.qpos[:] = a.standing_qpos(angles)
        mujoco.mj_kinematics(model, data)
        inertia, _ = composite_inertia(model, data, bodies)
        _, axes = np.linalg.eigh(inertia)  # ascending: the somersault axis's place among them
        ranks.append(int(np.argmax(np.abs(axes[1]))))
    assert ranks == [1, 2]


def test_perturbed_pike_dives_enter_head_first() -> None:
    """Starts 0, 3 and 5 of the pike dive's capture region at full size (seed 0): each took
    off with a few kg m^2/s of cartwheel momentum (-5..-9 against -48 of somersault). In the
    pike at -2.2 rad that grew into a tilt and a twist (-320, +247, -258 deg at the water,
    entries 32-42 deg off vertical); at the dive's hips (its largest principal axis) they
    stay in the plane and enter clean."""
    starts = full_starts(6)
    m = dive_maneuver("pike")
    for i in (0, 3, 5):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert r["landed"] and r["entry_angle_deg"] <= 30.0, (i, r["entry_angle_deg"])
        assert abs(r["twist_deg"]) < 180.0 and abs(r["rotation_deg"] + 540.0) <= 30.0, i


def test_a_tumble_hip_out_of_range_names_it() -> None:
    with pytest.raises(ConfigError, match=r"tumble hip must be in \[-2.6, 0\]"):
        TumbleParams(position="pike", hip=-3.0)


def test_the_dive_pike_turns_well_clear_of_its_intermediate_axis() -> None:
    """At -2.0 rad of hip flexion the male pike's somersault axis was its largest principal
    axis by 0.28 kg m^2 only: starts 7 and 23 (seed 0, full size) took off with 2-4 kg m^2/s of
    yaw, twisted 240-410 deg and entered 34-40 deg off vertical. At the dive's hips (0.59 kg
    m^2 clear) they enter clean; and start 14, which at those hips with the old lead (2.0)
    turned short (31.6 deg off), enters clean with the dive's lead."""
    a = athlete("male")
    model = a.character.model
    data = mujoco.MjData(model)
    bodies = np.array([model.body(b).id for b in SIM_BODIES])
    angles = position_angles("pike")
    angles[[joint_index("l_hip"), joint_index("r_hip")], 0] = DIVE_PIKE_HIP
    data.qpos[:] = a.standing_qpos(angles)
    mujoco.mj_kinematics(model, data)
    ev = np.linalg.eigvalsh(composite_inertia(model, data, bodies)[0])
    assert ev[2] - ev[1] >= 0.5
    starts = full_starts(24)
    m = dive_maneuver("pike")
    k = next(i for i, p in enumerate(m.phases) if p.controller == "tumble")

    def tumble(**params: float) -> Maneuver:
        phase = replace(m.phases[k], params={**m.phases[k].params, **params})
        return replace(m, phases=(*m.phases[:k], phase, *m.phases[k + 1 :]))

    for i in (7, 14, 23):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert r["landed"] and r["entry_angle_deg"] <= 30.0, (i, r["entry_angle_deg"])
    for i in (7, 23):
        old = run_maneuver(tumble(hip=-2.0, lead=2.0), perturbation=starts[i], fps=10.0)
        assert not old.report["landed"], i
    assert not run_maneuver(tumble(lead=2.0), perturbation=starts[14], fps=10.0).report["landed"]


def test_a_perturbed_forward_tuck_stands_up_on_both_feet_with_the_roll_eased() -> None:
    """Start 8 of the capture region at full size (seed 0) touched down as the landers do
    (+312 deg) but with the pelvis rolled (its left-right axis 23 deg out of the horizontal,
    its anatomical roll -37 deg); the hips righted it at once, and the reaction lifted the
    left foot: it stood up on the right one, which pivoted (the body turned about the
    vertical), and ended on it, not balanced. With a roll of 0.5 rad or more eased to upright over 0.3 s (the
    landing's ``roll_ease`` and ``roll_min``, the preset since 2026-12-03) it lands."""
    start = full_starts(9)[8]
    m = _forward_hold_015()
    assert m.phases[3].params["roll_ease"] > 0
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    land = replace(m.phases[3], params={**m.phases[3].params, "roll_ease": 0.0})
    before = replace(m, phases=(*m.phases[:3], land, *m.phases[4:]))
    r = run_maneuver(before, perturbation=start, fps=10.0).report
    assert not r["landed"]


def test_the_landing_refuses_a_roll_ease_or_roll_min_out_of_range() -> None:
    for bad in (-0.1, 1.0, math.nan):
        with pytest.raises(ConfigError, match="roll_ease|finite"):
            LandingParams(roll_ease=bad)
    for bad in (-0.1, 2.0, math.nan):
        with pytest.raises(ConfigError, match="roll_min|finite"):
            LandingParams(roll_min=bad)


def test_a_perturbed_forward_tuck_keeps_both_feet_pushing_and_lands() -> None:
    """Start 21 of the capture region at full size (seed 0): in its "com" push's last ticks
    one foot left the floor before the other, which took the whole planned force alone and
    rolled the body (-3.2 kg m^2/s of cartwheel at lift-off, heading frame); it stood up on
    one foot and fell. With a share kept on a foot off the floor (``push_both``, the preset
    since 2026-12-03) it leaves with little roll and lands."""
    start = full_starts(22)[21]
    m = _forward_hold_015()
    assert m.phases[1].params["push_both"] is True
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    leap = replace(m.phases[1], params={**m.phases[1].params, "push_both": False})
    before = replace(m, phases=(m.phases[0], leap, *m.phases[2:]))
    assert not run_maneuver(before, perturbation=start, fps=10.0).report["landed"]


def test_a_perturbed_forward_tuck_pushes_off_without_yaw_with_the_yaw_gain() -> None:
    """Start 22 of the capture region at full size (seed 0) takes off with -1.9 kg m^2/s of
    momentum about the vertical, touches down with the pelvis rolled -38 deg and falls. The
    "com" push's ``yaw_gain`` (an option, off in the preset: 29/50 against 32/50 at full size,
    docs/athletics.md) tilts the feet's ground forces fore and aft against the yaw: it leaves
    with under 1.2 and lands."""
    start = full_starts(23)[22]
    m = _forward_hold_015()
    r = run_maneuver(m, perturbation=start, fps=10.0)
    assert not r.report["landed"]
    assert abs(_liftoff_momentum(r)[2]) > 1.5
    leap = replace(m.phases[1], params={**m.phases[1].params, "yaw_gain": 3.0})
    r = run_maneuver(replace(m, phases=(m.phases[0], leap, *m.phases[2:])), perturbation=start,
                     fps=10.0)  # fmt: skip
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["rotation_deg"] - 360.0) <= 30.0
    assert abs(_liftoff_momentum(r)[2]) < 1.2


def test_the_leap_refuses_a_yaw_gain_out_of_range() -> None:
    for bad in (-1.0, 101.0, math.nan):
        with pytest.raises(ConfigError, match="yaw_gain|finite"):
            LeapParams(yaw_gain=bad)


def test_a_perturbed_forward_tuck_crouches_onto_both_feet_with_crouch_plant() -> None:
    """Start 12 of the capture region at full size (seed 0): its COM went 10 cm over the left
    foot before the crouch, the balance's COM target followed the foot in contact, the right
    foot hung 3-4 cm up through the crouch and the push ran on one foot; it fell. The leap's
    ``crouch_plant`` (an option, off in the preset: 31/50 against 32/50 at full size,
    docs/athletics.md) aims the crouch's COM at both soles' middle and brings the hanging
    foot down: both feet carry weight at the thrust and it lands."""
    start = full_starts(13)[12]
    m = _forward_timed()
    assert not run_maneuver(m, perturbation=start, fps=10.0).report["landed"]
    leap = replace(m.phases[1], params={**m.phases[1].params, "crouch_plant": True})
    r = run_maneuver(replace(m, phases=(m.phases[0], leap, *m.phases[2:])), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0


def test_the_back_layout_moves_its_feet_by_the_rotation_predicted_at_touchdown() -> None:
    """Start 6 of ``back_layout.toml``'s capture region at a tenth (seed 0) opens a tick
    early and, the feet placed as the nominal's (``turn_gain`` 0, before 2026-12-03 22:00),
    touches down at -305.4 deg still turning backward and falls over backward. The landing's
    ``turn_gain`` (the file's 0.3 m/rad in the reach's last 50 ms) sees the touchdown
    predicted past ``turn_ref`` and puts the feet farther behind: the ground stops the spin
    and it lands."""
    start = _tenth_start(0, 6)
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = m.phases[3]
    assert land.controller == "land" and land.params["turn_gain"] > 0.0
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    # lean as it was then too (0.8 since 2026-12-04 13:12 lands it without turn_gain)
    off = replace(land, params={**land.params, "turn_gain": 0.0, "lean": 0.5})
    r = run_maneuver(replace(m, phases=(*m.phases[:3], off, *m.phases[4:])), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["rotation_at_touchdown_deg"] < -305.0, r["rotation_at_touchdown_deg"]
    assert not (r["landed"] and not r["fell"])


def test_the_landing_refuses_a_turn_window_out_of_range() -> None:
    for bad in (0.0, -0.1, 1.5, math.nan):
        with pytest.raises(ConfigError, match="turn_window"):
            LandingParams(turn_window=bad)
    with pytest.raises(ConfigError, match="turn_gain"):
        LandingParams(turn_gain=math.inf)


def test_a_perturbed_forward_tuck_waits_in_the_crouch_with_crouch_until() -> None:
    """Start 45 of the capture region at full size (seed 0): its crouch ended at the fixed
    time with the COM over one foot, the other unloaded, and it fell. The leap's
    ``crouch_until`` (an option, off in the preset, docs/athletics.md) holds the crouch until
    both feet are down and the COM is within 2 cm of the soles' middle sideways, moving
    sideways under 0.05 m/s (at most 0.3 s more): it thrusts later and lands."""
    start = full_starts(46)[45]
    m = _forward_timed()
    before = run_maneuver(m, perturbation=start, fps=10.0).report
    assert not before["landed"] or before["fell"]
    leap = replace(m.phases[1], params={**m.phases[1].params, "crouch_until": [0.02, 0.05, 0.3]})
    r = run_maneuver(replace(m, phases=(m.phases[0], leap, *m.phases[2:])), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["time_to_liftoff_s"] > before["time_to_liftoff_s"] + 0.05
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0


def test_the_leap_refuses_a_bad_crouch_until() -> None:
    for bad in ((0.02, 0.05), (0.0, 0.05, 0.3), (0.02, 0.05, -0.1), (0.02, math.nan, 0.3)):
        with pytest.raises(ConfigError, match="crouch_until"):
            LeapParams(crouch_until=bad)


def test_a_perturbed_forward_tuck_lets_its_crouch_settle_before_the_thrust() -> None:
    """Start 22 of the capture region at full size (seed 0) took off with -1.9 kg m^2/s of
    momentum about the vertical after a 0.15 s hold in the crouch, touched down rolled and
    fell. The preset's 0.25 s hold (since 2026-12-03; on 100 full-size starts 58 -> 66 and
    62 -> 79 on seeds 0 and 1, docs/athletics.md) lets the start's motion settle first: it
    lands."""
    start = full_starts(23)[22]
    m = _forward_timed()
    assert m.phases[1].params["hold"] == 0.25
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0
    assert not run_maneuver(_forward_hold_015(), perturbation=start, fps=10.0).report["landed"]


def test_a_perturbed_forward_tuck_holds_its_crouch_without_the_creep_with_hold_com() -> None:
    """Start 2 of the capture region at a tenth (seed 0): through the preset's 0.25 s hold
    the crouch's COM goes on past its target (5.4 cm ahead of the soles' middle at the thrust,
    moving forward), it takes off with +54 kg m^2/s of pitch (+50 with the 0.15 s hold) and
    falls after touchdown. The leap's ``hold_com`` (an option, off in the preset,
    docs/athletics.md) holds the COM target where the COM stands at the crouch's end: it
    takes off with less pitch and lands."""
    start = _tenth_start(0, 2)
    m = _forward_timed()
    assert not m.phases[1].params.get("hold_com", False)
    before = run_maneuver(m, perturbation=start, fps=10.0).report
    assert before["liftoff_pitch_momentum"] > 53.0 and (not before["landed"] or before["fell"])
    leap = replace(m.phases[1], params={**m.phases[1].params, "hold_com": True})
    r = run_maneuver(replace(m, phases=(m.phases[0], leap, *m.phases[2:])), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["liftoff_pitch_momentum"] < 51.0
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] - 360.0) <= 30.0


def test_a_late_back_layout_touchdown_lands_with_the_feet_ahead_from_the_reach_s_start() -> None:
    """Start 5 of ``back_layout.toml``'s capture region at a tenth (seed 0) opens a tick late
    in the legs' swing: 24 ms into the reach its feet are 0.21 m from the COM (at most 0.085
    on the starts that touch down in the window), it touches down too little turned (the late
    class, -296..-301.5 deg) and falls forward. With ``late_delta`` (0.024 s, 0.15 m, -0.11 m,
    the file since 2026-12-04) the feet go 2 cm farther ahead for the rest of the reach and it
    lands."""
    start = _tenth_start(0, 5)
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = m.phases[3]
    assert land.controller == "land" and land.params["late_delta"] == [0.024, 0.15, -0.11]
    late = ("late_delta", "late_kv", "late_kv_rotation")  # late_kv acts on late_delta's class
    before = _with_land_params(m, {k: v for k, v in land.params.items() if k not in late})
    r = run_maneuver(before, perturbation=start, fps=10.0).report
    assert -301.5 < r["rotation_at_touchdown_deg"] < -296.0, r["rotation_at_touchdown_deg"]
    assert not (r["landed"] and not r["fell"])
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0


def test_the_landing_refuses_a_bad_late_delta() -> None:
    for bad in ((0.024, 0.15), (0.024, 0.0, -0.11), (-0.1, 0.15, -0.11), (0.024, math.nan, 0.1)):
        with pytest.raises(ConfigError, match="late_delta"):
            LandingParams(late_delta=bad)
    assert LandingParams(late_delta=(0.024, 0.15, -0.11)).late_delta[2] == -0.11


def test_the_layout_preset_puts_a_late_start_s_feet_ahead() -> None:
    """The command's preset (settled start) carries the file's ``late_delta`` since
    2026-12-04 (a tenth 24 -> 29 and 17 -> 28 of 50 on seeds 0 and 1): start 6 of its capture
    region at a tenth (seed 1) falls without it and lands with it."""
    start = _tenth_start(1, 6)
    m = somersault_maneuver("layout")
    i = next(k for k, ph in enumerate(m.phases) if ph.controller == "land")
    assert m.phases[i].params["late_delta"] == [0.024, 0.15, -0.11]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    r = run_maneuver(_without_land_param(m, "late_delta"), perturbation=start, fps=10.0).report
    assert not (r["landed"] and not r["fell"])


def test_a_back_layout_turning_forward_over_its_feet_hands_over_on_the_pitch_momentum() -> None:
    """Start 39 of ``back_layout.toml``'s capture region at a tenth (seed 0) touches down in
    the window and stands with the COM 2-3 cm from the feet, creeping on, its pitch momentum
    at +8..+10 kg m^2/s: with ``recover_spin`` 0 (before 2026-12-04 11:30 UTC) the recovery
    never sees the COM stop or move away, stays in it for 0.5 s and falls forward. The file's
    ``recover_spin`` 5 hands over on that momentum within 0.07 s and the balance lands it."""
    start = _tenth_start(0, 39)
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = m.phases[3]
    assert land.controller == "land" and land.params["recover_spin"] == 5.0
    # lean as it was then too (0.5; the file's 0.8 since 2026-12-04 13:12)
    res = run_maneuver(_with_land_params(m, {**land.params, "recover_spin": 0.0, "lean": 0.5}),
                       perturbation=start, fps=10.0)  # fmt: skip
    held = [t for t, _, c in res.transitions if str(c) in ("land.recover", "land.done")]
    assert held[1] - held[0] > 0.4, held
    assert not (res.report["landed"] and not res.report["fell"])
    res = run_maneuver(m, perturbation=start, fps=10.0)
    held = [t for t, _, c in res.transitions if str(c) in ("land.recover", "land.done")]
    assert held[1] - held[0] < 0.1, held
    r = res.report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    with pytest.raises(ConfigError, match="recover_spin"):
        LandingParams(recover_spin=-1.0)


def test_a_back_layout_falling_forward_off_its_absorption_leans_into_it() -> None:
    """Start 42 of ``back_layout.toml``'s capture region at full size (seed 0) stands up
    from the absorption with its capture point past the feet and, the trunk pitched 0.5 rad
    per radian of knee flexion (the default ``lean``, before 2026-12-04 13:12 UTC), falls.
    The file's ``lean`` 0.8 pitches the trunk farther forward as the knees bend (the trunk
    takes forward pitch momentum from the legs): it lands."""
    start = full_starts(43)[42]
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = m.phases[3]
    assert land.controller == "land" and land.params["lean"] == 0.8
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0
    r = run_maneuver(_without_land_param(m, "lean"), perturbation=start, fps=10.0).report
    assert not (r["landed"] and not r["fell"])


def test_a_late_back_layout_with_the_late_class_s_servo_undamped_lands() -> None:
    """Start 15 of ``back_layout.toml``'s capture region at full size (seed 0) opens late
    (``late_delta``'s class); the placement servo's ``kv`` brakes its legs' swing and its COM
    touches down 10 cm ahead of the feet: it falls forward. With ``late_kv`` 0 its feet get
    farther along and it lands."""
    start = full_starts(16)[15]
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = next(ph for ph in m.phases if ph.controller == "land")
    assert land.params["late_kv"] == 0.0  # the file's, gated by late_kv_rotation since 2026-12-05
    damped = {k: v for k, v in land.params.items() if k not in ("late_kv", "late_kv_rotation")}
    r = run_maneuver(_with_land_params(m, damped), perturbation=start, fps=10.0).report
    assert not (r["landed"] and not r["fell"])
    r = run_maneuver(_with_land_params(m, {**damped, "late_kv": 0.0}), perturbation=start,
                     fps=10.0).report  # fmt: skip
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0


def test_a_late_back_layout_undamps_its_servo_only_past_the_late_kv_margin() -> None:
    """``late_kv`` 0 lands full size's late start 15 (its feet 0.31 m past ``late_delta``'s
    0.15 m offset at the decision) but loses a tenth's late start 5 (0.09 m past), which
    lands with the file's ``kv``. With ``late_kv_margin`` (0.11, 0.11) the tenth's start
    keeps ``kv`` and lands, and the full size's still gets ``late_kv`` 0 and lands."""
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = next(ph for ph in m.phases if ph.controller == "land")
    params = {k: v for k, v in land.params.items() if k != "late_kv_rotation"}  # the file's gate
    undamped = _with_land_params(m, {**params, "late_kv": 0.0})
    margin = _with_land_params(m, {**params, "late_kv": 0.0, "late_kv_margin": [0.11, 0.11]})
    tenth = _tenth_start(0, 5)
    r = run_maneuver(undamped, perturbation=tenth, fps=10.0).report
    assert not (r["landed"] and not r["fell"])
    for start in (tenth, full_starts(16)[15]):
        r = run_maneuver(margin, perturbation=start, fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0


def test_a_late_back_layout_undamps_its_servo_only_once_turned_past_late_kv_rotation() -> None:
    """Full size's late starts 33 and 43 (seed 0) are alike at ``late_delta``'s decision
    (feet 0.303 / 0.293 m from the COM, so ``late_kv_margin`` cannot part them), but 33 lands
    only with the file's ``kv`` and 43 only with ``late_kv`` 0. 43 has turned further by then
    (-3.094 rad against -3.076): with ``late_kv_rotation`` -3.085 rad 33 keeps ``kv`` and
    lands, and 43 gets ``late_kv`` 0 and lands."""
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = next(ph for ph in m.phases if ph.controller == "land")
    assert land.params["late_kv_rotation"] == -3.085  # the file's since 2026-12-05
    params = {k: v for k, v in land.params.items() if k != "late_kv_rotation"}
    undamped = _with_land_params(m, {**params, "late_kv": 0.0})
    gated = _with_land_params(m, {**params, "late_kv": 0.0, "late_kv_rotation": -3.085})
    starts = full_starts(44)
    r = run_maneuver(undamped, perturbation=starts[33], fps=10.0).report
    assert not (r["landed"] and not r["fell"])
    for k in (33, 43):
        r = run_maneuver(gated, perturbation=starts[k], fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 30.0, k


def test_a_back_layout_carrying_its_pitch_target_leans_on_past_the_hand_over() -> None:
    """``back_layout.toml``'s landing leans the trunk 0.8 rad per radian of knee flexion, the
    balance after it 0.5: at the hand-over its pelvis pitch target dropped to the pelvis's
    pitch (0.44 rad on a perturbed start). With ``carry_pitch`` the balance starts from the
    landing's last target, so the trunk leans farther forward over the next 0.15 s."""
    m = load_maneuver(Path(__file__).parents[2] / "examples/athletics/maneuvers/back_layout.toml")
    land = next(ph for ph in m.phases if ph.controller == "land")

    def lean_after_hand_over(carry: bool) -> float:
        r = run_maneuver(_with_land_params(m, {**land.params, "carry_pitch": carry}), fps=10.0)
        t0 = next(t for t, a, _ in r.transitions if a == "land.done")
        t = r.log["t"]
        window = (t >= t0) & (t <= t0 + 0.15)
        assert window.sum() > 10 and r.report["landed"]
        # the pelvis-to-head line's angle from the vertical, at its largest
        return float(np.arccos(np.clip(r.log["trunk"][window, 2], -1.0, 1.0)).max())

    assert lean_after_hand_over(True) > lean_after_hand_over(False) + 0.03
