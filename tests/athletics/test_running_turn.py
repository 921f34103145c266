"""A commanded facing change turns the runner by the commanded angle; at 2.5 m/s (the speed
the paths are run at) the stance estimate of eqs. 1-2 is smoothed over the steps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from reactmocap.athletics.paths import Facing, Polyline
from reactmocap.athletics.run_course import (
    CONTROL_EVERY,
    RunResult,
    athletics_world,
    make_athlete,
    parse_course,
    run_course,
)
from reactmocap.athletics.running import PATH_AFTER, SHOULDER, Runner, running_start
from reactmocap.athletics.running_body import euler_yxz, qmul1, qyaw
from reactmocap.athletics.running_params import RunParams
from reactmocap.errors import ConfigError
from reactmocap.rotations import wrap_angle
from reactmocap.sim.bodies import SIM_BODY_INDEX
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.rollout import rollout
from reactmocap.sim.world import World


@pytest.mark.parametrize("angle", [45.0])
def test_commanded_turn_changes_the_heading(angle: float) -> None:
    course = Facing([(0.0, 0.0), (2.0, math.radians(angle))])
    rep = run_course(3.5, seconds=8.0, path=course, fps=10.0).report
    assert not rep["fell"], rep["notes"]
    # the pelvis's mean heading over the last second, against the command (+-10 degrees)
    assert rep["heading_deg"] == pytest.approx(angle, abs=10.0)


def test_stance_estimate_is_smoothed_at_the_path_speed() -> None:
    res = run_course(2.5, seconds=3.0, fps=10.0)
    runner = res.runner
    blend = runner.params.at(2.5)["stance_blend"]
    assert 0 < blend < 1
    # replay the law on the logged stances: each lift-off moves the estimate part of the way
    est = runner.params.at(2.5)["stance_time"]
    downs = [t for t, *_ in runner.log.touchdowns]
    ups = [t for t, _ in runner.log.liftoffs]
    assert len(ups) >= 6
    for up in ups:
        last = min(max(up - max(t for t in downs if t < up), 0.12), 0.4)
        est = est + blend * (last - est)
    assert runner.stance_estimate == pytest.approx(est, rel=1e-12)
    # and it is not the last stance's duration alone (eqs. 1-2 unsmoothed)
    assert abs(runner.stance_estimate - last) > 1e-4


def _assert_runs_alike(a: RunResult, b: RunResult) -> None:
    """Two runs the same to the bit (an option that must not act on them)."""
    for key in ("t", "com", "cross_track", "heading"):
        assert np.array_equal(a.log[key], b.log[key]), key
    assert np.array_equal(a.motion.rotations, b.motion.rotations)


def _arms_past_eq5(params: RunParams) -> tuple[Runner, list[float]]:
    """A circle run 0.5 s past ``PATH_AFTER`` and how far each shoulder's pitch goal lies
    from eq. 5's on its last state (the arms' law run once more there)."""
    r = run_course(2.5, seconds=PATH_AFTER + 0.5, path="circle:10", fps=10.0, params=params).runner
    hips = r._angles[r._hip_rows, 0].copy()
    r._upper(hips)
    k = r.k
    extra = [r.goal[SHOULDER[leg], 0] - (k["arm_gain"] * hips[1 - leg] + k["arm_offset"])
             for leg in range(2)]  # fmt: skip
    return r, extra


def test_arm_yaw_counter_rotates_the_arms_against_the_trunks_yaw() -> None:
    """``arm_yaw``: from ``PATH_AFTER`` on the shoulders' pitch goals leave eq. 5 by the gain
    times the trunk's yaw past the desired facing, the left arm back and the right forward
    for a trunk turned left of it; before it the run is the one without it to the bit, and
    off eq. 5 is left as it is."""
    gain = 2.0
    runs = {}
    for g in (0.0, gain):
        r, extra = _arms_past_eq5(RunParams(arm_yaw=g, arm_yaw_rate=0.0))
        chest = r._anat(r._chest, SIM_BODY_INDEX["chest"])
        yaw = euler_yxz(qmul1(qyaw(-r.heading_d), chest))[2]
        runs[g] = (r.log.arrays(), extra, yaw)
    (off, extra0, _), (on, extra1, yaw) = runs[0.0], runs[gain]
    assert extra0 == [0.0, 0.0]
    assert abs(yaw) > 1e-4
    assert extra1 == pytest.approx([gain * yaw, -gain * yaw], rel=1e-9)
    before = off["t"] < PATH_AFTER
    assert np.array_equal(off["com"][before], on["com"][before])
    assert not np.array_equal(off["com"][~before], on["com"][~before])


def test_arm_yaw_rate_moves_the_arms_by_the_trunks_yaw_rate_past_the_facings() -> None:
    """``arm_yaw_rate``: beside ``arm_yaw``'s angle term the shoulders' pitch goals move by
    the gain times the chest's yaw rate past the desired facing's rate (same signs), from
    ``PATH_AFTER`` on; before it the run is ``arm_yaw``'s alone to the bit."""
    rate = 0.1
    runs = {}
    for g in (0.0, rate):
        r, extra = _arms_past_eq5(RunParams(arm_yaw=2.0, arm_yaw_rate=g))
        chest = r._anat(r._chest, SIM_BODY_INDEX["chest"])
        spin = 2.0 * euler_yxz(qmul1(qyaw(-r.heading_d), chest))[2]
        past = float(r.world.data.cvel[r._chest, 2]) - r.facing_rate
        runs[g] = (r.log.arrays(), extra, spin, past, r.facing_rate)
    (off, extra0, spin0, _, _), (on, extra1, spin1, past, facing) = runs[0.0], runs[rate]
    assert extra0 == pytest.approx([spin0, -spin0], rel=1e-9)
    # on the circle the facing turns (about 0.25 rad/s) and the chest's rate differs from it
    assert 0.1 < facing <= 0.35 + 1e-9
    assert abs(rate * past) > 1e-3
    assert extra1 == pytest.approx([spin1 + rate * past, -spin1 - rate * past], rel=1e-9)
    before = off["t"] < PATH_AFTER
    assert np.array_equal(off["com"][before], on["com"][before])
    assert not np.array_equal(off["com"][~before], on["com"][~before])


