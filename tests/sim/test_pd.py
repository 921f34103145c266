"""The PD servo as MuJoCo actuators: MuJoCo's ball-joint actuator semantics the servo relies on,
exactness against the reference torque at a refresh, passivity, chunked stepping and
determinism (see reactmocap.sim.servo and docs/design.md)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from reactmocap.errors import SimulationError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_normalize
from reactmocap.sim import Impact, PDServo, PDTracker, World, WorldConfig, build_character
from reactmocap.sim import rollout as run_rollout
from reactmocap.sim.servo import HALF_TURN_MARGIN, _right_matrix

NJ = 15


def _rotvec(q: np.ndarray) -> np.ndarray:
    """Shortest-arc rotation vector of a (possibly unnormalised, either-sign) quaternion."""
    q = q / np.linalg.norm(q)
    s = np.linalg.norm(q[1:])
    if s < 1e-15:
        return np.zeros(3)
    ang = 2.0 * np.arctan2(s, q[0])
    if ang > np.pi:
        ang -= 2.0 * np.pi
    return q[1:] / s * ang


def _one_ball(integrator: int = mujoco.mjtIntegrator.mjINT_IMPLICITFAST) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    spec.option.gravity = [0.0, 0.0, 0.0]
    spec.option.integrator = integrator
    body = spec.worldbody.add_body(name="b", pos=[0.0, 0.0, 1.0])
    body.add_joint(name="j", type=mujoco.mjtJoint.mjJNT_BALL)
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.1, 0.05], pos=[0.2, 0.05, 0.0])
    for a in range(3):
        spec.add_actuator(
            name=f"a{a}",
            target="j",
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gaintype=mujoco.mjtGain.mjGAIN_FIXED,
            biastype=mujoco.mjtBias.mjBIAS_AFFINE,
        )
    return spec.compile()


def test_mujoco_ball_actuator_semantics() -> None:
    """What the servo assumes of MuJoCo: for a joint-transmission actuator on a ball joint,
    length = g . r(q) (shortest-arc rotation vector, either quaternion sign), velocity =
    g . qdot, torque = g * force (child frame), for gears of any length and direction; and
    implicitfast puts the velocity-bias derivative -kv g g^T into qDeriv."""
    m = _one_ball()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    for trial in range(300):
        if trial % 3 == 0:  # near a half turn
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            th = np.pi - 10 ** rng.uniform(-6, -1)
            q = np.r_[np.cos(th / 2), np.sin(th / 2) * axis]
        else:
            q = rng.normal(size=4)
        q *= rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 2.0)
        g = rng.normal(size=(3, 3)) * rng.uniform(0.1, 3.0)  # rows: gears
        kp, kv = rng.uniform(1.0, 1e4, 3), rng.uniform(0.0, 1e3, 3)
        m.actuator_gear[:, :3] = g
        m.actuator_gainprm[:, 0] = kp
        m.actuator_biasprm[:, :3] = np.c_[np.zeros(3), -kp, -kv]
        d.qpos[:] = q
        d.qvel[:] = rng.normal(size=3) * 5.0
        mujoco.mj_forward(m, d)
        length = g @ _rotvec(q)
        norm = np.linalg.norm(g, axis=1)
        d.ctrl[:] = length + rng.uniform(-3.0, 3.0, 3) * norm  # within half a turn (pi |g|)
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(d.actuator_length, length, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(d.actuator_velocity, g @ d.qvel, rtol=1e-12, atol=1e-12)
        force = kp * (d.ctrl - length) - kv * (g @ d.qvel)
        np.testing.assert_allclose(d.actuator_force, force, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(d.qfrc_actuator, g.T @ force, rtol=1e-9, atol=1e-8)
    # MuJoCo >= 3.11 (gain == -bias[1], a position servo): a setpoint beyond half a turn acts
    # through its representative nearest the current length, modulo 2 pi |g|; the servo's
    # setpoints never are that far at a refresh (|g . e0| <= pi |g|)
    if tuple(int(x) for x in mujoco.__version__.split(".")[:2]) >= (3, 11):
        d.ctrl[:] = d.actuator_length + 4.0 * norm
        mujoco.mj_forward(m, d)
        wrapped = kp * (4.0 - 2.0 * np.pi) * norm - kv * d.actuator_velocity
        np.testing.assert_allclose(d.actuator_force, wrapped, rtol=1e-9, atol=1e-9)
    # implicit damping: qDeriv's ball block after an implicitfast step
    g = rng.normal(size=(3, 3))
    kv = np.array([3.0, 5.0, 7.0])
    m.actuator_gear[:, :3] = g
    m.actuator_biasprm[:, 2] = -kv
    mujoco.mj_step(m, d)
    q_deriv = np.zeros((3, 3))
    for i in range(3):
        for a in range(m.D_rowadr[i], m.D_rowadr[i] + m.D_rownnz[i]):
            q_deriv[i, m.D_colind[a]] = d.qDeriv[a]
    np.testing.assert_allclose(q_deriv, -g.T @ np.diag(kv) @ g, rtol=1e-12, atol=1e-12)


def test_mujoco_actuator_damping_is_implicit() -> None:
    """Damping far too stiff for explicit integration (kv dt / I ~ 100) stays stable under
    implicitfast, and blows up under Euler (implicit only in joint damping)."""
    for integrator, stable in (
        (mujoco.mjtIntegrator.mjINT_IMPLICITFAST, True),
        (mujoco.mjtIntegrator.mjINT_EULER, False),
    ):
        m = _one_ball(integrator)
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        d = mujoco.MjData(m)
        m.actuator_biasprm[:, 2] = -500.0
        d.qvel[:] = 1.0
        with np.errstate(all="ignore"):
            mujoco.mj_step(m, d, nstep=200)
        finite_and_small = bool(np.all(np.isfinite(d.qvel)) and np.abs(d.qvel).max() < 1.0)
        assert finite_and_small == stable


def _random_world(guard: Motion, max_angle: float, seed: int) -> tuple[World, PDServo]:
    """Two characters in random joint rotations (angle <= max_angle, random quaternion sign),
    random velocities, random targets, some joints frozen or off."""
    ch = build_character(guard)
    world = World([ch, ch])
    world.set_from_motion(0, guard, 0)
    world.set_from_motion(1, guard.transformed(yaw=np.pi, translation=(0.6, 0.0, 0.0)), 0)
    rng = np.random.default_rng(seed)
    servo = PDServo(world, kp=4000.0)

    def rotations() -> np.ndarray:
        axis = rng.normal(size=(NJ, 3))
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        ang = rng.uniform(0.0, max_angle, NJ)
        q = np.c_[np.cos(ang / 2), np.sin(ang / 2)[:, None] * axis]
        return q * rng.choice([-1.0, 1.0], (NJ, 1))

    for wc in world.characters:
        world.data.qpos[wc.ball_qpos_start : wc.ball_qpos_start + 4 * NJ] = rotations().ravel()
    world.data.qvel[:] = rng.normal(0.0, 2.0, world.model.nv)
    servo.freeze(0, ["l_elbow", "r_knee"])
    servo.enable(1, ["neck"], on=False)
    for c in range(2):
        servo.set_targets(c, rotations())  # errors up to a half turn
    mujoco.mj_forward(world.model, world.data)  # d.M at this state
    return world, servo


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_actuator_torque_equals_reference_at_refresh(guard: Motion, seed: int) -> None:
    """At a refresh the actuators' torque is I (kp e - kv qdot) (exact log, full 3x3 damping)
    to 1e-9, for random poses (either quaternion sign), targets, velocities, frozen and
    disabled joints; nothing of the servo's stiffness goes through qfrc_applied."""
    world, servo = _random_world(guard, np.pi - HALF_TURN_MARGIN - 0.05, seed)
    servo.refresh()
    mujoco.mj_forward(world.model, world.data)
    ref = servo.torques()
    act = world.data.qfrc_actuator[servo.dof_indices].reshape(-1, 3)
    assert np.abs(act - ref).max() <= 1e-9 * np.abs(ref).max()
    assert np.array_equal(world.data.qfrc_applied[servo.dof_indices], np.zeros(3 * servo.n))
    off = ~(servo.enabled | servo.frozen)
    assert off.any() and np.all(act[off] == 0.0) and np.all(ref[off] == 0.0)


