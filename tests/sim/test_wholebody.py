"""Whole-body tracker: its plan is exact inverse dynamics (MuJoCo's forward dynamics under the
planned torques and ground forces gives the planned accelerations), the forces respect the
friction pyramid, it keeps clips up where the PD servo falls, and it is deterministic."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim import (
    CONTROLLERS,
    FunctionController,
    PDServo,
    WholeBodyTracker,
    World,
    build_character,
    controller_spec,
    rollout,
    track_clip,
)
from reactmocap.sim.character import BALL_JOINTS, PATCH_GEOM_GROUP
from reactmocap.sim.controllers.registry import WHOLE_CLIP, build

SHARED = Path(__file__).resolve().parents[3] / "shared" / "mocap"


def _tracker(world: World, motion: Motion, start: float, **kw: float | None) -> WholeBodyTracker:
    """The registry's whole-body tracker, its servo gains set as a rollout would."""
    spec = controller_spec("wholebody")
    args = {"kp_joint": spec.defaults["kp"], "servo_kv": spec.defaults["servo_kv"],
            "control_every": 4, **kw}  # fmt: skip
    wb = WholeBodyTracker(world, 0, motion, start=start, **args)  # type: ignore[arg-type]
    wb.reset(world)
    return wb


def _standing(
    motion: Motion, frame: int, **kw: float | None
) -> tuple[World, PDServo, WholeBodyTracker]:
    world = World(build_character(motion, frame=frame))
    world.set_from_motion(0, motion, frame)
    mujoco.mj_forward(world.model, world.data)
    wb = _tracker(world, motion, frame / motion.fps, **kw)
    return world, world.servo, wb


@pytest.mark.parametrize(("clip", "frame"), [("guard", 10), ("step_forward", 20)])
def test_plan_is_inverse_dynamics(request: pytest.FixtureRequest, clip: str, frame: int) -> None:
    motion: Motion = request.getfixturevalue(clip)
    world, servo, wb = _standing(motion, frame)
    plan = wb.plan(0.0)
    assert plan.support, "a standing frame must have a supporting foot"
    fz = plan.forces[:, 2]
    assert np.all(fz >= -1e-9)
    # pyramid: each horizontal component within mu * normal
    mu = 0.7 * world.config.friction
    assert np.all(np.abs(plan.forces[:, :2]) <= mu * fz[:, None] + 1e-6)
    weight = float(world.model.body_subtreemass[world.characters[0].body_ids[0]]) * 9.81
    assert 0.3 * weight < fz.sum() < 3.0 * weight
    # forward dynamics with contacts and limits off, the servo silent, the planned joint
    # torques applied and the planned ground forces as generalised forces: qacc == plan
    m, d = world.model, world.data
    servo.clear()
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_LIMIT)
    wc = world.characters[0]
    d.qfrc_applied[:] = 0.0
    mujoco.mj_forward(m, d)
    # the plan leaves passive joint damping out on purpose: cancel it here
    d.qfrc_applied[wc.qvel_slice] = plan.generalized_contact - d.qfrc_passive[wc.qvel_slice]
    d.qfrc_applied[wc.ball_dof_start : wc.ball_dof_start + 45] += plan.torques.reshape(-1)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(
        d.qacc[wc.qvel_slice], plan.qacc, atol=1e-6 * (1 + np.abs(plan.qacc).max())
    )


def test_plan_without_support_conserves_momentum(guard: Motion) -> None:
    world, _servo, wb = _standing(guard, 10)
    world.data.qpos[2] += 0.5  # in the air
    mujoco.mj_forward(world.model, world.data)
    plan = wb.plan(0.0)
    assert plan.support == () and plan.forces.shape == (0, 3)
    # only gravity acts on the whole body: the pelvis rows of M qacc + bias are zero
    m, d = world.model, world.data
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    root = (full @ plan.qacc + d.qfrc_bias)[:6]
    np.testing.assert_allclose(root, 0.0, atol=1e-6)


