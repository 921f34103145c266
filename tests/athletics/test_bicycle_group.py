"""Group riding (eq. 13), courses and the CLI commands."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from reactmocap.athletics.bicycle import Placement
from reactmocap.athletics.course import Route, load_course, parse_course
from reactmocap.athletics.cycling import group_ride
from reactmocap.athletics.group import GroupGains, GroupRiding
from reactmocap.cli import main
from reactmocap.errors import ConfigError

COURSE = Path(__file__).resolve().parents[2] / "examples/athletics/courses/corner_on_a_hill.toml"
#: avoidance switched off: no separation, no look-ahead for close passes
BLIND = GroupGains(horizon=1e-6, separation=1e-6)


def _head_on(gains: GroupGains | None) -> dict:
    """Two riders 36 m apart on the same line, riding at each other at 5 m/s."""
    course = parse_course({"group": {"speed": 5.0, "route": [[0.0, 0.0], [100.0, 0.0]]},
                           "seconds": 6.0})  # fmt: skip
    routes = [Route(np.array([[0.0, 0.0], [100.0, 0.0]])),
              Route(np.array([[36.0, 0.1], [-64.0, 0.1]]))]  # fmt: skip
    starts = [Placement(0.0, 0.0, 0.0, 5.0), Placement(36.0, 0.1, math.pi, 5.0, crank=2.0)]
    return group_ride(course, 2, placements=starts, routes=routes, gains=gains).report


def test_two_riders_on_a_collision_course_avoid_each_other() -> None:
    rep = _head_on(None)
    assert rep["collisions"] == 0, rep["collision_log"]
    assert rep["fell"] == 0
    assert rep["min_separation_m"] >= 0.5
    # the same riders without the avoidance rules do collide: the test can fail
    blind = _head_on(BLIND)
    assert blind["collisions"] > 0 or blind["min_separation_m"] < 0.5


def test_round_a_corner_the_outer_rider_keeps_its_lane() -> None:
    """The global velocity follows the rider's own lane (the route offset by the rider's
    distance from it) on the outside of a turn: of a pair side by side before a left corner,
    the outer rider rides on to its own corner while the inner one turns along the centre
    line's chord; on the straights neither is pulled across. With ``lane=0`` both aim along
    the chord, the same direction: the pair slides across the corner instead of turning (the
    old behaviour); with ``inner_lane=1`` the inner rider turns on its own lane, sharper."""
    c = load_course(COURSE)  # left corner at (90, 0)
    pos = np.array([[84.0, 1.5], [84.0, -1.5], [40.0, 2.5], [90.0 + 2.5, 60.0]])

    def angles(**gains: float) -> np.ndarray:
        g = GroupRiding([None] * 4, c.route, c.speed, gains=GroupGains(**gains),  # type: ignore[list-item]
                        spacing=c.spacing, lookahead=c.lookahead)  # fmt: skip
        v = g.global_velocity(pos)
        assert np.linalg.norm(v, axis=1) == pytest.approx(c.speed)
        return np.degrees(np.arctan2(v[:, 1], v[:, 0]))

    inner, outer, straight, after = angles()
    chord = math.degrees(math.atan2(2.0, 6.0))  # (84, 0) to the route point 8 m on, (90, 2)
    assert inner == pytest.approx(chord, abs=0.1)
    assert outer == pytest.approx(math.degrees(math.atan2(0.5, 7.5)), abs=0.1)  # to (91.5, -1)
    assert straight == pytest.approx(0.0) and after == pytest.approx(90.0)
    old = angles(lane=0.0)
    assert old[:2] == pytest.approx([chord, chord], abs=0.1)
    own = angles(inner_lane=1.0)  # to (88.5, 5) on its own lane
    assert own[0] == pytest.approx(math.degrees(math.atan2(3.5, 4.5)), abs=0.1)
    with pytest.raises(ConfigError):
        GroupGains(lane=2.0)


def test_course_file_with_an_unknown_key_gets_a_clear_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(COURSE.read_text().replace("spacing = ", "spaceing = "))
    with pytest.raises(ConfigError) as err:
        load_course(bad)
    msg = str(err.value)
    assert str(bad) in msg and "spaceing" in msg and "[group]" in msg and "'spacing'" in msg
    (tmp_path / "t.toml").write_text('[group]\nspeed = "fast"\nroute = [[0, 0], [1, 0]]\n')
    with pytest.raises(ConfigError, match=r"\[group\].speed must be a number"):
        load_course(tmp_path / "t.toml")
    (tmp_path / "v.toml").write_text("[group]\nspeed = 40\nroute = [[0, 0], [1, 0]]\n")
    with pytest.raises(ConfigError, match="speed"):
        load_course(tmp_path / "v.toml")
    with pytest.raises(ConfigError, match="does not exist"):
        load_course(tmp_path / "missing.toml")


def test_shipped_course_is_a_corner_on_a_hill_with_five_obstacles() -> None:
    c = load_course(COURSE)
    assert len(c.obstacles) == 5
    assert c.terrain.grade > 0
    d = np.diff(c.route.points, axis=0)
    turn = np.degrees(np.arctan2(d[1, 1], d[1, 0]) - np.arctan2(d[0, 1], d[0, 0]))
    assert abs(turn) == pytest.approx(90.0)


def test_cli_bicycle_smoke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ride"
    code = main(["athletics", "bicycle", "--speed", "4", "--seconds", "1.5", "--heading", "20",
                 "--out", str(out), "--report", str(tmp_path / "r.json"), "--plot",
                 str(tmp_path / "p.png"), "--video", str(tmp_path / "v.gif")])  # fmt: skip
    assert code == 0
    assert (out / "rider0.bvh").is_file() and (out / "bicycle0.bvh").is_file()
    assert (tmp_path / "p.png").stat().st_size > 1000
    rep = json.loads((tmp_path / "r.json").read_text())
    for key in (
        "mean_speed_m_s",
        "speed_error_m_s",
        "heading_error_deg",
        "fell",
        "realtime_factor",
    ):
        assert key in rep
    assert Path(rep["outputs"]["video"]).is_file()
    assert "bicycle (male)" in capsys.readouterr().out
    assert main(["athletics", "bicycle", "--speed", "40"]) == 2
    assert "speed must be within" in capsys.readouterr().err


def test_cli_group_smoke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["athletics", "group", "--riders", "2", "--course", str(COURSE), "--seconds", "1",
                 "--out", str(tmp_path / "g"), "--report", str(tmp_path / "g.json"),
                 "--plot", str(tmp_path / "g.png")])  # fmt: skip
    assert code == 0
    for k in range(2):
        assert (tmp_path / "g" / f"rider{k}.bvh").is_file()
        assert (tmp_path / "g" / f"bicycle{k}.bvh").is_file()
    rep = json.loads((tmp_path / "g.json").read_text())
    for key in ("collisions", "min_separation_m", "fell", "finish_times_s"):
        assert key in rep
    assert rep["collisions"] == 0 and rep["fell"] == 0
    assert "group of 2" in capsys.readouterr().out


def test_cli_reports_a_bad_course_without_a_traceback(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    bad = tmp_path / "bad.toml"
    bad.write_text("colour = 1\n[group]\nspeed = 5\nroute = [[0, 0], [1, 0]]\n")
    code = main(["athletics", "group", "--riders", "2", "--course", str(bad)])
    assert code != 0
    err = capsys.readouterr().err
    assert "unknown key(s) ['colour']" in err and "Traceback" not in err
