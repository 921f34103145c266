"""The commanded step by speed (``step_until``), and a run the engine stopped as unstable
(real MuJoCo, the thesis male)."""

from __future__ import annotations

import dataclasses

import pytest

from reactmocap.athletics.run_course import run_course
from reactmocap.athletics.running import Runner, RunParams
from reactmocap.athletics.running_params import STEP_PARAMS
from reactmocap.errors import ConfigError


def test_step_until_switches_the_commanded_step_off_above_its_speed() -> None:
    """``STEP_PARAMS`` runs the commanded step up to 3 m/s and the leg spring (its push held
    as tuned) above: at 3.5 m/s it runs 4 s on the spring's stances (under 0.2 s) without
    falling, where the same set with the step at every speed (``step_until`` 0, the set before)
    fell at 3.18 s, just after the step took over (2 s). Bad values are ConfigErrors naming the
    field."""
    assert STEP_PARAMS.step_until == 3.0
    assert STEP_PARAMS.at(3.0)["step_stance"] == STEP_PARAMS.step_stance
    assert STEP_PARAMS.at(3.0)["push_hold"] == STEP_PARAMS.push_hold < 1.0
    assert STEP_PARAMS.at(3.01)["step_stance"] == 0.0 and STEP_PARAMS.at(3.01)["push_hold"] == 1.0
    kept = run_course(3.5, seconds=4.0, fps=10.0, params=STEP_PARAMS)
    assert not kept.report["fell"], kept.report["notes"]
    log = kept.runner.log
    downs = [t for t, *_ in log.touchdowns]
    stances = [up - max(d for d in downs if d < up) for up, _ in log.liftoffs if up > 2.5]
    assert len(stances) >= 4 and max(stances) < 0.2, stances
    every = run_course(3.5, seconds=4.0, fps=10.0,
                       params=dataclasses.replace(STEP_PARAMS, step_until=0.0))  # fmt: skip
    assert every.report["fell"] and 2.0 < every.report["fell_at_s"] < 4.0, every.report
    for bad in (2.4, 5.5, -1.0):
        with pytest.raises(ConfigError, match="step_until must be 0 .off. or a speed in 2.5-5"):
            dataclasses.replace(STEP_PARAMS, step_until=bad)
    with pytest.raises(ConfigError, match="with step_stance given"):
        RunParams(step_until=3.0)


def test_an_unstable_simulation_is_reported_with_its_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """A run the engine stops as unstable (here the body thrown at 1 km/s at 0.5 s) is a
    fall with no fall time in the log; the report says so plainly: ``unstable_at_s`` and a
    note with that time. A run that holds has ``unstable_at_s`` None."""
    control = Runner.control

    def thrown(self: Runner, world, t: float) -> None:  # type: ignore[no-untyped-def]
        control(self, world, t)
        if t >= 0.5:
            world.data.qvel[:3] = 1000.0

    monkeypatch.setattr(Runner, "control", thrown)
    r = run_course(2.61, seconds=1.5, fps=10.0).report
    assert r["status"] == "unstable" and r["fell"] and r["fell_at_s"] is None, r
    assert 0.5 <= r["unstable_at_s"] < 0.6, r
    assert any(n.startswith(f"the simulation went unstable at {r['unstable_at_s']:.2f} s")
               for n in r["notes"]), r["notes"]  # fmt: skip
    monkeypatch.setattr(Runner, "control", control)
    ok = run_course(2.61, seconds=0.6, fps=10.0).report
    assert ok["unstable_at_s"] is None and not any("unstable" in n for n in ok["notes"])