def test_wholebody_keeps_the_guard_up_where_pd_falls(guard: Motion) -> None:
    loop = Motion.concatenate([guard, guard.slice(1)], name="guard_x2")
    pd = track_clip(loop, seconds=3.5, controller="pd").report
    wb = track_clip(loop, seconds=3.5).report
    assert pd.fell
    assert wb.controller == "wholebody" and not wb.fell
    assert wb.max_root_error_m < 0.03
    assert wb.mean_joint_error_rad < 0.05


def test_wholebody_tracks_a_step_where_pd_and_balance_fall(step_forward: Motion) -> None:
    rep = track_clip(step_forward).report
    for other in ("pd", "balance"):
        o = track_clip(step_forward, controller=other).report
        assert o.fell and o.max_root_error_m > 0.5
    assert not rep.fell
    assert rep.max_root_error_m < 0.5
    assert rep.root_angle_error_rad < np.radians(10.0)


@pytest.mark.parametrize("clip", ["step_forward", "punch"])
def test_planned_forces_are_the_simulated_ones(request: pytest.FixtureRequest, clip: str) -> None:
    """The plan's total ground force matches what MuJoCo's contacts then produce under the
    planned torques (within 15% at the 90th percentile of control ticks). Planning on corners
    hovering within 1 cm with a soft tangential-only no-slip term gave 26-34% here."""
    motion: Motion = request.getfixturevalue(clip)
    # exactly MuJoCo's contact set (the default 3 mm band plans on corners about to touch)
    world, _servo, wb = _standing(motion, 0, touch=0.0)
    m = world.model
    probe = mujoco.MjData(m)
    f6 = np.zeros(6)
    errors: list[float] = []

    def check(w: World, t: float) -> None:
        wb.control(w, t)
        plan = wb.last_plan
        assert plan is not None
        if not plan.support or t < 0.01:
            return
        mujoco.mj_copyData(probe, m, w.data)
        mujoco.mj_forward(m, probe)
        total = np.zeros(3)
        for c in range(probe.ncon):
            con = probe.contact[c]
            mujoco.mj_contactForce(m, probe, c, f6)
            on_character = con.frame.reshape(3, 3).T @ f6[:3]
            total += on_character if m.geom_bodyid[con.geom1] == 0 else -on_character
        planned = plan.forces.sum(axis=0)
        errors.append(float(np.linalg.norm(total - planned) / np.linalg.norm(planned)))

    rollout(world, 1.0, controllers=[FunctionController(check, 4)])
    assert len(errors) > 100
    assert np.percentile(errors, 90) < 0.15, np.percentile(errors, [50, 90])


def test_wholebody_is_deterministic(step_forward: Motion) -> None:
    a = track_clip(step_forward, seconds=0.3).rollout
    b = track_clip(step_forward, seconds=0.3).rollout
    assert np.array_equal(a.qpos, b.qpos)


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"shared mocap not found at {SHARED}")
def test_wholebody_tracks_a_real_walk() -> None:
    from reactmocap.library.bvh import read_bvh

    clips = sorted(SHARED.glob("*/*walk_normal_001.bvh"))
    if not clips:
        pytest.skip(f"no walk_normal_001 clip under {SHARED}")
    walk = read_bvh(clips[0])
    for start in (2.5, 3.5):
        res = track_clip(walk, start=start, seconds=1.0)
        assert not res.report.fell
        assert float(np.max(res.errors.root)) <= 0.10
        assert float(np.max(res.errors.angle)) <= np.radians(15.0)