def test_arm_yaw_terms_are_off_on_a_straight_line() -> None:
    """The arms' yaw terms act only where the course curves (``ARM_CURVE``): on a straight
    line a run with them is the run without them to the bit, past ``PATH_AFTER`` too, while
    on the circle the same terms change the run from ``PATH_AFTER`` on."""
    on = RunParams(arm_yaw=2.0, arm_yaw_rate=0.05)
    off = RunParams(arm_yaw=0.0, arm_yaw_rate=0.0)
    secs = PATH_AFTER + 0.5
    line = [run_course(2.5, seconds=secs, fps=10.0, params=p) for p in (on, off)]
    assert line[0].report["simulated_s"] == pytest.approx(secs)
    assert max(line[0].log["t"]) > PATH_AFTER + 0.4
    _assert_runs_alike(*line)
    curve = [run_course(2.5, seconds=secs, path="circle:10", fps=10.0, params=p).log
             for p in (on, off)]  # fmt: skip
    before = curve[0]["t"] < PATH_AFTER
    assert np.array_equal(curve[0]["com"][before], curve[1]["com"][before])
    assert not np.array_equal(curve[0]["com"][~before], curve[1]["com"][~before])


def test_arm_yaw_is_checked() -> None:
    with pytest.raises(ConfigError, match=r"arm_yaw must be in \[0, 5\]"):
        RunParams(arm_yaw=(0.0, 0.0, 6.0))
    with pytest.raises(ConfigError, match=r"arm_yaw must be in \[0, 5\]"):
        RunParams(arm_yaw=-0.1)
    assert RunParams().at(2.5)["arm_yaw"] == 1.0
    with pytest.raises(ConfigError, match=r"arm_yaw_rate must be in \[0, 1\]"):
        RunParams(arm_yaw_rate=1.5)
    with pytest.raises(ConfigError, match=r"arm_yaw_rate must be in \[0, 1\]"):
        RunParams(arm_yaw_rate=(0.0, -0.05, 0.0))
    assert RunParams().at(2.5)["arm_yaw_rate"] == 0.05


