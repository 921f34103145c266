"""Torque-free reorientation (thesis 5.1.1): with no angular momentum, windmilling the arms turns
the rest of the body the other way, because the arms' moment of inertia about the somersault
axis is much smaller than the body's ("if the male character windmilled the arms clockwise 360
degrees, the torso would tilt counter-clockwise by 20 degrees"). :func:`arm_windmill` drops the
athlete from high up with no rotation, windmills both arms through full circles in the
sagittal plane and measures how far the trunk turned per cycle and that the angular momentum
stayed at zero. The full backdrop (Frohlich's sequence of Fig. 5.4) is not built."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from reactmocap.athletics.bodies import athlete
from reactmocap.athletics.machine import Basis, Context, law
from reactmocap.athletics.rig import joint_index, per_joint, smoothstep
from reactmocap.athletics.scene import athletics_world, stand_angles
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.athletics.tumble import TUMBLE_STIFFNESS
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State
from reactmocap.sim.rollout import rollout
from reactmocap.sim.world import World

__all__ = ["Windmill", "arm_windmill"]

NJ = len(BALL_JOINTS)
_SHOULDERS = [joint_index(f"{s}_shoulder") for s in "lr"]
#: height (m) of the feet above the floor at the drop: the fall outlasts the windmilling
DROP_HEIGHT = 60.0


class Windmill(Basis):
    """Both arms turn ``cycles`` full circles in the sagittal plane, each in ``period`` s
    (forward over the head when ``cycles`` > 0: the shoulders' pitch falls), the rest of the
    body held in its pose; no gravity compensation (the body is in free fall)."""

    name = "windmill"
    initial = "windmill"

    def __init__(self, cycles: float = 1.0, period: float = 1.0) -> None:
        if not (math.isfinite(cycles) and math.isfinite(period) and period > 0):
            raise ConfigError(
                f"windmill cycles must be finite and period > 0, got {cycles}, {period}"
            )
        self.cycles = float(cycles)
        self.period = float(period)

    def states(self, ctx: Context) -> list[State]:
        rig = ctx.rig
        memo: dict[str, Any] = {}

        def enter(world: World, t: float) -> None:
            del world
            rig.gravity_compensation = False
            stiff = per_joint({**TUMBLE_STIFFNESS, "shoulder": 0.6, "elbow": 0.3})
            rig.set_stiffness(stiff)
            rig.support[:] = 0.0
            memo["t0"] = t
            memo["pose"] = rig.current_angles()

        def turn(world: World, t: float) -> None:
            del world
            x = (t - memo["t0"]) / self.period
            n = abs(self.cycles)
            k = min(math.floor(x), math.ceil(n) - 1) if n > 0 else 0
            done = min(x, n)
            frac = float(smoothstep(np.array(done - k)))
            angle = -math.copysign(2.0 * math.pi, self.cycles) * (k + frac) if n else 0.0
            goal = np.full((NJ, 3), np.nan)
            for j in _SHOULDERS:
                goal[j] = (angle, 0.0, 0.0)
            rig.move(goal, 0.0, t, _SHOULDERS)

        return [State("windmill", law(turn, ctx.control_every), enter, ())]


def arm_windmill(
    body: str = "male", cycles: float = 1.0, period: float = 1.0, settle: float = 0.3
) -> dict[str, Any]:
    """Drop ``body`` from :data:`DROP_HEIGHT` m with no rotation and windmill the arms
    (:class:`Windmill`); the report: the trunk's somersault rotation (deg, forward > 0) over
    the windmilling and per cycle, the largest whole-body angular momentum about the COM
    (kg m^2/s; 0 in theory), and the seconds simulated."""
    ath = athlete(body)
    world = athletics_world(ath)
    m = world.model
    wc = world.characters[0]
    for side in "lr":  # a full circle passes the shoulder's cone limit
        m.jnt_limited[m.joint(f"{wc.prefix}{side}_shoulder").id] = 0
    world.set_pose(0, ath.standing_qpos(stand_angles(ath), clearance=DROP_HEIGHT))
    ctx = Context.make(world, ath, control_every=8)
    seq = Sequencer(ctx, [Windmill(cycles, period)])
    seconds = abs(cycles) * period + settle
    fall = math.sqrt(2.0 * DROP_HEIGHT / float(np.linalg.norm(m.opt.gravity)))
    if seconds > fall - 0.1:
        raise ConfigError(f"{cycles} cycles of {period} s outlast the {fall:.1f} s fall")
    try:
        # the fall itself reaches ~30 m/s: the rollout's kinetic-energy check (100 J/kg)
        # would stop a free fall at 14 m/s
        res = rollout(world, seconds, controllers=[seq], record_fps=30.0, on_unstable="stop",
                      energy_limit_per_kg=2000.0)  # fmt: skip
    finally:
        ctx.rig.release()
    log = ctx.log.arrays()
    rot = math.degrees(float(log["rotation"][-1] - log["rotation"][0]))
    return {
        "body": body, "cycles": cycles, "period_s": period, "rotation_deg": rot,
        "rotation_per_cycle_deg": rot / cycles if cycles else 0.0,
        "max_momentum": float(np.linalg.norm(log["momentum"], axis=1).max()),
        "simulated_s": res.seconds, "status": res.status,
    }  # fmt: skip
