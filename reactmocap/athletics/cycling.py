"""Riding a bicycle, alone (:func:`ride`: speed, heading or path, grade) or in a group around a
course (:func:`group_ride`), on the one engine (:func:`~reactmocap.sim.rollout`): the scene, the
riders seated on their bicycles, the controllers, a monitor that measures what happened
(speed held, heading reached, falls, collisions, separation, finish times) and the outputs (a
BVH per rider and per bicycle, a JSON report, a top-view plot, a video), written all or
nothing. The monitor is in :mod:`reactmocap.athletics.cycling_monitor`, the result and its
outputs in :mod:`reactmocap.athletics.cycling_results` (re-exported here). Figures and design:
``docs/athletics.md``."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bicycle import RIDER_BICYCLE, Bicycle, BicycleParams, Placement
from reactmocap.athletics.bodies import Athlete, athlete
from reactmocap.athletics.course import SPEED_RANGE, Course, Route
from reactmocap.athletics.cycling_monitor import Monitor
from reactmocap.athletics.cycling_results import CyclingResult, bicycle_motion
from reactmocap.athletics.cycling_scene import CyclingScene, Obstacle, Terrain
from reactmocap.athletics.group import GroupGains, GroupRiding
from reactmocap.athletics.rider import RIDER_WORLD, Rider, RiderMount, fit_bicycle
from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.rotations import wrap_angle
from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.world import World

__all__ = [
    "CyclingResult",
    "Monitor",
    "PathFollower",
    "Team",
    "bicycle_motion",
    "group_ride",
    "ride",
    "setup",
    "start_grid",
]

F64 = NDArray[np.float64]
#: the measured quality bars of docs/athletics.md (the report says when a run misses one)
SPEED_ERROR_BAR = 0.2
HEADING_SETTLE_BAR = 3.0
OVERSHOOT_BAR = math.degrees(0.1745)
MIN_SEPARATION_BAR = 0.5
#: speed error is measured after this long (s): the issue's "after 5 s"
SPEED_SETTLE = 5.0
#: a heading is settled within this (deg)
SETTLED_DEG = 5.0


# ------------------------------------------------------------------------------- the setup
@dataclass(eq=False)
class Team:
    """A world of riders on bicycles: ``riders[k]`` rides ``bicycles[k]``."""

    world: World
    scene: CyclingScene
    athlete: Athlete
    bicycles: list[Bicycle]
    riders: list[Rider]


def setup(
    placements: Sequence[Placement],
    *,
    body: str | Path | Motion = "male",
    params: BicycleParams = RIDER_BICYCLE,
    terrain: Terrain | None = None,
    obstacles: Sequence[Obstacle] = (),
) -> Team:
    """Riders on fitted bicycles at ``placements`` (speed, heading), seated and rolling."""
    if not placements:
        raise ConfigError("at least one rider")
    ath = athlete(body)
    fitted = fit_bicycle(params, ath)
    prefixes = [f"{chr(ord('a') + k)}/" for k in range(len(placements))]
    bikes = [Bicycle(fitted, pre + "bike/", pl) for pre, pl in zip(prefixes, placements)]
    mounts = [RiderMount(ath, b, pre) for b, pre in zip(bikes, prefixes)]
    scene = CyclingScene(bikes, terrain=terrain, obstacles=obstacles, parts=mounts,
                         riders=list(range(len(bikes))))  # fmt: skip
    world = World([ath.character] * len(bikes), RIDER_WORLD, scene=scene)
    scene.place(world)
    riders = []
    for k, (b, mnt) in enumerate(zip(bikes, mounts)):
        r = Rider(world, ath, b, mnt, k, speed=b.placement.speed, heading=b.placement.heading)
        r.seat()
        riders.append(r)
    return Team(world, scene, ath, bikes, riders)


class PathFollower:
    """Rides a route: the heading command points at the route ``lookahead`` m ahead of the
    rider's nearest route point (pure pursuit)."""

    def __init__(self, rider: Rider, route: Route, lookahead: float = 4.0,
                 control_every: int = 10) -> None:  # fmt: skip
        self.rider, self.route, self.lookahead = rider, route, float(lookahead)
        self.control_every = control_every

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        del world, t
        p = self.rider.bicycle.position[None, :2]
        s, _ = self.route.project(p)
        target = self.route.point(s + self.lookahead)[0]
        d = target - p[0]
        if float(np.linalg.norm(d)) > 1e-6:
            self.rider.heading_cmd = math.atan2(d[1], d[0])


