"""The back handspring (issue 19, thesis 8.3): the hands reach the floor with the body past
inverted and carry it, the rotation carries on over them to the feet, the athlete lands a full
circle round, and the command writes a BVH and a complete report whose figures agree with the
run's own log."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from reactmocap.athletics.handspring import HandspringParams
from reactmocap.athletics.land import LandingParams
from reactmocap.athletics.leap import LeapParams
from reactmocap.athletics.maneuvers import Maneuver, Perturbation, load_maneuver, run_maneuver
from reactmocap.athletics.routines import (
    SETTLED_START,
    TIMED_START,
    handspring,
    handspring_maneuver,
)
from reactmocap.cli import main
from reactmocap.errors import ConfigError
from reactmocap.library.bvh import read_bvh

EXAMPLE = Path(__file__).resolve().parents[2] / "examples/athletics/maneuvers/back_handspring.toml"
KEYS = {"rotation_deg", "twist_deg", "landed", "fell", "hands_contact_s", "rotation_at_hands_deg",
        "hands_first_contact_s", "hands_last_contact_s", "touchdown_s"}  # fmt: skip


def test_the_example_file_is_the_built_in_handspring() -> None:
    assert load_maneuver(EXAMPLE).phases == handspring_maneuver("male").phases


def test_bad_handspring_parameters_are_config_errors() -> None:
    with pytest.raises(ConfigError, match="snap"):
        HandspringParams(snap=0.0)
    with pytest.raises(ConfigError, match="push"):
        HandspringParams(push=float("nan"))
    for cap in (0.0, 1.0, float("nan")):
        with pytest.raises(ConfigError, match="swing_cap"):
            LandingParams(swing_cap=cap)
    with pytest.raises(ConfigError, match="spin_ref"):
        LandingParams(spin_ref=float("inf"))
    with pytest.raises(ConfigError, match=r"aim must be in \[-2 pi, 0\]"):
        HandspringParams(aim=0.5)
    with pytest.raises(ConfigError, match="aim_knees"):
        HandspringParams(aim=-3.4, aim_knees=0.0)
    with pytest.raises(ConfigError, match="twist_gain"):
        HandspringParams(twist_gain=-1.0)
    with pytest.raises(ConfigError, match="twist_above"):
        HandspringParams(twist_gain=3.0, twist_above=-1.0)
    for cap in (-0.1, 2.5):
        with pytest.raises(ConfigError, match="rise_cap"):
            LeapParams(rise_cap=cap)
    for lead in (-0.004, 0.2, float("nan")):
        with pytest.raises(ConfigError, match="rise_lead"):
            LeapParams(rise_lead=lead)
    for lim in (-0.1, 3.5):
        with pytest.raises(ConfigError, match="rise_spin_limit"):
            LeapParams(rise_spin_limit=lim)
    for bad in ({"rise_spin_rate": -1.0}, {"rise_spin_rate": 120.0},
                {"rise_spin_rate": 33.5, "rise_spin_limit": 1.6},
                {"rise_spin_rate": 33.5, "rise_cap": 1.0}):  # fmt: skip
        with pytest.raises(ConfigError, match="rise_spin_rate"):
            LeapParams(**bad)


def test_the_hands_carry_the_body_past_inverted_and_the_report_matches_the_log() -> None:
    r = handspring("male", fps=10.0)
    rep, log = r.report, r.log
    assert rep["status"] == "ok" and KEYS <= set(rep)
    # the hands, and only the hands, touched the floor between the leap and the feet
    assert rep["hands_contact_s"] >= 0.05 and rep["handspring_other_contacts"] == []
    first, last, td = rep["hands_first_contact_s"], rep["hands_last_contact_s"], rep["touchdown_s"]
    assert rep["time_to_liftoff_s"] < first <= last < td
    # the log's own contacts: something but the feet touched from the first hand contact on,
    # and nothing but the feet while the athlete was on them before the leap
    t, others = log["t"], log["others"]
    assert others[(t >= first) & (t <= last)].any() and not others[t < first].any()
    dt = float(np.median(np.diff(t)))
    on_hands = (t >= first - 1e-9) & (t <= last + 1e-9)
    assert rep["hands_contact_s"] <= on_hands.sum() * dt + 1e-6
    # the body is past inverted when the hands land, and turns on over them to the feet
    assert rep["rotation_at_hands_deg"] < -150.0
    assert rep["rotation_at_touchdown_deg"] < -180.0
    assert rep["rotation_at_touchdown_deg"] < rep["rotation_at_hands_deg"]
    i = int(np.searchsorted(t, td))
    assert np.degrees(log["rotation"][i]) == pytest.approx(
        rep["rotation_at_touchdown_deg"], abs=1e-6
    )
    assert rep["rotation_deg"] == pytest.approx(np.degrees(log["rotation"][-1]), abs=1e-6)
    # the male preset lands: on its feet, balanced and still 2 s later, turned a full circle
    assert rep["landed"] is True and rep["fell"] is False
    assert abs(rep["rotation_deg"] + 360.0) <= 45.0
    assert log["feet"][-1] > 0 and not others[t > last + dt].any()


def test_the_handspring_command_writes_bvh_and_report_to_a_folder(tmp_path: Path) -> None:
    out, rep = tmp_path / "out", tmp_path / "h.json"
    assert main(["athletics", "handspring", "--out", str(out), "--report", str(rep),
                 "--fps", "20"]) == 0  # fmt: skip
    report = json.loads(rep.read_text())
    assert KEYS <= set(report) and report["hands_contact_s"] > 0.0
    assert isinstance(report["landed"], bool) and isinstance(report["fell"], bool)
    assert read_bvh(out / "back_handspring_male.bvh").num_frames > 50


def test_the_female_handspring_lands_on_feet_placed_past_the_default_hip_swing() -> None:
    r = handspring("female", fps=10.0)
    rep, log = r.report, r.log
    assert rep["status"] == "ok" and rep["body"] == "female"
    assert rep["rotation_at_hands_deg"] < -150.0 and rep["handspring_other_contacts"] == []
    assert rep["landed"] is True and rep["fell"] is False
    assert abs(rep["rotation_deg"] + 360.0) <= 45.0
    assert log["feet"][-1] > 0
    # the same preset with the landing's hip swing held at the default cap falls
    m = handspring_maneuver("female")
    phases = tuple(
        replace(ph, params={**ph.params, "swing_cap": 0.9}) if ph.controller == "land" else ph
        for ph in m.phases
    )
    capped = run_maneuver(replace(m, phases=phases), fps=10.0).report
    assert capped["landed"] is False and capped["fell"] is True


def test_the_female_crouch_eased_in_narrows_her_take_off_and_her_hands_meet_the_floor() -> None:
    """A tenth's start 3 (seed 0): with the crouch's COM target stepped back at once and the
    hips' feedback allowed 2.0 rad (her preset before 2026-12-05) the step rocks her, she
    leaves with over 52 kg m^2/s of backward spin against the nominal's 48.8 and turns past
    her hands before they reach the floor. Her preset eases the target in over 0.2 s
    (``com_ramp``, 1.8 rad): she leaves within 0.3 of the nominal's spin and her hands touch
    (docs/athletics.md). Cut at 1.8 s, past the hands' contact (1.60 s)."""
    m = replace(handspring_maneuver("female"), seconds=1.8)
    leap = next(p for p in m.phases if p.controller == "leap").params
    start = _starts(0.1, 4)[3]
    nominal = run_maneuver(m, fps=10.0).report
    eased = run_maneuver(m, perturbation=start, fps=10.0).report
    stepped = run_maneuver(_with(m, "leap", {**leap, "com_ramp": 0.0, "spin_limit": 2.0}),
                           perturbation=start, fps=10.0).report  # fmt: skip
    assert stepped["liftoff_pitch_momentum"] < -52.0 and stepped["rotation_at_hands_deg"] is None
    assert abs(eased["liftoff_pitch_momentum"] - nominal["liftoff_pitch_momentum"]) < 0.3
    assert -200.0 < eased["rotation_at_hands_deg"] < -180.0


