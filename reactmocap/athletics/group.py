"""Group riding (Hodgins et al. 1995, eq. 13, after Reynolds 1987 and Brogan & Hodgins): each
rider's desired position comes from what it sees, the positions and velocities of the riders in
its field of view and the obstacles ahead; the group's global velocity comes from the course (a
speed along a route). Eq. 13 turns the position error ``e`` into a desired velocity in the
plane,

    v_d = v + k_p e + k_v (v_gl - v),

which we read as the change the rider makes to its current velocity ``v`` (with ``k_v = 1`` it is
``v_gl + k_p e``): its length is the rider's speed command and its direction the heading
command for :class:`~reactmocap.athletics.rider.Rider`. Riders know each other only by
observation: a rider's desired position is its own, the others see where it goes. The global
velocity follows each rider's own lane (the route offset by the rider's distance from it, its
corners mitred) on the outside of a turn, so round a corner the pack's outer riders ride wide
instead of cutting across the riders inside them.

The desired position, relative to the rider's own: for each visible neighbour closer than
1.25 spacings, a point ``spacing`` from it on the rider's side (separation, as Reynolds); for each
visible neighbour or obstacle whose closest approach within :attr:`GroupGains.horizon` s, at the
current velocities, passes nearer than the clearance, a sideways step to clear it (on the side
the rider already passes, to the right when dead ahead). Design and figures:
``docs/athletics.md``."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.course import Route
from reactmocap.athletics.cycling_scene import Obstacle
from reactmocap.athletics.rider import Rider
from reactmocap.errors import ConfigError
from reactmocap.rotations import wrap_angle
from reactmocap.sim.world import World

__all__ = ["GroupGains", "GroupRiding", "observe"]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class GroupGains:
    """Eq. 13's gains ``k_p`` (1/s) and ``k_v``; what a rider sees: ``view`` (m) and the field
    of view ``fov`` (rad, full angle); the time ``horizon`` (s) a rider looks ahead for close
    passes; the clearance kept from obstacles' surfaces (m); the speed command's range as
    fractions of the global speed; the largest position correction (m); the road's half width
    (m) around the route, inside which nothing pulls a rider back to the route; neighbours
    closer than ``separation`` times the spacing push the desired position away; ``lane``: the
    global velocity follows the route offset by this fraction of the rider's own distance from
    it (1: the rider keeps its lane round a corner; 0: along the centre line's chord, and a
    pack slides across a corner instead of turning: its outer riders cut across the inner
    riders of the row behind), ``inner_lane`` the same factor for a rider on the inside of the
    turn ahead (0: it rides the centre line's chord; its own lane would cut the corner
    closer to whatever stands on the inside, as the shipped course's obstacle)."""

    kp: float = 0.5
    kv: float = 1.0
    view: float = 20.0
    fov: float = math.radians(240.0)
    horizon: float = 4.0
    clearance: float = 1.2
    min_speed: float = 0.6
    max_speed: float = 1.3
    max_correction: float = 3.0
    road: float = 4.0
    separation: float = 1.25
    lane: float = 1.0
    inner_lane: float = 0.0

    def __post_init__(self) -> None:
        if not (self.kp >= 0 and self.kv >= 0 and self.view > 0 and 0 < self.fov <= 2 * math.pi
                and self.horizon > 0 and self.clearance >= 0
                and 0 < self.min_speed <= 1.0 <= self.max_speed
                and 0 <= self.lane <= 1 and 0 <= self.inner_lane <= 1):  # fmt: skip
            raise ConfigError("group gains out of range (see GroupGains)")


def observe(riders: Sequence[Rider]) -> tuple[F64, F64, F64]:
    """What the riders see of each other: positions ``(n, 2)`` (the middle of each
    wheelbase), velocities ``(n, 2)`` and headings ``(n,)``."""
    pos = np.empty((len(riders), 2))
    vel = np.empty((len(riders), 2))
    head = np.empty(len(riders))
    for k, r in enumerate(riders):
        b = r.bicycle
        fwd = b.rotation()[:2, 0]
        pos[k] = b.position[:2] + 0.5 * b.params.wheelbase * fwd
        vel[k] = b.velocity[:2]
        head[k] = b.yaw
    return pos, vel, head


def _offset(route: Route, p: F64) -> float:
    """Signed distance (m, > 0 left) of ``p`` ``(2,)`` from ``route`` as its lane's offset: in a
    corner's outer wedge (the nearest route point its vertex) the larger of the distances from
    the two legs' lines, so the lane (:func:`_lane`) through ``p`` is mitred like the route."""
    s, near = route.project(p[None])
    r = p - near[0]
    d = route.direction(np.array([s[0] - 1e-6, s[0] + 1e-6]))
    off = d[:, 0] * r[1] - d[:, 1] * r[0]
    return float(off[np.argmax(np.abs(off))])


def _lane(route: Route, side: float) -> Route:
    """``route`` offset ``side`` m to its left (< 0: right), its corners mitred: each leg
    parallel to the route's at that distance."""
    p = route.points
    d = np.diff(p, axis=0)
    n = np.column_stack([-d[:, 1], d[:, 0]]) / np.linalg.norm(d, axis=1, keepdims=True)
    miter = np.vstack(
        [n[:1], (n[:-1] + n[1:]) / (1.0 + np.einsum("ij,ij->i", n[:-1], n[1:]))[:, None], n[-1:]]
    )
    return Route(p + side * miter)


def _pass_step(rel: F64, rel_vel: F64, clearance: F64, horizon: float, fallback: F64) -> F64:
    """Sideways steps ``(k, 2)`` that clear threats at ``rel`` ``(k, 2)`` (their position
    minus the rider's) closing at ``rel_vel`` (theirs minus the rider's) by ``clearance``
    ``(k,)`` at the closest approach within ``horizon``; ``fallback`` ``(2,)`` the direction to
    step when the pass is dead centre."""
    vv = np.einsum("ij,ij->i", rel_vel, rel_vel)
    t = np.where(vv > 1e-9, -np.einsum("ij,ij->i", rel, rel_vel) / np.maximum(vv, 1e-9), 0.0)
    closing = (t > 0) & (t < horizon)
    miss = rel + t[:, None] * rel_vel  # the threat's position relative to us at closest approach
    dist = np.linalg.norm(miss, axis=1)
    need = closing & (dist < clearance)
    away = np.where(dist[:, None] > 1e-3, -miss / np.maximum(dist, 1e-3)[:, None], fallback)
    return np.where(need[:, None], (clearance - dist)[:, None] * away, 0.0)


class GroupRiding:
    """The group behaviour as an engine controller: every ``control_every`` steps it sets each
    rider's speed and heading commands (tick it before the riders)."""

    def __init__(
        self,
        riders: Sequence[Rider],
        route: Route | Sequence[Route],
        speed: float,
        *,
        obstacles: Sequence[Obstacle] = (),
        spacing: float = 2.0,
        lookahead: float = 6.0,
        gains: GroupGains | None = None,
        control_every: int = 10,
    ) -> None:
        if not riders:
            raise ConfigError("group riding needs at least one rider")
        if not (math.isfinite(speed) and speed > 0 and spacing > 0 and lookahead > 0):
            raise ConfigError("group speed, spacing and lookahead must be > 0")
        self.riders = list(riders)
        #: the route each rider's global velocity follows (one route for a group; a route per
        #: rider lets riders meet, e.g. head on)
        self.routes = [route] * len(self.riders) if isinstance(route, Route) else list(route)
        if len(self.routes) != len(self.riders):
            raise ConfigError(f"{len(self.riders)} riders need 1 or {len(self.riders)} routes")
        self.speed = float(speed)
        self.obstacles = np.array([[o.x, o.y, o.radius] for o in obstacles]).reshape(-1, 3)
        self.spacing = float(spacing)
        self.lookahead = float(lookahead)
        self.gains = gains or GroupGains()
        self.control_every = int(control_every)
        #: per rider, the desired position (world x, y) of the last tick (known only to it)
        self.desired = np.zeros((len(self.riders), 2))

    def reset(self, world: World) -> None:
        del world

    def global_velocity(self, pos: F64) -> F64:
        """``(n, 2)`` the group's global velocity at each rider: the course speed along the
        rider's lane, the route offset by the rider's distance from it (from the rider's
        nearest lane point toward the one ``lookahead`` m further, so corners are taken in
        time; :attr:`GroupGains.lane`), plus a pull back toward the route for a rider more than
        :attr:`GroupGains.road` m off it (the road's half width)."""
        out = np.empty_like(pos)
        gn_road = self.gains.road
        for k, route in enumerate(self.routes):
            p = pos[k : k + 1]
            s, near = route.project(p)
            off = (near - p)[0]
            dist = float(np.linalg.norm(off))
            if self.gains.lane > 0:  # along the rider's own lane: round a corner the pack turns
                side = self.gains.lane * float(np.clip(_offset(route, p[0]), -gn_road, gn_road))
                d0, d1 = route.direction(np.array([s[0], s[0] + self.lookahead]))
                if side * (d0[0] * d1[1] - d0[1] * d1[0]) > 0:  # inside the turn ahead
                    side *= self.gains.inner_lane
                lane = _lane(route, side)
                s_lane, near_lane = lane.project(p)
                ahead = lane.point(s_lane + self.lookahead) - near_lane
            else:
                ahead = route.point(s + self.lookahead) - near
            n = float(np.linalg.norm(ahead))
            along = ahead[0] / n if n > 1e-6 else route.direction(s)[0]
            excess = max(dist - self.gains.road, 0.0)
            out[k] = self.speed * along + self.gains.kp * excess * off / max(dist, 1e-6)
        return out

    def commands(self, pos: F64, vel: F64, head: F64) -> tuple[F64, F64]:
        """Speed ``(n,)`` and heading ``(n,)`` commands from the observed state."""
        gn = self.gains
        n = len(pos)
        vgl = self.global_velocity(pos)
        speeds = np.empty(n)
        heads = np.empty(n)
        for i in range(n):  # a few riders; each sees its own neighbourhood
            fwd = np.array([math.cos(head[i]), math.sin(head[i])])
            right = np.array([fwd[1], -fwd[0]])
            rel = pos - pos[i]
            dist = np.linalg.norm(rel, axis=1)
            ang = np.arctan2(rel[:, 1], rel[:, 0]) - head[i]
            ang = wrap_angle(ang)
            seen = (dist < gn.view) & (np.abs(ang) <= gn.fov / 2)
            seen[i] = False
            e = np.zeros(2)
            near = seen & (dist < gn.separation * self.spacing)
            if near.any():  # separation: a point `spacing` from each close neighbour
                spots = pos[near] - rel[near] / np.maximum(dist[near], 1e-6)[:, None] * self.spacing
                e += np.mean(spots, axis=0) - pos[i]
            if seen.any():  # close passes with neighbours, at the velocities we see
                steps = _pass_step(rel[seen], vel[seen] - vel[i], np.full(int(seen.sum()), self.spacing),
                                   gn.horizon, right)  # fmt: skip
                e += steps.sum(axis=0)
            if self.obstacles.size:
                orel = self.obstacles[:, :2] - pos[i]
                odist = np.linalg.norm(orel, axis=1)
                oang = np.arctan2(orel[:, 1], orel[:, 0]) - head[i]
                oang = wrap_angle(oang)
                ok = (odist < gn.view) & (np.abs(oang) <= gn.fov / 2)
                if ok.any():
                    steps = _pass_step(orel[ok], np.tile(-vel[i], (int(ok.sum()), 1)),
                                       self.obstacles[ok, 2] + gn.clearance, gn.horizon, right)  # fmt: skip
                    e += steps.sum(axis=0)
            norm = float(np.linalg.norm(e))
            if norm > gn.max_correction:
                e *= gn.max_correction / norm
            self.desired[i] = pos[i] + e
            vd = vel[i] + gn.kp * e + gn.kv * (vgl[i] - vel[i])
            sp = float(np.linalg.norm(vd))
            speeds[i] = min(max(sp, gn.min_speed * self.speed), gn.max_speed * self.speed)
            heads[i] = math.atan2(vd[1], vd[0]) if sp > 1e-6 else head[i]
        return speeds, heads

    def control(self, world: World, t: float) -> None:
        del world, t
        speeds, heads = self.commands(*observe(self.riders))
        for r, s, h in zip(self.riders, speeds, heads):
            r.speed_cmd = float(s)
            r.heading_cmd = float(h)
