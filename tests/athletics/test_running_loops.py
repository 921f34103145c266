"""The opt-ins for 20 m loops at 4-5 m/s (``docs/athletics.md``, "The 20 m loops at 4-5 m/s
traced"): the foot placement's sideways reach (``lateral_reach``) and the speed correction's
step measured along its own chord on curves (``step_chord``); and a 10 m loop entered along a
clothoid ("The 10 m loops at 3.5-5 m/s entered along a clothoid"); an eight whose loops are
joined by a clothoid pair ("The figure eight's reversal along a clothoid pair")."""

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


def _facing_flip(run: Any) -> tuple[float, float]:
    """When the desired facing's rate (over 0.5 s) was last above +0.15 rad/s before it first
    fell below -0.15 after 5 s, and that first time: the first reversal's flip."""
    t, h = run.log["t"], np.unwrap(run.log["desired_heading"])
    w = int(round(0.25 / float(np.median(np.diff(t)))))
    rate, tr = (h[2 * w :] - h[: -2 * w]) / (t[2 * w :] - t[: -2 * w]), t[w:-w]
    neg = int(np.nonzero((rate < -0.15) & (tr > 5.0))[0][0])
    pos = int(np.nonzero((rate > 0.15) & (tr > 5.0) & (tr < tr[neg]))[0][-1])
    return float(tr[pos]), float(tr[neg])


def test_a_reversal_clothoid_spreads_the_eights_facing_flip_and_leaves_the_loop_alone() -> None:
    # eight:10 at 2.5 m/s: the facing's rate flips from +0.15 to -0.15 rad/s in 0.53 s at the
    # first reversal (26.6 s); with a 10 m clothoid pair there in 1.84 s (24.0-25.8 s), and
    # the run is the same to the bit until the path ahead reaches the pair (21.1 s)
    plain, turned = (run_course(2.5, seconds=27.5, path=p, fps=10.0)
                     for p in ("eight:10", "eight:10+turn:10"))  # fmt: skip
    assert not plain.report["fell"] and not turned.report["fell"]
    early = plain.log["t"] < 20.0
    assert np.array_equal(plain.log["com"][early], turned.log["com"][early])
    assert not np.array_equal(plain.log["com"], turned.log["com"][: len(plain.log["com"])])
    (a0, a1), (b0, b1) = _facing_flip(plain), _facing_flip(turned)
    assert a1 - a0 < 0.8 and b1 - b0 > 1.4
    assert b1 < a1  # the pair starts the turn back earlier, where the arc ends
