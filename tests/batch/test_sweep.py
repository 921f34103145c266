"""Sweep files: expansion, stable ids, subsampling and clear errors for bad files."""

from __future__ import annotations

import json
from dataclasses import dataclass, fields, replace
from dataclasses import field as dc_field
from pathlib import Path
from typing import Literal

import pytest

from reactmocap.batch import (
    ALIASES,
    AXES,
    TABLES,
    describe_axes,
    get_runner,
    load_sweep,
    parse_sweep,
    plot_axes,
    point_id,
    run_batch,
)
from reactmocap.batch.sweep import _field_axes
from reactmocap.cli import main
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.response.scenario import ResponseConfig

from . import fake_tasks
from .conftest import EXAMPLES, FRONT_KICK, REPO


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


# --- axes derived from the scenario's fields ---------------------------------------------------


def test_every_scenario_field_is_an_axis() -> None:
    for table, cls in TABLES.items():
        for f in fields(cls):
            assert f"{table}.{f.name}" in AXES, f"{table}.{f.name}"
    assert {ALIASES[a] for a in ALIASES} <= set(AXES)
    text = describe_axes()
    assert "response.kp" in text and "alias facing_deg" in text and "replicate label" in text


def test_a_field_added_later_is_picked_up() -> None:
    # as a branch adding controller names to ResponseConfig would
    @dataclass(frozen=True)
    class Grown(ResponseConfig):
        sim2_controller: str = "pd"
        mode: Literal["a", "b"] = "a"
        gains: tuple[float, float] = (1.0, 2.0)
        limit: float | None = None
        steps: int = 3
        extra: dict[str, float] = dc_field(default_factory=dict)

    kinds = {a.name: (a.kind, a.length) for a in _field_axes("response", Grown)}
    assert kinds["response.sim2_controller"] == ("str", 0)
    assert kinds["response.mode"] == ("str", 0)
    assert kinds["response.gains"] == ("vector", 2)
    assert kinds["response.limit"] == ("float", 0)
    assert kinds["response.steps"] == ("int", 0)
    assert kinds["response.extra"] == ("value", 0)  # passed through for parse_scenario
    assert kinds["response.foot_lock"] == ("bool", 0) and kinds["response.kp"] == ("float", 0)


def test_kp_and_friction_sweep_expand_and_validate(write_sweep) -> None:  # type: ignore[no-untyped-def]
    p = write_sweep(
        '"response.kp" = [2000, 4000]\n'
        '"response.friction_sim2" = { start = 0.3, stop = 0.7, step = 0.2 }'
    )
    points = load_sweep(p).points()
    assert len(points) == 6
    assert {(q.scenario.response.kp, q.scenario.response.friction_sim2) for q in points} == {
        (kp, fr) for kp in (2000.0, 4000.0) for fr in (0.3, 0.5, 0.7)
    }
    assert all(set(q.params) == {"response.kp", "response.friction_sim2"} for q in points)
    # an unquoted dotted key is a nested TOML table: it means the same axis, same ids
    dotted = write_sweep(
        "response.kp = [2000, 4000]\n"
        "response.friction_sim2 = { start = 0.3, stop = 0.7, step = 0.2 }",
        name="dotted",
    )
    assert [q.id for q in load_sweep(dotted).points()] == [q.id for q in points]


@pytest.mark.parametrize(
    ("axes", "needles"),
    [
        ('"response.kp" = [4000, -1]', ["sweep point", "[response].kp", "> 0", "-1"]),
        ('"response.friction_sim2" = [-0.5]', ["sweep point", "[response].friction_sim2", ">= 0"]),
        ('"response.kp" = ["stiff"]', ["[axes].response.kp[0]", "expected a number", "'stiff'"]),
        ('"response.top_k" = [2.5]', ["[axes].response.top_k[0]", "integer"]),
        ('"response.top_k" = [0]', ["sweep point", "[response].top_k", "positive integer"]),
        ('"response.foot_lock" = [1]', ["[axes].response.foot_lock[0]", "true or false"]),
        ('"response.foot_lock" = { start = 0, stop = 1, step = 1 }', ["foot_lock", "numeric"]),
        ('"response.sim1_mode" = ["flying"]', ["[response].sim1_mode", "passive", "'flying'"]),
        ('"attacker.position" = [[0.9]]', ["[axes].attacker.position[0]", "list of 2 numbers"]),
        ('"attacker.position" = [[0.9, "x"]]', ["[axes].attacker.position[0][1]", "'x'"]),
        ('"impact.duration" = [0.1]', ["impact.duration", "needs an explicit [base.impact]"]),
        (
            'facing_deg = [0]\n"recipient.facing_deg" = [0]',
            ["[axes].recipient.facing_deg", "same field as [axes].facing_deg"],
        ),
    ],
)
def test_field_axes_get_clear_errors(write_sweep, axes, needles) -> None:  # type: ignore[no-untyped-def]
    path = write_sweep(axes)
    with pytest.raises(ConfigError) as info:
        load_sweep(path).points()
    msg = str(info.value)
    assert str(path) in msg
    for n in needles:
        assert n in msg, msg


