"""The engine: chunked stepping is bit-identical to single steps, frames sit at exact times,
instability raises or ends the rollout with a partial result, contacts are logged, and the
controller interface (state machines, groups, the registry) works through it."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest

from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim import (
    CONTROLLERS,
    FunctionController,
    Impact,
    ImpactSchedule,
    PDTracker,
    RolloutResult,
    State,
    StateMachine,
    World,
    WorldConfig,
    build,
    build_character,
    controller_help,
    rollout,
)
from reactmocap.sim.controllers import Group, after, when


def _two(step_forward: Motion, guard: Motion) -> World:
    ch = build_character(step_forward)
    world = World([ch, ch], WorldConfig(friction=0.5))
    world.set_from_motion(0, step_forward, 0)
    world.set_from_motion(1, guard.transformed(yaw=np.pi, translation=(0.4, 0.0, 0.0)), 0)
    return world


def _trackers(world: World, step_forward: Motion, guard: Motion) -> list[PDTracker]:
    return [
        PDTracker(world, 0, step_forward, kp=4000.0, control_every=5, refresh_every=5),
        PDTracker(world, 1, guard, kp=3000.0, control_every=7, refresh_every=5),
    ]


IMPACTS = [
    Impact(body="head", force=(200.0, 50.0, 0.0), start=0.01, duration=0.03),
    Impact(body="chest", force=(-300.0, 0.0, 0.0), point=(0.05, 0.1, 0.0), start=0.02),
]


def test_chunked_stepping_equals_single_steps(step_forward: Motion, guard: Motion) -> None:
    """The engine's chunks (``mj_step(nstep=k)`` between events) against a plain loop of one
    step at a time with the same controllers and impacts: bit-identical states."""
    seconds = 0.15
    world = _two(step_forward, guard)
    res = rollout(world, seconds, controllers=_trackers(world, step_forward, guard),
                  impacts=IMPACTS, record_fps=200.0)  # fmt: skip

    ref = _two(step_forward, guard)
    ctrls = _trackers(ref, step_forward, guard)
    schedule = ImpactSchedule(ref, IMPACTS)
    for c in ctrls:
        c.reset(ref)
    frames = []
    t0 = ref.data.time
    n = round(seconds / ref.timestep)
    for k in range(n + 1):
        if k % 10 == 0:  # 200 fps at dt = 0.5 ms
            frames.append(ref.data.qpos.copy())
        if k == n:
            break
        for c in ctrls:
            if k % c.control_every == 0:
                c.control(ref, ref.data.time - t0)
        schedule.apply(k)
        ref.step(1)
    assert np.array_equal(res.qpos, np.array(frames))
    assert np.array_equal(res.final_state, ref.get_state())


def test_frames_sit_at_exact_times(guard: Motion) -> None:
    world = World(build_character(guard))
    world.set_from_motion(0, guard, 0)
    res = rollout(world, 0.1, record_fps=(60.0, 25.0))
    times, q = res.frames()
    assert np.allclose(times, np.arange(7) / 60.0) and q.shape == (7, world.model.nq)
    np.testing.assert_array_equal(q[0], res.qpos[0])  # frame 0: the initial state
    t25, _ = res.frames(25.0)
    assert np.allclose(t25, [0.0, 0.04, 0.08])
    # 1/60 s is 33.33 steps: the frame is the state after 33 steps; 1/25 s after 80
    assert list(res.record_steps[:4]) == [0, 33, 67, 80]
    with pytest.raises(ConfigError, match="30"):
        res.frames(30.0)
    assert res.motion(0).num_frames == 7 and res.status == "ok"


def test_instability_raises_or_stops(guard: Motion, capfd: pytest.CaptureFixture[str]) -> None:
    def spun() -> World:
        world = World(build_character(guard), WorldConfig(gravity=(0.0, 0.0, 0.0)))
        world.set_from_motion(0, guard, 0)
        world.data.qpos[2] += 1.0
        return world

    # an elbow spun at an absurd rate from 0.05 s on
    spin = FunctionController(
        lambda w, t: w.data.qvel.__setitem__(slice(21, 24), 5e4) if 0.05 <= t < 0.051 else None
    )
    with pytest.raises(SimulationError, match="unstable"):
        rollout(spun(), 0.2, controllers=[spin])
    res = rollout(spun(), 0.2, controllers=[spin], on_unstable="stop", record_fps=100.0)
    assert res.status == "unstable" and "unstable at t =" in (res.reason or "")
    assert 0.05 <= res.seconds < 0.2
    times, q = res.frames()
    assert 5 <= times.size < 21 and np.isfinite(q).all()
    assert res.motion(0).num_frames == times.size
    out, err = capfd.readouterr()
    assert "WARNING" not in out + err  # MuJoCo's own warnings are caught, not printed


def test_a_state_diverged_between_checks_is_unstable_not_a_crash(guard: Motion) -> None:
    # a mass matrix gone indefinite (as a diverging state's can be, still finite): the servo's
    # Cholesky meets it first; the same result as the engine's own check, not a LinAlgError
    def run(on_unstable: Literal["raise", "stop"]) -> RolloutResult:
        world = World(build_character(guard))
        world.set_from_motion(0, guard, 0)
        tracker = PDTracker(world, 0, guard, kp=4000.0, control_every=4, refresh_every=4)
        spoil = FunctionController(
            lambda w, t: w.data.M.__setitem__(slice(None), -1.0) if t >= 0.1 else None,
            control_every=4,
        )
        return rollout(world, 0.3, controllers=[tracker, spoil], check_every=1000,
                       on_unstable=on_unstable)  # fmt: skip

    with pytest.raises(SimulationError, match="not positive definite"):
        run("raise")
    res = run("stop")
    assert res.status == "unstable" and "positive definite" in (res.reason or "")


def test_contacts_between_characters_are_logged(guard: Motion) -> None:
    ch = build_character(guard)
    world = World([ch, ch])
    world.set_from_motion(0, guard, 0)
    # the second character stands 0.15 m in front and walks into the first
    b = guard.transformed(yaw=np.pi, translation=(0.3, 0.0, 0.0))
    world.set_from_motion(1, b, 0)
    world.data.qvel[world.characters[1].dof_adr] = -1.0
    res = rollout(world, 0.3, contact_every=10)
    log = res.contact_log
    assert log is not None and not log.empty
    assert np.all(np.diff(log.times) > 0) and log.peak_force > 0
    assert log.impulse[0] < 0  # character 0 is pushed toward -x by the one coming from +x
    assert np.all(log.depth >= 0)


def test_a_state_machine_switches_states_on_events(guard: Motion) -> None:
    world = World(build_character(guard))
    world.set_from_motion(0, guard, 0)
    hold = build("pd", world, guard)
    entered: list[tuple[str, float]] = []
    machine = StateMachine(
        [
            State("hold", hold, exits=((after(0.05), "drop"),)),
            State(
                "drop",
                on_enter=lambda w, t: (w.servo.enable(0, on=False), entered.append(("drop", t))),
                exits=((when(lambda w: w.com(0)[2] < 0.7), "low"),),
            ),
            State("low"),
        ],
        "hold",
        control_every=hold.control_every,
    )
    res = rollout(world, 1.0, controllers=[machine])
    assert [(tr.source, tr.target) for tr in machine.transitions] == [
        ("hold", "drop"),
        ("drop", "low"),
    ]
    assert machine.transitions[0].time == pytest.approx(0.05)
    assert entered == [("drop", pytest.approx(0.05))]
    assert machine.current.name == "low"
    assert res.body_transforms(0)[0][-1, 0, 2] < 0.7  # a ragdoll falls
    with pytest.raises(UnknownKeyError, match="hold"):
        StateMachine([State("hold", exits=((after(1.0), "nowhere"),))], "hold")
    with pytest.raises(ConfigError, match="ticks every"):
        StateMachine([State("hold", hold)], "hold", control_every=3)


def test_registry_lists_keys_and_parameters(guard: Motion) -> None:
    world = World(build_character(guard))
    with pytest.raises(UnknownKeyError, match="wholebody"):
        build("nope", world, guard)
    with pytest.raises(ConfigError, match="kp_com"):
        build("pd", world, guard, {"kp_com": 1.0})
    bal = build("balance", world, guard, {"kp": 900.0, "kp_com": 50.0})
    assert (
        isinstance(bal, Group)
        and bal.control_every == CONTROLLERS["balance"].defaults["control_every"]
    )
    for name in ("pd", "wholebody"):
        assert f"{name}:" in controller_help()
    assert "kp 4000" in CONTROLLERS["pd"].help()


def test_function_controllers_tick_at_their_rate(guard: Motion) -> None:
    world = World(build_character(guard))
    world.set_from_motion(0, guard, 0)
    seen: list[float] = []
    rollout(world, 0.01, controllers=[FunctionController(lambda _w, t: seen.append(t), 4)])
    assert np.allclose(seen, np.arange(5) * 4 * world.timestep)
    with pytest.raises(ConfigError, match="control_every"):
        FunctionController(lambda _w, _t: None, 0)
