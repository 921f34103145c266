"""Clear errors for bad running inputs, and the courses' geometry (no simulation)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from reactmocap.athletics.paths import (
    Circle,
    EntryPath,
    Facing,
    Polyline,
    Straight,
    figure_eight,
    loop_with_entry,
    parse_course,
)
from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import SPEED_RANGE, RunParams, check_speed
from reactmocap.cli import main
from reactmocap.errors import ConfigError, ReactMocapError
from tests.conftest import SYNTHETIC


@pytest.mark.parametrize("speed", [2.4, 5.1, -1.0, float("nan"), 0.0])
def test_out_of_range_speed_names_the_range(speed: float) -> None:
    with pytest.raises(ConfigError, match=r"supported range 2\.5-5 m/s"):
        check_speed(speed)
    with pytest.raises(ReactMocapError, match="2.5-5 m/s"):
        run_course(speed, seconds=1.0)


def test_speed_range_is_the_papers() -> None:
    assert SPEED_RANGE == (2.5, 5.0)
    assert check_speed(2.5) == 2.5 and check_speed(5) == 5.0


def test_cli_out_of_range_speed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "x.bvh"
    assert main(["athletics", "run", "--speed", "7", "--out", str(out)]) == 2
    assert "2.5-5 m/s" in capsys.readouterr().err
    assert not out.exists()


def test_run_params_are_checked() -> None:
    with pytest.raises(ConfigError, match="touchdown_leg"):
        RunParams(touchdown_leg=1.5)
    with pytest.raises(ConfigError, match="a number or three"):
        RunParams(thrust=(1.0, 2.0))  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="finite"):
        RunParams(pitch=float("nan"))
    with pytest.raises(ConfigError, match="stance_blend"):
        RunParams(stance_blend=(0.0, 1.0, 1.0))
    with pytest.raises(ConfigError, match="path_integral"):
        RunParams(path_integral=-1.0)
    with pytest.raises(ConfigError, match="thrust_drop"):
        RunParams(thrust_drop=0.0)
    p = RunParams(thrust=(1.0, 2.0, 4.0))
    assert p.at(2.5)["thrust"] == 1.0 and p.at(3.0)["thrust"] == pytest.approx(1.5)
    assert p.at(4.25)["thrust"] == pytest.approx(3.0) and p.at(9.0)["thrust"] == 4.0


def test_unknown_path_lists_the_valid_ones() -> None:
    with pytest.raises(ConfigError, match="'line', 'circle:R', 'eight:R' or FILE.csv"):
        parse_course("spiral")
    with pytest.raises(ConfigError, match="radius"):
        parse_course("circle:wide")
    with pytest.raises(ConfigError, match="does not exist"):
        parse_course("nowhere.csv")


def test_csv_path(tmp_path: Path) -> None:
    f = tmp_path / "p.csv"
    f.write_text("x,y\n0,0\n10,0\n10,10\n")
    c = parse_course(str(f))
    assert isinstance(c, Polyline) and c.total == pytest.approx(20.0)
    f.write_text("x,y\n0,0\nten,0\n")
    with pytest.raises(ConfigError, match="p.csv:3"):
        parse_course(str(f))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0,0\n", "p.csv: a path needs at least 2 'x,y' points, got 1"),
        ("0,0\nnan,1\n", "p.csv:2: expected finite x,y within"),
        ("0,0\n1,nan\n", "p.csv:2: expected finite x,y within"),
        ("0,0\n1e300,0\n", "p.csv:2: expected finite x,y within"),
        ("0,0,0\n5,0,1\n", "p.csv:2: expected 'x,y' in metres"),
    ],
)
def test_a_bad_csv_path_names_the_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    # before: one point or a NaN gave "got (1, 2)" without the file, 1e300 ran (overflowing),
    # and a third column was silently dropped
    f = tmp_path / "p.csv"
    f.write_text(text)
    with pytest.raises(ConfigError) as err:
        parse_course(str(f))
    assert str(err.value).startswith(str(tmp_path / message))


def test_circle_steering() -> None:
    c = Circle((0.0, 10.0), 10.0)  # anticlockwise, through the origin heading +X
    heading, curvature, cross = c.steer(np.array([0.0, 0.0]), 0.0)
    assert 0 < heading < 0.5 and curvature == pytest.approx(0.1) and cross == pytest.approx(0.0)
    _, _, inside = c.steer(np.array([0.0, 1.0]), 0.0)
    assert inside == pytest.approx(1.0)  # left of an anticlockwise path: inside


def test_polyline_follows_in_order() -> None:
    eight = figure_eight(5.0)
    heading, _, cross = eight.steer(np.array([0.0, 0.0]), 0.0)
    assert abs(heading) < 0.7 and abs(cross) < 1e-6
    line = Straight(0.5, (1.0, 1.0))
    heading, curvature, cross = line.steer(np.array([1.0, 1.0]), 0.0)
    assert heading == pytest.approx(0.5) and curvature == 0.0 and cross == pytest.approx(0.0)


def test_figure_eight_curvature_is_its_loops() -> None:
    """Along the eight the curvature read by the steering is +1/R on the first loop and -1/R
    on the second, to 2%, between the segments' corners as well as at them (a lean read
    from the segments' own directions jumped by 10-20%)."""
    eight = figure_eight(10.0)
    loop = 2 * math.pi * 10.0
    got = []
    for s in np.arange(2.0, 2 * loop - 5.0, 0.13):
        pos = eight.point_at(float(s))
        _, curvature, _ = eight.steer(pos, 0.0)
        if 2.0 < s < loop - 5.0:
            got.append(curvature)
        elif loop + 2.0 < s:
            got.append(-curvature)
    assert len(got) > 500
    assert np.allclose(got, 0.1, rtol=0.02), (min(got), max(got))