def test_the_female_landing_places_her_feet_by_the_spin_the_push_left() -> None:
    """A tenth's start 3 (seed 0): her hands meet the floor at -187.8 deg, 2 deg before the
    nominal's, and the push leaves her -39.0 kg m^2/s against the nominal's -41.0. With her
    feet put 56 cm back whatever the spin (the preset before 2026-12-05, later) she falls;
    scaled by the spin (``spin_ref`` -41.0, her preset's) they go nearer and she lands
    (docs/athletics.md)."""
    m = handspring_maneuver("female")
    land = next(p for p in m.phases if p.controller == "land").params
    assert land["spin_ref"] == -41.0
    start = _starts(0.1, 4)[3]
    scaled = run_maneuver(m, perturbation=start, fps=10.0).report
    assert scaled["landed"] and not scaled["fell"] and abs(scaled["rotation_deg"] + 360.0) <= 45.0
    fixed = run_maneuver(_with(m, "land", {**land, "spin_ref": 0.0}), perturbation=start,
                         fps=10.0).report  # fmt: skip
    assert fixed["fell"] and not fixed["landed"]
    assert abs(fixed["rotation_at_hands_deg"] - scaled["rotation_at_hands_deg"]) < 1e-9


def _starts(scale: float, n: int, seed: int = 0) -> list[Perturbation]:
    """The first ``n`` of the capture region's starts (``seed``) at ``scale`` of the benchmark's
    distribution, written as it writes it (the same floats)."""
    rng = np.random.default_rng(seed)
    sd = {"joint_sd": math.radians(3.0) * scale, "pitch_sd": math.radians(2.0) * scale,
          "velocity_sd": 0.05 * scale, "spin_sd": 0.1 * scale}  # fmt: skip
    return [Perturbation.sample(rng, **sd) for _ in range(n)]


def _with(m: Maneuver, controller: str, params: dict[str, float]) -> Maneuver:
    """``m`` with ``controller``'s phase parameters replaced by ``params``."""
    phases = tuple(replace(ph, params=params) if ph.controller == controller else ph
                   for ph in m.phases)  # fmt: skip
    return replace(m, phases=phases)