def _stance_yaw_lag(
    kick: Motion, start: float, seconds: float, pivot_rate: float | None
) -> tuple[float, int]:
    """Largest gap (deg) between the simulated and the mocap left-sole yaw while tracking, and
    the number of control ticks the left foot spent on its ball patch."""
    world = World(build_character(kick, frame=round(start * kick.fps)))
    world.set_from_motion(0, kick, round(start * kick.fps))
    wb = _tracker(world, kick, start, pivot_rate=pivot_rate)
    sole = int(world.characters[0].sole_ids[0])
    ref = mujoco.MjData(world.model)
    sim_yaw: list[float] = []
    ref_yaw: list[float] = []
    ticks = [0]

    def spy(w: World, t: float) -> None:
        wb.control(w, t)
        ticks[0] += int(w.foot_patch_on(0)[0])
        ref.qpos[world.characters[0].qpos_slice] = wb.reference(t)[0]
        mujoco.mj_kinematics(world.model, ref)
        for data, out in ((w.data, sim_yaw), (ref, ref_yaw)):
            x = data.geom_xmat[sole]
            out.append(float(np.arctan2(x[3], x[0])))

    rollout(world, seconds, controllers=[FunctionController(spy, 4)])
    gap = np.abs(np.unwrap(sim_yaw) - np.unwrap(ref_yaw))
    return float(np.degrees(gap.max())), ticks[0]


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"shared mocap not found at {SHARED}")
def test_a_pivoting_stance_foot_turns_on_its_ball_patch() -> None:
    """The kick clip turns the planted left foot by about 84 degrees in 0.25 s from 1.35 s: on
    its ball patch the simulated foot follows, a box foot under friction 1.0 lags behind."""
    from reactmocap.library.bvh import read_bvh

    clips = sorted(SHARED.glob("*/*kick_normal_001.bvh"))
    if not clips:
        pytest.skip(f"no kick_normal_001 clip under {SHARED}")
    kick = read_bvh(clips[0])
    lag_patch, ticks = _stance_yaw_lag(kick, 1.35, 0.25, pivot_rate=2.0)
    lag_box, no_ticks = _stance_yaw_lag(kick, 1.35, 0.25, pivot_rate=None)
    assert ticks > 20 and no_ticks == 0
    assert lag_patch < 10.0  # measured 3.4
    assert lag_box > 25.0  # measured 39.4


def test_foot_patch_moves_the_contact(guard: Motion) -> None:
    """The ball patch is hidden and off until switched on; then it, not the box,
    touches the floor, and switching back restores the box."""
    world = World(build_character(guard, frame=0))
    world.set_from_motion(0, guard, 0)
    m, d = world.model, world.data
    wc = world.characters[0]
    assert np.all(m.geom_group[wc.patch_ids] == PATCH_GEOM_GROUP)
    d.qpos[wc.qpos_slice.start + 2] -= 0.005  # press the feet into the floor

    def touching() -> set[int]:
        mujoco.mj_forward(m, d)
        return {int(d.contact[i].geom[j]) for i in range(d.ncon) for j in range(2)}

    assert not world.foot_patch_on(0).any()
    assert set(wc.sole_ids) <= touching() and not set(wc.patch_ids) & touching()
    world.set_foot_patch(0, 0, True)
    assert world.foot_patch_on(0).tolist() == [True, False]
    on = touching()
    assert int(wc.patch_ids[0]) in on and int(wc.sole_ids[0]) not in on
    assert int(wc.sole_ids[1]) in on
    world.set_foot_patch(0, 0, False)
    assert set(wc.sole_ids) <= touching() and not set(wc.patch_ids) & touching()


