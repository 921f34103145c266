"""A commanded facing change turns the runner by the commanded angle; at 2.5 m/s (the speed
the paths are run at) the stance estimate of eqs. 1-2 is smoothed over the steps."""

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


def test_stance_estimate_is_smoothed_at_the_path_speed() -> None:
    res = run_course(2.5, seconds=3.0, fps=10.0)
    runner = res.runner
    blend = runner.params.at(2.5)["stance_blend"]
    assert 0 < blend < 1
    # replay the law on the logged stances: each lift-off moves the estimate part of the way
    est = runner.params.at(2.5)["stance_time"]
    downs = [t for t, *_ in runner.log.touchdowns]
    ups = [t for t, _ in runner.log.liftoffs]
    assert len(ups) >= 6
    for up in ups:
        last = min(max(up - max(t for t in downs if t < up), 0.12), 0.4)
        est = est + blend * (last - est)
    assert runner.stance_estimate == pytest.approx(est, rel=1e-12)
    # and it is not the last stance's duration alone (eqs. 1-2 unsmoothed)
    assert abs(runner.stance_estimate - last) > 1e-4