def _uncapped(m: Maneuver) -> Maneuver:
    """``m`` as the file was before its leap's height cap (2026-12-05): no ``rise_cap`` /
    ``rise_lead``."""
    leap = next(p for p in m.phases if p.controller == "leap").params
    return _with(m, "leap", {k: v for k, v in leap.items() if not k.startswith("rise_")})


def _unspun(m: Maneuver) -> Maneuver:
    """``m`` as the file was before the hips gave the cut push's spin back (2026-12-05,
    later): no ``rise_spin_limit`` / ``rise_spin_rate``."""
    leap = next(p for p in m.phases if p.controller == "leap").params
    return _with(m, "leap", {k: v for k, v in leap.items() if not k.startswith("rise_spin")})


def _unforeseen(m: Maneuver) -> Maneuver:
    """``m`` with the landing's step as the file had it before 2026-12-05 (later): no
    ``step_across`` / ``step_foresee`` (nor the later ``step_knees`` / ``step_hang_plant``)."""
    land = next(p for p in m.phases if p.controller == "land").params
    drop = ("step_across", "step_foresee", "step_knees", "step_hang_plant")
    old = {k: v for k, v in land.items() if k not in drop}
    return _with(m, "land", old)


def _unpaired(m: Maneuver) -> Maneuver:
    """``m`` with the landing and the last balance as the file had them before 2026-12-05
    (later): the step to 10 cm past the capture point (reach 0.1), no ``recover_leg``, no
    ``side_both`` (nor the later ``step_across`` / ``step_foresee``)."""
    m = _unforeseen(m)
    land = next(p for p in m.phases if p.controller == "land").params
    old = {k: v for k, v in land.items() if k != "recover_leg"}
    m = _with(m, "land", {**old, "step": [0.05, 0.1, 0.3, 0.25]})
    last = m.phases[-1]
    plain = {k: v for k, v in last.params.items() if k != "side_both"}
    return replace(m, phases=(*m.phases[:-1], replace(last, params=plain)))


def _aimed_at_196(m: Maneuver) -> Maneuver:
    """``m`` with the knees' aim as it was before it was centred on the ramped crouch
    (2026-12-04): -196 deg at contact about 0.4 rad, clipped at the default 0.9 (and no
    height cap)."""
    m = _uncapped(m)
    hands = next(p for p in m.phases if p.controller == "handspring").params
    return _with(m, "handspring", {**{k: v for k, v in hands.items() if k != "aim_knees"},
                                   "aim": -3.42, "knees": 0.4})  # fmt: skip


def _hopping(m: Maneuver) -> Maneuver:
    """``m`` as the file was before its ramped crouch (2026-12-04): the crouch's COM target 10
    cm back at once (the step that hops the feet off the floor), the feet landing 55 cm back,
    the knees' aim at -196 deg (and no height cap)."""
    m = _uncapped(m)
    leap = next(p for p in m.phases if p.controller == "leap").params
    land = next(p for p in m.phases if p.controller == "land").params
    m = _with(_aimed_at_196(m), "leap", {**{k: v for k, v in leap.items() if k != "com_ramp"},
                                         "com_offset": -0.1})  # fmt: skip
    return _with(m, "land", {**land, "delta": -0.55})


def _timed_start(m: Maneuver) -> Maneuver:
    """``m`` as the file was before its settled start (2026-12-03 22:13 UTC): the leap 0.3 s
    into the start (:data:`TIMED_START`), its crouch held the default 0.15 s, 5.5 s."""
    m = _hopping(m)
    leap = next(p for p in m.phases if p.controller == "leap").params
    m = _with(m, "leap", {k: v for k, v in leap.items() if k != "hold"})
    return replace(m, phases=(TIMED_START, *m.phases[1:]), seconds=5.5)


#: the file as it was before the knees' aim (2026-12-03): the leap's feedback allowed 1.5 rad,
#: the knees straight in the air, the feet 45 cm behind the capture point, 5.0 s
BEFORE_AIM = {
    "leap": {"effort": 0.6, "spin": -110.0, "spin_limit": 1.5, "com_offset": -0.1},
    "handspring": {"give": 0.5, "push_after": 0.06, "push": -2.65, "snap_hips": -1.2,
                   "snap_trunk": 0.5, "snap_knees": 0.6, "snap": 0.1},
    "land": {"delta": -0.45, "spin_ref": -96.8},
}  # fmt: skip


def test_the_landing_places_the_feet_by_the_spin_the_push_left() -> None:
    """Start 3 of the capture region's tenth-size starts (seed 0), on the file before the
    knees' aim: the push leaves -99.7 kg m^2/s at touchdown against the nominal's -96, too
    much for the fixed delta (it turned on over its feet to -397 deg and fell); with the delta
    scaled by the spin measured as the landing begins (``spin_ref``) the feet land farther
    back and it stands."""
    start = _starts(0.1, 4)[3]
    m = replace(_timed_start(load_maneuver(EXAMPLE)), seconds=5.0)
    for controller, params in BEFORE_AIM.items():
        m = _with(m, controller, params)
    land = next(i for i, p in enumerate(m.phases) if p.controller == "land")
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 45.0
    phases = list(m.phases)
    phases[land] = replace(phases[land], params={"delta": -0.45})
    old = run_maneuver(replace(m, phases=tuple(phases)), perturbation=start, fps=10.0).report
    assert old["fell"] and not old["landed"]