def test_unknown_controller_lists_the_keys(guard: Motion) -> None:
    with pytest.raises(UnknownKeyError, match="wholebody"):
        track_clip(guard, seconds=0.1, controller="nope")
    with pytest.raises(UnknownKeyError, match="balance"):
        controller_spec("nope")
    assert {"wholebody", "predictive", "balance", "pd"} <= set(CONTROLLERS)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("kp_root", -1.0),
        ("kp_joint", float("nan")),
        ("friction", -0.5),
        ("reach", float("inf")),
        ("pivot_rate", -2.0),
        ("anchor_tau", -0.1),
        ("step_time", float("nan")),
        ("trunk_weight", -1.0),
        ("torque_limit", -100.0),
        ("hip_weight", -1.0),
        ("hip_free", 0.0),
        ("hip_free", 1.5),
        ("step_leg", -0.1),
        ("step_leg", 3.0),
        ("step_short", -0.3),
        ("place_pushed", -1.0),
        ("warp_lead", -0.5),
        ("warp_phase", -1.0),
        ("hip_tilt_step", -0.5),
        ("step_ease", -0.1),
        ("step_ease_in", -0.1),
        ("step_hold", -0.3),
        ("step_hold_for", -0.5),
        ("step_soft", -0.05),
        ("step_soft_reg", -1e-2),
        ("anchor_lag", -0.3),
        ("anchor_lag_heading", -30.0),
        ("anchor_lag_speed", -0.45),
        ("step_ahead", -1.0),
        ("step_ahead_horizon", -0.1),
        ("step_ahead_swing", -0.5),
        ("step_ahead_phase", -0.05),
        ("centre_speed", -1.0),
        ("centre_speed_lock", -2.5),
        ("centre_speed_lock_walking", -0.7),
        ("anchor_turn_rate", -0.5),
        ("step_ahead_servo", -20.0),
        ("flat_weight", -1.0),
        ("flat_band", 0.0),
        ("flat_band", 2.0),
        ("flat_toe", -0.1),
    ],
)
def test_bad_parameters_rejected(guard: Motion, key: str, value: float) -> None:
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match=key):
        _tracker(world, guard, 0.0, **{key: value})


def _edge_tilt(
    clip: Motion, start: float, seconds: float, flat_weight: float, flat_toe: float = 0.0
) -> float:
    """Mean over the control ticks and the feet planted in the clip of how far (deg) the
    simulated sole tilts past the clip's, tracking with ``WHOLE_CLIP``, ``flat_weight`` and
    ``flat_toe``."""
    frame = round(start * clip.fps)
    world = World(build_character(clip, frame=frame))
    world.set_from_motion(0, clip, frame)
    params = {**WHOLE_CLIP, "flat_weight": flat_weight, "flat_toe": flat_toe}
    wb = build("wholebody", world, clip, params, start=start)
    assert isinstance(wb, WholeBodyTracker) and wb.path.sole_up is not None
    excess: list[float] = []

    def spy(w: World, t: float) -> None:
        wb.control(w, t)
        i = wb.clock.nearest(t)
        up = w.data.geom_xmat[wb.sole].reshape(2, 3, 3)[:, 2, 2]  # the soles' z axes' height
        tilt = np.degrees(np.arccos(np.clip(up, -1.0, 1.0)))
        clip_tilt = np.degrees(np.arccos(np.clip(wb.path.sole_up[i, :, 2], -1.0, 1.0)))  # type: ignore[index]
        excess.extend((tilt - clip_tilt)[wb.path.planted[i]])

    rollout(world, seconds, controllers=[FunctionController(spy, 4)], on_unstable="stop")
    return float(np.mean(excess))


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"shared mocap not found at {SHARED}")
def test_flat_weight_turns_feet_standing_on_an_edge_back_toward_the_clips_soles() -> None:
    """``punch_normal_001``'s fighting stance from 2.0 s: the simulated feet stand on one or two
    corners tilted past the clip's soles (mean 7.8 deg over 1.5 s); the flat rows turn them
    back (5.3 deg)."""
    from reactmocap.library.bvh import read_bvh

    clips = sorted(SHARED.glob("*/*punch_normal_001.bvh"))
    if not clips:
        pytest.skip(f"no punch_normal_001 clip under {SHARED}")
    punch = read_bvh(clips[0])
    off, on = (_edge_tilt(punch, 2.0, 1.5, w) for w in (0.0, 1.0))
    assert off > 5.0, off  # the defaults' feet do stand tilted past the clip's
    assert on < 0.8 * off, (on, off)


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"shared mocap not found at {SHARED}")
def test_flat_toe_spares_a_clip_standing_on_the_balls_of_its_feet() -> None:
    """``punch_normal_001`` stands on the balls of its feet (its planted soles' median
    toe-down pitch 9 deg): ``flat_toe`` 0.1 rad leaves it the defaults' run exactly (no flat
    rows), 0.2 rad (past its 9 deg) ``flat_weight``'s own run."""
    from reactmocap.library.bvh import read_bvh

    clips = sorted(SHARED.glob("*/*punch_normal_001.bvh"))
    if not clips:
        pytest.skip(f"no punch_normal_001 clip under {SHARED}")
    punch = read_bvh(clips[0])
    off, on = (_edge_tilt(punch, 2.0, 0.5, w) for w in (0.0, 1.0))
    spared, kept = (_edge_tilt(punch, 2.0, 0.5, 1.0, toe) for toe in (0.1, 0.2))
    assert on != off, (on, off)  # the rows act on this clip
    assert spared == off, (spared, off)
    assert kept == on, (kept, on)


