"""Maneuvers in TOML (issue 19): strict validation naming the file and field, every shipped
example runs, and the ``maneuver`` and ``somersault`` commands write what they say."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from reactmocap.athletics.maneuvers import (
    CONTROLLERS,
    Perturbation,
    capture_region,
    load_maneuver,
    run_maneuver,
)
from reactmocap.athletics.routines import dive, somersault, somersault_maneuver
from reactmocap.cli import main
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.bvh import read_bvh

EXAMPLES = sorted(
    (Path(__file__).resolve().parents[2] / "examples/athletics/maneuvers").glob("*.toml")
)

GOOD_PHASE = '[[phase]]\ncontroller = "balance"\nexit = { event = "after", seconds = 0.2 }\n'


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "m.toml"
    path.write_text(text)
    return path


def test_an_unknown_controller_names_the_file_the_phase_and_the_valid_ones(tmp_path: Path) -> None:
    path = _file(
        tmp_path, GOOD_PHASE + '[[phase]]\ncontroller = "flip"\nexit = { event = "open" }\n'
    )
    with pytest.raises(ConfigError) as err:
        load_maneuver(path)
    msg = str(err.value)
    assert str(path) in msg and "phase[2].controller" in msg and "'flip'" in msg
    assert all(name in msg for name in CONTROLLERS)


def test_a_missing_exit_event_is_a_config_error_naming_the_field(tmp_path: Path) -> None:
    path = _file(tmp_path, '[[phase]]\ncontroller = "leap"\nparams = { effort = 0.5 }\n')
    with pytest.raises(ConfigError, match=r"phase\[1\]\.exit is missing") as err:
        load_maneuver(path)
    assert str(path) in str(err.value) and "liftoff" in str(err.value)


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ('[[phase]]\ncontroller = "tumble"\nexit = { event = "apex" }\n', r"phase\[1\]\.exit\.event"),
        ('[[phase]]\ncontroller = "leap"\nparams = { spinn = 1.0 }\nexit = { event = "apex" }\n',
         r"phase\[1\]\.params\.spinn"),
        ('[[phase]]\ncontroller = "leap"\nparams = { spin = "fast" }\nexit = { event = "apex" }\n',
         r"phase\[1\]\.params\.spin must be a number"),
        # an effort beyond the measured 0-1 ran (7: a leap past the tables)
        ('[[phase]]\ncontroller = "leap"\nparams = { effort = 7 }\nexit = { event = "apex" }\n',
         r"phase\[1\]\.params\.effort: must be 0-1, got 7"),
        ('[[phase]]\ncontroller = "tumble"\nparams = { position = "straddle" }\n'
         'exit = { event = "open" }\n', r"phase\[1\]\.params\.position"),
        ('[[phase]]\ncontroller = "balance"\nexit = { event = "after" }\n',
         r"phase\[1\]\.exit\.seconds"),
        ('[[phase]]\ncontroller = "balance"\nexit = { event = "settled", seconds = 0 }\n',
         r"phase\[1\]\.exit\.seconds"),
        ('[[phase]]\ncontroller = "balance"\nparams = { plant = 1 }\nexit = { event = "never" }\n',
         r"phase\[1\]\.params\.plant must be true or false"),
        ('seconds = -1\n' + GOOD_PHASE, "seconds must be"),
        ('name = "x"\n', "phase"),
        ('nmae = "x"\n' + GOOD_PHASE, "unknown field"),
        ('[[phase]\n', "invalid TOML"),
    ],
)  # fmt: skip
def test_bad_files_are_refused_naming_the_field(tmp_path: Path, text: str, field: str) -> None:
    with pytest.raises(ConfigError, match=field):
        load_maneuver(_file(tmp_path, text))


def test_every_example_is_valid_and_names_a_maneuver_the_issue_asks_for() -> None:
    names = {p.stem for p in EXAMPLES}
    assert {"back_somersault", "forward_somersault", "vertical_leap", "broad_jump",
            "dive_pike", "dive_twist", "back_handspring"} <= names  # fmt: skip
    for path in EXAMPLES:
        m = load_maneuver(path)
        assert m.name == path.stem and m.phases[0].controller == "balance"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_each_example_maneuver_runs_and_lands(path: Path) -> None:
    r = run_maneuver(load_maneuver(path)).report
    assert r["status"] == "ok" and r["time_to_liftoff_s"] is not None
    assert r["landed"] and not r["fell"]
    if path.stem in ("back_somersault", "back_somersault_female", "back_layout"):
        assert abs(r["rotation_deg"] + 360.0) <= 30.0
    elif path.stem == "back_somersault_full_twist":  # one somersault, one twist
        assert abs(r["rotation_deg"] + 360.0) <= 30.0
        assert abs(abs(r["twist_deg"]) - 360.0) <= 45.0
    elif path.stem.startswith("back_handspring"):  # on the hands, and only the hands, then the feet
        assert abs(r["rotation_deg"] + 360.0) <= 45.0
        assert r["hands_contact_s"] > 0.05 and r["handspring_other_contacts"] == []
    elif path.stem == "forward_somersault":
        assert abs(r["rotation_deg"] - 360.0) <= 30.0
    elif path.stem == "dive_twist":  # half a somersault and one twist, head first
        assert abs(r["rotation_deg"] + 180.0) <= 30.0 and r["entry_angle_deg"] <= 30.0
        assert abs(abs(r["twist_deg"]) - 360.0) <= 45.0 and r["flight_momentum_drift"] <= 0.01
    elif path.stem.startswith("dive"):  # 1.5 somersaults: head first into the water
        assert abs(r["rotation_deg"] + 540.0) <= 30.0 and r["entry_angle_deg"] <= 30.0
        assert r["flight_momentum_drift"] <= 0.01
    else:
        assert abs(r["rotation_deg"]) <= 30.0
    if path.stem == "broad_jump":
        assert r["travel_m"] > 0.6


def test_the_maneuver_command_writes_bvh_and_report(tmp_path: Path) -> None:
    src = EXAMPLES[[p.stem for p in EXAMPLES].index("vertical_leap")]
    out = tmp_path / "out"
    assert main(["athletics", "maneuver", str(src), "--out", str(out)]) == 0
    report = json.loads((out / "vertical_leap.json").read_text())
    assert report["landed"] is True and report["achieved_height_m"] > 0.2
    assert read_bvh(out / "vertical_leap.bvh").num_frames > 100


def test_the_somersault_command_reports_rotation_twist_landed_and_fell(tmp_path: Path) -> None:
    out, rep = tmp_path / "s.bvh", tmp_path / "s.json"
    args = ["athletics", "somersault", "--position", "tuck", "--direction", "backward"]
    assert main([*args, "--out", str(out), "--report", str(rep)]) == 0
    report = json.loads(rep.read_text())
    assert {"rotation_deg", "twist_deg", "landed", "fell"} <= set(report)
    assert report["landed"] is True and abs(report["rotation_deg"] + 360) <= 30
    assert abs(report["twist_deg"]) < 30
    assert read_bvh(out).num_frames > 100


def test_somersault_refuses_what_is_not_built(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "s.bvh"
    # a twist is built only as the male back layout with one twist: the tuck (the default
    # position), a half twist and the female body are refused with the reason
    for extra in ([], ["--position", "layout", "--twist", "0.5"],
                  ["--position", "layout", "--body", "female"]):  # fmt: skip
        args = ["athletics", "somersault", "--twist", "1", *extra, "--out", str(out)]
        assert main(args) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("reactmocap: error:") and "twist" in err[0]
        assert "layout" in err[0] and not out.exists()
    with pytest.raises(UnknownKeyError, match="valid positions"):
        somersault("straddle")
    with pytest.raises(UnknownKeyError, match="valid directions"):
        somersault("tuck", "sideways")


def test_the_full_twist_example_is_the_routines_preset() -> None:
    # the example file and `somersault --position layout --twist 1` run the same phases
    path = EXAMPLES[[p.stem for p in EXAMPLES].index("back_somersault_full_twist")]
    ex, built = load_maneuver(path), somersault_maneuver("layout", twist=1.0)
    assert [(p.controller, p.exit, dict(p.params), p.seconds) for p in ex.phases] == [
        (p.controller, p.exit, dict(p.params), p.seconds) for p in built.phases
    ]
    assert (ex.body, ex.seconds) == (built.body, built.seconds)


def test_the_dive_command_enters_head_first_and_a_layout_dive_does_not(tmp_path: Path) -> None:
    out, rep = tmp_path / "d.bvh", tmp_path / "d.json"
    assert (
        main(["athletics", "dive", "--position", "tuck", "--out", str(out), "--report", str(rep)])
        == 0
    )
    report = json.loads(rep.read_text())
    assert {"rotation_deg", "twist_deg", "landed", "fell", "entry_angle_deg"} <= set(report)
    assert report["landed"] is True and report["fell"] is False
    assert abs(report["rotation_deg"] + 540.0) <= 30.0
    # the report tells the truth: a layout has too little rotation for 1.5 somersaults
    layout = dive("layout").report
    assert layout["landed"] is False and layout["fell"] is True and layout["entry_angle_deg"] > 30


def test_a_dive_with_one_twist_stops_it_within_45_degrees_and_keeps_its_momentum() -> None:
    # thesis 5.2: the arm throw tilts the body and it twists; undoing the throw when the
    # predicted twist reaches the goal stops it; the air exerts no torque on the body
    report = dive(twist=1.0).report
    assert report["position"] == "layout" and report["twist_turns"] == 1.0
    assert abs(abs(report["twist_deg"]) - 360.0) <= 45.0
    assert report["twist_stopped"] is True and report["twist_undone_s"] < report["entry_s"]
    assert report["flight_momentum_drift"] < 0.01
    assert report["landed"] is True and report["entry_angle_deg"] <= 30.0


def test_a_dive_twist_outside_what_is_built_names_the_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(ConfigError, match=r"one of \[0.5, 1.0\] turns, got 2"):
        dive(twist=2.0)
    with pytest.raises(ConfigError, match="one of"):
        dive(twist=-1.0)
    with pytest.raises(ConfigError, match="layout back dive"):
        dive("pike", twist=1.0)
    out = tmp_path / "d.bvh"
    assert main(["athletics", "dive", "--twist", "1.5", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "0.5, 1.0" in err[0]
    assert not out.exists()


def test_the_dive_command_twists_half_a_turn(tmp_path: Path) -> None:
    out, rep = tmp_path / "d.bvh", tmp_path / "d.json"
    assert (
        main(["athletics", "dive", "--twist", "0.5", "--out", str(out), "--report", str(rep)]) == 0
    )
    report = json.loads(rep.read_text())
    assert report["twist_turns"] == 0.5 and report["turns"] == 0.5
    assert abs(abs(report["twist_deg"]) - 180.0) <= 45.0
    assert abs(report["twist_error_deg"]) <= 45.0
    assert read_bvh(out).num_frames > 100


def test_capture_region_runs_perturbed_starts_and_says_where_they_succeed() -> None:
    m = load_maneuver(EXAMPLES[[p.stem for p in EXAMPLES].index("vertical_leap")])
    small = {"joint_sd": 0.005, "pitch_sd": 0.003, "velocity_sd": 0.005, "spin_sd": 0.01}
    r = capture_region(m, starts=2, seed=1, **small)
    assert r["starts"] == 2 and len(r["runs"]) == 2
    assert r["landed"] == 2 and r["success_rate"] == 1.0
    assert {"joint_rms_deg", "speed_mps"} <= set(r["region"])
    # the starts really were perturbed, differently, by the stated sizes
    a, b = r["runs"]
    assert a["joint_rms_deg"] != b["joint_rms_deg"] and 0.05 < a["joint_rms_deg"] < 1.0


def test_a_perturbed_back_somersault_stands_up_without_leaving_the_floor() -> None:
    """Starts 1 and 6 of the capture region at a tenth (seed 0): with the balance leveling the
    legs on the ankles' own heights, a foot that lifted in the stand-up shortened its leg and
    the other leg pushed the body off the floor (pelvis 1.04-1.10 m, standing 0.92) and it
    fell; leveled on the floor's height, neither leaves the floor nor falls."""
    rng = np.random.default_rng(0)
    tenth = {"joint_sd": math.radians(0.3), "pitch_sd": math.radians(0.2),
             "velocity_sd": 0.005, "spin_sd": 0.01}  # fmt: skip
    starts = [Perturbation.sample(rng, **tenth) for _ in range(7)]
    for i in (1, 6):
        r = run_maneuver(somersault_maneuver(), perturbation=starts[i], fps=10.0)
        pelvis, t = r.log["pelvis"], r.log["t"]
        assert pelvis[t > r.report["touchdown_s"]].max() < pelvis[0] + 0.03
        assert not r.report["fell"]
        if i == 1:
            assert r.report["landed"] and abs(r.report["rotation_deg"] + 360.0) <= 30.0