def test_the_knees_aim_the_hands_contact_at_the_rotation_the_push_needs() -> None:
    """Full-size starts 2 and 12 (seed 0): start 2 leaps high and would meet the floor late
    (-203.6 deg with the knees held at the file's 0.4 rad), start 12 leaps with too little
    spin and early (-174.4 deg); both fall so. With the knees steering the rotation predicted
    at contact (``aim``, the file since 2026-12-03) start 2 straightens them, start 12 bends
    them, both meet the floor within 15 deg of the aimed -196 deg and land."""
    starts = _starts(1.0, 13)
    m = _timed_start(load_maneuver(EXAMPLE))  # as measured then
    hands = next(p for p in m.phases if p.controller == "handspring").params
    assert hands["aim"] == -3.42
    held = _with(m, "handspring", {k: v for k, v in hands.items() if k != "aim"})
    for i, late in ((2, True), (12, False)):
        r = run_maneuver(m, perturbation=starts[i], fps=10.0).report
        assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 45.0
        assert abs(r["rotation_at_hands_deg"] + 196.0) <= 15.0
        knees = r["handspring_aim_knees"]
        assert knees < 0.4 if late else knees > 0.4
        off = run_maneuver(held, perturbation=starts[i], fps=10.0).report
        assert off["fell"] and not off["landed"] and off["handspring_aim_knees"] is None
        h = off["rotation_at_hands_deg"]
        assert h < -199.0 if late else h > -185.0


def test_the_hands_split_their_push_against_the_twist_and_off_changes_nothing() -> None:
    """Full-size start 7 (seed 0) leaves the leap with +5.1 kg m^2/s about the vertical and the
    hands leave the floor with +2.5 (the body turns on over its feet and falls). With the
    shoulders' pitch split against it while the hands are down (``twist_gain``) the hands
    leave with less than a fifth of that; ``twist_gain`` 0, or the feedback gated off by
    ``twist_above``, is the file's run to the bit."""
    start = _starts(1.0, 8)[7]
    m = _timed_start(load_maneuver(EXAMPLE))  # as measured then
    hands = next(p for p in m.phases if p.controller == "handspring").params

    def lz_as_hands_leave(params: dict[str, float]) -> tuple[float, float]:
        r = run_maneuver(_with(m, "handspring", params), perturbation=start, fps=10.0)
        t, lz = r.log["t"], r.log["momentum"][:, 2]
        i = min(int(np.searchsorted(t, r.report["hands_last_contact_s"])), t.size - 1)
        return float(lz[i]), float(r.report["rotation_deg"])

    off = lz_as_hands_leave({**hands, "twist_gain": 0.0})
    assert lz_as_hands_leave({k: v for k, v in hands.items() if k != "twist_gain"}) == off
    assert off[0] > 2.0
    on, _ = lz_as_hands_leave({**hands, "twist_gain": 3.0})
    assert abs(on) < 0.2 * off[0]
    # gated off above the momentum the hands meet the floor with (+5.5): the file's run
    assert lz_as_hands_leave({**hands, "twist_gain": 3.0, "twist_above": 6.0}) == off


def test_the_male_handspring_starts_settled_and_a_start_that_crouched_turning_lands() -> None:
    """Since 2026-12-03 the male handspring starts settled onto both feet (as the back tuck)
    and holds its crouch 0.22 s; the female keeps the timed start. Full-size start 13 (seed 0)
    crouched 0.3 s into the start with its pelvis turning (+9 deg) and left the leap with +2.8
    kg m^2/s about the vertical, turned on over its feet and fell; settled first it leaves with
    under 2 and lands."""
    assert handspring_maneuver("male") == load_maneuver(EXAMPLE)
    m = _hopping(load_maneuver(EXAMPLE))  # as measured then
    assert m.phases[0] == SETTLED_START
    assert handspring_maneuver("female").phases[0] == TIMED_START
    start = _starts(1.0, 14)[13]

    def run(man: Maneuver) -> tuple[bool, float]:
        r = run_maneuver(man, perturbation=start, fps=10.0)
        t, lz = r.log["t"], r.log["momentum"][:, 2]
        i = min(int(np.searchsorted(t, r.report["time_to_liftoff_s"])), t.size - 1)
        return bool(r.report["landed"] and not r.report["fell"]), float(lz[i])

    landed, lz = run(m)
    assert landed and abs(lz) < 2.0
    landed, lz = run(_timed_start(m))
    assert not landed and lz > 2.0