def test_yaw_momentum_damps_the_bodys_mean_yaw_rate_on_a_curve_and_not_a_line() -> None:
    """``yaw_momentum``: on the circle the run is the one without it to the bit before
    ``PATH_AFTER`` and differs after; on its last state the attitude torque differs from
    the chest-damped one only about the vertical, by the yaw damping times the share of the
    whole body's mean yaw rate (its yaw momentum over its yaw inertia about the COM) past
    the chest's; on a straight line the run is the one without it to the bit."""
    w, secs = 0.5, PATH_AFTER + 0.5
    runs = [run_course(2.5, seconds=secs, path="circle:10", fps=10.0,
                       params=RunParams(yaw_momentum=v)) for v in (w, 0.0)]  # fmt: skip
    on, off = runs[0].log, runs[1].log
    before = off["t"] < PATH_AFTER
    assert max(on["t"]) > PATH_AFTER + 0.4
    assert np.array_equal(on["com"][before], off["com"][before])
    assert not np.array_equal(on["com"][~before], off["com"][~before])
    r = runs[0].runner
    d, m = r.world.data, r.world.model
    # the yaw inertia about the vertical through the COM, from the bodies' own inertias
    iz = 0.0
    for b in r._bodies:
        rot = d.ximat[b].reshape(3, 3)
        arm = d.xipos[b, :2] - d.subtree_com[r._root, :2]
        iz += (rot @ np.diag(m.body_inertia[b]) @ rot.T)[2, 2] + m.body_mass[b] * arm @ arm
    body = float(d.subtree_angmom[r._root, 2]) / iz
    chest = float(d.cvel[r._chest, 2])
    assert abs(body - chest) > 1e-3
    # the torque unclamped (limits, ramp, grip off) with the option and without
    r.k.update(attitude_limit=0.0, touchdown_limit=0.0, attitude_ramp=0.0, pitch_integral=0.0,
               yaw_grip=1e12)  # fmt: skip
    with_it = r._attitude_torque(r.heading_d)
    r.k["yaw_momentum"] = 0.0
    without = r._attitude_torque(r.heading_d)
    kv = r.params.attitude_kv[2]
    want = -r.inertia_unit * kv * w * (body - chest)
    assert with_it - without == pytest.approx([0.0, 0.0, want], rel=1e-6, abs=1e-6 * abs(want))
    line = [run_course(2.5, seconds=secs, fps=10.0, params=RunParams(yaw_momentum=v))
            for v in (1.0, 0.0)]  # fmt: skip
    _assert_runs_alike(*line)


def test_yaw_momentum_is_checked() -> None:
    with pytest.raises(ConfigError, match=r"yaw_momentum must be in \[0, 1\]"):
        RunParams(yaw_momentum=1.5)
    with pytest.raises(ConfigError, match=r"yaw_momentum must be in \[0, 1\]"):
        RunParams(yaw_momentum=(0.0, -0.1, 0.0))
    assert RunParams().at(2.5)["yaw_momentum"] == 0.0


def test_turn_place_turns_the_velocity_with_the_facing_and_holds_the_20_m_circle() -> None:
    """``turn_place``: on the 20 m circle at 3.5 m/s the run is the one without it to the bit
    before ``PATH_AFTER``; after it the COM's velocity lags the desired facing by less than
    half as much as without it (eqs. 1-2 alone make the centripetal force only from that
    lag, and the runner drifts outside the path) and the runner comes back onto the path;
    on a straight line the run is the one without it to the bit."""
    secs = 8.0
    runs = {g: run_course(3.5, seconds=secs, path="circle:20", fps=10.0,
                          params=RunParams(turn_place=g)) for g in (0.0, 0.5)}  # fmt: skip
    on, off = runs[0.5].log, runs[0.0].log
    before = off["t"] < PATH_AFTER
    assert np.array_equal(on["com"][before], off["com"][before])
    assert not np.array_equal(on["com"][~before], off["com"][~before])
    lag, out = {}, {}
    for g, res in runs.items():
        assert not res.report["fell"], g
        log = res.log
        after = log["t"] >= PATH_AFTER
        vel = np.arctan2(log["com_vel"][after, 1], log["com_vel"][after, 0])
        lag[g] = float(np.mean([wrap_angle(a) for a in vel - log["desired_heading"][after]]))
        # over the last 3 s; < 0: outside the circle
        out[g] = float(np.mean(log["cross_track"][log["t"] >= secs - 3.0]))
    # anticlockwise: a velocity turned right of the facing lags it
    assert lag[0.0] < -0.15
    assert lag[0.0] < 2.0 * lag[0.5] < 0.0
    assert out[0.0] < -0.3
    assert abs(out[0.5]) < 0.3 * abs(out[0.0])
    line = [run_course(3.5, seconds=PATH_AFTER + 1.0, fps=10.0, params=RunParams(turn_place=g))
            for g in (1.0, 0.0)]  # fmt: skip
    _assert_runs_alike(*line)