def test_half_turn_joints_are_held_exactly_at_refresh(guard: Motion) -> None:
    """Joints near a half turn: stiffness as a held torque in qfrc_applied, damping in the
    actuators; their sum is still the reference torque at the refresh."""
    world, servo = _random_world(guard, np.pi, seed=5)
    servo.refresh()
    assert servo.hot.any() and not servo.hot.all()
    mujoco.mj_forward(world.model, world.data)
    ref = servo.torques()
    d = world.data
    total = (d.qfrc_actuator + d.qfrc_applied)[servo.dof_indices].reshape(-1, 3)
    assert np.abs(total - ref).max() <= 1e-9 * np.abs(ref).max()
    # back from the half turn: gains restored, qfrc_applied back to the feed-forward only
    q = d.qpos[servo.qpos_indices].reshape(-1, 4)
    q[servo.hot] = [1.0, 0.0, 0.0, 0.0]
    d.qpos[servo.qpos_indices] = q.ravel()
    mujoco.mj_forward(world.model, d)
    servo.refresh()
    assert not servo.hot.any()
    assert np.all(d.qfrc_applied[servo.dof_indices] == 0.0)


def test_feedforward_goes_to_qfrc_applied_at_refresh(guard: Motion) -> None:
    world, servo = _random_world(guard, 1.0, seed=3)
    d = world.data
    servo.refresh()
    servo.feedforward[:] = np.arange(servo.n * 3).reshape(-1, 3)  # in place, as a controller
    assert np.all(d.qfrc_applied[servo.dof_indices] == 0.0)  # only at the next refresh
    servo.refresh()
    np.testing.assert_array_equal(d.qfrc_applied[servo.dof_indices], np.arange(servo.n * 3))
    servo.clear()
    assert np.all(d.qfrc_applied[servo.dof_indices] == 0.0)
    mujoco.mj_forward(world.model, d)
    assert np.all(d.qfrc_actuator == 0.0)


