"""``regress``: a results folder passes against its own baseline and fails against a tightened
one; versions and per-scenario drift are reported."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from reactmocap.batch import ResultStore, compare, load_baseline, make_baseline
from reactmocap.cli import main
from reactmocap.errors import ConfigError

VERSIONS = {"reactmocap": "0.1.0", "mujoco": "3.2.0"}


def _rows(scale: float = 1.0, clip: str = "guard") -> list[dict[str, Any]]:
    rows = []
    for i in range(10):
        rows.append(
            {
                "id": f"id{i}",
                "facing_deg": 36.0 * i,
                "status": "ok",
                "error": None,
                "matched_clip": clip,
                "matched_frame": 80 + i,
                "distance": 0.3 + 0.02 * i,
                "match_distance": (0.3 + 0.02 * i) * scale,
                "blend_root_offset_max_m": 0.01 * scale,
                "blend_joint_correction_max_rad": (0.05 + 0.01 * i) * scale,
                "stitch_velocity_jump_rad_s": 1.0 * scale,
                "foot_skate_m": 0.05 * scale,
                "penetration_max_m": 0.0,
                "fell": i == 0,
                "intended_fall": False,
            }
        )
    rows.append({"id": "bad", "facing_deg": 400.0, "status": "error", "error": "boom"})
    return rows


def _results(
    tmp_path: Path, rows: list[dict[str, Any]], versions: dict[str, str] = VERSIONS
) -> Path:
    d = tmp_path / "res"
    store = ResultStore(d)
    for r in rows:
        store.append(r)
    store.close()
    (d / "sweep.json").write_text(json.dumps({"versions": versions}))
    return d


def test_regress_passes_own_baseline_and_fails_a_tightened_one(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    d = _results(tmp_path, _rows())
    base = tmp_path / "baseline.json"
    assert main(["regress", str(d), "--baseline", str(base), "--update"]) == 0
    doc = load_baseline(base)
    assert doc["versions"] == VERSIONS and doc["count"] == 11 and doc["failures"] == 1
    assert doc["stats"]["match_distance"]["median"] == pytest.approx(0.39)
    assert main(["regress", str(d), "--baseline", str(base)]) == 0
    out = capsys.readouterr().out
    assert "no regression" in out and "VERSIONS DIFFER" not in out

    # tightened: the baseline claims blend corrections half as large
    doc["stats"]["blend_joint_correction_max_rad"]["median"] *= 0.5
    base.write_text(json.dumps(doc))
    assert main(["regress", str(d), "--baseline", str(base)]) == 1
    out = capsys.readouterr().out
    line = next(
        ln
        for ln in out.splitlines()
        if ln.startswith("blend_joint_correction_max_rad") and "median" in ln
    )
    assert line.split()[-1] == "worse"
    assert "REGRESSION" in out


def test_better_is_not_a_regression_unless_strict(tmp_path: Path) -> None:
    doc = make_baseline(_rows(), VERSIONS)
    better = _rows(scale=0.5)
    cmp = compare(better, doc, VERSIONS)
    assert {ln.verdict for ln in cmp.lines if ln.metric == "match_distance"} == {"better"}
    assert not cmp.regressed
    assert compare(better, doc, VERSIONS, strict=True).regressed
    worse = compare(_rows(scale=1.5), doc, VERSIONS)
    assert worse.regressed and worse.per_scenario["match_distance"][0]


def test_failures_clip_changes_and_versions_are_reported(tmp_path: Path) -> None:
    doc = make_baseline(_rows(), VERSIONS)
    rows = _rows(clip="sway")
    rows[3] = {"id": "id3", "facing_deg": 108.0, "status": "error", "error": "boom"}
    cmp = compare(rows, doc, {"reactmocap": "0.1.0", "mujoco": "3.3.0"})
    assert cmp.regressed  # one more failure
    assert next(ln for ln in cmp.lines if ln.metric == "failures").verdict == "worse"
    assert cmp.newly_failing == ["id3"] and len(cmp.clip_changed) == 9
    from reactmocap.batch import format_comparison

    text = format_comparison(cmp)
    assert "VERSIONS DIFFER" in text and "mujoco 3.2.0 (baseline) vs 3.3.0 (now)" in text
    assert "matched clip/frame changed in 9" in text


def test_tolerances_are_overridable_in_the_baseline(tmp_path: Path) -> None:
    doc = make_baseline(_rows(), VERSIONS)
    slightly = _rows(scale=1.04)
    assert not compare(slightly, doc, VERSIONS).regressed
    doc["tolerances"]["match_distance"] = {"abs": 0.0, "rel": 0.001}
    assert compare(slightly, doc, VERSIONS).regressed
    doc["tolerances"]["match_distance"] = {"abs": -1}
    p = tmp_path / "b.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(ConfigError, match="tolerances.match_distance"):
        load_baseline(p)


def test_update_keeps_tolerance_overrides_and_missing_inputs_are_clear(tmp_path: Path) -> None:
    d = _results(tmp_path, _rows())
    base = tmp_path / "b.json"
    doc = make_baseline(_rows(), VERSIONS, {"foot_skate_m": {"abs": 0.5, "rel": 0.0}})
    base.write_text(json.dumps(doc))
    assert main(["regress", str(d), "--baseline", str(base), "--update"]) == 0
    assert load_baseline(base)["tolerances"] == {"foot_skate_m": {"abs": 0.5, "rel": 0.0}}
    assert main(["regress", str(tmp_path / "nothing"), "--baseline", str(base)]) == 2
    assert main(["regress", str(d), "--baseline", str(tmp_path / "none.json")]) == 2


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("stats", "oops", "stats: expected a table, got 'oops'"),
        ("stats", {"match_distance": "x"}, "stats.match_distance: expected a table of numbers"),
        ("scenarios", 5, "scenarios: expected a table, got 5"),
        ("count", "eight", "count: expected a number, got 'eight'"),
    ],
)
def test_a_baseline_field_of_the_wrong_type_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], field: str, value: Any, message: str
) -> None:
    # before: compare() failed on them with an AttributeError/TypeError/ValueError traceback
    d = _results(tmp_path, _rows())
    base = tmp_path / "b.json"
    base.write_text(json.dumps(make_baseline(_rows(), VERSIONS) | {field: value}))
    assert main(["regress", str(d), "--baseline", str(base)]) == 2
    assert capsys.readouterr().err.startswith(f"reactmocap: error: {base}: {message}")