def test_flat_toe_needs_flat_weight(guard: Motion) -> None:
    """``flat_toe`` without the flat rows, or past a right angle, is refused."""
    world = World(build_character(guard, frame=0))
    for kw in ({"flat_toe": 0.1}, {"flat_weight": 1.0, "flat_toe": 2.0}):
        with pytest.raises(ConfigError, match="flat_toe"):
            _tracker(world, guard, 0.0, **kw)


def test_centre_speed_lock_walking_needs_the_lock(guard: Motion) -> None:
    """The foot lock's walking gate (``centre_speed_lock_walking``) without the lock is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="centre_speed_lock_walking"):
        _tracker(world, guard, 0.0, centre_speed_lock_walking=0.7)


def test_anchor_turn_rate_needs_the_anchoring(guard: Motion) -> None:
    """The anchoring's turn bound (``anchor_turn_rate``) without the anchoring is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="anchor_turn_rate"):
        _tracker(world, guard, 0.0, anchor_turn_rate=0.5)


def test_step_ahead_growth_needs_its_step(guard: Motion) -> None:
    """The lead's growth (``step_ahead_horizon``) only extends ``step_ahead``'s trigger:
    alone it is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="step_ahead_horizon"):
        _tracker(world, guard, 0.0, step_ahead_horizon=0.1)


@pytest.mark.parametrize("extra", [{}, {"step_ahead": 1.0, "step_ahead_swing": 1.5}])
def test_step_ahead_swing_needs_its_step_and_a_fraction(guard: Motion, extra: dict) -> None:
    """``step_ahead_swing`` only extends ``step_ahead``'s trigger and is a fraction of the
    clip's swing left: alone, or past 1, it is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="step_ahead_swing"):
        _tracker(world, guard, 0.0, **({"step_ahead_swing": 1.0} | extra))


