"""Torque-free reorientation (thesis 5.1.1): with no angular momentum, windmilling the arms turns
the rest of the body the other way, because the arms' moment of inertia about the somersault
axis is much smaller than the body's ("if the male character windmilled the arms clockwise 360
degrees, the torso would tilt counter-clockwise by 20 degrees"). :func:`arm_windmill` drops the
athlete from high up with no rotation, windmills both arms through full circles in the
sagittal plane and measures how far the trunk turned per cycle and that the angular momentum
stayed at zero.

The backdrop ("a partial somersault of nearly 90 degrees ... a series of limb motions (figure
5.4)"; Frohlich 1979): :class:`Backdrop` runs the arms and hips through a closed loop of shapes
(pike, circle the arms, open), so the body ends in its starting shape but turned;
:func:`backdrop` runs it in zero gravity and measures the turn and the angular momentum. The
thesis gives the figure's six sketches but no angles: the loop here is our reading of it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import athlete
from reactmocap.athletics.machine import NEXT, Basis, Context, law
from reactmocap.athletics.rig import joint_index, per_joint, smoothstep
from reactmocap.athletics.scene import athletics_world, stand_angles
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.athletics.tumble import TUMBLE_STIFFNESS
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.rollout import rollout
from reactmocap.sim.world import World

__all__ = ["Backdrop", "Windmill", "arm_windmill", "backdrop", "backdrop_keyframes"]

F64 = NDArray[np.float64]
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


_HIPS = [joint_index(f"{s}_hip") for s in "lr"]
#: the deepest hip flexion (rad) of the backdrop's pike (the tumbling pike's,
#: :data:`.tumble.POSITIONS`), also its default depth below the entry pose
PIKE_HIP = -2.2


def backdrop_keyframes(direction: str = "backward", hip: float = PIKE_HIP) -> F64:
    """The backdrop's loop of shapes as keyframes ``[shoulder pitch, hip pitch]`` (rad, from
    the pose the phase starts in; arms forward/up < 0, hips flexed < 0): pike, circle both arms once (``backward``: up behind the
    back, turning the body backward; ``forward``: up in front), open the hips. The last
    keyframe is the first shape again (the shoulders a full turn on)."""
    if direction not in ("backward", "forward"):
        raise ConfigError(f"backdrop direction must be 'backward' or 'forward', got {direction!r}")
    turn = 2.0 * math.pi if direction == "backward" else -2.0 * math.pi
    return np.array([(0.0, 0.0), (0.0, hip), (turn, hip), (turn, 0.0)])


class Backdrop(Basis):
    """Frohlich's backdrop (thesis 5.1.1, Fig. 5.4): the arms and hips run ``loops`` times
    through a closed loop of shapes (``keyframes`` of ``[shoulder pitch, hip pitch]``, rad;
    ``segment`` s from one to the next, smoothstep in between, taken from the pose at entry,
    the hips no deeper than :data:`PIKE_HIP`;
    ``handover``: hand over to the next basis controller once done). Every leg of the loop turns
    the body, by different amounts because the inertias differ between the shapes (the arms
    circle while the body is piked, its inertia a third of the layout's), so with zero
    angular momentum the body ends in its starting shape but turned; the rest of the body
    holds its pose; no gravity compensation (free fall or zero gravity)."""

    name = "backdrop"
    initial = "backdrop"

    def __init__(
        self, keyframes: Any = None, segment: float = 0.5, loops: int = 1, handover: bool = False
    ) -> None:
        keys = (
            backdrop_keyframes() if keyframes is None else np.asarray(keyframes, dtype=np.float64)
        )
        if keys.ndim != 2 or keys.shape[1] != 2 or len(keys) < 2 or not np.isfinite(keys).all():
            raise ConfigError(
                f"backdrop keyframes must be >= 2 finite [shoulder, hip] pairs, got shape {keys.shape}"
            )
        if not (math.isfinite(segment) and segment > 0 and int(loops) == loops and loops >= 1):
            raise ConfigError(
                f"backdrop segment must be > 0 s and loops a whole number >= 1, got {segment}, {loops}"
            )
        # each pass starts where the last ended (the arms' circles carry on, not unwind)
        step = keys[-1] - keys[0]
        passes = [keys[:-1] + r * step for r in range(int(loops))]
        self.path = np.concatenate([*passes, keys[-1:] + (int(loops) - 1) * step])
        self.segment = float(segment)
        self.handover = handover

    @property
    def seconds(self) -> float:
        """How long the loops take (s)."""
        return (len(self.path) - 1) * self.segment

    def states(self, ctx: Context) -> list[State]:
        rig = ctx.rig
        memo: dict[str, Any] = {}
        joints = _SHOULDERS + _HIPS
        last = len(self.path) - 1
        m, d = ctx.world.model, ctx.world.data
        prefix = ctx.world.characters[ctx.character].prefix
        limbs = [int(m.jnt_bodyid[m.joint(f"{prefix}{BALL_JOINTS[j]}").id]) for j in joints]
        root = int(m.jnt_bodyid[m.joint(f"{prefix}{BALL_JOINTS[_HIPS[0]]}").id])
        root = int(m.body_rootid[root])
        self.limb_momentum: list[float] = []
        for j in _SHOULDERS:  # the arms circle past the shoulder's cone limit (for the run)
            m.jnt_limited[m.joint(f"{prefix}{BALL_JOINTS[j]}").id] = 0

        def enter(world: World, t: float) -> None:
            del world
            rig.gravity_compensation = False
            rig.set_stiffness(per_joint({**TUMBLE_STIFFNESS, "shoulder": 0.6, "elbow": 0.3}))
            rig.support[:] = 0.0
            rig.offset[:] = 0.0  # a leap's last corrections would bend the loop
            memo["t0"] = t
            pose = rig.current_angles()
            # the loop is taken from the pose at entry, so it closes on it (from the standing
            # pose's hips, flexed 0.18 rad, a loop ending at 0 turned the arm circle by 5 deg)
            memo["start"] = np.array([pose[_SHOULDERS, 0].mean(), pose[_HIPS, 0].mean()])

        def shape(world: World, t: float) -> None:
            del world
            x = min((t - memo["t0"]) / self.segment, float(last))
            k = min(int(x), last - 1)
            a, b = self.path[k], self.path[k + 1]
            s, h = memo["start"] + a + (b - a) * float(smoothstep(np.array(x - k)))
            goal = np.full((NJ, 3), np.nan)
            goal[_SHOULDERS] = (s, 0.0, 0.0)
            # no deeper than the tumbling pike, inside the hip's 2.4 rad cone (from a flexed
            # entry pose an offset would press the hip into its limit)
            goal[_HIPS] = (max(h, PIKE_HIP), 0.0, 0.0)
            rig.move(goal, 0.0, t, joints)
            # the moving limbs' angular momentum about the whole-body COM (mj_subtreeVel has
            # run): the scale the trunk's counter-momentum must match, the drift's reference
            r = d.subtree_com[limbs] - d.subtree_com[root]
            v = d.subtree_linvel[limbs] - d.subtree_linvel[root]
            own = d.subtree_angmom[limbs] + m.body_subtreemass[limbs, None] * np.cross(r, v)
            self.limb_momentum.append(float(np.linalg.norm(own.sum(axis=0))))

        exits = ((after(self.seconds), NEXT),) if self.handover else ()
        return [State("backdrop", law(shape, ctx.control_every), enter, exits)]


def backdrop(
    body: str = "male",
    direction: str = "backward",
    loops: int = 1,
    segment: float = 0.5,
    keyframes: Any = None,
    settle: float = 0.3,
) -> dict[str, Any]:
    """Hold ``body`` in zero gravity clear of the floor with no angular momentum and run
    :class:`Backdrop` (``keyframes``, default :func:`backdrop_keyframes` of ``direction``);
    the report: the trunk's somersault rotation (deg, forward > 0) at the end, the body back
    in its starting shape, and per loop; the largest whole-body angular momentum about the
    COM (kg m^2/s; 0 in theory), the largest angular momentum of the moving limbs (the arms
    and legs, as subtrees, about the whole-body COM) and ``momentum_drift``, the one over the
    other; and the seconds simulated."""
    keys = backdrop_keyframes(direction) if keyframes is None else keyframes
    bd = Backdrop(keys, segment, loops)
    ath = athlete(body)
    world = athletics_world(ath)
    m = world.model
    world.set_pose(0, ath.standing_qpos(stand_angles(ath), clearance=3.0))
    ctx = Context.make(world, ath, control_every=8)
    # torque-free without a fall to outlast; the servo's units were set with gravity on
    m.opt.gravity[:] = 0.0
    seq = Sequencer(ctx, [bd])
    try:
        res = rollout(
            world, bd.seconds + settle, controllers=[seq], record_fps=30.0, on_unstable="stop"
        )
    finally:
        ctx.rig.release()
    log = ctx.log.arrays()
    rot = math.degrees(float(log["rotation"][-1] - log["rotation"][0]))
    peak = float(np.linalg.norm(log["momentum"], axis=1).max())
    limbs = max(bd.limb_momentum, default=0.0)
    return {
        "body": body, "direction": direction if keyframes is None else "custom",
        "loops": loops, "segment_s": segment, "rotation_deg": rot,
        "rotation_per_loop_deg": rot / loops,
        "max_momentum": peak, "max_limb_momentum": limbs,
        "momentum_drift": peak / max(limbs, 1e-9),
        "simulated_s": res.seconds, "status": res.status,
    }  # fmt: skip
