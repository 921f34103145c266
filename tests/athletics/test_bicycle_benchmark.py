"""The bicycle against the benchmark bicycle of Meijaard et al. (2007), from simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reactmocap.athletics.bicycle import (
    BENCHMARK,
    BENCHMARK_CAPSIZE_SPEED,
    BENCHMARK_WEAVE_SPEED,
    Bicycle,
    BicycleParams,
    Placement,
    benchmark_matrices,
    linear_eigenvalues,
)
from reactmocap.athletics.cycling_scene import CyclingScene, Obstacle, Terrain
from reactmocap.athletics.stability import (
    BICYCLE_WORLD,
    coast,
    self_stable_speeds,
    stability_sweep,
)
from reactmocap.errors import ConfigError
from reactmocap.sim.world import World


def test_benchmark_matrices_match_the_published_values() -> None:
    m, c1, k0, k2 = benchmark_matrices(BENCHMARK)
    np.testing.assert_allclose(
        m, [[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]], rtol=1e-9
    )
    np.testing.assert_allclose(
        c1, [[0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]], rtol=1e-9, atol=1e-12
    )
    np.testing.assert_allclose(
        k0, [[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]], rtol=1e-9
    )
    np.testing.assert_allclose(
        k2, [[0, 76.59734589573222], [0, 2.65431523794604]], rtol=1e-9, atol=1e-12
    )
    # the published weave and capsize speeds are where the linear model's modes cross zero
    assert max(linear_eigenvalues(BENCHMARK_WEAVE_SPEED).real) == pytest.approx(0.0, abs=1e-6)
    assert max(linear_eigenvalues(BENCHMARK_CAPSIZE_SPEED).real) == pytest.approx(0.0, abs=1e-6)


def test_uncontrolled_benchmark_bicycle_stays_upright_at_5_m_s_for_10_s() -> None:
    res, bike = coast(5.0, 10.0, roll_rate=0.1, steer_rate=0.0)
    assert res.status == "ok"
    roll, _ = bike.roll_steer_from_qpos(res.qpos)
    assert np.abs(roll).max() < 0.05  # the kick leans it ~1 degree
    assert np.abs(roll[-100:]).max() < 0.002  # and the lean has died away
    assert bike.speed == pytest.approx(5.0, abs=0.05)


def test_uncontrolled_benchmark_bicycle_falls_at_2_m_s() -> None:
    res, bike = coast(2.0, 5.0, roll_rate=0.1, steer_rate=0.0)
    roll, _ = bike.roll_steer_from_qpos(res.qpos)
    assert np.abs(roll).max() > 1.0  # weave grows: it falls over


def test_weave_and_capsize_speeds_from_simulation_within_5_percent() -> None:
    points = stability_sweep(np.arange(3.5, 7.01, 0.5))
    weave, capsize = self_stable_speeds(points)
    assert weave == pytest.approx(BENCHMARK_WEAVE_SPEED, rel=0.05)
    assert capsize == pytest.approx(BENCHMARK_CAPSIZE_SPEED, rel=0.05)
    by_speed = {p.speed: p for p in points}
    assert not by_speed[3.5].stable and by_speed[5.0].stable and not by_speed[7.0].stable
    # every mode at 5 m/s within 5% of the linear model (by modulus)
    ours = np.sort_complex(by_speed[5.0].eigenvalues)
    theirs = linear_eigenvalues(5.0)
    np.testing.assert_allclose(np.abs(ours), np.abs(theirs), rtol=0.05)


@pytest.mark.parametrize("heading", [0.0, 1.0, 2.5])
def test_bicycle_placed_on_a_grade_touches_with_both_wheels(heading: float) -> None:
    bike = Bicycle(BENCHMARK, "bike/", Placement(x=1.0, y=2.0, heading=heading, speed=3.0))
    scene = CyclingScene([bike], terrain=Terrain(0.1, 0.3), obstacles=[Obstacle(5.0, 5.0)])
    world = World([], BICYCLE_WORLD, scene=scene)
    scene.place(world)
    d = world.data
    assert d.ncon == 2
    np.testing.assert_allclose(d.contact.dist[:2], -1e-4, atol=2e-5)
    assert bike.speed == pytest.approx(3.0)
    assert bike.yaw == pytest.approx(heading)
    assert abs(bike.roll) < 1e-9


def test_bad_bicycle_parameters_raise_config_errors() -> None:
    from dataclasses import replace

    with pytest.raises(ConfigError, match="wheelbase"):
        replace(BENCHMARK, wheelbase=-1.0)
    with pytest.raises(ConfigError, match="rolling_resistance"):
        replace(BENCHMARK, rolling_resistance=math.nan)
    with pytest.raises(ConfigError, match="speed"):
        coast(-1.0, 1.0)
    with pytest.raises(ConfigError, match="grade"):
        Terrain(0.5)
    assert isinstance(BENCHMARK, BicycleParams)