def test_passive_world_and_disabled_servo_exert_nothing(guard: Motion) -> None:
    """No servo: actuation off, zero gains, zero actuator force. A servo with every joint off
    gives zero force and zero damping: the same trajectory as no servo, bit for bit."""

    def ragdoll(with_servo: bool) -> np.ndarray:
        world = World(build_character(guard))
        world.set_from_motion(0, guard, 0)
        m, d = world.model, world.data
        assert m.nu == 3 * NJ
        if with_servo:
            servo = PDServo(world, kp=4000.0)
            servo.enable(0, on=False)
            servo.step(1)
            assert not m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
            assert np.all(m.actuator_gainprm[:, 0] == 0.0)
            assert np.all(m.actuator_biasprm[:, :3] == 0.0)
            servo.step(399)
        else:
            assert m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
            assert np.all(m.actuator_gainprm == 0.0) and np.all(m.actuator_biasprm == 0.0)
            mujoco.mj_step(m, d, nstep=400)
        assert np.all(d.actuator_force == 0.0) and np.all(d.qfrc_actuator == 0.0)
        return np.r_[d.qpos, d.qvel]

    assert np.array_equal(ragdoll(False), ragdoll(True))


def test_chunked_stepping_equals_single_steps(guard: Motion) -> None:
    """servo.step(n) (mj_step with nstep between refreshes) is bit-identical to apply() +
    mj_step() one step at a time, including refreshes forced by new targets and set_state."""

    def run(chunked: bool) -> np.ndarray:
        world, servo = _random_world(guard, 1.0, seed=7)
        world.data.qvel[:] = 0.0
        state = world.get_state()
        targets = servo.targets[:NJ].copy()
        m, d = world.model, world.data
        for n in (3, 1, 11, 6):
            if chunked:
                servo.step(n)
            else:
                for _ in range(n):
                    servo.apply()
                    mujoco.mj_step(m, d)
            servo.set_targets(0, targets)
        world.set_state(state)  # the servo re-linearises before the next step
        for _ in range(2):
            if chunked:
                servo.step(9)
            else:
                for _ in range(9):
                    servo.apply()
                    mujoco.mj_step(m, d)
        return world.get_state()

    assert np.array_equal(run(True), run(False))