def test_aliases_keep_the_ids_of_earlier_versions(tmp_path: Path) -> None:
    # ids computed with the code before axes were derived from the scenario's fields: results
    # folders and baselines made then must keep joining
    base = {
        "library": "data/synthetic_clips",
        "recipient": {"clip": "guard"},
        "attacker": {"clip": "front_kick"},
    }
    short = {
        "facing_deg": [90],
        "attacker_clip": ["side_kick"],
        "recipient_start": [0.25],
        "reaction_delay": [0.2],
        "seed": [3],
    }
    full = {ALIASES.get(k, k): v for k, v in short.items()}
    for axes in (short, full):
        (p,) = parse_sweep({"base": base, "axes": axes}, base_dir=REPO).points()
        assert p.id == "0a8c9deee2b4", axes
        assert set(p.params) == set(short)  # the alias is the column, whichever name is used
    impact = {
        "library": "data/synthetic_clips",
        "recipient": {"clip": "guard"},
        "impact": {"force": [-300.0, 0.0, 40.0]},
    }
    axes = {"force_N": [500], "force_dir_deg": [90], "impact_body": ["head"]}
    (p,) = parse_sweep({"base": impact, "axes": axes}, base_dir=REPO).points()
    assert p.id == "fab38ea9b266"
    # and the committed regression baseline's ids
    baseline = json.loads((REPO / "tests" / "baselines" / "sweep_small.json").read_text())
    ids = [q.id for q in load_sweep(EXAMPLES / "sweep_small.toml").points()]
    assert sorted(ids) == sorted(baseline["scenarios"])


def test_unknown_axis_lists_fields_then_aliases(write_sweep) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(UnknownKeyError) as info:
        load_sweep(write_sweep('"response.stiffness" = [1]'))
    msg = str(info.value)
    assert "unknown axis 'response.stiffness'" in msg
    for n in ("response.kp", "response.friction_sim2", "impact.at", "force_N", "seed"):
        assert f"'{n}'" in msg, n
    assert msg.index("'response.total_mass'") < msg.index("'seed'") < msg.index("'facing_deg'")


def test_bool_str_and_vector_fields(write_sweep) -> None:  # type: ignore[no-untyped-def]
    p = write_sweep(
        '"response.foot_lock" = [true, false]\n'
        '"response.sim1_mode" = ["passive", "holding"]\n'
        '"attacker.position" = [[0.9, 0], [1.1, 0.2]]'
    )
    points = load_sweep(p).points()
    assert len(points) == 8
    got = {
        (
            q.scenario.response.foot_lock,
            q.scenario.response.sim1_mode,
            q.scenario.attacker.position if q.scenario.attacker else None,
        )
        for q in points
    }
    assert got == {
        (fl, mode, pos)
        for fl in (True, False)
        for mode in ("passive", "holding")
        for pos in ((0.9, 0.0), (1.1, 0.2))
    }
    assert points[0].params["attacker.position"] == [0.9, 0.0]  # canonical floats: 0 == 0.0
    same = write_sweep(
        '"response.foot_lock" = [true, false]\n'
        '"response.sim1_mode" = ["passive", "holding"]\n'
        '"attacker.position" = [[0.9, 0.0], [1.1, 0.2]]',
        name="same",
    )
    assert [q.id for q in load_sweep(same).points()] == [q.id for q in points]


def test_impact_fields_and_force_axes_combine(tmp_path: Path) -> None:
    data = {
        "base": {
            "library": "data/synthetic_clips",
            "recipient": {"clip": "guard"},
            "impact": {"body": "chest", "force": [-300.0, 0.0, 0.0]},
        },
        # force_N comes first in the file but scales the swept force all the same
        "axes": {
            "force_N": [100],
            "impact.force": [[0.0, 3.0, 4.0]],
            "impact.at": [0.2, 0.4],
            "impact.duration": [0.05],
        },
    }
    points = parse_sweep(data, base_dir=REPO).points()
    assert len(points) == 2
    for q in points:
        assert q.scenario.impact is not None
        assert q.scenario.impact.force == pytest.approx((0.0, 60.0, 80.0))
        assert q.scenario.impact.at == q.params["impact.at"]
        assert q.scenario.impact.duration == 0.05


def test_seed_is_only_a_replicate_label(write_sweep) -> None:  # type: ignore[no-untyped-def]
    points = load_sweep(write_sweep("seed = [1, 2, 3]")).points()
    assert len({q.id for q in points}) == 3
    plain = [replace(q.scenario, name="x") for q in points]
    assert plain[0] == plain[1] == plain[2]  # nothing but the name (which carries the id)
    assert "replicate label" in AXES["seed"].help


def test_plots_draw_bool_and_vector_axes(write_sweep, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("matplotlib")
    sweep = load_sweep(
        write_sweep(
            '"response.foot_lock" = [true, false]\n'
            '"attacker.position" = [[0.9, 0.0], [1.1, 0.2]]\n'
            '"attacker.facing_deg" = [150, 180, 210]'
        )
    )
    out = tmp_path / "out"
    run_batch(sweep, out, runner="serial", task=fake_tasks.fake_report, progress=False)
    names = {p.name for p in plot_axes(out)}
    assert names == {
        "plot_response.foot_lock.png",
        "plot_attacker.position.png",
        "plot_attacker.facing_deg.png",
    }