@pytest.mark.parametrize(
    "extra",
    [{"step_ahead": 1.0}, {"step_ahead": 1.0, "step_ahead_swing": 1.0, "step_ahead_phase": 0.8}],
)
def test_step_ahead_phase_needs_the_swing_step_and_a_margin(guard: Motion, extra: dict) -> None:
    """``step_ahead_phase`` sets ``step_ahead_swing``'s limit and is a margin of at most
    0.5 m: without the swing step, or past 0.5 m, it is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="step_ahead_phase"):
        _tracker(world, guard, 0.0, **({"step_ahead_phase": 0.1} | extra))


@pytest.mark.parametrize("extra", [{}, {"step_ahead": 1.0, "step_ahead_servo": 150.0}])
def test_step_ahead_servo_needs_its_step_and_a_gain(guard: Motion, extra: dict) -> None:
    """``step_ahead_servo`` is the pelvis gain during ``step_ahead``'s steps, at most 100:
    without ``step_ahead``, or past 100, it is refused."""
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="step_ahead_servo"):
        _tracker(world, guard, 0.0, **({"step_ahead_servo": 20.0} | extra))


def test_a_look_ahead_restores_the_lead_growths_state(guard: Motion) -> None:
    """``step_ahead_horizon``'s smoothed capture-point velocity is tick-to-tick state: a
    predictive look ahead (:meth:`memory` / :meth:`restore`) must put it back."""
    world = World(build_character(guard, frame=0))
    tracker = _tracker(world, guard, 0.0, step_ahead=1.0, step_ahead_horizon=0.1)
    memory = tracker.memory()
    tracker._xi_rate += (0.5, -0.2)  # in place, as the slow tick updates it
    tracker._xi_last = (1.0, np.ones(2))
    tracker.restore(memory)
    assert np.array_equal(tracker._xi_rate, np.zeros(2))
    assert tracker._xi_last[0] == -np.inf


def test_unknown_character_rejected(guard: Motion) -> None:
    world = World(build_character(guard, frame=0))
    with pytest.raises(ConfigError, match="character 2"):
        WholeBodyTracker(world, 2, guard, kp_joint=1000.0, servo_kv=20.0, control_every=4)


def test_cli_track_controller_choice(
    guard: Motion, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    from reactmocap.cli import main
    from reactmocap.library.bvh import write_bvh

    clip = tmp_path / "guard.bvh"
    write_bvh(guard, clip)
    for controller in ("pd", "balance", "wholebody", "predictive"):
        report = tmp_path / f"{controller}.json"
        args = ["track", str(clip), "--seconds", "0.3", "--controller", controller]
        assert main([*args, "--report", str(report)]) == 0
        assert json.loads(report.read_text())["controller"] == controller
    assert main(["track", str(clip), "--seconds", "0.3", "--controller", "nope"]) == 2
    err = capsys.readouterr().err
    assert "unknown controller 'nope'" in err and "wholebody" in err
    assert not (tmp_path / "nope.json").exists()


def test_trunk_rows_keep_the_chest_turning_as_tracked(guard: Motion) -> None:
    """With the pelvis pushed 8 cm off its target the plan cannot follow every target; with
    ``trunk_weight`` it keeps the chest's world angular acceleration nearer the one the
    targets ask (rather than bending the waist to hold the pelvis)."""
    misses = []
    for weight in (0.0, 30.0):
        world, _, wb = _standing(guard, 10, trunk_weight=weight)
        m, d = world.model, world.data
        d.qpos[world.characters[0].qpos_adr] += 0.08
        mujoco.mj_forward(m, d)
        plan = wb.plan(0.0)
        chest = int(world.characters[0].body_ids[2])
        jr = np.zeros((3, m.nv))
        mujoco.mj_jac(m, d, None, jr, d.xpos[chest], chest)
        sl = world.characters[0].qvel_slice
        misses.append(float(np.linalg.norm(jr[:, sl] @ (plan.qacc - plan.desired_qacc))))
    assert misses[0] > 10.0, misses  # rad/s^2: the offset is big enough to matter
    assert misses[1] < 0.1 * misses[0], misses


def test_hold_balance_keeps_the_pelvis_and_legs_stiff_once_the_capture_point_leaves_the_feet(
    guard: Motion,
) -> None:
    # the body set off its reference at the pelvis, a knee and an elbow, standing still or
    # thrown forward at 2 m/s (its capture point ~0.6 m ahead of the feet); the desired
    # accelerations of one control tick at full gains or yielding to 10%
    frame = 10
    t = frame / guard.fps
    rows = {j: 6 + 3 * BALL_JOINTS.index(j) + np.arange(3) for j in ("l_knee", "l_elbow")}

    def desired(speed: float, scale: float, **kw: bool) -> NDArray[np.float64]:
        world = World(build_character(guard, frame=frame))
        world.set_from_motion(0, guard, frame)
        wc = world.characters[0]
        world.data.qvel[wc.qvel_slice] = 0.0
        world.data.qvel[wc.qvel_slice.start] = speed
        world.data.qpos[wc.qpos_slice.start] += 0.05
        for joint in ("l_knee", "l_elbow"):
            k = wc.qpos_slice.start + 7 + 4 * BALL_JOINTS.index(joint)
            world.data.qpos[k : k + 4] = [np.cos(0.1), np.sin(0.1), 0.0, 0.0]
        mujoco.mj_forward(world.model, world.data)
        wb = _tracker(world, guard, t, **kw)  # type: ignore[arg-type]
        wb.scale_gains(scale)
        wb.control(world, t)
        assert wb.last_plan is not None
        return wb.last_plan.desired_qacc

    thrown = {"full": desired(2.0, 1.0), "low": desired(2.0, 0.1),
              "held": desired(2.0, 0.1, hold_balance=True)}  # fmt: skip
    for r in (np.arange(6), rows["l_knee"]):  # the pelvis and the knee keep their gains
        np.testing.assert_allclose(thrown["held"][r], thrown["full"][r])
        assert not np.allclose(thrown["low"][r], thrown["full"][r])
    np.testing.assert_allclose(thrown["held"][rows["l_elbow"]], thrown["low"][rows["l_elbow"]])
    assert not np.allclose(thrown["held"][rows["l_elbow"]], thrown["full"][rows["l_elbow"]])
    # standing still, the capture point is over the feet: everything yields
    np.testing.assert_allclose(desired(0.0, 0.1, hold_balance=True), desired(0.0, 0.1))


def test_torque_limit_bounds_every_joint_torque_the_plan_applies(step_forward: Motion) -> None:
    # the plan's torques reach the body as the servo's feed-forward, which no actuator limit
    # clips; with ``torque_limit`` each ball joint's total torque at a tick stays within it
    limit = 40.0
    world, servo, wb = _standing(step_forward, 20, torque_limit=limit)
    asked = []
    for k in range(40):  # 20 control ticks
        t = k * wb.control_every * world.timestep
        wb.control(world, t)
        asked.append(np.linalg.norm(wb.last_plan.torques, axis=1).max())  # type: ignore[union-attr]
        applied = wb._ff + servo.torques(0)
        assert np.linalg.norm(applied, axis=1).max() <= limit * (1 + 1e-9)
        servo.step(wb.control_every)
    # the plan asked for more than the limit: the bound did something
    assert max(asked) > 2 * limit


def test_stiffen_joints_stiffens_the_joint_rows_only_and_reset_undoes_it(guard: Motion) -> None:
    # the response's physical mode stiffens the hit body's joints from the match on
    frame = 10
    world = World(build_character(guard, frame=frame))
    world.set_from_motion(0, guard, frame)
    wc = world.characters[0]
    world.data.qpos[wc.qpos_slice.start] += 0.05  # the pelvis and a knee off the reference
    k = wc.qpos_slice.start + 7 + 4 * BALL_JOINTS.index("l_knee")
    world.data.qpos[k : k + 4] = [np.cos(0.1), np.sin(0.1), 0.0, 0.0]
    mujoco.mj_forward(world.model, world.data)
    wb = _tracker(world, guard, frame / guard.fps)
    kp, kv = wb.kp.copy(), wb.kv.copy()
    wb.control(world, frame / guard.fps)
    assert wb.last_plan is not None
    before = wb.last_plan.desired_qacc.copy()
    wb.stiffen_joints(4.0)
    np.testing.assert_allclose(wb.kp[6:], 4.0 * kp[6:])
    np.testing.assert_allclose(wb.kv[6:], 2.0 * kv[6:])
    np.testing.assert_array_equal(wb.kp[:6], kp[:6])
    wb.control(world, frame / guard.fps)
    after = wb.last_plan.desired_qacc
    knee = 6 + 3 * BALL_JOINTS.index("l_knee") + np.arange(3)
    np.testing.assert_allclose(after[:6], before[:6])  # the pelvis rows as built
    assert np.abs(after[knee]).max() > 2.0 * np.abs(before[knee]).max()
    wb.scale_gains(0.5)  # a gain schedule scales the stiffened gains
    np.testing.assert_allclose(wb.kp[6:], 2.0 * kp[6:])
    wb.reset(world)
    wb.scale_gains(1.0)
    np.testing.assert_allclose(wb.kp, kp)
    np.testing.assert_allclose(wb.kv, kv)
    with pytest.raises(ConfigError, match="factor must be > 0"):
        wb.stiffen_joints(0.0)
