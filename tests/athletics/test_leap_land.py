"""Leaping and landing (thesis ch. 4 and 6), measured on the motion itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reactmocap.athletics import AthleticsResult, run, tables
from reactmocap.athletics.behaviours import LANDING_LEG
from reactmocap.athletics.bodies import athlete
from reactmocap.athletics.land import LandingParams
from reactmocap.athletics.report import ground_force
from reactmocap.athletics.scene import stand_angles
from reactmocap.errors import ConfigError


def test_a_leap_to_30_cm_lands_within_3_cm_and_balanced() -> None:
    r = run("leap", "male", height=0.3)
    assert abs(r.report["achieved_height_m"] - 0.3) <= 0.03
    assert r.report["landed"] and not r.report["fell"]
    # the height is the COM's rise at the apex over standing, from the log itself
    com = r.log["com"][:, 2]
    assert com.max() - com[0] == pytest.approx(r.report["achieved_height_m"])


def test_a_short_female_leap_never_bounces_off_its_landing() -> None:
    # a 0.1 m flight leaves no time to bend the knees; a switched-off straight knee used to
    # buckle backwards under the landing's push and the servo's return launched the body
    # (reported as a 4.7 m leap); below the measured range, so run with check_range=False
    r = run("leap", "female", height=0.1, check_range=False)
    assert abs(r.report["achieved_height_m"] - 0.1) <= 0.03
    com = r.log["com"][:, 2]
    assert com.max() - com[0] < 0.15  # nothing after the touchdown went higher than the leap


def test_vertical_leaps_land_with_the_ready_bend(monkeypatch: pytest.MonkeyPatch) -> None:
    """The landing takes over at lift-off, so its knees are bent ready at touchdown, and
    places the feet by the vertical leap's own lead and delta. With her drops' landing (the
    capture-point lead of 1.0) the female's half-metre leap falls."""
    r = run("leap", "female", height=0.5, check_range=False, push="timed")
    assert r.report["landed"] and not r.report["fell"]
    reach = next(t for t, _, target in r.transitions if target == "land.reach")
    assert reach - r.report["time_to_liftoff_s"] < 0.02
    # fell before: feet too far back
    m = run("leap", "male", height=0.2, check_range=False, push="timed")
    assert m.report["landed"] and not m.report["fell"]
    monkeypatch.setattr(tables, "VERTICAL_LANDING", {})
    r0 = run("leap", "female", height=0.5, check_range=False, push="timed")
    assert abs(r0.report["achieved_height_m"] - r.report["achieved_height_m"]) < 0.01
    assert not r0.report["landed"]


def test_the_ground_force_of_a_standing_athlete_is_its_weight() -> None:
    r = run("balance", "female", seconds=1.0)
    t, force = ground_force(r.log, r.report["mass_kg"], np.array([0.0, 0.0, -9.81]))
    late = t > 0.5
    weight = r.report["mass_kg"] * 9.81
    assert np.abs(force[late, 2].mean() / weight - 1.0) < 0.02
    assert np.abs(force[late, :2]).max() < 0.05 * weight


def test_a_broad_jump_of_1_m_within_5_cm() -> None:
    r = run("broad-jump", "male", distance=1.0)
    assert abs(r.report["achieved_distance_m"] - 1.0) <= 0.05


def test_a_2_2_m_broad_jump_lands_within_5_cm(monkeypatch: pytest.MonkeyPatch) -> None:
    """The male's long jumps crouch deeper with the trunk pitched further (BROAD_CROUCH, as
    the thesis's Table 4.2): a commanded 2.2 m, the fitness norm, lands within 5 cm. On the
    default crouch the same effort takes off slower and travels far less."""
    r = run("broad-jump", "male", distance=2.2)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["achieved_distance_m"] - 2.2) <= 0.05
    monkeypatch.setattr(tables, "BROAD_CROUCH", {})
    r0 = run("broad-jump", "male", effort=r.report["effort"], check_range=False)
    assert r0.report["achieved_distance_m"] < 1.6


