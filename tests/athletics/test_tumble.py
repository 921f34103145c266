"""Tumbling (thesis ch. 5) and the standing back somersault (ch. 8.4), measured on the bodies and
on the simulated motion."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.athletics import athlete
from reactmocap.athletics.maneuvers import somersault
from reactmocap.athletics.tumble import POSITIONS, TumbleParams, somersault_inertia
from reactmocap.errors import ConfigError, UnknownKeyError

#: Fig. 5.2: moment of inertia about the somersault axis (kg m^2)
THESIS_FIG_5_2 = {
    "male": {"layout": 18.31, "pike": 5.84, "tuck": 4.84},
    "female": {"layout": 7.43, "pike": 2.52, "tuck": 1.92},
}


@pytest.mark.parametrize("body", ["male", "female"])
def test_somersault_inertia_within_10_percent_of_the_thesis(body: str) -> None:
    a = athlete(body)
    for position, thesis in THESIS_FIG_5_2[body].items():
        measured = somersault_inertia(a, position)
        assert abs(measured - thesis) <= 0.10 * thesis, (position, measured, thesis)
    # the tuck is the tightest: about a third of the layout's (section 5.1)
    assert (
        somersault_inertia(a, "tuck")
        < somersault_inertia(a, "pike")
        < somersault_inertia(a, "layout") / 2.5
    )


def test_positions_and_params_are_checked() -> None:
    assert set(POSITIONS) == {"layout", "pike", "tuck"}
    with pytest.raises(UnknownKeyError, match="valid positions"):
        TumbleParams(position="straddle")
    with pytest.raises(ConfigError, match="> 0"):
        TumbleParams(turns=0.0)


@pytest.fixture(scope="module")
def back_tuck():  # type: ignore[no-untyped-def]
    return somersault("tuck", "backward", "male")


def test_a_back_somersault_turns_360_and_lands(back_tuck) -> None:  # type: ignore[no-untyped-def]
    r = back_tuck.report
    assert abs(abs(r["rotation_deg"]) - 360.0) <= 30.0
    assert r["rotation_deg"] < 0  # backward
    assert r["landed"] and not r["fell"] and r["status"] == "ok"
    # the rotation is the log's: the trunk came back upright, one turn round
    assert np.degrees(back_tuck.log["rotation"][-1]) == pytest.approx(r["rotation_deg"])
    assert [t for _, _, t in back_tuck.transitions][3:5] == ["tumble.tumble", "land.reach"]


def test_angular_momentum_is_conserved_in_the_somersault_flight(back_tuck) -> None:  # type: ignore[no-untyped-def]
    r = back_tuck.report
    t, momentum = back_tuck.log["t"], back_tuck.log["momentum"]
    flight = (t > r["time_to_liftoff_s"] + 0.01) & (t < r["touchdown_s"] - 0.01)
    assert flight.sum() > 100
    m = momentum[flight]
    assert np.linalg.norm(m[0]) > 30.0  # a real back somersault's momentum
    assert np.abs(m - m[0]).max() / np.linalg.norm(m[0]) <= 0.01
    # tucking speeds the rotation up (Fig. 5.3): peak rate well above the layout's L / I
    layout = np.linalg.norm(m[0]) / somersault_inertia(athlete("male"), "layout")
    assert r["peak_somersault_rate_rad_s"] > 2.5 * layout
