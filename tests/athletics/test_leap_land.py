"""Leaping and landing (thesis ch. 4 and 6), measured on the motion itself."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.athletics import run, tables
from reactmocap.errors import ConfigError


def test_a_leap_to_30_cm_lands_within_3_cm_and_balanced() -> None:
    r = run("leap", "male", height=0.3)
    assert abs(r.report["achieved_height_m"] - 0.3) <= 0.03
    assert r.report["landed"] and not r.report["fell"]
    # the height is the COM's rise at the apex over standing, from the log itself
    com = r.log["com"][:, 2]
    assert com.max() - com[0] == pytest.approx(r.report["achieved_height_m"])


def test_a_broad_jump_of_1_m_within_5_cm() -> None:
    r = run("broad-jump", "male", distance=1.0)
    assert abs(r.report["achieved_distance_m"] - 1.0) <= 0.05


def test_flight_conserves_angular_momentum() -> None:
    # a leap with pitch momentum; in the air only internal torques act
    r = run("leap", "male", effort=0.4, spin=15.0)
    t, momentum = r.log["t"], r.log["momentum"]
    lift, down = r.report["time_to_liftoff_s"], r.report["touchdown_s"]
    flight = (t > lift + 0.01) & (t < down - 0.01)
    assert flight.sum() > 50
    m = momentum[flight]
    assert np.linalg.norm(m[0]) > 5.0  # a real rotation
    assert np.abs(m - m[0]).max() / np.linalg.norm(m[0]) < 0.01


def test_a_half_metre_drop_lands() -> None:
    r = run("land", "male", drop=0.5)
    assert r.report["landed"] and not r.report["fell"]


def test_a_3_metre_drop_is_never_a_success() -> None:
    rng = tables.supported_range("land", "drop", "male")
    assert rng is not None and rng[1] < 3.0
    with pytest.raises(ConfigError, match="supported range"):
        run("land", "male", drop=3.0)


def test_commands_outside_the_measured_range_are_refused() -> None:
    _, hi = tables.supported_range("leap", "height", "female") or (0.0, 0.0)
    with pytest.raises(ConfigError, match=f"{hi:g}"):
        run("leap", "female", height=hi + 0.5)
    with pytest.raises(ConfigError, match="finite"):
        run("leap", "male", height=float("nan"))
    with pytest.raises(ConfigError, match="no parameter"):
        run("leap", "male", hight=0.3)
    with pytest.raises(ConfigError, match=">= 0"):
        run("land", "male", drop=-1.0)