class _Step:
    """Changes the heading command at a time (a heading step)."""

    def __init__(self, rider: Rider, heading: float, at: float, control_every: int) -> None:
        self.rider, self.heading, self.at, self.control_every = rider, heading, at, control_every

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        del world
        if t >= self.at - 1e-9:
            self.rider.heading_cmd = self.heading


# ------------------------------------------------------------------------------- running
def _check_speed(v: float, what: str = "speed") -> float:
    if not (math.isfinite(v) and SPEED_RANGE[0] <= v <= SPEED_RANGE[1]):
        raise ConfigError(
            f"{what} must be within {SPEED_RANGE[0]:g}-{SPEED_RANGE[1]:g} m/s (the range the "
            f"rider's controller is built and measured for), got {v!r}"
        )
    return float(v)


def _run(team: Team, seconds: float, controllers: Sequence[Controller], fps: float,
         on_tick: Callable[[float], None] | None) -> tuple[RolloutResult, float]:  # fmt: skip
    tick = None if on_tick is None else (lambda t: on_tick(min(t / seconds, 1.0)))
    cpu = time.process_time()
    res = rollout(team.world, seconds, controllers=controllers, record_fps=fps,
                  on_unstable="stop", on_tick=tick, tick_every=500)  # fmt: skip
    return res, time.process_time() - cpu


def _heading_step(log: dict[str, F64], target: float, at: float, start: float) -> dict[str, Any]:
    t = log["t"]
    h = np.unwrap(log["heading"])
    err = np.degrees(h - target)
    after = t >= at
    if not after.any():
        return {}
    sign = math.copysign(1.0, target - start) if target != start else 1.0
    overshoot = float(max(0.0, np.max(sign * err[after])))
    out = np.flatnonzero(after & (np.abs(err) > SETTLED_DEG))
    settled = not out.size or out[-1] < t.size - 1
    settle = float(t[out[-1] + 1] - at) if out.size and settled else (0.0 if not out.size else None)
    return {"settle_time_s": settle, "overshoot_deg": overshoot}


def ride(
    speed: float = 5.0,
    seconds: float = 10.0,
    *,
    heading: float | None = None,
    heading_at: float = 1.0,
    path: Sequence[tuple[float, float]] | None = None,
    grade: float = 0.0,
    gear: float | None = None,
    body: str | Path | Motion = "male",
    fps: float = 30.0,
    on_tick: Callable[[float], None] | None = None,
) -> CyclingResult:
    """One rider from the origin facing +X at ``speed`` (m/s) for ``seconds``: straight on,
    turning to ``heading`` (rad) at ``heading_at`` s, or along ``path`` (waypoints, m, from
    the start); ``grade``: the ground's rise along +X (0.05 = 5%); ``gear``: rear-wheel turns
    per crank turn (default the bicycle's)."""
    _check_speed(speed)
    if not (math.isfinite(seconds) and 0.5 <= seconds <= 3600):
        raise ConfigError(f"seconds must be within 0.5-3600, got {seconds!r}")
    if heading is not None and path is not None:
        raise ConfigError("give a heading or a path, not both")
    params = RIDER_BICYCLE if gear is None else RIDER_BICYCLE.with_gear(_check_gear(gear))
    team = setup([Placement(speed=speed)], body=body, params=params, terrain=Terrain(grade))
    rider = team.riders[0]
    ctrls: list[Controller] = []
    route = None
    if heading is not None:
        if not math.isfinite(heading):
            raise ConfigError(f"heading must be finite, got {heading!r}")
        ctrls.append(_Step(rider, heading, heading_at, rider.control_every))
    if path is not None:
        route = Route(np.vstack([[0.0, 0.0], np.asarray(path, dtype=np.float64).reshape(-1, 2)]))
        ctrls.append(PathFollower(rider, route, control_every=rider.control_every))
    mon = Monitor(team, route)
    res, cpu = _run(team, seconds, [*ctrls, rider, mon], fps, on_tick)
    log = rider.log.arrays()
    t = log["t"]
    window = t >= min(SPEED_SETTLE, 0.5 * seconds)
    err = log["speed"][window] - log["speed_cmd"][window]
    last = t >= t[-1] - 1.0 if t.size else window
    herr = np.degrees(np.abs(wrap_angle(log["heading"][last] - log["heading_cmd"][last])))
    fell = bool(not np.isnan(mon.fell_at[0]) or res.status != "ok")
    rep: dict[str, Any] = {
        "behaviour": "bicycle", "body": team.athlete.name, "speed_cmd_m_s": speed,
        "seconds": seconds, "grade_pct": 100.0 * grade,
        "gear": team.bicycles[0].params.drivetrain.gear,  # type: ignore[union-attr]
        "mean_speed_m_s": float(np.mean(log["speed"][window])) if window.any() else None,
        "speed_error_m_s": float(np.sqrt(np.mean(err**2))) if err.size else None,
        "speed_error_window_s": [float(min(SPEED_SETTLE, 0.5 * seconds)), float(seconds)],
        "heading_cmd_deg": math.degrees(heading) if heading is not None else None,
        "heading_error_deg": float(np.mean(herr)) if herr.size else None,
        "max_roll_deg": float(np.degrees(np.abs(log["roll"]).max())) if t.size else None,
        "distance_m": float(np.hypot(log["x"][-1], log["y"][-1])) if t.size else 0.0,
        "fell": fell, "fell_at_s": None if np.isnan(mon.fell_at[0]) else float(mon.fell_at[0]),
    }  # fmt: skip
    if heading is not None:
        rep.update(_heading_step(log, heading, heading_at, 0.0))
    rep.update(_timing(res, cpu, 1))
    rep["notes"] = _notes(rep)
    return CyclingResult("bicycle", team, res, rep, [log], route, (), cpu)


