"""A commanded facing change turns the runner by the commanded angle."""

from __future__ import annotations

import math

import pytest

from reactmocap.athletics.paths import Facing
from reactmocap.athletics.run_course import run_course


@pytest.mark.parametrize("angle", [45.0])
def test_commanded_turn_changes_the_heading(angle: float) -> None:
    course = Facing([(0.0, 0.0), (2.0, math.radians(angle))])
    rep = run_course(3.5, seconds=8.0, path=course, fps=10.0).report
    assert not rep["fell"], rep["notes"]
    # the pelvis's mean heading over the last second, against the command (+-10 degrees)
    assert rep["heading_deg"] == pytest.approx(angle, abs=10.0)
