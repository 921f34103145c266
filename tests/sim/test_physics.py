"""Physics invariants of the simulated character (each test can fail: see the comments)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim import (
    Impact,
    PDServo,
    World,
    WorldConfig,
    build_character,
    contact_report,
    critical_kv,
    rollout,
)

# RK4 for the conservation tests: MuJoCo's default first-order schemes (Euler/implicitfast) do
# not conserve momentum exactly in generalised coordinates (drift O(dt); measured ~3% of a
# 33 N s impulse over 0.1 s of violent joint motion at dt = 0.5 ms). RK4 shows what the model
# itself does: any spurious external force (a bad impact torque, a floor contact) still fails.
ZERO_G = WorldConfig(gravity=(0.0, 0.0, 0.0), joint_damping=0.0, integrator="rk4")
# the servo's damping needs implicit integration at high gains (see reactmocap.sim.servo)
ZERO_G_IMPLICIT = WorldConfig(gravity=(0.0, 0.0, 0.0), joint_damping=0.0)


def _airborne(guard: Motion, config: WorldConfig = ZERO_G) -> World:
    """The guard pose floating 2 m up (no floor contact), at rest."""
    world = World(build_character(guard), config)
    q = world.characters[0].character.qpos_from_motion(guard, [0])[0]
    q[2] += 2.0
    world.set_pose(0, q)
    return world


def _momentum(world: World) -> tuple[np.ndarray, np.ndarray]:
    """Linear momentum and angular momentum about the centre of mass of character 0."""
    m, d = world.model, world.data
    mujoco.mj_forward(m, d)  # after mj_step, positions-derived fields lag qvel by one step
    mujoco.mj_subtreeVel(m, d)
    root = world.characters[0].body_ids[0]
    return m.body_subtreemass[root] * d.subtree_linvel[root].copy(), d.subtree_angmom[root].copy()


def test_free_flight_conserves_momentum(guard: Motion) -> None:
    """No gravity, no contact, random joint velocities (joints flail and hit their cone
    limits: internal forces only): linear and angular momentum are conserved to 1e-4
    relative over 0.5 s (RK4)."""
    world = _airborne(guard)
    rng = np.random.default_rng(3)
    world.data.qvel[:] = rng.normal(0.0, 1.0, world.model.nv)
    mujoco.mj_forward(world.model, world.data)
    p0, l0 = _momentum(world)
    rollout(world, 0.5, record_fps=30)  # joints flail and hit their limits: internal forces
    p1, l1 = _momentum(world)
    assert np.linalg.norm(p1 - p0) <= 1e-4 * np.linalg.norm(p0)
    assert np.linalg.norm(l1 - l0) <= 1e-4 * np.linalg.norm(l0)


def test_impulse_changes_momentum_by_j(guard: Motion) -> None:
    world = _airborne(guard)
    p0, _ = _momentum(world)
    j = np.array([30.0, -12.0, 5.0])
    impact = Impact(
        body="chest", impulse=tuple(j), point=(0.05, 0.1, 0.0), start=0.01, duration=0.02
    )
    rollout(world, 0.1, impacts=[impact])
    p1, _ = _momentum(world)
    assert np.linalg.norm((p1 - p0) - j) <= 0.01 * np.linalg.norm(j)


def _elbow_step(guard: Motion, kp: float, kv: float) -> np.ndarray:
    """Angle error of the left elbow after a 0.5 rad target step, sampled every step."""
    world = _airborne(guard, ZERO_G_IMPLICIT)
    servo = PDServo(world, kp=kp, kv=kv, refresh_every=1)
    ball = world.characters[0].character
    del ball
    row = 5  # BALL_JOINTS index of l_elbow
    tgt = servo.targets[:15].copy()
    axis = np.array([0.0, 1.0, 0.0])
    tgt[row] = np.concatenate([[np.cos(0.25)], np.sin(0.25) * axis])
    tgt[row] = np.array(
        [
            tgt[row, 0] * servo.targets[row, 0] - tgt[row, 1:] @ servo.targets[row, 1:],
            *(
                servo.targets[row, 0] * tgt[row, 1:]
                + tgt[row, 0] * servo.targets[row, 1:]
                + np.cross(servo.targets[row, 1:], tgt[row, 1:])
            ),
        ]
    )  # current rotation times a 0.5 rad turn about the local y axis
    servo.set_targets(0, tgt)
    errs = []
    for _ in range(int(1.0 / world.timestep)):
        servo.apply()
        mujoco.mj_step(world.model, world.data)
        errs.append(servo.pose_error()[row])
    return np.array(errs)


def test_pd_step_response_critical_and_underdamped(guard: Motion) -> None:
    kp = 400.0
    crit = _elbow_step(guard, kp, critical_kv(kp))
    # critically damped (or more, since the forearm's effective inertia is below I): converges
    # without overshoot: the error never crosses to the other side by more than 2% of the step
    dt = 0.0005
    t_settle = int((8.0 / np.sqrt(kp)) / dt)
    assert crit[t_settle:].max() < 0.02 * 0.5
    reached = int(np.argmax(crit < 0.01 * 0.5))
    assert reached > 0 and crit[reached:].max() < 0.02 * 0.5  # no overshoot coming back
    under = _elbow_step(guard, kp, 0.1 * critical_kv(kp))
    # under-damped: the error goes through zero and comes back (overshoot > 20% of the step)
    first_min = np.argmax(under < 0.01 * 0.5)
    assert first_min > 0 and under[first_min:].max() > 0.2 * 0.5


def test_two_runs_are_bit_identical(guard: Motion) -> None:
    def run() -> np.ndarray:
        world = World(build_character(guard), WorldConfig(friction=0.5))
        world.set_from_motion(0, guard, 0)
        PDServo(world, kp=4000.0)
        res = rollout(
            world,
            0.3,
            record_fps=120,
            impacts=[Impact(body="head", force=(200.0, 50.0, 0.0), start=0.05, duration=0.05)],
        )
        return np.concatenate([res.qpos.ravel(), res.final_state])

    a, b = run(), run()
    assert np.array_equal(a, b)


@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"body": "tail", "force": (1, 0, 0)}, UnknownKeyError, ["tail", "chest", "l_forearm"]),
        ({"body": "chest", "force": (np.nan, 0, 0)}, ConfigError, ["NaN"]),
        ({"body": "chest", "force": (1, 0, 0), "duration": -0.1}, ConfigError, ["duration"]),
        ({"body": "chest"}, ConfigError, ["force", "impulse"]),
        ({"body": "chest", "force": (1, 0)}, ConfigError, ["3 numbers"]),
        ({"body": "chest", "force": (1, 0, 0), "start": -1.0}, ConfigError, ["start"]),
    ],
)
def test_bad_impacts_get_clear_errors(kwargs: dict, error: type, words: list[str]) -> None:
    with pytest.raises(error) as info:
        Impact(**kwargs)
    for w in words:
        assert w in str(info.value)


def test_aliases_and_valid_impacts() -> None:
    assert Impact(body="thorax", force=(1, 2, 3)).body == "chest"
    assert Impact(body="abdomen", impulse=(1, 0, 0), duration=0.0).body == "waist"


def test_instability_is_reported_with_time_and_body(guard: Motion) -> None:
    world = _airborne(guard, WorldConfig())
    wc = world.characters[0]
    world.data.qvel[wc.dof_adr + 6 + 3 * 5 : wc.dof_adr + 6 + 3 * 6] = 5e4  # elbow spin
    with pytest.raises(SimulationError, match=r"unstable at t = .* s.*a/"):
        rollout(world, 0.05)


def test_standing_contacts_support_the_weight(guard: Motion) -> None:
    world = World(build_character(guard))
    world.set_from_motion(0, guard, 0, velocity=False)
    PDServo(world, kp=4000.0)
    rollout(world, 0.2)
    rep = contact_report(world)
    assert {"l_foot", "r_foot"} <= set(rep.ground[0])
    weight = 75.0 * 9.81
    assert 0.8 * weight < rep.ground_force[0][2] < 1.2 * weight
    assert rep.between == ()
