"""The vertical leap's "com" push-off (LeapParams.push): a servo on the COM's height and speed
with its ground force planned, against the thesis's timed push (8.0 BW at 0.5 m)."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.athletics import run, tables
from reactmocap.athletics.leap import COM_PUSH_LEGS, LeapParams, com_push
from reactmocap.athletics.report import ground_force
from reactmocap.errors import ConfigError


def test_a_half_metre_com_push_stays_under_3_5_body_weights_and_lands() -> None:
    r = run("leap", "male", height=0.5)  # the com push is the leap's default
    rep = r.report
    assert rep["push"] == "com"
    assert abs(rep["achieved_height_m"] - 0.5) <= 0.03
    assert rep["peak_grf_bw"] <= 3.5
    assert rep["landed"] and not rep["fell"]
    # from the log itself: no control tick's mean ground force (from the COM's momentum)
    # between the push's start and the touchdown goes over 3.5 body weights (the tick that
    # the touchdown is seen at holds the landing's impact)
    tl = r.log["t"]
    _, force = ground_force(r.log, rep["mass_kg"], np.array([0.0, 0.0, -9.81]))
    thrust = next(tm for tm, _src, dst in r.transitions if dst == "leap.thrust")
    span = (tl[1:] > thrust) & (tl[1:] < rep["touchdown_s"])
    assert np.linalg.norm(force[span], axis=1).max() / (rep["mass_kg"] * 9.81) <= 3.5
    # and the timed push makes well over that (the figure the com push replaces)
    timed = run("leap", "male", height=0.5, push="timed").report
    assert timed["peak_grf_bw"] > 6.0


def test_push_choices_are_checked() -> None:
    with pytest.raises(ConfigError, match="push"):
        run("leap", "male", height=0.5, push="spring")
    with pytest.raises(ConfigError, match="push"):
        LeapParams(push="spring")
    with pytest.raises(ConfigError, match="rise"):
        LeapParams(push="com", rise=0.0)
    with pytest.raises(ConfigError, match="push_limit"):
        LeapParams(push="com", push_limit=0.5)


def test_com_push_leaves_the_broad_jump_alone() -> None:
    broad = LeapParams(broad=True)
    assert com_push(broad, 0.5, "male") is broad
    vertical = com_push(LeapParams(), 0.4, "male")
    assert vertical.push == "com" and vertical.rise == 0.4


def test_the_com_push_lands_on_its_own_landing_setting(monkeypatch: pytest.MonkeyPatch) -> None:
    """The male's 1.0 m "com" leap (upright take-off) lands with VERTICAL_LANDING_COM's delta
    and falls with the timed push's VERTICAL_LANDING."""
    lp = tables.landing_params("female", 0.0, vertical=True, push="com")
    assert lp.deltas == tables.VERTICAL_LANDING_COM["female"][1]
    assert lp.delta_at(-0.47) == pytest.approx(0.0) and lp.delta_at(-0.3) == pytest.approx(-0.05)
    r = run("leap", "male", height=1.0, push="com", check_range=False)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.report["achieved_height_m"] - 1.0) <= 0.03
    monkeypatch.setattr(tables, "VERTICAL_LANDING_COM", {})
    r0 = run("leap", "male", height=1.0, push="com", check_range=False)
    assert abs(r0.report["achieved_height_m"] - r.report["achieved_height_m"]) < 0.01
    assert not r0.report["landed"]


@pytest.mark.parametrize("height", [0.1, 0.9])
def test_the_female_0_1_and_0_9_m_com_leaps_land_within_3_cm(height: float) -> None:
    """Her com push's hips and ankles at half stiffness (COM_PUSH_LEGS): at 1 and 1 the
    servo's damping took the force of her fast-straightening legs and her 0.9 m leap fell;
    her 0.1 m one (drift -0.21 m/s) lands with VERTICAL_LANDING_COM's -0.1 row at -0.22."""
    p = com_push(LeapParams(), height, "female")
    assert (p.push_hip, p.push_ankle) == COM_PUSH_LEGS["female"] == (0.5, 0.5)
    rep = run("leap", "female", height=height, push="com", check_range=False).report
    assert abs(rep["achieved_height_m"] - height) <= 0.03
    assert rep["landed"] and not rep["fell"]
    with pytest.raises(ConfigError, match="push_hip"):
        LeapParams(push_hip=-1.0)


def test_the_female_0_75_m_com_leap_lands_on_its_pitch_momentum(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Her 0.75 m com leap lifts off pitching forward (+1.6 kg m^2/s, her neighbours' +0.4 to
    +0.9): the landing puts the feet farther ahead by VERTICAL_LANDING_COM_MOMENTUM's gain and
    she lands; on the drift speed's delta alone she falls."""
    r = run("leap", "female", height=0.75)
    assert r.report["liftoff_pitch_momentum"] > 1.2
    assert abs(r.report["achieved_height_m"] - 0.75) <= 0.03
    assert r.report["landed"] and not r.report["fell"]
    monkeypatch.setattr(tables, "VERTICAL_LANDING_COM_MOMENTUM", {})
    r0 = run("leap", "female", height=0.75)
    assert r0.report["liftoff_pitch_momentum"] == pytest.approx(r.report["liftoff_pitch_momentum"])
    assert not r0.report["landed"]


def test_each_push_has_its_own_measured_range() -> None:
    """The com push's heights are checked against its own measured range (the message names
    it), the timed push's against the timed push's."""
    com = tables.supported_range("leap", "height", "female", "com")
    timed = tables.supported_range("leap", "height", "female", "timed")
    assert com is not None and timed is not None and com != timed
    assert timed == tables.supported_range("leap", "height", "female")
    with pytest.raises(ConfigError, match=f"{com[0]:g}-{com[1]:g} m .*'com'"):
        run("leap", "female", height=com[1] + 0.05)
    with pytest.raises(ConfigError, match=f"{timed[0]:g}-{timed[1]:g} m .*'timed'"):
        run("leap", "female", height=timed[1] + 0.01, push="timed")
    with pytest.raises(ConfigError, match=f"{com[0]:g}-{com[1]:g} m .*'com'"):
        run("leap", "female", height=com[0] - 0.01)


def test_the_female_0_825_m_com_leap_lands_with_the_legs_aimed_sideways(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Her 0.825 m com leap lands with the landing's legs aimed from the pelvis's whole
    orientation (VERTICAL_LANDING_COM_AIM); aimed by the servo alone she touches down on one
    foot and falls sideways."""
    assert tables.landing_params("female", 0.0, vertical=True, push="com").aim_sideways
    r = run("leap", "female", height=0.825, check_range=False)
    assert r.report["landed"] and not r.report["fell"]
    assert abs(r.log["com"][-1, 1]) < 0.1  # stood where she landed
    monkeypatch.setattr(tables, "VERTICAL_LANDING_COM_AIM", frozenset())
    r0 = run("leap", "female", height=0.825, check_range=False)
    assert r0.report["fell"] and not r0.report["landed"]
    assert abs(r0.log["com"][-1, 1]) > 0.3  # fell to the side
