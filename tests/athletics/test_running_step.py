"""The commanded step's forward speed regulated within the stance (issue 20, the ninth round;
real MuJoCo, the thesis male)."""

from __future__ import annotations

import math

import pytest

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import STEP_AFTER, STEP_TILT, Runner, RunParams
from reactmocap.athletics.running_params import STEP_PARAMS
from reactmocap.errors import ConfigError

_CONTROL = Runner.control


def _trace(params: RunParams, monkeypatch: pytest.MonkeyPatch) -> tuple[list[tuple], float]:
    """Per commanded-stance tick of a 3 s run at 2.61 m/s: the speed regulation's horizontal
    force (N), the forward speed's error (m/s), the leg force's vertical part (N); and the
    body's mass (kg)."""
    rows: list[tuple] = []

    def traced(self: Runner, world, t: float) -> None:  # type: ignore[no-untyped-def]
        _CONTROL(self, world, t)
        if self.step_stance and self.machine.current.name != "flight":
            h = self.heading_d
            v = self.senses.com_vel
            err = math.cos(h) * v[0] + math.sin(h) * v[1] - self.speed
            rows.append((self.speed_push, float(err), float(self._force[2])))

    monkeypatch.setattr(Runner, "control", traced)
    res = run_course(2.61, seconds=STEP_AFTER + 1.0, fps=10.0, params=params)
    assert len(rows) > 20
    return rows, res.runner.mass


def test_the_forward_speed_is_regulated_within_the_stance(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With ``step_speed_gain`` the leg's force gets a horizontal part against the forward
    speed's error (gain times mass times error), within STEP_TILT of its vertical part;
    without it none."""
    gain = 3.0
    rows, m = _trace(RunParams(**{**_step(), "step_speed_gain": gain}), monkeypatch)
    pushed = 0
    for push, err, fz in rows:
        assert abs(push) <= STEP_TILT * fz + 1e-9
        want = -m * gain * err
        assert push == pytest.approx(max(-STEP_TILT * fz, min(want, STEP_TILT * fz)), abs=1e-6)
        pushed += abs(push) > 5.0
    assert pushed > 10
    off, _ = _trace(STEP_PARAMS, monkeypatch)
    assert all(r[0] == 0.0 for r in off)
    with pytest.raises(ConfigError, match="step_speed_gain must be >= 0"):
        RunParams(step_speed_gain=-1.0)


def _step() -> dict:
    return {
        "step_stance": 0.2391,
        "step_takeoff": 0.9598,
        "step_placement": 0.7,
        "speed_integral": (0.03, 0.0, 0.03),
        "toe_fraction": (0.6, 0.42, 0.3199),
        "push_hold": 0.75,
    }