def test_turn_place_is_checked() -> None:
    with pytest.raises(ConfigError, match=r"turn_place must be in \[0, 3\]"):
        RunParams(turn_place=-0.1)
    with pytest.raises(ConfigError, match=r"turn_place must be in \[0, 3\]"):
        RunParams(turn_place=(0.0, 0.5, 3.5))
    assert RunParams().at(3.5)["turn_place"] == 0.0


def _foot_slips(grip: float, secs: float) -> tuple[Runner, dict[tuple[float, int], float]]:
    """The 10 m loop at 3.5 m/s after a 10 m entry (``run_course``'s set-up, a recorder
    ticked after the runner): each stance's foot yaw past the facing's turn from
    ``PATH_AFTER`` on (rad, by touchdown time and leg)."""
    ath = make_athlete("male")
    world = athletics_world(ath)
    qpos, qvel = running_start(ath, 3.5)
    world.set_pose(0, qpos, qvel)
    course = parse_course("circle:10+entry:10", world.com(0)[:2], 0.0)
    assert isinstance(course, Polyline)
    course.reset()
    r = Runner(world, ath, 3.5, course, RunParams(grip_reserve=grip), control_every=CONTROL_EVERY)
    dt = CONTROL_EVERY * world.timestep
    slips: dict[tuple[float, int], float] = {}

    def record(w: World, t: float) -> None:
        if t >= PATH_AFTER and r.machine.current.name != "flight":
            key = (r.t_touchdown, r.active)
            turn = float(w.data.cvel[r._feet[r.active], 2]) - r.facing_rate
            slips[key] = slips.get(key, 0.0) + turn * dt

    rollout(world, secs, controllers=[r, FunctionController(record, CONTROL_EVERY)],
            record_fps=10.0, on_unstable="stop")  # fmt: skip
    return r, slips


def test_grip_reserve_keeps_the_stance_feet_from_spinning_on_the_10_m_loop() -> None:
    """``grip_reserve``: on the 10 m loop at 3.5 m/s the run is the one without it to the bit
    before ``PATH_AFTER``; after it the stance hip's twist along the thigh stays within the
    grip on the vertical ground force less its horizontal part, and the stance feet turn
    past the facing's turn less than half as much (the outer, right foot's median per
    stance)."""
    secs = 6.5
    runs = {g: _foot_slips(g, secs) for g in (0.0, 1.0)}
    on, off = runs[1.0][0].log, runs[0.0][0].log
    n = min(len(on.rows), len(off.rows))
    before = [i for i in range(n) if off.rows[i][0] < PATH_AFTER]
    assert all(np.array_equal(on.rows[i][1], off.rows[i][1]) for i in before)
    assert not all(np.array_equal(on.rows[i][1], off.rows[i][1]) for i in range(n))
    med = {}
    for g, (r, slips) in runs.items():
        assert r.world.data.time > secs - 0.01, g  # neither fell over these seconds
        right = [abs(v) for (_, leg), v in slips.items() if leg == 1]
        assert len(right) >= 6
        med[g] = float(np.median(right))
    assert med[0.0] > 0.15
    assert med[1.0] < 0.5 * med[0.0]
    # on the last state the twist along the stance thigh is within the reduced grip
    r = runs[1.0][0]
    assert r.machine.current.name != "flight"
    torque = r._attitude_torque(r.heading_d)
    leg = r.active
    d = r.world.data
    axis = d.xanchor[r._knees[leg]] - d.xanchor[r._hips[leg]]
    axis /= np.linalg.norm(axis)
    grf = r.senses.grf
    load = max(float(grf[2]) - float(np.hypot(grf[0], grf[1])), 0.0)
    assert abs(float(torque @ axis)) <= r.k["yaw_grip"] * r.foot_length * load + 1e-9


def test_grip_reserve_is_checked() -> None:
    with pytest.raises(ConfigError, match=r"grip_reserve must be in \[0, 2\]"):
        RunParams(grip_reserve=-0.5)
    with pytest.raises(ConfigError, match=r"grip_reserve must be in \[0, 2\]"):
        RunParams(grip_reserve=(0.0, 1.0, 2.5))
    assert RunParams().at(3.5)["grip_reserve"] == 0.0