def test_the_crouch_keeps_its_com_between_the_feet_and_off_changes_nothing() -> None:
    """Full-size start 3 (seed 0) settles on both feet, then crouches onto its right foot (the
    left off the floor at the crouch's end, the COM 4.8 cm to the right): the crouch's COM
    target follows the soles in contact. With it over the middle of both soles sideways
    (``crouch_middle``) the crouch ends on both feet. While both feet stay down (the nominal)
    the option is the file's run to the bit."""
    m = _hopping(load_maneuver(EXAMPLE))  # as measured then
    leap = next(p for p in m.phases if p.controller == "leap").params
    mid = _with(m, "leap", {**leap, "crouch_middle": True})
    nominal = run_maneuver(m, fps=10.0).report["rotation_deg"]
    assert run_maneuver(mid, fps=10.0).report["rotation_deg"] == nominal
    start = _starts(1.0, 4)[3]

    def feet_at_crouch_end(man: Maneuver) -> int:
        log = run_maneuver(man, perturbation=start, fps=10.0).log
        return int(log["feet"][np.flatnonzero(log["state"] == "leap.crouch")[-1]])

    assert feet_at_crouch_end(m) == 1
    assert feet_at_crouch_end(mid) == 2


def test_the_crouch_eases_its_com_target_in_and_levels_the_hips() -> None:
    """Full-size start 3 (seed 0): the crouch's COM target steps 10 cm back at once and both
    feet leave the floor in its first 0.1 s (the file before 2026-12-04). Eased in over 0.2 s (``com_ramp``)
    both feet stay down through the crouch, but the pelvis rolls as it goes down and the feet
    leave with over 3 kg m^2/s about the vertical; with the legs also levelling the hips
    (``crouch_level`` 10) under 2. The file ramps its crouch since 2026-12-04 (with the COM
    13 cm back and the feet landing 60 cm back: docs/athletics.md); the levelling is off."""
    m = replace(_hopping(load_maneuver(EXAMPLE)), seconds=2.2)  # past the lift-off (1.94 s)
    leap = next(p for p in m.phases if p.controller == "leap").params
    start = _starts(1.0, 4)[3]

    def crouch_feet_and_lz(man: Maneuver) -> tuple[int, float]:
        """The fewest feet down in the crouch and ``Lz`` at the thrust's last tick."""
        log = run_maneuver(man, perturbation=start, fps=10.0).log
        crouch = np.flatnonzero(log["state"] == "leap.crouch")
        thrust = np.flatnonzero(log["state"] == "leap.thrust")
        return int(log["feet"][crouch].min()), float(log["momentum"][thrust[-1], 2])

    assert crouch_feet_and_lz(m)[0] == 0
    feet, lz = crouch_feet_and_lz(_with(m, "leap", {**leap, "com_ramp": 0.2}))
    assert feet == 2 and lz > 3.0
    _, lz = crouch_feet_and_lz(_with(m, "leap", {**leap, "com_ramp": 0.2, "crouch_level": 10.0}))
    assert abs(lz) < 2.0


def test_the_knees_aim_is_centred_on_the_ramped_crouch() -> None:
    """Since the crouch is ramped (2026-12-04) the nominal meets the floor at -186 deg, and the
    knees aimed at -196 deg about 0.4 rad sat at their 0.9 rad clip. Centred there (aim -3.25
    rad about 0.9, up to 1.3: the file) the nominal lands as before, with its knees inside
    the range; full-size start 5 (seed 0) leaps high (0.67 m), and with the knees straightened
    further it meets the floor earlier and lands, where it fell with the old aim (both on the
    landing and last balance as they were then: the file's since 2026-12-05 lands start 5
    with the old aim too)."""
    m = load_maneuver(EXAMPLE)
    old = _aimed_at_196(_unpaired(m))
    nominal = run_maneuver(m, fps=10.0).report
    assert nominal["landed"] and 0.5 < nominal["handspring_aim_knees"] < 1.3
    assert run_maneuver(old, fps=10.0).report["handspring_aim_knees"] == 0.9
    start = _starts(1.0, 6)[5]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"] and abs(r["rotation_deg"] + 360.0) <= 45.0
    before = run_maneuver(old, perturbation=start, fps=10.0).report
    assert before["fell"] and not before["landed"]
    assert before["handspring_aim_knees"] > r["handspring_aim_knees"]


def test_the_leap_holds_its_height_and_a_start_that_over_leapt_lands() -> None:
    """Full-size start 43 (seed 0) leaps high: the COM rises 0.99 m (the landers 0.45-0.67),
    the hands meet the floor past -220 deg with the knees' aim straight, and it does not
    land. With the push's knees and ankles stopped once the COM's ballistic apex reaches 0.5
    m (``rise_cap``) it rises under 0.6 m, meets the floor within the aim's range and lands."""
    m = _uncapped(load_maneuver(EXAMPLE))  # the file before its look-ahead cap
    leap = next(p for p in m.phases if p.controller == "leap").params
    start = _starts(1.0, 44)[43]
    high = run_maneuver(m, perturbation=start, fps=10.0).report
    assert high["achieved_height_m"] > 0.9 and high["rotation_at_hands_deg"] < -220.0
    assert not (high["landed"] and not high["fell"])  # capture_region's failure
    held = run_maneuver(_with(m, "leap", {**leap, "rise_cap": 0.5}), perturbation=start,
                        fps=10.0).report  # fmt: skip
    assert held["achieved_height_m"] < 0.6 and held["rotation_at_hands_deg"] > -195.0
    assert held["landed"] and not held["fell"] and abs(held["rotation_deg"] + 360.0) <= 45.0