def test_state_restore_relinearises(guard: Motion) -> None:
    """ctrl is state, gears are model: after set_state the first step refreshes, so the
    actuators match the reference torque again."""
    world, servo = _random_world(guard, 1.0, seed=4)
    state = world.get_state()
    servo.step(7)
    world.set_state(state)
    servo.step(0)  # nothing
    assert servo.due
    servo.apply()  # refresh at the restored state
    mujoco.mj_forward(world.model, world.data)
    ref = servo.torques()
    act = world.data.qfrc_actuator[servo.dof_indices].reshape(-1, 3)
    assert np.abs(act - ref).max() <= 1e-9 * np.abs(ref).max()


def test_torque_limit_per_axis(guard: Motion) -> None:
    world = World(build_character(guard))
    world.set_from_motion(0, guard, 0)
    servo = PDServo(world, kp=4000.0, torque_limit=5.0)
    servo.set_targets(0, quat_normalize(servo.targets[:NJ] + 0.5))  # large errors
    servo.refresh()
    mujoco.mj_forward(world.model, world.data)
    m, d = world.model, world.data
    gear_norm = np.linalg.norm(m.actuator_gear[:, :3], axis=1)
    along = np.abs(d.actuator_force) * gear_norm  # torque along each unit axis
    assert along.max() == pytest.approx(5.0)
    assert np.all(along <= 5.0 + 1e-9)


def test_right_matrix_is_the_conjugate_product() -> None:
    from reactmocap.rotations import quat_conj, quat_mul

    rng = np.random.default_rng(2)
    qd, q = rng.normal(size=(6, 4)), rng.normal(size=(6, 4))
    np.testing.assert_allclose(
        (_right_matrix(qd) @ q[:, :, None])[:, :, 0], quat_mul(quat_conj(q), qd), atol=1e-14
    )


def test_tracking_rollout_is_deterministic(step_forward: Motion, guard: Motion) -> None:
    """Chunked rollout with two characters, trackers, impacts (one with a moving force point)
    and records: two runs are bit-identical."""

    def run() -> np.ndarray:
        ch = build_character(step_forward)
        world = World([ch, ch], WorldConfig(friction=0.5))
        world.set_from_motion(0, step_forward, 0)
        world.set_from_motion(1, guard.transformed(yaw=np.pi, translation=(0.5, 0.0, 0.0)), 0)
        ctrls = [
            PDTracker(world, 0, step_forward, kp=4000.0, control_every=5, refresh_every=3),
            PDTracker(world, 1, guard, kp=4000.0, control_every=5, refresh_every=3),
        ]
        res = run_rollout(
            world,
            0.25,
            controllers=ctrls,
            record_fps=70,
            check_every=7,
            impacts=[
                Impact(body="head", force=(200.0, 50.0, 0.0), start=0.05, duration=0.05),
                Impact(body="chest", force=(-300.0, 0.0, 0.0), point=(0.05, 0.1, 0.0), start=0.08),
            ],
        )
        assert res.final_state is not None
        return np.concatenate([res.qpos.ravel(), res.final_state])

    assert np.array_equal(run(), run())