def _curvature(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Headings of a polyline's segments and its curvature at the inner points (the turn
    between neighbouring segments over their mean length)."""
    seg = np.diff(points, axis=0)
    heading = np.unwrap(np.arctan2(seg[:, 1], seg[:, 0]))
    length = np.hypot(seg[:, 0], seg[:, 1])
    return heading, np.diff(heading) / (0.5 * (length[1:] + length[:-1]))


@pytest.mark.parametrize(("kind", "entry"), [("circle", 5.0), ("circle", 20.0), ("eight", 10.0)])
def test_an_entry_ramps_the_curvature_onto_the_loop_tangent_to_it(kind: str, entry: float) -> None:
    """The clothoid's curvature grows linearly from 0 to 1/R over the entry and goes on at
    1/R on the loop: no jump at the join, the heading there continuous, the loop a circle of
    R through the join."""
    r = 10.0
    path = parse_course(f"{kind}:{r:g}+entry:{entry:g}")
    assert isinstance(path, EntryPath) and path.entry == entry
    heading, curv = _curvature(path.points)
    s = path.cum[1:-1]  # the inner points' arc lengths
    ramp, loop = s < entry - 0.1, (s > entry + 0.1) & (s < entry + 0.9 * 2 * math.pi * r)
    assert np.allclose(curv[ramp], s[ramp] / (entry * r), atol=2e-3)
    assert np.allclose(curv[loop], 1.0 / r, atol=2e-3)
    join = int(np.abs(path.cum - entry).argmin())  # the chords fall short of the arc by < 1e-3 m
    assert path.cum[join] == pytest.approx(entry, abs=1e-3)
    near = slice(join - 3, join + 3)
    assert np.abs(np.diff(curv[near])).max() < 0.02  # the curvature continuous
    assert heading[join] - heading[join - 1] < 0.05  # one corner's turn: tangent
    assert heading[join - 1] == pytest.approx(entry / (2 * r), abs=0.02)  # s^2 / (2 L R)
    # the first lap after the join is a circle of R
    lap = path.points[join : join + 100]
    turn = entry / (2 * r)
    centre = path.points[join] + r * np.array([-math.sin(turn), math.cos(turn)])
    assert np.allclose(np.hypot(*(lap - centre).T), r, atol=1e-9)
    # the steering's curvature (over its look-ahead) ramps too
    assert path.steer(path.points[0], 0.0)[1] < 0.5 / r
    path.reset()
    assert path.entered_at is None


def test_no_entry_is_the_loop_as_before() -> None:
    for spec in ("circle:10", "circle:10+entry:0"):
        c = parse_course(spec, (1.0, 2.0))
        assert isinstance(c, Circle) and np.array_equal(c.centre, [1.0, 12.0])
    e = parse_course("eight:10", entry=0.0)
    assert isinstance(e, Polyline) and np.array_equal(e.points, figure_eight(10.0).points)


@pytest.mark.parametrize(
    ("spec", "entry", "message"),
    [
        ("circle:10", -1.0, r"entry must be within \[0, 100\] m"),
        ("circle:10", math.nan, "entry must be within"),
        ("eight:10", 101.0, "entry must be within"),
        ("circle:10+entry:far", 0.0, "entry:L needs a length"),
        ("circle:10+entry:inf", 0.0, "entry must be within"),
        ("line+entry:5", 0.0, "entry is for 'circle:R' or 'eight:R'"),
        ("p.csv", 5.0, "entry is for 'circle:R' or 'eight:R'"),
    ],
)
def test_a_bad_entry_is_refused(spec: str, entry: float, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_course(spec, entry=entry)


def test_loop_with_entry_checks_its_inputs() -> None:
    with pytest.raises(ConfigError, match=r"entry must be within \(0, 100\] m"):
        loop_with_entry("circle", 10.0, 0.0)
    with pytest.raises(ConfigError, match="radius"):
        loop_with_entry("eight", -1.0, 5.0)
    with pytest.raises(ConfigError, match="'circle' or 'eight'"):
        loop_with_entry("spiral", 10.0, 5.0)


@pytest.mark.parametrize(("r", "length"), [(10.0, 5.0), (10.0, 20.0), (12.5, 10.0), (20.0, 40.0)])
def test_a_reversal_joins_the_eights_loops_by_a_clothoid_pair(r: float, length: float) -> None:
    """``eight:R+turn:L``: the lap closes on itself tangent to its start, its curvature is
    continuous everywhere (no corner), +-1/R on the arcs and
    ramped linearly +1/R -> -1/R over L at each reversal; the runner starts on the first
    circle, heading +X, as on the eight without."""
    eight = parse_course(f"eight:{r:g}+turn:{length:g}")
    assert isinstance(eight, Polyline) and eight.closed
    pts = eight.points  # closed: the last point is the first
    assert np.array_equal(pts[0], [0.0, 0.0]) and np.array_equal(pts[-1], pts[0])
    # the headings and curvature round the lap and across its closing point
    heading, curv = _curvature(np.vstack([pts, pts[1:3]]))
    assert heading[0] == pytest.approx(0.0, abs=2 * math.pi / 120)  # along +X
    # tangent: no corner beyond the arc's own steps (the arc is the eight's first circle's
    # points, its last step up to 1.5 of them)
    assert np.abs(np.diff(heading)).max() < 1.3 * 2 * math.pi / 120
    assert np.abs(curv).max() < 1.0 / r + 1e-3
    # continuous: no step beyond the ramp's over its 0.25 m points (the chord estimate's
    # 4/3 of it where they meet the arc's), where the eight without jumps by 2/R
    assert np.abs(np.diff(curv)).max() < 1.5 * 0.25 * 2 / (r * length)
    # the arcs are +-1/R, the two reversals ramps of slope -+2 / (R L) over L
    s, k = eight.cum[1:-1], curv[: len(pts) - 2]  # the inner points' arc lengths
    arc = np.abs(k) > (1 - 1e-3) / r
    assert np.allclose(np.abs(k[arc]), 1.0 / r, rtol=1e-3)
    for sign, part in ((-1.0, s < eight.total / 2), (1.0, s > eight.total / 2)):
        assert np.ptp(s[~arc & part]) == pytest.approx(length, abs=0.6)
        sel = (np.abs(k) < 0.9 / r) & part
        assert np.polyfit(s[sel], k[sel], 1)[0] == pytest.approx(sign * 2 / (r * length), rel=0.02)
    # with an entry the same lap follows the entry's ramp
    entered = parse_course(f"eight:{r:g}+entry:10+turn:{length:g}")
    assert isinstance(entered, EntryPath)
    join = int(np.abs(entered.cum - 10.0).argmin())
    lap = entered.points[join : join + len(pts) - 1] - entered.points[join]
    turn = 10.0 / (2 * r)
    c, s_ = math.cos(-turn), math.sin(-turn)
    assert np.allclose(lap @ np.array([[c, -s_], [s_, c]]).T, pts[:-1], atol=1e-9)
    _, ecurv = _curvature(entered.points[: join + 2 * len(pts)])
    assert np.abs(np.diff(ecurv)).max() < 0.02


def test_no_reversal_is_the_eight_as_before() -> None:
    for spec, kw in (("eight:10+turn:0", {}), ("eight:10", {"reversal": 0.0})):
        e = parse_course(spec, **kw)
        assert isinstance(e, Polyline) and np.array_equal(e.points, figure_eight(10.0).points)
    a, b = parse_course("eight:10+entry:20"), parse_course("eight:10+entry:20+turn:0")
    assert isinstance(a, EntryPath) and isinstance(b, EntryPath)
    assert np.array_equal(a.points, b.points)


@pytest.mark.parametrize(
    ("spec", "reversal", "message"),
    [
        ("eight:10", -1.0, r"reversal must be within \[0, 2R\] m"),
        ("eight:10", math.nan, "reversal must be within"),
        ("eight:10+turn:inf", 0.0, "reversal must be within"),
        ("eight:10+turn:20.5", 0.0, r"reversal must be within \(0, 20\] m"),
        ("eight:10+turn:far", 0.0, "turn:L needs a length"),
        ("circle:10+turn:5", 0.0, "reversal is for 'eight:R'"),
        ("circle:10+entry:5", 5.0, "reversal is for 'eight:R'"),
        ("line", 5.0, "reversal is for 'eight:R'"),
        ("p.csv", 5.0, "reversal is for 'eight:R'"),
    ],
)
def test_a_bad_reversal_is_refused(spec: str, reversal: float, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        parse_course(spec, reversal=reversal)


def test_the_eights_builders_check_the_reversal() -> None:
    with pytest.raises(ConfigError, match=r"reversal must be within \(0, 50\] m"):
        figure_eight(25.0, reversal=-2.0)
    with pytest.raises(ConfigError, match="reversal is for 'eight' loops"):
        loop_with_entry("circle", 10.0, 5.0, reversal=5.0)
    with pytest.raises(ConfigError, match=r"reversal must be within \(0, 20\] m"):
        loop_with_entry("eight", 10.0, 5.0, reversal=30.0)


def test_facing_turns_at_a_limited_rate() -> None:
    f = Facing([(0.0, 0.0), (1.0, math.pi / 2)], rate=0.5)
    assert f.steer(np.zeros(2), 0.5)[0] == 0.0
    h1, curv, cross = f.steer(np.zeros(2), 1.5)
    assert h1 == pytest.approx(0.5) and curv == pytest.approx(0.5) and math.isnan(cross)


def test_path_progress_counts_the_laps_of_a_closed_path() -> None:
    """Following the eight's points in order, the progress grows by the path's length each
    lap (the closing point does not reset it)."""
    eight = figure_eight(5.0)
    pts = eight.points[::3]
    for p in np.vstack([pts, pts, pts[:10]]):
        eight.steer(p, 0.0)
    assert eight.progress == pytest.approx(2 * eight.total + float(eight.cum[27]), abs=0.5)
    eight.reset()
    assert eight.progress == 0.0


@pytest.mark.parametrize(
    "argv",
    [
        ["athletics", "run", "--speed", "3", "--out", "{dir}"],
        ["athletics", "leap", "--height", "0.3", "--plot", "{dir}/"],
        ["track", str(SYNTHETIC / "guard.bvh"), "--report", "{dir}"],
    ],
)
def test_an_output_file_option_given_a_folder_is_refused_before_running(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: the run simulated for its whole length and then crashed in os.replace
    args = [a.replace("{dir}", str(tmp_path)) for a in argv]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "is a folder" in err and str(tmp_path) in err
    assert list(tmp_path.iterdir()) == []
