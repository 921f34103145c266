"""What the athletic controllers measure, once per control tick: the centre of mass and its
velocity (``mj_subtreeVel``), which feet touch the floor and how hard, the ground reaction
force, the floor's normal (slopes), the support area, and whether anything but the feet
touches the ground."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.sim.bodies import SIM_BODIES
from reactmocap.sim.feet import SoleCorners, foot_soles
from reactmocap.sim.world import World

__all__ = ["LIFTOFF_CLEARANCE", "Senses"]

F64 = NDArray[np.float64]
#: how far (m) the lowest sole corner must be above the floor before the athlete counts as
#: airborne
LIFTOFF_CLEARANCE = 0.005


class Senses:
    """Measurements of one character, refreshed by :meth:`update` at most once per time."""

    def __init__(self, world: World, athlete: Athlete, character: int = 0) -> None:
        m = world.model
        self.world = world
        self.athlete = athlete
        self.character = character
        wc = world.characters[character]
        self.wc = wc
        self.root = int(wc.body_ids[0])
        self.mass = float(m.body_subtreemass[self.root])
        self.floor = int(m.geom("floor").id)
        self.feet, self.soles, self._corners = foot_soles(world, character, "athletics")
        self._sole_side = {int(g): k for k, g in enumerate(self.soles)}
        self._ids = {b: int(i) for b, i in zip(SIM_BODIES, wc.body_ids)}
        #: joint ids of the ankles (left, right)
        self.ankle_joints = np.array([m.joint(f"{wc.prefix}{s}_ankle").id for s in "lr"])
        #: body ids of the thighs, shins and feet (left, right each)
        self.leg_bodies = np.array([self._ids[f"{s}_{p}"] for p in ("thigh", "shin", "foot")
                                    for s in "lr"])  # fmt: skip
        self._own = world.geom_character == character
        self._own_list = self._own.tolist()
        self._body = world.geom_body
        self._f6 = np.zeros(6)
        self._forward = _axis_in_body(athlete, np.array([1.0, 0.0, 0.0]))
        self._left = _axis_in_body(athlete, np.array([0.0, 1.0, 0.0]))
        self._up = _axis_in_body(athlete, np.array([0.0, 0.0, 1.0]))
        self.time = -1.0
        self.com = np.zeros(3)
        self.com_vel = np.zeros(3)
        self.foot_contact = np.zeros(2, dtype=bool)
        self.foot_force = np.zeros(2)
        self.foot_point = np.zeros((2, 3))
        self.grf = np.zeros(3)
        self.other_contact: tuple[str, ...] = ()
        self.up = np.array([0.0, 0.0, 1.0])
        self.floor_normal = np.array([0.0, 0.0, 1.0])
        #: height (m) of the lowest sole corner above the floor
        self.clearance = 0.0
        #: ``(2, 4, 3)`` world sole corners at the last update
        self.corners = np.zeros((2, 4, 3))
        # MjData's rows read at every update, as views made once (the World keeps one MjData)
        d = world.data
        self._rows = (d.subtree_com[self.root], d.subtree_linvel[self.root],
                      d.geom_xmat[self.floor].reshape(3, 3)[:, 2], d.geom_xpos[self.floor])  # fmt: skip
        self._root_xmat = d.xmat[self.root].reshape(3, 3)
        self._sole_corners = SoleCorners(d, self.soles, self._corners)

    def body(self, name: str) -> int:
        return self._ids[name]

    def update(self, t: float) -> None:
        """Measure at rollout time ``t`` (no-op if already done at ``t``)."""
        if t == self.time:
            return
        self.time = t
        m, d = self.world.model, self.world.data
        mujoco.mj_subtreeVel(m, d)
        com, com_vel, normal, floor_pos = self._rows
        self.com[:] = com
        self.com_vel[:] = com_vel
        self.floor_normal[:] = normal
        # summed in floats, contact by contact: the same roundings as numpy's in-place sums,
        # without a numpy call per term (a quarter of the runner's senses)
        grf = [0.0, 0.0, 0.0]
        force = [0.0, 0.0]
        point = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
        touch = [False, False]
        others: set[str] = set()
        n = d.ncon
        if n:
            # the contact arrays' views made once (each attribute read makes a new one)
            con = d.contact
            # the contacts' rows as lists at once (a row's index and list cost per contact)
            frames, points = con.frame[:n].tolist(), con.pos[:n].tolist()
            floor, own, f6 = self.floor, self._own_list, self._f6
            for i, (g1, g2) in enumerate(con.geom[:n].tolist()):
                if not ((g1 == floor or g2 == floor) and (own[g1] or own[g2])):
                    continue  # not this character on the floor
                g = g2 if g1 == self.floor else g1
                mujoco.mj_contactForce(m, d, i, f6)
                # world force on geom2 from geom1: the contact frame's rows^T f
                r = frames[i]
                fx, fy, fz = f6.tolist()[:3]
                f = [r[0] * fx + r[3] * fy + r[6] * fz, r[1] * fx + r[4] * fy + r[7] * fz,
                     r[2] * fx + r[5] * fy + r[8] * fz]  # fmt: skip
                if g == g1:
                    f = [-f[0], -f[1], -f[2]]
                grf = [grf[0] + f[0], grf[1] + f[1], grf[2] + f[2]]
                k = self._sole_side.get(g, -1)
                if k >= 0:
                    fn = abs(fx)
                    touch[k] = True
                    force[k] += fn
                    px, py, pz = points[i]
                    q = point[k]
                    point[k] = [q[0] + fn * px, q[1] + fn * py, q[2] + fn * pz]
                else:
                    others.add(SIM_BODIES[int(self._body[g])])
        self.corners = self._sole_corners()
        for k in range(2):
            if force[k] > 0:
                point[k] = [x / force[k] for x in point[k]]
            elif touch[k]:  # touching without a normal force: the sole's centre
                point[k] = self.corners[k].mean(0).tolist()
        self.grf[:] = grf
        self.foot_contact[:] = touch
        self.foot_force[:] = force
        self.foot_point.reshape(-1)[:] = point[0] + point[1]  # a flat list converts faster
        self.other_contact = tuple(sorted(others))
        if self.floor_normal.tolist() == [0.0, 0.0, 1.0]:
            # a level floor: each corner's height over it, exactly the product below (x 0 +
            # y 0 + z 1 in any order), and min(z - f) = min(z) - f (rounding is monotonic)
            low = np.minimum.reduce(self.corners[..., 2], axis=None)
            self.clearance = float(low) - float(floor_pos[2])
        else:
            rel = self.corners - floor_pos
            self.clearance = float(np.minimum.reduce(rel @ self.floor_normal, axis=None))

    # ------------------------------------------------------------------ derived
    @property
    def airborne(self) -> bool:
        """Nothing touches the floor and the soles are clear of it by :data:`LIFTOFF_CLEARANCE`
        (a sole resting on the floor loses its contacts for a step now and then)."""
        return (not self.foot_contact.any() and not self.other_contact
                and self.clearance > LIFTOFF_CLEARANCE)  # fmt: skip

    def sole_corners(self) -> F64:
        """``(2, 4, 3)`` world corners of the soles (left, right) at the last update."""
        return self.corners

    def heading(self) -> float:
        """Heading (rad about +Z) of the pelvis's anatomical forward axis."""
        x, y, _ = (self._root_xmat @ self._forward).tolist()
        return math.atan2(y, x)  # np.arctan2's value, without a ufunc call on two scalars

    def side_axis(self) -> F64:
        """The pelvis's anatomical left-right axis (world, unit; left > 0): the axis a
        somersault turns about."""
        return self.world.data.xmat[self.root].reshape(3, 3) @ self._left

    def long_axis(self) -> F64:
        """The pelvis's anatomical up axis (world, unit): the long axis a body twists about."""
        return self.world.data.xmat[self.root].reshape(3, 3) @ self._up

    def side_heading(self) -> float:
        """Heading (rad about +Z) of the forward axis a quarter turn from the pelvis's
        left-right axis. Unlike :meth:`heading` it holds through a somersault: there the
        pelvis's forward axis passes through the vertical and its heading flips by half a
        turn."""
        left = self.side_axis()
        return float(np.arctan2(-left[0], left[1]))

    def local(self, v: F64, heading: float | None = None) -> F64:
        """Horizontal world vector(s) ``v (..., 3)`` in the heading frame (x forward, y left)."""
        h = self.heading() if heading is None else heading
        c, s = np.cos(h), np.sin(h)
        v = np.asarray(v, dtype=np.float64)
        return np.stack([c * v[..., 0] + s * v[..., 1], -s * v[..., 0] + c * v[..., 1]], -1)

    def support_center(self, heading: float | None = None, both: bool = False) -> F64:
        """World point (on the floor) at the middle of the support area's extents in the
        heading frame: the feet in contact, or both feet when none is (or ``both``)."""
        corners = self.sole_corners()
        use = self.foot_contact if self.foot_contact.any() and not both else np.ones(2, dtype=bool)
        pts = corners[use].reshape(-1, 3)
        loc = self.local(pts, heading)
        mid = 0.5 * (loc.min(axis=0) + loc.max(axis=0))
        h = self.heading() if heading is None else heading
        c, s = np.cos(h), np.sin(h)
        z = float(pts[:, 2].mean())
        return np.array([c * mid[0] - s * mid[1], s * mid[0] + c * mid[1], z])

    def support_extent(self, heading: float | None = None, both: bool = False) -> tuple[F64, F64]:
        """Min and max ``(2,)`` of the supporting soles' corners in the heading frame (both
        soles' when none is down, or ``both``)."""
        corners = self.sole_corners()
        use = self.foot_contact if self.foot_contact.any() and not both else np.ones(2, dtype=bool)
        loc = self.local(corners[use].reshape(-1, 3), heading)
        return loc.min(axis=0), loc.max(axis=0)


def _axis_in_body(athlete: Athlete, axis: F64) -> F64:
    """An axis of the pelvis's anatomical neutral frame (+X forward, +Y left) in its body
    frame."""
    from reactmocap.rotations import quat_conj, quat_rotate

    return quat_rotate(quat_conj(athlete.neutral[0]), axis)
