"""Sweep files: expansion, stable ids, subsampling and clear errors for bad files."""

from __future__ import annotations

from pathlib import Path

import pytest

from reactmocap.batch import AXES, get_runner, load_sweep, parse_sweep, point_id
from reactmocap.cli import main
from reactmocap.errors import ConfigError, UnknownKeyError

from .conftest import EXAMPLES, FRONT_KICK


def test_facing_example_expands_to_36_directions() -> None:
    sweep = load_sweep(EXAMPLES / "sweep_facing.toml")
    points = sweep.points()
    assert [p.params["facing_deg"] for p in points] == [float(a) for a in range(0, 360, 10)]
    assert len({p.id for p in points}) == 36
    assert all(p.scenario.recipient.facing_deg == p.params["facing_deg"] for p in points)
    assert points[0].scenario.attacker is not None and points[0].scenario.library.is_dir()


def test_grid_is_the_cartesian_product_and_ids_are_stable(write_sweep) -> None:  # type: ignore[no-untyped-def]
    p = write_sweep(
        'facing_deg = [0, 90.0]\nattacker_clip = ["front_kick", "side_kick"]\n'
        "reaction_delay = [0.1, 0.2]\nseed = [1, 2]"
    )
    points = load_sweep(p).points()
    assert len(points) == 16
    combos = {
        (
            q.params["facing_deg"],
            q.params["attacker_clip"],
            q.params["reaction_delay"],
            q.params["seed"],
        )
        for q in points
    }
    assert len(combos) == 16
    q = next(
        q
        for q in points
        if q.params["attacker_clip"] == "side_kick" and q.params["reaction_delay"] == 0.2
    )
    assert q.scenario.attacker is not None and q.scenario.attacker.clip == "side_kick"
    assert q.scenario.response.reaction_delay == 0.2
    # the id depends on parameter values only: 0 and 0.0 agree, key order does not matter
    assert point_id({"facing_deg": 0.0, "seed": 1}) == point_id({"seed": 1, "facing_deg": 0.0})
    again = load_sweep(p).points()
    assert [a.id for a in again] == [b.id for b in points]


def test_subsample_is_deterministic(write_sweep) -> None:  # type: ignore[no-untyped-def]
    axes = "facing_deg = { start = 0, stop = 350, step = 10 }"
    a = load_sweep(write_sweep(axes, extra="[sweep]\nsubsample = 5\nseed = 3")).points()
    b = load_sweep(write_sweep(axes, extra="[sweep]\nsubsample = 5\nseed = 3")).points()
    c = load_sweep(write_sweep(axes, extra="[sweep]\nsubsample = 0.25\nseed = 4")).points()
    assert [p.id for p in a] == [p.id for p in b] and len(a) == 5
    assert len(c) == 9
    assert [p.index for p in a] == sorted(p.index for p in a)


def test_force_axes_scale_and_turn_an_explicit_impact(tmp_path: Path) -> None:
    data = {
        "base": {
            "library": "data/synthetic_clips",
            "recipient": {"clip": "guard"},
            "impact": {"body": "chest", "force": [-300.0, 0.0, 40.0]},
        },
        "axes": {"force_N": [100, 500], "force_dir_deg": [90], "impact_body": ["chest", "head"]},
    }
    points = parse_sweep(data, base_dir=EXAMPLES.parent).points()
    assert len(points) == 4
    for p in points:
        assert p.scenario.impact is not None
        fx, fy, fz = p.scenario.impact.force
        assert abs(fx) < 1e-9 and fy > 0  # turned to +Y
        assert (fx**2 + fy**2 + fz**2) ** 0.5 == pytest.approx(p.params["force_N"])
        assert p.scenario.impact.body == p.params["impact_body"]


@pytest.mark.parametrize(
    ("axes", "exc", "needles"),
    [
        ("facing = [0, 90]", UnknownKeyError, ["unknown axis 'facing'", "facing_deg", "seed"]),
        ("facing_deg = []", ConfigError, ["[axes].facing_deg", "empty"]),
        ('facing_deg = [0, "north"]', ConfigError, ["[axes].facing_deg[1]", "'north'", "deg"]),
        ("facing_deg = { start = 0, stop = 350 }", ConfigError, ["facing_deg", "step"]),
        ("facing_deg = [0, 0]", ConfigError, ["facing_deg", "repeats"]),
        ("reaction_delay = [-0.1]", ConfigError, ["reaction_delay", ">= 0"]),
        ("force_N = [100]", ConfigError, ["force_N", "[base.impact]"]),
        ("seed = [1.5]", ConfigError, ["[axes].seed[0]", "integer"]),
    ],
)
def test_bad_sweep_files_get_clear_errors(write_sweep, axes, exc, needles) -> None:  # type: ignore[no-untyped-def]
    path = write_sweep(axes)
    with pytest.raises(exc) as info:
        load_sweep(path).points()
    msg = str(info.value)
    assert str(path) in msg
    for n in needles:
        assert n in msg, msg


def test_bad_top_level_and_base(tmp_path: Path, write_sweep) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError, match=r"\[sweep\].*unknown key\(s\) \['workers'\]"):
        load_sweep(write_sweep("facing_deg = [0]", extra="[sweep]\nworkers = 2"))
    with pytest.raises(ConfigError, match="not found"):
        load_sweep(write_sweep("facing_deg = [0]", base="nope.toml"))
    bad = tmp_path / "bad.toml"
    bad.write_text('[base]\nlibrary = "x"\n')
    with pytest.raises(ConfigError, match=r"\[base\]: \[recipient\]: missing"):
        load_sweep(bad)
    with pytest.raises(ConfigError, match="looks like a scenario file"):
        load_sweep(FRONT_KICK)


def test_unknown_runner_lists_runners() -> None:
    with pytest.raises(
        UnknownKeyError, match=r"unknown runner 'dask'.*\['local', 'ray', 'serial'\]"
    ):
        get_runner("dask")
    assert set(AXES) >= {
        "facing_deg",
        "force_N",
        "force_dir_deg",
        "impact_body",
        "attacker_clip",
        "recipient_start",
        "reaction_delay",
        "seed",
    }


def test_cli_reports_bad_sweep_without_traceback(write_sweep, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = write_sweep('facing_deg = [0, "north"]')
    assert main(["batch", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "facing_deg[1]" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()  # nothing is created for an invalid sweep
    small = str(EXAMPLES / "sweep_small.toml")
    assert main(["batch", small, "--out", str(tmp_path / "o"), "--runner", "x"]) == 2
    assert "valid runners" in capsys.readouterr().err