def test_euler_worlds_take_the_damping_diagonal_in_dof_damping(guard: Motion) -> None:
    """Euler integrates only joint damping implicitly: the servo's damping goes there (as the
    diagonal of kv I), the stiffness stays in the actuators; a stiff standing servo is stable."""
    world = World(build_character(guard), WorldConfig(integrator="euler"))
    world.set_from_motion(0, guard, 0, velocity=False)
    base = world.model.dof_damping.copy()
    servo = PDServo(world, kp=4000.0)
    run_rollout(world, 0.2)
    m = world.model
    assert np.all(m.actuator_biasprm[:, 2] == 0.0) and np.all(m.actuator_gainprm[:, 0] == 4000.0)
    assert np.all(m.dof_damping[servo.dof_indices] > base[servo.dof_indices])
    assert world.kinetic_energy(0) < 5.0  # standing, not flailing
    servo.clear()
    np.testing.assert_array_equal(m.dof_damping, base)


def test_axis_gains_free_one_axis_and_keep_the_others(guard: Motion) -> None:
    """Per-axis gains: with an axis's share 0 the servo exerts nothing about it (neither
    stiffness nor damping), the torque is S I S (kp e - kv qdot) with S = A^T diag(sqrt g) A,
    other joints and the other character keep theirs (to rounding), and shares of 1 give back
    the full servo bit for bit; shares outside [0, 1] are a ConfigError naming the range."""
    from scipy.spatial.transform import Rotation

    from reactmocap.errors import ConfigError

    world, servo = _random_world(guard, 1.0, 3)
    d = world.data
    servo.refresh()
    mujoco.mj_forward(world.model, d)
    full = d.qfrc_actuator[servo.dof_indices].reshape(-1, 3).copy()
    axes = Rotation.random(NJ, random_state=4).as_matrix().transpose(0, 2, 1)  # rows: axes
    scale = np.ones((NJ, 3))
    scale[[3, 7], 0] = 0.0
    scale[5] = (0.25, 1.0, 0.5)
    servo.set_axis_gains(0, axes, scale)
    servo.refresh()
    mujoco.mj_forward(world.model, d)
    act = d.qfrc_actuator[servo.dof_indices].reshape(-1, 3)
    inertia = d.M[servo._midx]
    for j in (3, 5, 7):
        s = axes[j].T @ np.diag(np.sqrt(scale[j])) @ axes[j]
        want = s @ inertia[j] @ s @ np.linalg.solve(inertia[j], full[j])
        np.testing.assert_allclose(act[j], want, rtol=1e-9, atol=1e-9 * np.abs(full).max())
    for j in (3, 7):
        assert abs(act[j] @ axes[j, 0]) <= 1e-9 * np.abs(full[j]).max()
        assert np.abs(act[j]).max() > 1e-3 * np.abs(full[j]).max()
    rest = np.ones(2 * NJ, dtype=bool)
    rest[[3, 5, 7]] = False
    np.testing.assert_allclose(act[rest], full[rest], rtol=1e-12, atol=1e-12 * np.abs(full).max())
    np.testing.assert_allclose(servo.torques(), act, rtol=1e-9, atol=1e-9 * np.abs(full).max())
    servo.set_axis_gains(0, axes, np.ones((NJ, 3)))
    servo.refresh()
    mujoco.mj_forward(world.model, d)
    assert np.array_equal(d.qfrc_actuator[servo.dof_indices].reshape(-1, 3), full)
    with pytest.raises(ConfigError, match=r"in \[0, 1\]"):
        servo.set_axis_gains(0, axes, np.full((NJ, 3), 1.5))


