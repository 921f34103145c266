"""Adding a controller is one new file and one registration: the test controller in
``sway_controller.py`` then works in tracking, in a scenario's simulations and in their
validation, and its parameters are checked like the package's own."""

from __future__ import annotations

from dataclasses import replace

import pytest

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.response.pipeline import run_response
from reactmocap.response.scenario import load_scenario, parse_scenario
from reactmocap.sim import track_clip
from reactmocap.sim.controllers import CONTROLLERS, register
from tests.conftest import REPO

from .sway_controller import SPEC, ensure_registered


def test_a_registered_controller_tracks(guard: Motion) -> None:
    ensure_registered()
    assert "swaying_pd" in CONTROLLERS
    res = track_clip(guard, seconds=0.3, controller="swaying_pd", params={"period": 0.2})
    assert res.report.controller == "swaying_pd" and not res.report.fell
    assert res.report.kp == 3000.0
    with pytest.raises(ConfigError, match="period"):
        track_clip(guard, seconds=0.1, controller="swaying_pd", params={"perod": 0.2})
    with pytest.raises(ConfigError, match="already registered"):
        register(SPEC)


def test_a_scenario_uses_it_in_simulation_2() -> None:
    ensure_registered()
    sc = load_scenario(REPO / "examples" / "light_push.toml")
    sc = replace(sc, response=replace(sc.response, sim2_controller="swaying_pd"))
    res = run_response(sc)
    assert res.report["config"]["sim2_controller"] == "swaying_pd"
    assert res.sim2.num_frames > 3
    with pytest.raises(ConfigError, match="swaying_pd"):  # listed among the valid keys
        parse_scenario({"library": str(REPO / "data" / "synthetic_clips"),
                        "recipient": {"clip": "guard"}, "impact": {},
                        "response": {"sim1_controller": "nope"}})  # fmt: skip