def test_the_cap_looks_ahead_and_holds_only_the_over_leap() -> None:
    """Full-size start 1 (seed 0) leaps 0.89 m without the file's height cap and does not
    land. The file's cap at 1.0 m looks 12 ms ahead at the apex's rate (``rise_lead``, since
    2026-12-05) and fires in its push's last ticks, where an over-leap's apex grows fastest:
    it rises under 0.65 m and lands. Start 0, an ordinary leap (0.65 m) that lands, runs as
    without the cap (it never fires; the 0.5 m cap without a lead cut it and it fell)."""
    m = load_maneuver(EXAMPLE)
    leap = next(p for p in m.phases if p.controller == "leap").params
    assert (leap["rise_cap"], leap["rise_lead"]) == (1.0, 0.012)
    m = _unpaired(m)  # the landing and last balance as then (start 1 falls with the file's)
    uncapped = _uncapped(m)
    m = _unspun(m)  # as measured then
    ordinary, high = _starts(1.0, 2)
    before = run_maneuver(uncapped, perturbation=high, fps=10.0).report
    assert before["achieved_height_m"] > 0.85 and not (before["landed"] and not before["fell"])
    held = run_maneuver(m, perturbation=high, fps=10.0).report
    assert held["achieved_height_m"] < 0.65
    assert held["landed"] and not held["fell"] and abs(held["rotation_deg"] + 360.0) <= 45.0
    without = run_maneuver(uncapped, perturbation=ordinary, fps=10.0).report
    same = run_maneuver(m, perturbation=ordinary, fps=10.0).report
    assert without["landed"] and not without["fell"]
    for key in ("achieved_height_m", "rotation_deg", "landed", "fell"):
        assert same[key] == without[key]


def test_the_hips_give_the_spin_back_a_tick_before_the_cap() -> None:
    """Full-size start 25 (seed 0) over-leaps; the cap (1.0 m, 12 ms ahead) stops its knees
    and ankles in the push's last ticks, where the spin is made: without the file's spin
    given back it leaves with -68.7 kg m^2/s, meets the hands at -177 deg with the knees at
    their clip and falls back. The file opens the hips' spin allowance to 1.6 rad a tick
    before the cap, once the apex climbs faster than 33.5 m/s (``rise_spin_rate``,
    ``rise_spin_limit``, since 2026-12-05): it leaves with over 5 kg m^2/s more spin and
    lands. Start 0 (an ordinary lander, its apex never that fast) runs as without it."""
    m = load_maneuver(EXAMPLE)
    leap = next(p for p in m.phases if p.controller == "leap").params
    assert (leap["rise_spin_limit"], leap["rise_spin_rate"]) == (1.6, 33.5)
    cut_file = _unspun(m)
    starts = _starts(1.0, 26)
    cut = run_maneuver(cut_file, perturbation=starts[25], fps=10.0).report
    given = run_maneuver(m, perturbation=starts[25], fps=10.0).report
    assert not (cut["landed"] and not cut["fell"])
    assert given["liftoff_pitch_momentum"] < cut["liftoff_pitch_momentum"] - 5.0
    assert given["landed"] and not given["fell"] and abs(given["rotation_deg"] + 360.0) <= 45.0
    without = run_maneuver(cut_file, perturbation=starts[0], fps=10.0).report
    same = run_maneuver(m, perturbation=starts[0], fps=10.0).report
    for key in ("achieved_height_m", "liftoff_pitch_momentum", "rotation_deg", "landed"):
        assert same[key] == without[key]


def test_the_landing_steps_closing_swing_ends_sooner_put_down_or_placed_across() -> None:
    """Full-size start 28 (seed 0) steps back on landing; the file's closing swing (the front
    foot brought back beside the rear one) hangs over the floor, the foot 0.2 m beside its
    place, while the body falls sideways toward it, until the swing's 0.75 s limit. Opt-ins:
    with ``step_down_after`` 0.3 the place is the floor under the foot from 0.3 s on and the
    swing ends by 0.35 s; with ``step_across`` 0.15 the closing foot goes past the capture
    point across the feet and lands within 0.3 s. With ``step_down_after`` the first step is
    the file's, record for record. On the landing and last balance as they were then (the
    file's since 2026-12-05, the step to the capture point, ``recover_leg`` and
    ``side_both``, stands start 28 up)."""
    m = replace(_unpaired(load_maneuver(EXAMPLE)), seconds=4.6)
    land = next(p for p in m.phases if p.controller == "land").params
    assert "step_down_after" not in land and "step_across" not in land
    start = _starts(1.0, 29)[28]
    steps = run_maneuver(m, perturbation=start, fps=10.0).report["steps"]
    assert steps[1]["beyond_m"] == 0.0 and steps[1]["s"] >= 0.7  # the closing swing hangs
    down = _with(m, "land", {**land, "step_down_after": 0.3})
    put = run_maneuver(down, perturbation=start, fps=10.0).report["steps"]
    assert put[0] == steps[0]
    assert put[1]["t"] == steps[1]["t"] and put[1]["s"] <= 0.35
    wide = _with(m, "land", {**land, "step_across": 0.15})
    placed = run_maneuver(wide, perturbation=start, fps=10.0).report["steps"]
    assert placed[1]["beyond_m"] == 0.0 and placed[1]["s"] <= 0.3
    for bad in ({"step_down_after": -0.1}, {"step_across": -0.1}):
        with pytest.raises(ConfigError, match=next(iter(bad))):
            LandingParams(step=(0.05,), **bad)
    with pytest.raises(ConfigError, match="need a step"):
        LandingParams(step_down_after=0.3)


