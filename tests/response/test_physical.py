"""The physical response mode: Simulation 2 runs on until the body is back on the found clip,
so the final blend corrects only a small gap; when the body does not get there, the report
says so."""

from __future__ import annotations

from dataclasses import replace

import pytest

from reactmocap.errors import ConfigError
from reactmocap.response.pipeline import LibraryCache, run_response
from reactmocap.response.scenario import Scenario, load_scenario, parse_scenario
from tests.conftest import REPO

EXAMPLES = REPO / "examples"
CACHE = LibraryCache()


def _physical(name: str) -> Scenario:
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    return replace(sc, response=replace(sc.response, mode="physical"))


def test_a_push_lands_physically_and_the_blend_corrects_only_the_small_gap() -> None:
    sc = _physical("light_push")
    physical = run_response(sc, CACHE).report
    blend = run_response(replace(sc, response=replace(sc.response, mode="blend")), CACHE).report
    tr, q = physical["transition"], physical["quality"]
    assert tr["mode"] == "physical" and tr["landed_on_clip"], tr
    assert tr["end"] >= tr["match"] - 1e-9
    gap = tr["landing_gap"]
    assert gap["pelvis_m"] <= sc.response.land_position
    assert gap["joint_rad"] <= sc.response.land_joint
    assert q["blend_root_offset_max_m"] <= 0.02, q
    assert q["blend_joint_correction_max_rad"] <= 0.1 + 1e-9, q
    assert q["reaction_displacement_m"] >= 0.10  # a reaction, not the own clip played on
    assert not physical["warnings"]
    # the same fields as the blend mode, so regress can compare the two
    assert set(q) == set(blend["quality"])
    assert blend["transition"]["landing_gap"] == {"pelvis_m": 0, "root_rad": 0, "joint_rad": 0}


def test_a_body_that_does_not_land_is_reported_not_hidden() -> None:
    # the tracker cannot follow the found sway clip after this kick: the report must say so
    rep = run_response(_physical("front_kick"), CACHE).report
    tr = rep["transition"]
    if tr["landed_on_clip"]:
        pytest.skip("the kick now lands physically: nothing left to report")
    assert any("physical mode" in w for w in rep["warnings"]), rep["warnings"]
    assert tr["end"] > tr["match"]  # it kept trying past the match


def test_an_unknown_mode_is_a_clear_error() -> None:
    data = {"library": str(REPO / "data" / "synthetic_clips"), "recipient": {"clip": "guard"},
            "impact": {}, "response": {"mode": "ragdoll"}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"\[response\]\.mode: expected one of"):
        parse_scenario(data, source="s.toml")
