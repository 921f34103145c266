"""The bicycle in MuJoCo (Hodgins et al. 1995, "Bicycling"): a rear frame with a free joint, the
front fork and handlebar on a steer hinge along the tilted head tube, two wheels on hinges and,
for a rider, a crank that drives the rear wheel through a gear ratio (a joint equality: the
paper's spring-damper between crank and wheel). Rolling resistance is proportional to velocity
(damping on the wheel hinges). Geometry and mass default to the benchmark bicycle of Meijaard et
al. (2007), whose linearised dynamics (:func:`benchmark_matrices`) this model is validated
against from simulation (:mod:`reactmocap.athletics.stability`). The parameters, the benchmark's
and the rider's, and the linear model live in :mod:`reactmocap.athletics.bicycle_params`
(re-exported here).

Wheel contact: each wheel is a flat ellipsoid (semi-axes ``r, tyre, r``), i.e. a knife-edge disk
with a rounded rim: MuJoCo's plane-ellipsoid collision then puts one contact at the rim point
nearest the ground whatever the lean and steer, as the benchmark's knife-edge wheels. A sphere
(contact under the centre) or a cylinder (two rim edges, and four points when tilted) changes
the lean dynamics: weave and capsize eigenvalues off by 30-300% (``docs/athletics.md``). Rolling
without slip is MuJoCo's friction (condim 3: no torsional or rolling friction, as the benchmark)
with the noslip post-solver, on a stiff (4 ms) wheel contact.

Frames: the bicycle frame has x forward from the rear contact point, y to the left and z up (the
benchmark's table has y to the right and z down: its ``z`` and ``I_xz`` change sign here).
Angles: roll > 0 leans right (about +x), steer > 0 turns left (about the upward steer axis),
yaw > 0 turns left; the crank turns forward about +y."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from reactmocap.athletics.bicycle_params import (
    BENCHMARK,
    BENCHMARK_CAPSIZE_SPEED,
    BENCHMARK_WEAVE_SPEED,
    FALLEN_ROLL,
    RIDER_BICYCLE,
    WHEEL_SHAPES,
    BicycleParams,
    Drivetrain,
    Fit,
    Part,
    Wheel,
    benchmark_matrices,
    linear_eigenvalues,
)
from reactmocap.errors import ConfigError, SimulationError
from reactmocap.sim.world import World

__all__ = [
    "BENCHMARK",
    "BENCHMARK_CAPSIZE_SPEED",
    "BENCHMARK_WEAVE_SPEED",
    "RIDER_BICYCLE",
    "Bicycle",
    "BicycleParams",
    "Drivetrain",
    "Fit",
    "Part",
    "Placement",
    "WHEEL_SHAPES",
    "Wheel",
    "benchmark_matrices",
    "linear_eigenvalues",
]

F64 = NDArray[np.float64]


# ------------------------------------------------------------------------- the MuJoCo model
@dataclass(frozen=True)
class Placement:
    """Where a bicycle starts: the ground point ``(x, y)`` under the rear wheel's centre (m), the
    heading
    (rad, 0 = +X), the forward speed (m/s), the crank angle (rad) and a small initial roll rate
    and steer rate (rad/s) to perturb it."""

    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    speed: float = 0.0
    crank: float = 0.0
    roll_rate: float = 0.0
    steer_rate: float = 0.0


def _quat_y(angle: float) -> list[float]:
    return [math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0]


def _inertial(body: mujoco.MjsBody, part: Part, origin: F64) -> None:
    body.explicitinertial = True
    body.mass = part.mass
    body.ipos = [part.com[0] - origin[0], 0.0, part.com[1] - origin[2]]
    ixx, iyy, izz, ixz = part.inertia
    body.fullinertia = [ixx, iyy, izz, 0.0, ixz, 0.0]


def _visual(body: mujoco.MjsBody, a: Sequence[float], b: Sequence[float], radius: float,
            rgba: Sequence[float]) -> None:  # fmt: skip
    g = body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[*a, *b], size=[radius, 0, 0])
    g.contype = 0
    g.conaffinity = 0
    g.density = 0.0
    g.mass = 0.0
    g.group = 1
    g.rgba = list(rgba)


_FRAME_RGBA = (0.75, 0.15, 0.12, 1.0)
_TYRE_RGBA = (0.1, 0.1, 0.1, 1.0)
_METAL_RGBA = (0.7, 0.7, 0.72, 1.0)


@dataclass(eq=False)
class Bicycle:
    """One bicycle in a World. :meth:`build` adds its bodies to a spec under ``prefix`` (in the
    bicycle frame at the origin); :meth:`bind` finds them in the compiled model; the properties
    read its state. Body names: ``{prefix}frame``, ``rear_wheel``, ``fork``, ``front_wheel``,
    ``crank``; joints ``root``, ``rear_spin``, ``steer``, ``front_spin``, ``crank``."""

    params: BicycleParams
    prefix: str = "bike/"
    placement: Placement = field(default_factory=Placement)

    # --------------------------------------------------------------- building
    def build(self, spec: mujoco.MjSpec) -> None:
        p, pre = self.params, self.prefix
        rr, rf = p.rear.radius, p.front.radius
        origin = np.array([0.0, 0.0, rr])  # the frame body sits at the rear wheel's centre
        pl = self.placement  # compiled where it starts: bicycles never overlap, even at qpos0
        frame = spec.worldbody.add_body(
            name=pre + "frame", pos=[pl.x, pl.y, rr], quat=_yaw_pitch_quat(pl.heading, 0.0).tolist()
        )
        frame.add_freejoint(name=pre + "root")
        _inertial(frame, p.frame, origin)
        self._wheel(frame, "rear_wheel", "rear_spin", [0.0, 0.0, 0.0], p.rear)
        axis = p.steer_axis
        # the fork body's origin: on the steer axis at the front wheel's centre height
        head = p.steer_foot + axis * (rf / axis[2])
        fork = frame.add_body(name=pre + "fork", pos=(head - origin).tolist())
        fork.add_joint(name=pre + "steer", type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis.tolist())
        _inertial(fork, p.fork, head)
        front = np.array([p.wheelbase, 0.0, rf])
        self._wheel(fork, "front_wheel", "front_spin", (front - head).tolist(), p.front)
        # looks: frame tubes and fork (no collision, no mass)
        top = head + axis * 0.45
        seat = np.array([*(p.fit.seat if p.fit else (0.2, 0.95))])
        seat3 = np.array([seat[0], 0.0, seat[1]])
        bb = np.array([*(p.drivetrain.bottom_bracket if p.drivetrain else (0.4, 0.28))])
        bb3 = np.array([bb[0], 0.0, bb[1]])
        for a, b in ((origin, bb3), (origin, seat3), (bb3, seat3), (bb3, head + axis * 0.2),
                     (seat3, top)):  # fmt: skip
            _visual(frame, (a - origin).tolist(), (b - origin).tolist(), 0.015, _FRAME_RGBA)
        fork_top = top - head
        _visual(fork, [0.0, 0.0, 0.0], (front - head).tolist(), 0.012, _METAL_RGBA)
        _visual(fork, [0.0, 0.0, 0.0], fork_top.tolist(), 0.014, _METAL_RGBA)
        if p.fit is not None:
            gx, gz = p.fit.grips
            grip = np.array([gx, 0.0, gz]) - head
            half = p.fit.grip_offset
            _visual(fork, fork_top.tolist(), [grip[0], 0.0, grip[2]], 0.012, _METAL_RGBA)
            _visual(fork, [grip[0], -half, grip[2]], [grip[0], half, grip[2]], 0.012, _METAL_RGBA)
            _visual(frame, (seat3 - origin + [-0.08, 0, 0.01]).tolist(),
                    (seat3 - origin + [0.1, 0, 0.01]).tolist(), 0.03, _TYRE_RGBA)  # fmt: skip
        if p.drivetrain is not None:
            self._crank(spec, frame, bb3 - origin)

    def _wheel(self, parent: mujoco.MjsBody, name: str, joint: str, pos: Sequence[float],
               w: Wheel) -> None:  # fmt: skip
        pre = self.prefix
        body = parent.add_body(name=pre + name, pos=list(pos))
        body.add_joint(name=pre + joint, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 1.0, 0.0])
        body.explicitinertial = True
        body.mass = w.mass
        body.ipos = [0.0, 0.0, 0.0]
        body.inertia = [w.ixx, w.iyy, w.ixx]
        shape = self.params.wheel_shape
        if shape == "ellipsoid":
            g = body.add_geom(name=pre + name, type=mujoco.mjtGeom.mjGEOM_ELLIPSOID,
                              size=[w.radius, self.params.tyre, w.radius])  # fmt: skip
        elif shape == "cylinder":  # axis along the hinge (y)
            g = body.add_geom(name=pre + name, type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                              size=[w.radius, self.params.tyre, 0.0],
                              quat=[math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0])  # fmt: skip
        else:
            g = body.add_geom(name=pre + name, type=mujoco.mjtGeom.mjGEOM_SPHERE,
                              size=[w.radius, 0.0, 0.0])  # fmt: skip
        g.density = 0.0
        g.mass = 0.0
        g.rgba = list(_TYRE_RGBA)
        # spokes, so the wheel's turning shows
        for k in range(3):
            a = k * math.pi / 3
            d = [0.95 * w.radius * math.cos(a), 0.0, 0.95 * w.radius * math.sin(a)]
            _visual(body, [-d[0], 0.0, -d[2]], d, 0.004, _METAL_RGBA)

    def _crank(self, spec: mujoco.MjSpec, frame: mujoco.MjsBody, bb: F64) -> None:
        pre, dt = self.prefix, self.params.drivetrain
        assert dt is not None
        crank = frame.add_body(name=pre + "crank", pos=bb.tolist())
        crank.add_joint(name=pre + "crank", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 1.0, 0.0])
        crank.explicitinertial = True
        crank.mass = dt.crank_mass
        crank.ipos = [0.0, 0.0, 0.0]
        crank.inertia = [dt.crank_inertia / 2, dt.crank_inertia, dt.crank_inertia / 2]
        length, off = dt.crank_length, dt.pedal_offset
        # crank angle 0: right pedal up (Hodgins: "zero when the crank is vertical and the right
        # foot is higher than the left"); pedals at the arm ends, left at +y
        for side, sign, z in (("right", -1.0, length), ("left", 1.0, -length)):
            crank.add_site(name=f"{pre}{side}_pedal", pos=[0.0, sign * off, z])
            _visual(crank, [0.0, sign * 0.5 * off, 0.0], [0.0, sign * 0.5 * off, z], 0.01,
                    _METAL_RGBA)  # fmt: skip
            _visual(crank, [-0.05, sign * off, z], [0.05, sign * off, z], 0.012, _TYRE_RGBA)
        spec.add_equality(
            name=pre + "chain", type=mujoco.mjtEq.mjEQ_JOINT, name1=pre + "rear_spin",
            name2=pre + "crank", data=[0.0, dt.gear] + [0.0] * 10, solref=list(dt.chain),
        )  # fmt: skip

    # --------------------------------------------------------------- binding
    def bind(self, world: World) -> None:
        """Find the bicycle in the compiled model, apply its wheel contact, rolling resistance
        and noslip settings (after the World's own contact settings), and place it."""
        m, pre, p = world.model, self.prefix, self.params
        self.world = world
        self.frame_id = int(m.body(pre + "frame").id)
        self.fork_id = int(m.body(pre + "fork").id)
        self.wheel_geoms = np.array([m.geom(pre + n).id for n in ("rear_wheel", "front_wheel")])
        self.body_ids = np.array(self._subtree(m), dtype=np.int64)
        root = m.joint(pre + "root")
        self.qpos_adr = int(root.qposadr[0])
        self.dof_adr = int(root.dofadr[0])
        self.joint = {n: m.joint(pre + n) for n in ("rear_spin", "steer", "front_spin")}
        self.has_crank = p.drivetrain is not None
        if self.has_crank:
            self.joint["crank"] = m.joint(pre + "crank")
            self.crank_id = int(m.body(pre + "crank").id)
        self._q = {n: int(j.qposadr[0]) for n, j in self.joint.items()}
        self._v = {n: int(j.dofadr[0]) for n, j in self.joint.items()}
        if p.wheel_contact[0] < 2 * world.timestep:
            raise ConfigError(
                f"wheel contact time constant {p.wheel_contact[0]} s must be at least twice the "
                f"timestep {world.timestep} s"
            )
        m.geom_solref[self.wheel_geoms] = p.wheel_contact
        m.geom_solmix[self.wheel_geoms] = 1e3  # the wheel's contact settings win the mix
        m.geom_condim[self.wheel_geoms] = 3
        m.opt.noslip_iterations = max(int(m.opt.noslip_iterations), p.noslip)
        # rolling resistance: force b v at each contact = hinge damping b r^2 times v / r^2
        half = 0.5 * p.rolling_resistance
        m.dof_damping[self._v["rear_spin"]] = half * p.rear.radius**2
        m.dof_damping[self._v["front_spin"]] = half * p.front.radius**2

    def _subtree(self, m: mujoco.MjModel) -> list[int]:
        out = []
        for b in range(m.nbody):
            k = b
            while k > 0 and k != self.frame_id:
                k = int(m.body_parentid[k])
            if k == self.frame_id:
                out.append(b)
        return out

    def place(self, placement: Placement | None = None, floor_normal: F64 | None = None,
              floor_point: F64 | None = None) -> None:  # fmt: skip
        """Put the bicycle upright at ``placement`` with its wheels on the floor (a plane
        through ``floor_point`` with unit ``floor_normal``; default z = 0), rolling at the
        placement's speed (wheels and crank spinning to match). Runs ``mj_forward``."""
        pl = self.placement if placement is None else placement
        self.placement = pl
        w = self.world
        m, d, p = w.model, w.data, self.params
        n = np.array([0.0, 0.0, 1.0]) if floor_normal is None else np.asarray(floor_normal, float)
        p0 = np.zeros(3) if floor_point is None else np.asarray(floor_point, float)
        h = np.array([math.cos(pl.heading), math.sin(pl.heading), 0.0])
        pitch = _pitch_on_plane(p, n, h)
        # rear wheel centre: above the ground point (x, y) so its rim touches the plane
        ground = np.array(
            [pl.x, pl.y, p0[2] - (n[0] * (pl.x - p0[0]) + n[1] * (pl.y - p0[1])) / n[2]]
        )
        lift = p.rear.radius * math.hypot(float(n @ h), float(n[2]))
        centre = ground + np.array([0.0, 0.0, lift / n[2]])
        quat = _yaw_pitch_quat(pl.heading, pitch)
        qa, da = self.qpos_adr, self.dof_adr
        d.qpos[qa : qa + 3] = centre - 1e-4 * n / n[2]  # a hair into the ground: in contact
        d.qpos[qa + 3 : qa + 7] = quat
        for name in self._q:
            d.qpos[self._q[name]] = 0.0
        if self.has_crank:
            d.qpos[self._q["crank"]] = pl.crank
            d.qpos[self._q["rear_spin"]] = pl.crank * p.drivetrain.gear  # type: ignore[union-attr]
        fwd = np.array([math.cos(pitch) * h[0], math.cos(pitch) * h[1], math.sin(pitch)])
        d.qvel[da : da + 6] = 0.0
        d.qvel[da : da + 3] = pl.speed * fwd
        d.qvel[da + 3] = pl.roll_rate  # body frame: about the bicycle's x axis
        d.qvel[self._v["rear_spin"]] = pl.speed / p.rear.radius
        d.qvel[self._v["front_spin"]] = pl.speed / p.front.radius
        d.qvel[self._v["steer"]] = pl.steer_rate
        if self.has_crank:
            d.qvel[self._v["crank"]] = pl.speed / p.rear.radius / p.drivetrain.gear  # type: ignore[union-attr]
        w.state_epoch += 1
        mujoco.mj_forward(m, d)

    # --------------------------------------------------------------- state
    def rotation(self) -> F64:
        """``(3, 3)`` world rotation of the rear frame."""
        return self.world.data.xmat[self.frame_id].reshape(3, 3)

    @property
    def roll(self) -> float:
        """Lean (rad, > 0 to the right): the rear frame's lateral axis out of horizontal."""
        return float(math.asin(np.clip(self.rotation()[2, 1], -1.0, 1.0)))

    @property
    def yaw(self) -> float:
        """Heading (rad) of the rear frame's forward axis."""
        r = self.rotation()
        return float(math.atan2(r[1, 0], r[0, 0]))

    @property
    def steer(self) -> float:
        return float(self.world.data.qpos[self._q["steer"]])

    @property
    def steer_rate(self) -> float:
        return float(self.world.data.qvel[self._v["steer"]])

    @property
    def roll_rate(self) -> float:
        """Rate of :attr:`roll` (rad/s), from the rear frame's angular velocity."""
        d = self.world.data
        r = self.rotation()
        w = r @ d.qvel[self.dof_adr + 3 : self.dof_adr + 6]  # world angular velocity
        fwd = r[:, 0].copy()
        fwd[2] = 0.0
        n = float(np.linalg.norm(fwd))
        return float(w @ fwd / n) if n > 1e-9 else 0.0

    @property
    def yaw_rate(self) -> float:
        d = self.world.data
        return float((self.rotation() @ d.qvel[self.dof_adr + 3 : self.dof_adr + 6])[2])

    @property
    def position(self) -> F64:
        """``(3,)`` the rear wheel's centre (world)."""
        return self.world.data.xpos[self.frame_id].copy()

    @property
    def velocity(self) -> F64:
        """``(3,)`` world velocity of the rear wheel's centre."""
        return self.world.data.qvel[self.dof_adr : self.dof_adr + 3].copy()

    @property
    def speed(self) -> float:
        """Forward speed (m/s): the rear wheel's centre velocity along the frame's heading."""
        r = self.rotation()
        return float(self.velocity @ r[:, 0])

    @property
    def crank_angle(self) -> float:
        """Crank angle (rad, 0: right pedal up, increasing forward), wrapped to [0, 2 pi)."""
        if not self.has_crank:
            raise SimulationError("this bicycle has no crank")
        return float(self.world.data.qpos[self._q["crank"]] % (2 * math.pi))

    @property
    def crank_rate(self) -> float:
        return float(self.world.data.qvel[self._v["crank"]])

    @property
    def fallen(self) -> bool:
        return abs(self.roll) > FALLEN_ROLL

    # roll and steer from recorded qpos rows (the engine records qpos only)
    def roll_steer_from_qpos(self, qpos: F64) -> tuple[F64, F64]:
        """``(T,)`` roll and steer (rad) from recorded qpos rows ``(T, nq)``."""
        q = qpos[:, self.qpos_adr + 3 : self.qpos_adr + 7]
        w, x, y, z = q.T
        # world z component of the body's y axis: 2 (y z + w x)
        roll = np.arcsin(np.clip(2.0 * (y * z + w * x), -1.0, 1.0))
        return roll, qpos[:, self._q["steer"]].copy()


def _yaw_pitch_quat(yaw: float, pitch: float) -> F64:
    """Heading ``yaw`` about +Z, then nose-up ``pitch`` (about the body's -y)."""
    qz = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
    qy = np.array(_quat_y(-pitch))
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, qz, qy)
    return out


def _pitch_on_plane(p: BicycleParams, n: F64, h: F64) -> float:
    """Nose-up pitch of an upright bicycle heading ``h`` with both rims on the plane of unit
    normal ``n``. A vertical wheel's rim touches the plane where the normal, projected into the
    wheel's plane, points; its centre is then ``r |(n.h, n.z)|`` off the plane along ``n``."""
    k = math.hypot(float(n @ h), float(n[2]))
    rise = -float(n @ h) / float(n[2])  # dz/ds along h on the plane
    dr = p.front.radius - p.rear.radius
    off = dr * k / float(n[2])

    def gap(pitch: float) -> float:  # front centre height over where the plane wants it
        c, s = math.cos(pitch), math.sin(pitch)
        dx, dz = p.wheelbase * c - dr * s, p.wheelbase * s + dr * c
        return dz - rise * dx - off

    return float(brentq(gap, -1.2, 1.2))