def test_the_landings_recover_leg_stands_the_recovery_up_taller() -> None:
    """``LandingParams.recover_leg`` (0.8 in the file since 2026-12-05, with the step's reach
    0): the recovery's stand-up goes to at least that fraction of the straight leg, not to
    where the landing's crouch left the legs. Full-size start 28 (seed 0), on the landing as
    it was before (no ``recover_leg``): the run is that one's up to the recovery, and 0.5 s
    after the feet touch its COM stands higher; a bad value is named."""
    assert next(p for p in load_maneuver(EXAMPLE).phases
                if p.controller == "land").params["recover_leg"] == 0.8  # fmt: skip
    m = replace(_unpaired(load_maneuver(EXAMPLE)), seconds=4.2)
    land = next(p for p in m.phases if p.controller == "land").params
    assert "recover_leg" not in land
    start = _starts(1.0, 29)[28]
    base = run_maneuver(m, perturbation=start, fps=10.0)
    tall = run_maneuver(_with(m, "land", {**land, "recover_leg": 0.8}), perturbation=start,
                        fps=10.0)  # fmt: skip
    td = base.report["touchdown_s"]
    assert tall.report["touchdown_s"] == td
    t = base.log["t"]
    before, after = t < td, int(np.searchsorted(t, td + 0.5))
    assert np.array_equal(base.log["com"][before], tall.log["com"][before])
    assert tall.log["com"][after, 2] > base.log["com"][after, 2] + 0.03
    for bad in (0.3, 1.2):
        with pytest.raises(ConfigError, match="recover_leg"):
            LandingParams(recover_leg=bad)


def test_the_last_balance_keeps_the_com_between_both_feet_after_the_landings_steps() -> None:
    """Full-size start 16 (seed 0) lands, steps back and closes its feet as the landers do, then
    drifts sideways over one foot and falls during a third step 2.0 s after touchdown. With
    the last balance's COM target kept between both soles while one is unloaded
    (``Posture.side_both``, the file since 2026-12-05) it stands; without it it falls. On
    the landing's step as it was then (no ``step_across`` / ``step_foresee``)."""
    m = replace(_unforeseen(load_maneuver(EXAMPLE)), seconds=5.0)  # touchdown at 2.55 s
    last = m.phases[-1]
    assert last.controller == "balance" and last.params["side_both"] is True
    start = _starts(1.0, 17)[16]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"]
    plain = replace(last, params={k: v for k, v in last.params.items() if k != "side_both"})
    old = run_maneuver(replace(m, phases=(*m.phases[:-1], plain)), perturbation=start, fps=10.0)
    assert old.report["fell"] and not old.report["landed"]


def test_the_landings_step_fires_on_the_capture_point_across_the_feet_foreseen() -> None:
    """Full-size start 40 (seed 0) lands and steps, then tips out sideways over one foot and
    falls (class S). With the landing's step also fired by the capture point across the feet
    carried 0.25 s on (``step_across`` 0.05, ``step_foresee`` 0.25: the file since 2026-12-05,
    latest) it stands. ``step_foresee`` needs ``step_across``; a bad value is named."""
    m = load_maneuver(EXAMPLE)
    land = next(p for p in m.phases if p.controller == "land").params
    assert land["step_across"] == 0.05 and land["step_foresee"] == 0.25
    start = _starts(1.0, 41)[40]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"]
    old = run_maneuver(_unforeseen(m), perturbation=start, fps=10.0).report
    assert old["fell"] and not old["landed"]
    for bad in ({"step_foresee": 0.25}, {"step_across": 0.05, "step_foresee": 1.5}):
        with pytest.raises(ConfigError, match="step_foresee"):
            LandingParams(step=(0.05,), **bad).balance_step()
    with pytest.raises(ConfigError, match="need a step"):
        LandingParams(step_foresee=0.25)