def _check_gear(gear: float) -> float:
    if not (math.isfinite(gear) and 1.0 <= gear <= 6.0):
        raise ConfigError(
            f"gear (rear-wheel turns per crank turn) must be within 1-6, got {gear!r}"
        )
    return float(gear)


def _timing(res: RolloutResult, cpu: float, riders: int) -> dict[str, Any]:
    return {
        "simulated_s": res.seconds, "wall_s": res.wall_s, "cpu_s": cpu,
        "realtime_factor": res.seconds / max(res.wall_s, 1e-9),
        "cpu_realtime_factor": res.seconds / max(cpu, 1e-9), "riders": riders,
        "status": res.status, "reason": res.reason,
    }  # fmt: skip


def _notes(rep: dict[str, Any]) -> list[str]:
    """Plain words for every measured bar a run misses (docs/athletics.md)."""
    notes = []
    if rep.get("fell"):
        notes.append("the rider fell")
    se = rep.get("speed_error_m_s")
    if se is not None and se > SPEED_ERROR_BAR:
        notes.append(f"speed error {se:.2f} m/s is above the {SPEED_ERROR_BAR} m/s bar")
    st = rep.get("settle_time_s", 0.0)
    if "settle_time_s" in rep and (st is None or st > HEADING_SETTLE_BAR):
        notes.append("the heading did not settle within 5 degrees "
                     + ("by the end" if st is None else f"for {st:.1f} s (bar {HEADING_SETTLE_BAR:g} s)"))  # fmt: skip
    ov = rep.get("overshoot_deg")
    if ov is not None and ov > OVERSHOOT_BAR:
        notes.append(f"heading overshoot {ov:.1f} deg is above the {OVERSHOOT_BAR:.0f} deg bar")
    if rep.get("collisions"):
        notes.append(f"{rep['collisions']} collision(s)")
    ms = rep.get("min_separation_m")
    if ms is not None and ms < MIN_SEPARATION_BAR:
        notes.append(f"minimum separation {ms:.2f} m is below the {MIN_SEPARATION_BAR} m bar")
    if rep.get("status") not in (None, "ok"):
        notes.append(f"the simulation stopped early: {rep.get('reason')}")
    return notes