def test_the_male_2_m_broad_jump_takes_off_pitching_back(monkeypatch: pytest.MonkeyPatch) -> None:
    """His take-off spin feedback's gain (BROAD_SPIN_GAIN, 20) stays under its limit in his
    deeper crouch: effort 0.9 (2.01 m) lifts off pitching back and lands. At the default
    gain of 40 the same push lifts off pitching forward."""
    r = run("broad-jump", "male", effort=0.9, check_range=False)
    assert r.report["liftoff_pitch_momentum"] < -1.0
    assert r.report["landed"] and not r.report["fell"]
    assert r.report["achieved_distance_m"] > 1.95
    monkeypatch.setattr(tables, "BROAD_SPIN_GAIN", {})
    r0 = run("broad-jump", "male", effort=0.9, check_range=False)
    assert r0.report["liftoff_pitch_momentum"] > 1.0


def test_the_female_longest_broad_jump_lands_past_1_7_m(monkeypatch: pytest.MonkeyPatch) -> None:
    """Her longest jumps crouch deeper with the trunk pitched 0.75 rad, the COM offset held at
    0.2 m and the take-off aiming for -5 kg m^2/s at gain 20 (BROAD_CROUCH, BROAD_LONG,
    BROAD_SPIN, BROAD_SPIN_GAIN): effort 1.0 lifts off pitching back and lands past the
    thesis's 1.57 m and the issue's 1.7 m. Without her entries it pitches forward and falls."""
    r = run("broad-jump", "female", effort=1.0, check_range=False)
    assert r.report["liftoff_pitch_momentum"] < -1.0
    assert r.report["landed"] and not r.report["fell"]
    assert r.report["achieved_distance_m"] > 1.7
    for name in ("BROAD_CROUCH", "BROAD_SPIN", "BROAD_SPIN_GAIN", "BROAD_LONG"):
        monkeypatch.setattr(tables, name, {k: v for k, v in getattr(tables, name).items()
                                           if k != "female"})  # fmt: skip
    r0 = run("broad-jump", "female", effort=1.0, check_range=False)
    assert r0.report["liftoff_pitch_momentum"] > 0.0
    assert r0.report["fell"] and not r0.report["landed"]


