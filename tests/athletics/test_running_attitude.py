"""The running attitude servo's integral on the trunk's pitch and its torque limit (real
MuJoCo, the thesis male)."""

from __future__ import annotations

import numpy as np

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import RunParams


def _pitch_error(params: RunParams) -> float:
    """Mean trunk pitch minus the desired, over 2-6 s of a 5 m/s run."""
    res = run_course(5.0, seconds=6.0, fps=10.0, params=params)
    assert not res.report["fell"], res.report["notes"]
    log = res.log
    late = log["t"] >= 2.0
    return float(np.mean(log["trunk_pitch"][late])) - params.at(5.0)["pitch"]


def test_the_pitch_integral_brings_the_trunk_toward_the_desired_pitch() -> None:
    """At 5 m/s the stance hip's PD alone leaves the trunk pitched forward of the desired;
    the integral takes at least a third of that off."""
    without = _pitch_error(RunParams(pitch_integral=0.0))
    with_integral = _pitch_error(RunParams())
    assert without > 0.05
    assert with_integral < (2.0 / 3.0) * without


def test_the_attitude_torque_stays_within_its_limit() -> None:
    """A trunk a radian off its desired pitch asks the servo for more than the limit: the
    torque is cut to it; without a limit it is not."""
    res = run_course(3.5, seconds=0.2, fps=10.0)
    runner = res.runner
    runner.k["pitch"] = 1.0
    top = runner.k["attitude_limit"] * runner.mass * runner.g * runner.athlete.leg_length
    limited = float(np.linalg.norm(runner._attitude_torque(runner.heading_d)))
    runner.k["attitude_limit"] = 0.0
    free = float(np.linalg.norm(runner._attitude_torque(runner.heading_d)))
    assert free > top
    # cut to the limit (the foot's grip may take a little more off the twist about the leg)
    assert 0.95 * top < limited <= top * (1 + 1e-9)


def test_the_attitude_torque_eases_in_after_touchdown() -> None:
    """At 5 m/s the attitude torque is zero at touchdown, part of it half the ramp later and
    all of it after the ramp; without the ramp it is whole at once."""
    res = run_course(5.0, seconds=1.5, fps=10.0)
    runner = res.runner
    ramp = runner.k["attitude_ramp"]
    assert ramp > 0
    runner.k["pitch"] = 0.5  # an error the servo acts on, well within the limit
    runner.k["pitch_integral"] = 0.0  # each call would add to the integral
    now = runner.world.data.time

    def size(since: float) -> float:
        runner.t_touchdown = now - since
        return float(np.linalg.norm(runner._attitude_torque(runner.heading_d)))

    full = size(2 * ramp)
    assert full > 0
    assert size(0.0) == 0.0
    assert 0.2 * full < size(0.5 * ramp) < 0.8 * full
    runner.k["attitude_ramp"] = 0.0
    assert size(0.0) == full


def test_the_touchdown_limit_caps_the_torque_until_the_ball_is_down() -> None:
    """At 2.5 m/s a trunk half a radian off its pitch asks for more than the touchdown limit:
    in the loading and heel states the torque is cut to it, once the ball is down only to
    the (larger) attitude limit."""
    res = run_course(2.5, seconds=0.2, fps=10.0)
    runner = res.runner
    k = runner.k
    assert 0 < k["touchdown_limit"] < k["attitude_limit"]
    k["pitch"] = -0.5  # the trunk well behind its desired pitch
    unit = runner.mass * runner.g * runner.athlete.leg_length
    states = runner.machine._by_name

    def size(state: str) -> float:
        runner.machine.current = states[state]
        return float(np.linalg.norm(runner._attitude_torque(runner.heading_d))) / unit

    assert size("toe") > 1.2 * k["touchdown_limit"]
    for state in ("loading", "heel"):
        assert size(state) <= k["touchdown_limit"] * (1 + 1e-9)
        assert size(state) > 0.9 * k["touchdown_limit"]
    k["touchdown_limit"] = 0.0  # off: the attitude limit alone
    assert size("loading") == size("toe")


def test_the_thrust_stops_at_the_take_off_speed_or_once_the_rise_slows() -> None:
    """In the toe phase the thrust is on while the body's rise speeds up below the take-off
    speed; it stops at the take-off speed, or once the rise falls ``thrust_drop`` below its
    peak (a push that cannot reach the take-off speed); above 4 m/s the drop is off."""
    res = run_course(2.5, seconds=0.2, fps=10.0)
    runner = res.runner
    k = runner.k
    runner.machine.current = runner.machine._by_name["toe"]
    vz = runner.senses.com_vel

    def push(*speeds: float) -> bool:
        runner.released, runner.vz_peak = False, -np.inf
        for v in speeds:
            vz[2] = v
            runner._stance(runner.world, 0.0)
        return bool(runner.released)

    top, drop = k["takeoff_vz"], k["thrust_drop"]
    assert 0 < drop < 0.2 * top
    assert not push(0.0, 0.3 * top, 0.6 * top, 0.9 * top)
    assert push(0.0, 0.5 * top, top)
    assert not push(0.0, 0.5 * top, 0.5 * top - 0.5 * drop)  # a small dip: still on
    assert push(0.0, 0.5 * top, 0.5 * top - 2.0 * drop)
    assert RunParams().at(4.0)["thrust_drop"] > 2.0  # off where the fast gaits were tuned
