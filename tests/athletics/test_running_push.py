"""The stance knee's and ankle's servos in the push: with ``push_hold`` their gains about
bending are a share of the full ones, roll and yaw held (real MuJoCo, the thesis male)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import Runner, RunParams
from reactmocap.athletics.running_body import ANKLE, KNEE
from reactmocap.athletics.running_params import STEP_PARAMS
from reactmocap.errors import ConfigError

_CONTROL = Runner.control


def _servo_bending(hold: float, monkeypatch: pytest.MonkeyPatch) -> tuple[float, float]:
    """Mean |servo torque| about the stance knee's bending axis and about its other two axes
    (N m) over the push ticks of a 1.5 s run at 2.61 m/s."""
    bend: list[float] = []
    other: list[float] = []

    def traced(self: Runner, world, t: float) -> None:  # type: ignore[no-untyped-def]
        _CONTROL(self, world, t)
        if self.machine.current.name in ("toe", "unloading"):
            j = KNEE[self.active]
            tau = self.world.servo.torques(self.character)[j]
            axes = self.rig._axes[j]  # rows: bending, roll, yaw (child frame)
            bend.append(abs(float(axes[0] @ tau)))
            other.append(float(np.linalg.norm(axes[1:] @ tau)))
            assert self.rig.axis_gain[ANKLE[self.active], 0] == hold

    monkeypatch.setattr(Runner, "control", traced)
    res = run_course(2.61, seconds=1.5, fps=10.0, params=RunParams(push_hold=hold))
    assert not res.report["fell"] and len(bend) > 20
    return float(np.mean(bend)), float(np.mean(other))


def test_the_push_is_free_in_bending_and_held_in_roll_and_yaw(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """As tuned (push_hold 1) the stance knee's servo opposes the push about bending with
    tens of N m; with push_hold 0 it exerts nothing about bending and still holds the other
    axes; a share outside [0, 1] is a ConfigError naming the range."""
    full_bend, full_other = _servo_bending(1.0, monkeypatch)
    free_bend, free_other = _servo_bending(0.0, monkeypatch)
    assert full_bend > 20.0
    assert free_bend < 1e-6 * full_bend
    assert free_other > 0.2 * full_other
    with pytest.raises(ConfigError, match=r"push_hold must be in \[0, 1\]"):
        RunParams(push_hold=(1.0, 1.0, 1.5))


def test_the_commanded_step_lasts_its_stance() -> None:
    """From STEP_AFTER on each stance lasts ``step_stance`` (0.226 s, to a tick or two), where the
    leg spring's lasts about 0.17 s; a commanded step given at some speeds only is a
    ConfigError."""
    res = run_course(2.61, seconds=4.0, fps=10.0, params=STEP_PARAMS)
    assert not res.report["fell"], res.report["notes"]
    log = res.runner.log
    downs = [t for t, *_ in log.touchdowns]
    stances = [
        up - max(d for d in downs if d < up) for up, _ in log.liftoffs if up > 2.5 and up > downs[0]
    ]
    assert len(stances) >= 4
    assert np.all(np.abs(np.array(stances) - STEP_PARAMS.step_stance) < 0.012), stances
    with pytest.raises(ConfigError, match="every speed or none"):
        RunParams(step_stance=(0.0, 0.24, 0.24))


@pytest.mark.parametrize("bias", [STEP_PARAMS.step_bias, 0.0])
def test_the_commanded_step_is_at_speed_when_the_figures_start(bias: float) -> None:
    """The commanded step's placement correction starts at its steady value (``step_bias``),
    so over 3-6 s of a run at 2.61 m/s (the figures start at 3 s) the runner is within 0.06
    m/s of the speed, at the step's cadence (under 3 steps/s; the leg spring's gait: 3.5).
    Started from the spring's correction instead (``step_bias`` 0) the steps after the
    switch run 0.2-0.4 m/s slow. A bias outside +-0.3 m is a ConfigError naming it."""
    params = dataclasses.replace(STEP_PARAMS, step_bias=bias)
    r = run_course(2.61, seconds=6.0, fps=10.0, params=params).report
    assert not r["fell"] and r["figures_from_s"] == 3.0
    assert r["cadence_steps_s"] < 3.0
    if bias:
        assert abs(r["mean_speed_m_s"] - 2.61) < 0.06, r
    else:
        assert r["mean_speed_m_s"] < 2.61 - 0.15, r
    with pytest.raises(ConfigError, match=r"step_bias must be in \[-0.3, 0.3\]"):
        RunParams(step_bias=0.5)


def _liftoff_vz(params: RunParams, seconds: float) -> list[float]:
    """The body's vertical speed (m/s) at each lift-off after 2.5 s (the commanded step's)
    of a run at 2.61 m/s."""
    res = run_course(2.61, seconds=seconds, fps=10.0, params=params)
    t, vz = res.log["t"], res.log["com_vel"][:, 2]
    return [float(vz[np.searchsorted(t, up)]) for up, _ in res.runner.log.liftoffs if up > 2.5]


def test_the_push_ramp_eases_the_servos_out_and_the_body_leaves_faster(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With ``push_ramp`` the stance knee's and ankle's kept share of bending falls over the
    commanded stance's push to ``(1 - push_ramp)`` of ``push_hold`` at its end, so more of the
    leg law's push reaches the ground: over the first commanded stances at 2.61 m/s the body
    leaves faster upward (0.48-0.57 m/s against 0.41-0.47 with ``push_ramp`` 0.3). Off (0) the share
    stays ``push_hold``; a ramp outside [0, 1] is a ConfigError."""
    shares: list[float] = []

    def traced(self: Runner, world, t: float) -> None:  # type: ignore[no-untyped-def]
        _CONTROL(self, world, t)
        if self.step_stance and self.machine.current.name == "toe":
            shares.append(float(self.rig.axis_gain[KNEE[self.active], 0]))

    ramped = dataclasses.replace(STEP_PARAMS, push_ramp=0.3)
    unramped = dataclasses.replace(STEP_PARAMS, push_ramp=0.0)
    with monkeypatch.context() as patch:
        patch.setattr(Runner, "control", traced)
        run_course(2.61, seconds=2.8, fps=10.0, params=ramped)
    hold = STEP_PARAMS.push_hold
    assert isinstance(hold, float) and len(shares) > 10
    assert max(shares) < hold and min(shares) > 0.7 * hold - 1e-9
    assert min(shares) < 0.75 * hold  # near the stance's end
    base = _liftoff_vz(unramped, 3.5)
    eased = _liftoff_vz(ramped, 3.5)
    assert len(base) >= 2 and len(eased) >= 2
    assert np.mean(eased) > np.mean(base) + 0.06, (base, eased)
    with pytest.raises(ConfigError, match=r"push_ramp must be in \[0, 1\]"):
        RunParams(push_ramp=1.2)