def start_grid(course: Course, n: int) -> list[Placement]:
    """``n`` riders in rows of two behind the route's start, facing along it, at the course
    speed: rows ``1.5 spacing`` apart, riders ``spacing`` apart across."""
    p0, p1 = course.route.points[0], course.route.points[1]
    fwd = (p1 - p0) / np.linalg.norm(p1 - p0)
    left = np.array([-fwd[1], fwd[0]])
    heading = math.atan2(fwd[1], fwd[0])
    out = []
    for k in range(n):
        row, col = divmod(k, 2)
        lateral = (col - 0.5) * course.spacing if n > 1 else 0.0
        pos = p0 - fwd * (row * 1.5 * course.spacing) + left * lateral
        out.append(Placement(x=float(pos[0]), y=float(pos[1]), heading=heading,
                             speed=course.speed, crank=1.3 * k))  # fmt: skip
    return out


def group_ride(
    course: Course,
    riders: int,
    *,
    seconds: float | None = None,
    body: str | Path | Motion = "male",
    gains: GroupGains | None = None,
    placements: Sequence[Placement] | None = None,
    routes: Sequence[Route] | None = None,
    fps: float = 30.0,
    on_tick: Callable[[float], None] | None = None,
) -> CyclingResult:
    """``riders`` riders around ``course`` (a start grid behind the route's start unless
    ``placements`` are given; the course's route for all unless each has its own in
    ``routes``) for the course's seconds (or ``seconds``)."""
    if not (isinstance(riders, int) and 1 <= riders <= 26):
        raise ConfigError(f"riders must be 1-26, got {riders!r}")
    length = float(course.seconds if seconds is None else seconds)
    if not (math.isfinite(length) and 0.5 <= length <= 3600):
        raise ConfigError(f"seconds must be within 0.5-3600, got {seconds!r}")
    pls = list(placements) if placements is not None else start_grid(course, riders)
    if len(pls) != riders:
        raise ConfigError(f"{riders} riders need {riders} placements, got {len(pls)}")
    for pl in pls:
        _check_speed(pl.speed, "a rider's start speed")
    team = setup(pls, body=body, terrain=course.terrain, obstacles=course.obstacles)
    group = GroupRiding(team.riders, course.route if routes is None else routes, course.speed,
                        obstacles=course.obstacles,
                        spacing=course.spacing, lookahead=course.lookahead, gains=gains,
                        control_every=team.riders[0].control_every * 2)  # fmt: skip
    mon = Monitor(team, course.route)
    res, cpu = _run(team, length, [group, *team.riders, mon], fps, on_tick)
    logs = [r.log.arrays() for r in team.riders]
    fell = ~np.isnan(mon.fell_at) | (res.status != "ok")
    speeds = np.concatenate([lg["speed"] for lg in logs])
    rep: dict[str, Any] = {
        "behaviour": "group", "course": course.name, "course_file": course.source,
        "riders": riders, "body": team.athlete.name, "seconds": length,
        "group_speed_m_s": course.speed, "grade_pct": 100.0 * course.terrain.grade,
        "obstacles": len(course.obstacles),
        "collisions": len(mon.collisions),
        "collision_log": [{"t": t, "rider": i, "with": "obstacle" if j == -2 else f"rider {j}"}
                          for t, i, j in mon.collisions],
        "min_separation_m": None if not math.isfinite(mon.min_separation) else mon.min_separation,
        "min_separation_pair": list(mon.separation_pair),
        "min_separation_at_s": mon.separation_time,
        "fell": int(fell.sum()),
        "finish_times_s": [None if np.isnan(f) else float(f) for f in mon.finish],
        "finished": int(np.sum(~np.isnan(mon.finish))),
        "mean_speed_m_s": float(np.mean(speeds)) if speeds.size else None,
    }  # fmt: skip
    rep.update(_timing(res, cpu, riders))
    rep["riders"] = riders
    rep["notes"] = _notes(rep) + ([f"{rep['fell']} rider(s) fell"] if rep["fell"] else [])
    if rep["finished"] < riders:
        rep["notes"].append(f"{riders - rep['finished']} rider(s) did not reach the finish in "
                            f"{length:g} s")  # fmt: skip
    return CyclingResult("group", team, res, rep, logs, course.route, course.obstacles, cpu,
                         {"group": group, "monitor": mon})  # fmt: skip
