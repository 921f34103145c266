"""The opt-ins for 20 m loops at 4-5 m/s (``docs/athletics.md``, "The 20 m loops at 4-5 m/s
traced"): the foot placement's sideways reach (``lateral_reach``) and the speed correction's
step measured along its own chord on curves (``step_chord``); and a 10 m loop entered along a
clothoid ("The 10 m loops at 3.5-5 m/s entered along a clothoid")."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running_params import RunParams
from reactmocap.errors import ConfigError

#: the set the 4.0-5.0 m/s sweep of both 20 m loops was judged with
LOOPS: dict[str, Any] = {
    "lateral_reach": 0.45,
    "step_chord": 1.0,
    "speed_integral": (0.0, 0.0, 0.01),
}


def test_step_chord_reads_less_shortfall_on_a_curve_and_leaves_a_line_alone() -> None:
    # on the 20 m circle at 4 m/s the velocity lags the facing by 0.3-0.6 rad: measured along
    # the facing every step reads short and the correction moves the feet back
    runs = [run_course(4.0, seconds=6.0, path="circle:20", fps=10.0,
                       params=RunParams(step_chord=v)) for v in (1.0, 0.0)]  # fmt: skip
    chord, facing = (r.runner.speed_bias for r in runs)
    assert facing < chord < 0.0
    assert chord - facing > 0.01
    line = [run_course(4.0, seconds=2.0, fps=10.0, params=RunParams(step_chord=v))
            for v in (1.0, 0.0)]  # fmt: skip
    assert line[0].runner.speed_bias != 0.0  # the correction ran
    assert np.array_equal(line[0].log["com"], line[1].log["com"])
    assert np.array_equal(line[0].motion.rotations, line[1].motion.rotations)


def test_lateral_reach_lets_the_placement_turn_the_runner_on_a_20_m_circle() -> None:
    # at 4 m/s the placement's sideways part is clamped from 2 s: reaching further, the
    # runner stays nearer the path
    far, tuned = (run_course(4.0, seconds=6.0, path="circle:20", fps=10.0,
                             params=RunParams(lateral_reach=v)).report for v in (0.45, 0.3))  # fmt: skip
    assert not far["fell"] and not tuned["fell"]
    assert far["path_error_m"] < tuned["path_error_m"] - 0.05


def test_the_loops_set_runs_past_the_defaults_fall_at_5_m_s() -> None:
    # the defaults fall on the 20 m circle at 5 m/s at 8.0 s (the path benchmark's row)
    runs = [
        run_course(5.0, seconds=10.0, path="circle:20", fps=10.0, params=p).report
        for p in (RunParams(**LOOPS), None)
    ]
    assert runs[1]["fell"] and runs[1]["fell_at_s"] < 9.0
    assert not runs[0]["fell"]


def test_lateral_reach_and_step_chord_are_checked() -> None:
    with pytest.raises(ConfigError, match=r"lateral_reach must be in \[0.3, 1\]"):
        RunParams(lateral_reach=0.2)
    with pytest.raises(ConfigError, match=r"lateral_reach must be in \[0.3, 1\]"):
        RunParams(lateral_reach=(0.3, 0.3, 1.5))
    with pytest.raises(ConfigError, match=r"step_chord must be in \[0, 1\]"):
        RunParams(step_chord=-0.1)
    with pytest.raises(ConfigError, match=r"step_chord must be in \[0, 1\]"):
        RunParams(step_chord=(0.0, 0.0, 2.0))
    assert RunParams().at(4.0)["lateral_reach"] == 0.3
    assert RunParams().at(4.0)["step_chord"] == 0.0


def test_a_clothoid_entry_carries_the_runner_past_the_10_m_circles_start_at_3_5_m_s() -> None:
    # started on circle:10 at 3.5 m/s the defaults fall at 1.70 s; entered over 5 m of
    # clothoid they reach the loop at 1.68 s and run on (they fall there at 8.0 s)
    on, entered = (run_course(3.5, seconds=3.0, path=p, fps=10.0)
                   for p in ("circle:10", "circle:10+entry:5"))  # fmt: skip
    assert on.report["fell"] and on.report["fell_at_s"] < 2.0
    r = entered.report
    assert not r["fell"] and r["path_entry_m"] == 5.0
    assert 1.5 < r["loop_from_s"] < 2.0 and r["path_progress_m"] > 8.0
    # the cross-track error is scored from the loop's start, not the figures' (1.5 s)
    t, cross = entered.log["t"], entered.log["cross_track"]
    assert r["figures_from_s"] < r["loop_from_s"]
    loop = np.sqrt(np.mean(cross[t >= r["loop_from_s"]] ** 2))
    assert r["path_error_m"] == pytest.approx(loop)