def _landing_with_and_without(
    key: str, value: float | list[float], start: Perturbation
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The male file's reports (run cut to 6 s) from ``start`` with the landing's ``key`` at
    ``value`` and without it."""
    m = replace(load_maneuver(EXAMPLE), seconds=6.0)
    land = next(p for p in m.phases if p.controller == "land").params
    # held_hip_share acts on absorb_spin's held starts only: it goes with it
    gone = {key, "held_hip_share"} if key == "absorb_spin" else {key}
    plain = {k: v for k, v in land.items() if k not in gone}
    runs = (_with(m, "land", {**plain, key: value}), _with(m, "land", plain))
    with_key, without = (run_maneuver(r, perturbation=start, fps=10.0).report for r in runs)
    return with_key, without


def test_the_landings_steps_leave_both_knees_alike() -> None:
    """Full-size start 29 (seed 0) steps after the landing with each stepped knee left at its
    swing's last target: it falls over a third and fourth step. With ``step_knees`` 1.0 (both
    knees' targets to their mean at each touchdown: the file since 2026-12-05, latest) it
    stands on its first step. A share outside [0, 1] or without a step is named."""
    r, old = _landing_with_and_without("step_knees", 1.0, _starts(1.0, 30)[29])
    assert r["landed"] and not r["fell"]
    assert old["fell"] and not old["landed"]
    for bad in (-0.1, 1.5, math.nan):
        with pytest.raises(ConfigError, match="step_knees"):
            LandingParams(step=(0.05,), step_knees=bad)
    with pytest.raises(ConfigError, match="need a step"):
        LandingParams(step_knees=1.0)


def test_the_landings_hung_foot_is_planted_after_step_hang_plant() -> None:
    """Full-size start 4 (seed 1) stands on one foot after the landing, the other hung, and
    falls over a late step. With ``step_hang_plant`` 0.4 (the landing's carried stepper puts
    the posture's plant on once a foot has hung 0.4 s with no swing) the hung foot is put
    down and it lands with no step. A bad value, or one without a step, is named."""
    r, old = _landing_with_and_without("step_hang_plant", 0.4, _starts(1.0, 5, seed=1)[4])
    assert r["landed"] and not r["fell"] and not r.get("steps")
    assert old["fell"] and not old["landed"]
    for bad in (-0.1, 2.5, math.nan):
        with pytest.raises(ConfigError, match="step_hang_plant"):
            LandingParams(step=(0.05,), step_hang_plant=bad)
    with pytest.raises(ConfigError, match="need a step"):
        LandingParams(step_hang_plant=0.4)


def test_the_landings_absorb_holds_its_hand_over_while_the_body_still_turns() -> None:
    """Full-size start 20 (seed 0) enters the landing's recovery still turning back (-33
    kg m^2/s about the pelvis's side axis), steps forward out of it and falls. With
    ``absorb_spin`` (-15, 0.5) (the file since 2026-12-06) the absorb hands over only once
    the momentum is above -15 kg m^2/s (or 0.5 s after touchdown) and it lands
    (docs/athletics.md, "the absorb's hand-over held"). A bad gate or wait is named."""
    r, old = _landing_with_and_without("absorb_spin", [-15.0, 0.5], _starts(1.0, 21)[20])
    assert r["landed"] and not r["fell"]
    assert old["fell"] and not old["landed"]
    for bad in ((1.0, 0.5), (-15.0, 0.0), (-15.0, 1.5), (-15.0,), (math.nan, 0.5)):
        with pytest.raises(ConfigError, match="absorb_spin"):
            LandingParams(absorb_spin=bad)


def test_the_female_hops_second_touchdown_is_placed_for_the_spin_it_left_with() -> None:
    """A tenth's start 14 (seed 0): the recovery's kick lifts her off with -8.2 kg m^2/s
    (her landers' hops leave with -8.5..-2.8); with her preset the hop's feet come down
    ahead of the COM and she falls on past (+39.5 deg). With ``hop_spin`` (-5.5, 0.02) the
    hop's feet go 5.4 cm farther back for that spin and she lands; up to the lift-off the run
    is the preset's (docs/athletics.md, "the hop's second touchdown placed"). Bad values are
    named."""
    m = handspring_maneuver("female")
    land = next(p for p in m.phases if p.controller == "land").params
    plain_land = {k: v for k, v in land.items() if k != "hop_spin"}
    start = _starts(0.1, 15)[14]
    plain, hop = (run_maneuver(_with(m, "land", params), perturbation=start, fps=10.0).report
                  for params in (plain_land, {**plain_land, "hop_spin": [-5.5, 0.02]}))  # fmt: skip
    assert hop["landed"] and not hop["fell"] and abs(hop["rotation_deg"] + 360.0) <= 45.0
    assert plain["fell"] and not plain["landed"]
    assert hop["rotation_at_touchdown_deg"] == plain["rotation_at_touchdown_deg"]
    for bad in ((-5.5,), (-5.5, 0.5), (math.nan, 0.02), (-500.0, 0.02)):
        with pytest.raises(ConfigError, match="hop_spin"):
            LandingParams(hop_spin=bad)


def test_the_held_absorbs_balance_drops_its_hip_offset() -> None:
    """Full-size start 14 (seed 0): the file's absorb holds its hand-over (``absorb_spin``),
    then the body stands on one foot while the COM servo's hip offset flexes the standing hip
    and the pelvis pitches forward; it steps forward and falls. With ``held_hip_share`` 0
    (that offset dropped after a held absorb) it lands (docs/athletics.md, "the balance's
    hip offset zeroed after a held absorb"). A share outside [0, 1] or without
    ``absorb_spin`` is named."""
    r, old = _landing_with_and_without("held_hip_share", 0.0, _starts(1.0, 15)[14])
    assert r["landed"] and not r["fell"]
    assert old["fell"] and not old["landed"]
    for bad in (-0.1, 1.5, math.nan):
        with pytest.raises(ConfigError, match="held_hip_share"):
            LandingParams(absorb_spin=(-15.0, 0.5), held_hip_share=bad)
    with pytest.raises(ConfigError, match="needs absorb_spin"):
        LandingParams(held_hip_share=0.0)
