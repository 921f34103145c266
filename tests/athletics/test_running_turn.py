"""A commanded facing change turns the runner by the commanded angle; at 2.5 m/s (the speed
the paths are run at) the stance estimate of eqs. 1-2 is smoothed over the steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reactmocap.athletics.paths import Facing
from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running_params import RunParams
from reactmocap.errors import ConfigError


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


def test_curve_ease_eases_the_curve_in_at_the_start_of_a_path_run() -> None:
    """``curve_ease`` (an opt-in, off by default) eases the curvature the lean, the turn's
    feed-forward and the path correction read in over its time from the start: on the circle
    the runner reads the smoothstep's share of 1/R and runs differently; on a straight line
    (curvature 0) it changes nothing."""
    eased = RunParams(curve_ease=3.0)
    plain = run_course(2.5, seconds=1.5, path="circle:10", fps=10.0)
    ease = run_course(2.5, seconds=1.5, path="circle:10", fps=10.0, params=eased)
    assert not plain.report["fell"] and not ease.report["fell"]
    assert plain.runner.curvature == pytest.approx(0.1, rel=0.02)
    # the last control tick is within 0.01 s of the end: smoothstep(0.5) = 0.5
    assert ease.runner.curvature == pytest.approx(0.05, rel=0.05)
    assert not np.array_equal(plain.log["com"], ease.log["com"])
    line = run_course(2.61, seconds=1.5, fps=10.0)
    line_eased = run_course(2.61, seconds=1.5, fps=10.0, params=eased)
    assert np.array_equal(line.log["com"], line_eased.log["com"])


def test_curve_ease_is_checked() -> None:
    with pytest.raises(ConfigError, match="curve_ease"):
        RunParams(curve_ease=-1.0)
    with pytest.raises(ConfigError, match="curve_ease"):
        RunParams(curve_ease=30.0)
