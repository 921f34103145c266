"""A 10 s run at 3.5 m/s holds its speed without falling (real MuJoCo, the thesis male)."""

from __future__ import annotations

import pytest

from reactmocap.athletics.run_course import run_course


@pytest.fixture(scope="module")
def run_35():  # type: ignore[no-untyped-def]
    return run_course(3.5, seconds=10.0, fps=30.0)


def test_runs_10_s_at_3_5_without_falling(run_35) -> None:  # type: ignore[no-untyped-def]
    rep = run_35.report
    assert rep["status"] == "ok", rep.get("reason")
    assert not rep["fell"], rep["notes"]
    assert run_35.rollout.seconds == pytest.approx(10.0)


def test_holds_the_speed(run_35) -> None:  # type: ignore[no-untyped-def]
    rep = run_35.report
    assert rep["strides_measured"] >= 8
    assert rep["speed_error_m_s"] <= 0.2, rep["notes"]
    assert rep["mean_speed_m_s"] == pytest.approx(3.5, abs=0.2)


def test_report_has_the_run_figures(run_35) -> None:  # type: ignore[no-untyped-def]
    rep = run_35.report
    for key in ("mean_speed_m_s", "speed_error_m_s", "path_error_m", "fell",
                "cadence_steps_s", "stride_m"):  # fmt: skip
        assert key in rep
    assert rep["cadence_steps_s"] > 1.0 and rep["stride_m"] > 0.5
    # a straight line is a path: the runner stays on it
    assert rep["path_error_m"] < 0.5


def test_the_states_cycle(run_35) -> None:  # type: ignore[no-untyped-def]
    """Every state of Fig. 3 is visited, the legs alternate and each stance has a flight."""
    import numpy as np

    from reactmocap.athletics.running import RUN_STATES

    log = run_35.log
    seen = {RUN_STATES[i] for i in np.unique(log["state"])}
    assert {"flight", "loading", "heel_toe", "toe"} <= seen
    legs = [leg for _, leg, _, _ in run_35.runner.log.touchdowns]
    assert all(a != b for a, b in zip(legs, legs[1:]))


def test_a_fast_run_starts_at_the_start_speed_and_ramps_up() -> None:
    """Asked for 5 m/s, the run starts at START_SPEED and the desired speed (and the tuning
    read at it) reaches 5 m/s after (5 - START_SPEED) / ACCEL seconds, and not before."""
    from reactmocap.athletics.running import ACCEL, START_SPEED, RunParams

    ramp = (5.0 - START_SPEED) / ACCEL
    early = run_course(5.0, seconds=0.5 * ramp, fps=30.0)
    assert early.log["com_vel"][0][0] == pytest.approx(START_SPEED, abs=0.05)
    assert START_SPEED < early.runner.speed < 5.0
    assert early.runner.k == RunParams().at(early.runner.speed)
    late = run_course(5.0, seconds=ramp + 0.05, fps=30.0)
    assert late.runner.speed == 5.0 and late.runner.target == 5.0
    assert late.runner.k == RunParams().at(5.0)
