"""The athletic state machines: events, the sequencer's hand-over, the rig's targets."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from reactmocap.athletics import Balance, Landing, Posture, Sequencer, athlete
from reactmocap.athletics.leap import pitch_momentum
from reactmocap.athletics.machine import NEXT, Basis, Context, angle, apex, touchdown
from reactmocap.athletics.rig import Rig, per_joint
from reactmocap.athletics.scene import athletics_world, stand_angles
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.rollout import rollout
from reactmocap.sim.world import World


def test_a_drop_runs_the_landing_states_in_order_and_hands_over_to_balance() -> None:
    ath = athlete("male")
    world = athletics_world(ath)
    drop = 0.3
    world.set_pose(0, ath.standing_qpos(stand_angles(ath, 0.92), clearance=drop))
    ctx = Context.make(world, ath, control_every=8)
    seq = Sequencer(ctx, [Landing(), Balance(Posture(settle=1.0))])
    rollout(world, 1.6, controllers=[seq])
    states = [tr.target for tr in seq.transitions]
    assert states[:4] == ["land.absorb", "land.recover", "land.done", "balance.hold"]
    # touchdown when the soles reach the floor: free fall of the drop height (to a tick)
    assert ctx.touchdown_time == pytest.approx(math.sqrt(2 * drop / 9.81), abs=0.012)
    # the hand-over moves no target: the knees' targets are continuous across it
    log = ctx.log.arrays()
    assert not log["others"].any()


class _Reader:
    """Each tick, reads again what the controllers read: the senses re-measured (their
    per-time cache emptied), their derived values, the world's state and kinetic energy.
    ``forward_at``: also one ``mj_forward`` then (not a pure read: it recomputes the mass
    matrix the servo linearises on)."""

    control_every = 8

    def __init__(self, ctx: Context, forward_at: float | None = None) -> None:
        self.ctx, self.forward_at = ctx, forward_at

    def reset(self, world: World) -> None:
        pass

    def control(self, world: World, t: float) -> None:
        s = self.ctx.senses
        s.time = -1.0
        s.update(t)
        s.heading(), s.side_heading(), s.local(s.com_vel), s.support_center(), s.airborne
        pitch_momentum(world, s), world.kinetic_energy(), world.get_state()
        if self.forward_at is not None and t >= self.forward_at:
            mujoco.mj_forward(world.model, world.data)
            self.forward_at = None


def _drop(reader: float | bool, first: bool = False) -> tuple[np.ndarray, list[str]]:
    """The drop above for 0.8 s: its recorded qpos and transitions, with a :class:`_Reader`
    (a float: its ``forward_at``; ``first``: ticked before the sequencer) or without."""
    ath = athlete("male")
    world = athletics_world(ath)
    world.set_pose(0, ath.standing_qpos(stand_angles(ath, 0.92), clearance=0.3))
    ctx = Context.make(world, ath, control_every=8)
    seq = Sequencer(ctx, [Landing(), Balance(Posture(settle=1.0))])
    extra = [] if reader is False else [_Reader(ctx, None if reader is True else reader)]
    res = rollout(world, 0.8, controllers=[*extra, seq] if first else [seq, *extra])
    return res.qpos, [tr.target for tr in seq.transitions]


def test_reading_the_senses_again_leaves_a_run_bit_identical() -> None:
    # a second read in a tick must not change the simulation (docs/athletics.md, 2026-12-05,
    # "reading the sensors"): the senses' mj_subtreeVel and mj_contactForce write no state
    plain, states = _drop(False)
    assert "land.absorb" in states
    for first in (True, False):  # the sequencer then reads the reader's measurement, or not
        read, read_states = _drop(True, first)
        assert read_states == states
        assert np.array_equal(read, plain)
    # the comparison catches a read that is not pure: one mj_forward mid-landing
    forward, _ = _drop(0.3)
    assert not np.array_equal(forward, plain)


def test_events_fire_on_what_they_measure() -> None:
    ath = athlete("female")
    world = athletics_world(ath)
    ctx = Context.make(world, ath)
    ctx.rig.reset()
    world.step(40)  # settle onto the floor (the pose starts 0.5 mm above it)
    ctx.sense(0.02)
    assert touchdown(ctx)(world, 0.02, 0.0)  # standing: the feet touch
    assert ctx.touchdown_time == 0.02
    assert apex(ctx)(world, 0.02, 0.0) == (ctx.senses.com_vel[2] <= 0.0)
    knee = float(stand_angles(ath)[10, 0])
    assert angle(ctx, "l_knee", 0, knee - 0.05)(world, 0.0, 0.0)
    assert not angle(ctx, "l_knee", 0, knee + 0.05)(world, 0.0, 0.0)
    with pytest.raises(UnknownKeyError, match="l_knee"):
        angle(ctx, "knee_l", 0, 0.1)
    with pytest.raises(ConfigError, match="axis"):
        angle(ctx, "l_knee", 3, 0.1)


def test_sequencer_chains_bases_and_drops_the_last_next() -> None:
    class Wait(Basis):
        name = "wait"
        initial = "w"

        def states(self, ctx: Context) -> list[State]:
            return [State("w", None, None, ((after(0.05), NEXT),))]

    ath = athlete("male")
    world = athletics_world(ath)
    ctx = Context.make(world, ath)
    seq = Sequencer(ctx, [Wait(), Wait(), Balance(seconds=0.05)])
    rollout(world, 0.3, controllers=[seq])
    assert [tr.target for tr in seq.transitions] == ["wait1.w", "balance.hold"]
    assert seq.state == "balance.hold"  # the last NEXT has nowhere to go: final state
    with pytest.raises(ConfigError, match="at least one"):
        Sequencer(ctx, [])


def test_rig_moves_targets_on_hermite_and_accelerating_paths() -> None:
    ath = athlete("male")
    world = athletics_world(ath)
    rig = Rig(world, ath)
    rig.reset(np.zeros((15, 3)))
    goal = np.ones((15, 3))
    rig.move(goal, 1.0, 0.0, [0])
    rig.move(goal, 1.0, 0.0, [1], accelerate=True)
    mid = rig.desired(0.5)
    assert mid[0, 0] == pytest.approx(0.5)  # Hermite: half way at half time
    assert mid[1, 0] == pytest.approx(0.25)  # constant acceleration: a quarter
    assert np.allclose(rig.desired(1.0)[:2], 1.0)
    assert np.allclose(rig.desired(0.5)[2:], 0.0)  # the others stay
    rig.move(goal * 2, 0.0, 0.5, [2])
    assert rig.desired(0.5)[2, 0] == pytest.approx(2.0)  # duration 0 jumps at once
    assert per_joint({"knee": 2.0, "l_knee": 3.0})[[10, 13]].tolist() == [3.0, 2.0]
    with pytest.raises(ConfigError):
        rig.set_stiffness(np.full(15, -1.0))


def test_the_registry_row_balances_any_character(guard) -> None:  # type: ignore[no-untyped-def]
    from reactmocap.athletics.bodies import athlete_of
    from reactmocap.sim.controllers import build
    from reactmocap.sim.world import World

    ath = athlete(guard)
    world = World(ath.character)
    world.set_pose(0, athlete_of(ath.character).standing_qpos(stand_angles(ath), 0.0005))
    ctl = build("athletic_balance", world, guard)
    res = rollout(world, 1.5, controllers=[ctl])
    pelvis = res.body_transforms(0)[0][:, 0, 2]
    assert pelvis.min() > 0.8 * pelvis[0]  # still standing