def test_the_female_commanded_broad_jumps_land_on_her_long_path(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Between her shallow crouch's 0.75 m and her longest jump her take-off holds the deep
    crouch and sets the length by the COM offset (BROAD_LONG): it lifts off pitching back and
    one landing delta lands it, so commanded 1.05 and 1.2 m land within 5 cm. On her former
    path the same efforts take off pitching forward and fall."""
    for distance in (1.05, 1.2):
        r = run("broad-jump", "female", distance=distance)
        assert r.report["landed"] and not r.report["fell"]
        assert abs(r.report["achieved_distance_m"] - distance) <= 0.05
        assert r.report["liftoff_pitch_momentum"] < -2.0
        monkeypatch.setattr(tables, "BROAD_LONG", {})
        r0 = run("broad-jump", "female", effort=r.report["effort"], check_range=False)
        assert r0.report["fell"] and not r0.report["landed"]
        monkeypatch.undo()


def test_the_female_broad_jump_range_is_what_lands() -> None:
    """Her supported distance is measured as what lands (her table's efforts from 0 up to the
    first that falls): a command past it, where her efforts 0.95-1.0 take off rolled and
    fall, is refused with the range."""
    lo, hi = tables.supported_range("broad-jump", "distance", "female") or (0.0, 0.0)
    assert lo < 0.3 and 1.6 < hi < 1.7
    with pytest.raises(ConfigError, match="supported range"):
        run("broad-jump", "female", distance=1.75)


def test_broad_jumps_land_with_the_trunk_righted_slowly(monkeypatch: pytest.MonkeyPatch) -> None:
    """A broad jump lands with the trunk pitched forward; the landing rights it over
    BROAD_PITCH_EASE s. Righted at once, the hips' extension pushes into the floor and
    throws the body back up off its legs: the same jumps fall."""
    f = run("broad-jump", "female", effort=0.45, check_range=False)
    m = run("broad-jump", "male", effort=0.6, check_range=False)
    for r in (f, m):
        assert r.report["landed"] and not r.report["fell"]
    assert f.report["achieved_distance_m"] > 0.6 and m.report["achieved_distance_m"] > 0.9
    monkeypatch.setattr(tables, "BROAD_PITCH_EASE", 0.0)
    f0 = run("broad-jump", "female", effort=0.45, check_range=False)
    assert f0.report["fell"] and not f0.report["landed"]


def test_the_female_broad_jump_swings_the_arms_back_to_land(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """After a broad jump her landing swings the arms from overhead on behind the trunk
    (BROAD_ARMS), which turns the rest of the body back in the air: the trunk touches down
    less pitched forward, and a 1.4 m/s landing that fell with the arms held in front lands
    (her shallow crouch's effort 0.65, without her long path, BROAD_LONG)."""
    monkeypatch.setattr(tables, "BROAD_LONG", {})
    r = run("broad-jump", "female", effort=0.65, check_range=False)
    assert r.report["landed"] and not r.report["fell"]
    assert r.report["achieved_distance_m"] > 0.85
    monkeypatch.setattr(tables, "BROAD_ARMS", {})
    r0 = run("broad-jump", "female", effort=0.65, check_range=False)
    assert r0.report["fell"] and not r0.report["landed"]

    def trunk_at_touchdown(res: AthleticsResult) -> float:
        i = int(np.searchsorted(res.log["t"], res.report["touchdown_s"]))
        return float(res.log["trunk"][i, 2])  # the pelvis-to-head line's upward component

    assert trunk_at_touchdown(r) > trunk_at_touchdown(r0) + 0.05


def test_landing_pitch_ease_must_not_be_negative() -> None:
    with pytest.raises(ConfigError, match="pitch_ease"):
        LandingParams(pitch_ease=-0.1)


def test_landing_side_lead_must_be_in_range() -> None:
    for bad in (-0.1, 2.5, float("nan")):
        with pytest.raises(ConfigError, match=r"side_lead must be in \[0, 2\]"):
            LandingParams(side_lead=bad)


def test_landing_twist_arms_must_be_in_range() -> None:
    for bad in (-1.0, 101.0, float("nan")):
        with pytest.raises(ConfigError, match="twist_arms"):
            LandingParams(twist_arms=bad)


def test_landing_carry_pitch_must_be_a_bool() -> None:
    with pytest.raises(ConfigError, match="carry_pitch"):
        LandingParams(carry_pitch=1)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", [-0.1, 1.5, math.nan, "0.1"])
def test_landing_late_kv_must_be_in_range(bad: object) -> None:
    with pytest.raises(ConfigError, match="late_kv"):
        LandingParams(late_kv=bad, late_delta=(0.024, 0.15, -0.11))  # type: ignore[arg-type]


def test_landing_late_kv_needs_late_delta() -> None:
    with pytest.raises(ConfigError, match="late_kv"):
        LandingParams(late_kv=0.0)


@pytest.mark.parametrize("bad", [(0.1,), (0.2, 0.1), (-0.1, 0.1), (0.1, 1.5), ("0.1", 0.2)])
def test_landing_late_kv_margin_must_be_from_to(bad: tuple[float, ...]) -> None:
    with pytest.raises(ConfigError, match="late_kv_margin"):
        LandingParams(late_kv=0.0, late_kv_margin=bad, late_delta=(0.024, 0.15, -0.11))


def test_landing_late_kv_margin_needs_late_kv() -> None:
    with pytest.raises(ConfigError, match="late_kv_margin"):
        LandingParams(late_kv_margin=(0.1, 0.1), late_delta=(0.024, 0.15, -0.11))


def test_landing_late_kv_margin_blends_kv_to_late_kv() -> None:
    late = (0.024, 0.15, -0.11)
    p = LandingParams(kv=0.15, late_kv=0.0, late_kv_margin=(0.1, 0.2), late_delta=late)
    assert [p.late_kv_at(x) for x in (0.05, 0.1, 0.2, 0.3)] == [0.15, 0.15, 0.0, 0.0]
    assert p.late_kv_at(0.15) == pytest.approx(0.075)
    step = LandingParams(kv=0.15, late_kv=0.0, late_kv_margin=(0.11, 0.11), late_delta=late)
    assert (step.late_kv_at(0.1), step.late_kv_at(0.11)) == (0.15, 0.0)
    assert LandingParams(late_kv=0.05, late_delta=late).late_kv_at(0.01) == 0.05


@pytest.mark.parametrize("bad", [0.0, math.nan, math.inf, "-3.1"])
def test_landing_late_kv_rotation_must_be_a_nonzero_rotation(bad: object) -> None:
    with pytest.raises(ConfigError, match="late_kv_rotation"):
        LandingParams(late_kv=0.0, late_kv_rotation=bad, late_delta=(0.024, 0.15, -0.11))  # type: ignore[arg-type]


def test_landing_late_kv_rotation_needs_late_kv() -> None:
    with pytest.raises(ConfigError, match="late_kv_rotation"):
        LandingParams(late_kv_rotation=-3.0, late_delta=(0.024, 0.15, -0.11))


def test_landing_late_kv_rotation_gates_late_kv_by_the_rotation_so_far() -> None:
    late = (0.024, 0.15, -0.11)
    back = LandingParams(kv=0.15, late_kv=0.0, late_kv_rotation=-3.085, late_delta=late)
    assert [back.late_kv_at(0.1, r) for r in (-3.0, -3.08, -3.085, -3.3)] == [0.15, 0.15, 0.0, 0.0]
    forward = LandingParams(kv=0.15, late_kv=0.05, late_kv_rotation=2.0, late_delta=late)
    assert (forward.late_kv_at(0.1, 1.9), forward.late_kv_at(0.1, 2.1)) == (0.15, 0.05)
    both = LandingParams(kv=0.15, late_kv=0.0, late_kv_rotation=-3.0, late_kv_margin=(0.1, 0.2),
                         late_delta=late)  # fmt: skip
    assert (both.late_kv_at(0.3, -2.9), both.late_kv_at(0.15, -3.1)) == (0.15, pytest.approx(0.075))


def test_flight_conserves_angular_momentum() -> None:
    # a leap with pitch momentum; in the air only internal torques act
    r = run("leap", "male", effort=0.4, spin=15.0, push="timed")
    t, momentum = r.log["t"], r.log["momentum"]
    lift, down = r.report["time_to_liftoff_s"], r.report["touchdown_s"]
    flight = (t > lift + 0.01) & (t < down - 0.01)
    assert flight.sum() > 50
    m = momentum[flight]
    assert np.linalg.norm(m[0]) > 5.0  # a real rotation
    assert np.abs(m - m[0]).max() / np.linalg.norm(m[0]) < 0.01


def test_a_half_metre_drop_lands() -> None:
    r = run("land", "male", drop=0.5)
    assert r.report["landed"] and not r.report["fell"]
    # the landing's peak is the tick-mean ground force after touchdown, as the push-off's
    # peak_grf_bw (once a sampled contact force, which read a chattering contact wrongly)
    t, force = ground_force(r.log, r.report["mass_kg"], np.array([0.0, 0.0, -9.81]))
    after = t >= r.report["touchdown_s"]
    peak = np.linalg.norm(force[after], axis=1).max() / (r.report["mass_kg"] * 9.81)
    assert r.report["landing_peak_grf_bw"] == pytest.approx(peak, rel=0.02)
    assert 2.0 < r.report["landing_peak_grf_bw"] < 40.0


def test_a_3_metre_drop_is_never_a_success() -> None:
    rng = tables.supported_range("land", "drop", "male")
    assert rng is not None and rng[1] < 3.0
    with pytest.raises(ConfigError, match="supported range"):
        run("land", "male", drop=3.0)


def test_commands_outside_the_measured_range_are_refused() -> None:
    _, hi = tables.supported_range("leap", "height", "female", "com") or (0.0, 0.0)
    with pytest.raises(ConfigError, match=f"{hi:g}"):
        run("leap", "female", height=hi + 0.5)
    with pytest.raises(ConfigError, match="finite"):
        run("leap", "male", height=float("nan"))
    with pytest.raises(ConfigError, match="no parameter"):
        run("leap", "male", hight=0.3)
    with pytest.raises(ConfigError, match=">= 0"):
        run("land", "male", drop=-1.0)


def _drop_for_com_height(body: str, com_height: float) -> float:
    """Sole clearance that puts the landing pose's COM at ``com_height`` (thesis ch. 6)."""
    ath = athlete(body)
    q = ath.standing_qpos(stand_angles(ath, LANDING_LEG), clearance=0.0)
    return com_height - float(ath.com_of(q)[2])


def test_a_forward_landing_at_2_m_per_s_lands_with_the_delta_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Thesis ch. 6: COM 1.25 m up, 2 m/s forward. With one foot-servo delta for every speed
    (the landing before the table) it falls: the feet land too close and the COM passes over
    them still moving."""
    drop = _drop_for_com_height("male", 1.25)
    r = run("land", "male", drop=drop, vx=2.0)
    assert r.report["landed"] and not r.report["fell"]
    lp = tables.landing_params("male", 2.0)
    assert r.report["foot_servo_delta_m"] == pytest.approx(lp.delta_at(2.0))
    # it travelled forward and ended still over the feet
    assert r.log["com"][-1, 0] - r.log["com"][0, 0] > 0.3
    assert abs(r.log["offset"][-1]) < 0.05
    # the same landing with the table removed (the constant delta) falls
    monkeypatch.setattr(tables, "LANDING_DELTAS", {})
    assert tables.landing_params("male", 2.0).delta != pytest.approx(lp.delta)
    r0 = run("land", "male", drop=drop, vx=2.0)
    assert r0.report["fell"] and not r0.report["landed"]


@pytest.mark.parametrize("vx", [2.5, 3.0])
def test_the_female_lands_at_2_5_and_3_m_per_s_with_the_fast_rows(
    monkeypatch: pytest.MonkeyPatch, vx: float
) -> None:
    """Thesis ch. 6 (-1.0 to 3.0 m/s, COM 1.25 m up) on the female: her measured delta table
    ends at 2.0 m/s, and held at its -0.38 m she fell at every faster speed; the fast rows
    (``tables.LANDING_DELTAS_FAST``) put her feet where she lands."""
    drop = _drop_for_com_height("female", 1.25)
    r = run("land", "female", drop=drop, vx=vx)  # inside her supported range now
    assert r.report["landed"] and not r.report["fell"]
    lp = tables.landing_params("female", vx)
    assert lp.delta < tables.landing_params("female", 2.0).delta - 0.05  # farther ahead
    assert r.report["foot_servo_delta_m"] == pytest.approx(lp.delta_at(vx))
    assert r.log["com"][-1, 0] - r.log["com"][0, 0] > 0.5
    assert abs(r.log["offset"][-1]) < 0.05
    # without the fast rows the same landing falls
    monkeypatch.setattr(tables, "LANDING_DELTAS_FAST", {})
    r0 = run("land", "female", drop=drop, vx=vx)
    assert r0.report["fell"] and not r0.report["landed"]


def test_the_fast_rows_only_extend_the_measured_table(monkeypatch: pytest.MonkeyPatch) -> None:
    fast = tables.LANDING_DELTAS_FAST["female"]
    rows = tables.landing_params("female", 0.0).deltas
    assert rows[-len(fast) :] == fast
    assert [v for v, _ in rows] == sorted(v for v, _ in rows)
    assert tables.landing_params("male", 0.0).deltas == tuple(tables.LANDING_DELTAS["male"])
    # a rebuilt table that reaches their speeds supersedes them
    monkeypatch.setattr(tables, "LANDING_DELTAS", {"female": ((0.0, -0.04), (2.5, -0.3))})
    assert tables.landing_params("female", 0.0).deltas == ((0.0, -0.04), (2.5, -0.3), *fast[-2:])


def test_landing_deltas_are_validated_and_interpolated() -> None:
    lp = LandingParams(delta=0.1, deltas=((0.0, -0.04), (1.0, 0.06)))
    assert lp.delta_at(0.5) == pytest.approx(0.01)
    assert lp.delta_at(5.0) == pytest.approx(0.06)
    assert LandingParams(delta=0.1).delta_at(3.0) == pytest.approx(0.1)
    with pytest.raises(ConfigError, match="deltas"):
        LandingParams(deltas=((0.0, float("nan")),))


def test_the_female_lands_fast_from_a_higher_drop_by_its_fall(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 18: the delta table was measured from COM 1.25 m up, and its windows (0.04 m wide)
    belong to that fall: from COM 1.35 m up she fell at 2.5 m/s. The placement scaled by the
    fall predicted in the air (``tables.LANDING_FALL``) puts her feet nearer after the longer fall."""
    drop = _drop_for_com_height("female", 1.35)
    r = run("land", "female", drop=drop, vx=2.5, check_range=False)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.log["offset"][-1]) < 0.05
    monkeypatch.setattr(tables, "LANDING_FALL", {})
    r0 = run("land", "female", drop=drop, vx=2.5, check_range=False)
    assert r0.report["fell"] and not r0.report["landed"]


def test_the_fall_placement_is_for_drops_only() -> None:
    lp = tables.landing_params("female", 2.5)
    assert lp.fall_gain > 0 and lp.fall_ref == pytest.approx(
        _drop_for_com_height("female", 1.25), abs=1e-3
    )
    for kw in ({"after_leap": True}, {"vertical": True}, {"broad": True}):
        assert tables.landing_params("female", 1.0, **kw).fall_gain == 0.0  # type: ignore[arg-type]
    assert LandingParams().fall_gain == 0.0
    with pytest.raises(ConfigError, match="fall_gain"):
        LandingParams(fall_gain=float("inf"))
