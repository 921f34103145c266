"""Stance-leg balance: gravity compensation is MuJoCo's gravity torque, the controller keeps a
standing clip up where plain PD tracking falls, and it only touches its own character."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips
from reactmocap.sim import PDServo, StanceBalance, World, build_character, track_clip
from reactmocap.sim.character import BALL_JOINTS


@pytest.fixture(scope="module")
def clips() -> dict[str, Motion]:
    return synthetic_clips(30.0)


@pytest.fixture(scope="module")
def guard_loop(clips: dict[str, Motion]) -> Motion:
    g = clips["guard"]
    return Motion.concatenate([g, g.slice(1)], name="guard_x2")


def test_gravity_compensation_is_mujocos_gravity_torque(clips: dict[str, Motion]) -> None:
    kick = clips["front_kick"]
    world = World(build_character(kick, frame=0))
    world.set_from_motion(0, kick, 20)
    m, d = world.model, world.data
    d.qvel[:] = 0.0
    d.qpos[2] += 1.0  # in the air: no support, only gravity compensation
    mujoco.mj_forward(m, d)
    servo = world.servo
    bal = StanceBalance(world, 0, kick, velocity_feedforward=False, control_every=10)
    bal.control(world, 0.0)
    wc = world.characters[0]
    bias = d.qfrc_bias[wc.ball_dof_start : wc.ball_dof_start + 45]  # gravity only at rest
    np.testing.assert_allclose(servo.feedforward.reshape(-1), bias, atol=1e-9)
    assert np.abs(bias).max() > 1.0


def test_feedforward_holds_a_standing_pose_with_a_weak_servo(clips: dict[str, Motion]) -> None:
    """Statics: with a PD servo far too weak to carry the body, the balance feed-forward keeps
    a standing character up for half a second; without it the character collapses. The
    other character in the world is left alone."""
    guard = clips["guard"]

    def pelvis_drop(balance: bool) -> tuple[float, PDServo]:
        world = World([build_character(guard, frame=0), build_character(guard, frame=0)])
        world.set_from_motion(0, guard, 0)
        world.set_from_motion(1, guard, 0)
        world.data.qpos[world.characters[0].qpos_adr] += 3.0  # apart
        mujoco.mj_forward(world.model, world.data)
        servo = PDServo(world, kp=100.0)  # 40x weaker than the default
        bal = StanceBalance(world, 1, guard, control_every=4) if balance else None
        z0 = world.com(1)[2]
        for k in range(250):  # 0.5 s, control every 2 ms
            if bal is not None:
                bal.control(world, 0.002 * k)
            for _ in range(4):
                servo.apply()
                mujoco.mj_step(world.model, world.data)
        return z0 - world.com(1)[2], servo

    weak, _ = pelvis_drop(False)
    held, servo = pelvis_drop(True)
    assert weak > 0.15, weak
    assert held < 0.02, held
    assert np.all(servo.feedforward[:15] == 0.0)


def test_balance_keeps_a_standing_clip_up(guard_loop: Motion) -> None:
    secs = 3.5
    plain = track_clip(guard_loop, seconds=secs, controller="pd").report
    bal = track_clip(guard_loop, seconds=secs, controller="balance").report
    assert plain.fell, "plain PD tracking is expected to topple (no balance control)"
    assert not bal.fell
    assert bal.max_root_error_m < 0.03
    assert bal.mean_joint_error_rad < 0.02
    assert bal.controller == "balance" and plain.controller == "pd"


@pytest.mark.parametrize(
    ("key", "value"), [("kp_com", -1.0), ("kp_rot", float("nan")), ("friction", -0.1)]
)
def test_bad_gains_rejected(clips: dict[str, Motion], key: str, value: float) -> None:
    world = World(build_character(clips["guard"], frame=0))
    with pytest.raises(ConfigError, match=key):
        StanceBalance(world, 0, clips["guard"], control_every=10, **{key: value})  # type: ignore[arg-type]


def test_unknown_character_rejected(clips: dict[str, Motion]) -> None:
    world = World(build_character(clips["guard"], frame=0))
    with pytest.raises(ConfigError, match="character 3"):
        StanceBalance(world, 3, clips["guard"], control_every=10)


@pytest.mark.parametrize("controller", ["balance", "wholebody"])
def test_root_assist_only_with_plain_pd(guard_loop: Motion, controller: str) -> None:
    with pytest.raises(ConfigError, match="root_assist cannot be combined"):
        track_clip(guard_loop, seconds=0.2, root_assist=100.0, controller=controller)
    rep = track_clip(guard_loop, seconds=0.2, root_assist=100.0, controller="pd").report
    assert rep.root_assist == 100.0 and rep.controller == "pd"


@pytest.mark.parametrize("gain", [-5.0, float("nan")])
def test_root_assist_refuses_a_negative_or_nan_gain(guard_loop: Motion, gain: float) -> None:
    with pytest.raises(ConfigError, match="root_assist must be a finite gain >= 0"):
        track_clip(guard_loop, seconds=0.2, root_assist=gain, controller="pd")


def test_stance_legs_get_stiffer_gains(clips: dict[str, Motion]) -> None:
    guard = clips["guard"]
    world = World(build_character(guard, frame=0))
    world.set_from_motion(0, guard, 0)
    servo = PDServo(world, kp=4000.0)
    bal = StanceBalance(world, 0, guard, stance_gain_scale=9.0, control_every=10)
    servo.step(40)  # settle onto the floor
    bal.control(world, 0.0)
    a = world.characters[0].actuator_adr
    gains = world.model.actuator_gainprm[a : a + 45, 0].reshape(15, 3)[:, 0]
    knee, elbow = BALL_JOINTS.index("l_knee"), BALL_JOINTS.index("l_elbow")
    assert gains[knee] == pytest.approx(9.0 * 4000.0)
    assert gains[elbow] == pytest.approx(4000.0)
    with pytest.raises(ConfigError, match="stance_gain_scale"):
        StanceBalance(world, 0, guard, stance_gain_scale=0.0, control_every=10)
    with pytest.raises(ConfigError, match="gain scale"):
        servo.set_gain_scale(0, ["l_knee"], float("nan"))
