"""The rider on the bicycle (eqs. 7-11): speed held, heading changed, a grade climbed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reactmocap.athletics.cycling import ride
from reactmocap.errors import ConfigError


def test_rider_holds_5_m_s_within_0_3_for_20_s() -> None:
    res = ride(5.0, 20.0)
    log = res.logs[0]
    assert not res.report["fell"] and res.rollout.status == "ok"
    assert np.all(np.abs(log["speed"] - 5.0) <= 0.3), float(np.abs(log["speed"] - 5.0).max())
    assert res.report["speed_error_m_s"] <= 0.2
    assert res.report["max_roll_deg"] < 5.0  # upright, not weaving
    assert res.report["distance_m"] == pytest.approx(100.0, rel=0.03)  # and straight on


def test_90_degree_heading_change_settles() -> None:
    res = ride(5.0, 5.0, heading=math.radians(90.0), heading_at=0.5)
    rep = res.report
    assert not rep["fell"]
    assert rep["settle_time_s"] is not None and rep["settle_time_s"] <= 3.0
    assert rep["overshoot_deg"] <= 10.0
    assert rep["heading_error_deg"] < 5.0


def test_rider_climbs_a_5_percent_grade_at_speed() -> None:
    res = ride(5.0, 8.0, grade=0.05)
    log = res.logs[0]
    assert not res.report["fell"]
    late = log["t"] >= 3.0
    assert np.all(np.abs(log["speed"][late] - 5.0) <= 0.5)
    # it climbed: the rear wheel rose 5% of the distance ridden
    z = res.team.bicycles[0].position[2] - res.team.bicycles[0].params.rear.radius
    assert z == pytest.approx(0.05 * log["x"][-1], abs=0.1)


def test_out_of_range_ride_inputs_raise_clear_errors() -> None:
    with pytest.raises(ConfigError, match="speed must be within 1.5-12 m/s"):
        ride(20.0, 2.0)
    with pytest.raises(ConfigError, match="gear"):
        ride(5.0, 2.0, gear=0.1)
    with pytest.raises(ConfigError, match="heading or a path"):
        ride(5.0, 2.0, heading=1.0, path=[(5.0, 0.0)])


def test_rider_is_built_by_name_from_the_controller_registry() -> None:
    from reactmocap.athletics.bicycle import Placement
    from reactmocap.athletics.cycling import setup
    from reactmocap.athletics.rider import Rider
    from reactmocap.sim.controllers import build
    from reactmocap.sim.rollout import rollout

    team = setup([Placement(speed=4.0)])
    # the registry's rider is the full controller, here asked to speed up to 5 m/s
    rider = build("bicycle_rider", team.world, None, {"speed": 5.0})  # type: ignore[arg-type]
    assert isinstance(rider, Rider) and rider.bicycle is team.bicycles[0]
    res = rollout(team.world, 4.0, controllers=[rider], on_unstable="stop")
    log = rider.log.arrays()
    assert res.status == "ok" and not team.bicycles[0].fallen
    assert log["speed"][-1] == pytest.approx(5.0, abs=0.2)
    with pytest.raises(ConfigError, match="not mounted on a bicycle"):
        build("bicycle_rider", team.world, None, {}, character=3)  # type: ignore[arg-type]