def test_gain_scales_at_once_equal_one_joint_at_a_time(guard: Motion) -> None:
    """set_gain_scales (one gain refresh, the athletic rigs' set_stiffness) leaves the
    actuators and their torques as set_gain_scale joint by joint; NaN keeps a joint's scale."""
    from reactmocap.errors import ConfigError
    from reactmocap.sim.bodies import BALL_JOINTS

    scales = np.linspace(0.5, 2.0, NJ)
    kept = BALL_JOINTS.index("l_knee")
    scales[kept] = np.nan
    worlds = []
    for at_once in (False, True):
        world, servo = _random_world(guard, 1.0, 0)
        servo.set_gain_scale(1, ["l_knee"], 3.0)
        if at_once:
            servo.set_gain_scales(1, scales)
        else:
            for j, scale in zip(BALL_JOINTS, scales):
                if not np.isnan(scale):
                    servo.set_gain_scale(1, [j], float(scale))
        servo.refresh()
        mujoco.mj_forward(world.model, world.data)
        worlds.append(world)
    one, both = worlds
    _assert_same_actuation(one, both)
    assert both.servo._gain_scale[NJ + kept] == 3.0  # the NaN kept the knee's scale
    with pytest.raises(ConfigError, match="gain scales"):
        both.servo.set_gain_scales(1, np.zeros(NJ))
    with pytest.raises(ConfigError, match="gain scales"):
        both.servo.set_gain_scales(1, np.ones(3))


def _assert_same_actuation(one: World, both: World) -> None:
    """The two worlds' actuators and the torques they apply are the same to the bit."""
    for name in ("actuator_gainprm", "actuator_biasprm", "actuator_gear"):
        np.testing.assert_array_equal(getattr(both.model, name), getattr(one.model, name))
    np.testing.assert_array_equal(both.data.qfrc_actuator, one.data.qfrc_actuator)


def test_gain_scales_with_switches_equal_enable_then_scales(guard: Motion) -> None:
    """set_gain_scales' ``enabled`` (the rigs' set_stiffness: one gain refresh) leaves the
    actuators and their torques as enable() for the joints off, then on, then the scales."""
    from reactmocap.errors import ConfigError
    from reactmocap.sim.bodies import BALL_JOINTS

    scales = np.linspace(0.5, 2.0, NJ)
    on = np.arange(NJ) % 3 != 0
    scales[~on] = np.nan
    worlds = []
    for at_once in (False, True):
        world, servo = _random_world(guard, 1.0, 0)
        if at_once:
            servo.set_gain_scales(1, scales, enabled=on)
        else:
            servo.enable(1, [BALL_JOINTS[i] for i in np.flatnonzero(~on)], False)
            servo.enable(1, [BALL_JOINTS[i] for i in np.flatnonzero(on)], True)
            servo.set_gain_scales(1, scales)
        servo.refresh()
        mujoco.mj_forward(world.model, world.data)
        worlds.append(world)
    one, both = worlds
    _assert_same_actuation(one, both)
    assert not both.servo.enabled[NJ:][~on].any()  # the switched-off joints are passive
    with pytest.raises(ConfigError, match="enabled"):
        both.servo.set_gain_scales(1, scales, enabled=np.ones(3, dtype=bool))


def test_set_targets_normalises_into_the_servo_and_keeps_frozen_clamps(guard: Motion) -> None:
    # set_targets writes into its buffers: the same q / |q| and right matrices as the plain
    # expressions, frozen joints keep their clamp targets
    _, servo = _random_world(guard, 2.0, 3)
    rng = np.random.default_rng(3)
    q = rng.normal(size=(NJ, 4)) * 3.0
    clamp = servo.targets[:NJ].copy()
    servo.set_targets(0, q)
    want = q / np.sqrt(np.einsum("ij,ij->i", q, q))[:, None]
    frozen = servo.frozen[:NJ]
    assert frozen.any()
    want[frozen] = clamp[frozen]
    np.testing.assert_array_equal(servo.targets[:NJ], want)
    np.testing.assert_array_equal(servo._rd[:NJ], _right_matrix(want))
    with pytest.raises(SimulationError, match="NaN"):
        servo.set_targets(0, np.full((NJ, 4), np.nan))


def test_refresh_raises_on_an_inertia_that_is_not_positive_definite(guard: Motion) -> None:
    world, servo = _random_world(guard, 1.0, 4)
    servo.refresh()
    world.data.M[servo._midx[3, 0, 0]] = -1.0  # one joint's block no longer positive definite
    with pytest.raises(SimulationError, match="not positive definite"):
        servo.refresh()
