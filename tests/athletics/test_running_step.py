"""The commanded step's landing and its forward speed regulation within the stance (issue 20,
the ninth round; real MuJoCo, the thesis male)."""

from __future__ import annotations

import math

import pytest

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import STEP_AFTER, STEP_TILT, Runner, RunParams
from reactmocap.athletics.running_params import STEP_PARAMS
from reactmocap.errors import ConfigError

_CONTROL = Runner.control


def _trace(params: RunParams, monkeypatch: pytest.MonkeyPatch) -> tuple[list[tuple], float]:
    """Per commanded-stance tick of a 3 s run at 2.61 m/s: time since touchdown, the
    touchdown's vertical speed, the leg law's force (N), the speed regulation's horizontal
    force (N), the forward speed's error (m/s), the force's vertical part (N); and the body's
    mass (kg)."""
    rows: list[tuple] = []

    def traced(self: Runner, world, t: float) -> None:  # type: ignore[no-untyped-def]
        _CONTROL(self, world, t)
        if self.step_stance and self.machine.current.name != "flight":
            h = self.heading_d
            v = self.senses.com_vel
            err = math.cos(h) * v[0] + math.sin(h) * v[1] - self.speed
            rows.append((t - self.t_touchdown, self.vz_touchdown, self.leg_force,
                         self.speed_push, float(err), float(self._force[2])))  # fmt: skip

    monkeypatch.setattr(Runner, "control", traced)
    res = run_course(2.61, seconds=STEP_AFTER + 1.0, fps=10.0, params=params)
    assert len(rows) > 20
    return rows, res.runner.mass


def test_the_landing_force_starts_from_the_falls_speed(monkeypatch: pytest.MonkeyPatch) -> None:
    """With ``step_landing`` the leg's force in a commanded stance's first tick is at least
    the body's weight plus what takes the fall's speed out over that share of the stance
    (the half-cosine alone asks about one body weight whatever the fall)."""
    land = 0.3
    params = RunParams(**{**_step(), "step_landing": land})
    rows, m = _trace(params, monkeypatch)
    firsts = [r for r in rows if r[0] < 1e-6 and r[1] < -0.5]
    assert firsts, "no commanded touchdown falling faster than 0.5 m/s"
    for _s, v0, force, *_ in firsts:
        acc0 = -v0 * 0.5 * math.pi / (land * 0.2391)
        assert force >= 0.9 * min(m * (9.81 + acc0), 4.0 * m * 9.81), (v0, force)
        assert force > 1.5 * m * 9.81
    with pytest.raises(ConfigError, match=r"step_landing must be in \[0, 1\]"):
        RunParams(step_landing=(0.0, 1.5, 0.0))


def test_the_forward_speed_is_regulated_within_the_stance(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With ``step_speed_gain`` the leg's force gets a horizontal part against the forward
    speed's error (gain times mass times error), within STEP_TILT of its vertical part;
    without it none."""
    gain = 3.0
    rows, m = _trace(RunParams(**{**_step(), "step_speed_gain": gain}), monkeypatch)
    pushed = 0
    for _s, _v0, _f, push, err, fz in rows:
        assert abs(push) <= STEP_TILT * fz + 1e-9
        want = -m * gain * err
        assert push == pytest.approx(max(-STEP_TILT * fz, min(want, STEP_TILT * fz)), abs=1e-6)
        pushed += abs(push) > 5.0
    assert pushed > 10
    off, _ = _trace(STEP_PARAMS, monkeypatch)
    assert all(r[3] == 0.0 for r in off)
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
