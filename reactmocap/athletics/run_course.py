"""One run of the runner (:mod:`reactmocap.athletics.running`) on a course: the world, the
engine's rollout, and the report measured from the run itself (speed held, path followed,
falls, cadence and stride), with optional cloth (:mod:`reactmocap.athletics.cloth`) and a
sideways push. :func:`run_course` is the Python entry point the ``athletics run`` command
wraps. How each figure is measured: ``docs/athletics.md``."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import athlete as make_athlete
from reactmocap.athletics.paths import Course, EntryPath, Facing, Polyline, parse_course
from reactmocap.athletics.report import FALL_HEIGHT, report_json
from reactmocap.athletics.running import (
    START_SPEED,
    Runner,
    RunParams,
    check_speed,
    running_start,
)
from reactmocap.athletics.scene import athletics_world, stand_angles
from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.impacts import Impact
from reactmocap.sim.rollout import RolloutResult, rollout

__all__ = [
    "SETTLE",
    "SPEED_TOLERANCE",
    "PATH_TOLERANCE",
    "RunResult",
    "run_course",
    "run_metrics",
]

F64 = NDArray[np.float64]
#: seconds at the start of a run that the figures leave out (the start from a set pose)
SETTLE = 3.0
#: the goals the report checks (docs/athletics.md): RMS stride-speed error and cross-track
#: error; a run past them is reported as poor
SPEED_TOLERANCE = 0.15
PATH_TOLERANCE = 0.3
#: physics steps per control tick (4 ms)
CONTROL_EVERY = 8


@dataclass
class RunResult:
    """A finished run: the motion on the athlete's skeleton, the report, what produced them
    (the runner and its log, the rollout) and the cloth's record if any."""

    motion: Motion
    report: dict[str, Any]
    rollout: RolloutResult
    runner: Runner
    log: dict[str, NDArray]
    course: Course
    cloth: Any = None
    extra: dict[str, Any] = field(default_factory=dict)

    def report_json(self) -> str:
        return report_json(self.report)


def run_course(
    speed: float,
    *,
    seconds: float = 10.0,
    path: str | Course = "line",
    body: str | Path | Motion = "male",
    params: RunParams | None = None,
    cloth: str | None = None,
    cloth_feedback: bool = False,
    push: tuple[float, float, float] | None = None,
    fps: float = 60.0,
    on_tick: Callable[[float], None] | None = None,
) -> RunResult:
    """Run at ``speed`` m/s (2.5-5) for ``seconds`` along ``path`` (``"line"``,
    ``"circle:R"``, ``"eight:R"``, either with ``"+entry:L"`` for a clothoid entry of L m onto
    the loop, the eight with ``"+turn:L"`` for a clothoid pair of L m between its loops, a CSV
    file, or a Course), starting in flight along +X from the origin.
    ``cloth="pants"`` dresses the runner in cloth driven by the body (with
    ``cloth_feedback`` its forces act back on the body). ``push`` is ``(time s, impulse N s,
    direction rad relative to the runner's heading)`` on the chest over 0.1 s. ``on_tick`` is
    called now and then with the fraction simulated."""
    speed = check_speed(speed)
    if not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and seconds > 0):
        raise ConfigError(f"seconds must be > 0, got {seconds!r}")
    if not (math.isfinite(fps) and fps > 0):
        raise ConfigError(f"fps must be > 0, got {fps!r}")
    ath = make_athlete(body)
    world = athletics_world(ath)
    # faster runs start at START_SPEED and the runner accelerates (Runner's ramp)
    qpos, qvel = running_start(ath, min(speed, START_SPEED))
    world.set_pose(0, qpos, qvel)
    start = world.com(0)[:2]
    course = parse_course(path, start, 0.0) if isinstance(path, str) else path
    if isinstance(course, (Polyline, Facing)):
        course.reset()
    if isinstance(course, Facing):
        course.speed = speed
    runner = Runner(world, ath, speed, course, params, control_every=CONTROL_EVERY)
    controllers: list[Controller] = [runner]
    dress = None
    if cloth is not None:
        from reactmocap.athletics.cloth import Cloth

        dress = Cloth(world, cloth, feedback=cloth_feedback, control_every=CONTROL_EVERY)
        controllers.append(dress)
    impacts: tuple[Impact, ...] = ()
    if push is not None:
        when, impulse, direction = (float(x) for x in push)
        if not (0 <= when < seconds and math.isfinite(impulse) and math.isfinite(direction)):
            raise ConfigError(f"push must be (time within the run, impulse, direction), got {push}")
        # the runner heads along +X at the start: the direction is from its forward axis
        # (pi/2: a push to its left)
        f = impulse / 0.1
        force = (f * math.cos(direction), f * math.sin(direction), 0.0)
        impacts = (Impact("chest", force=force, start=when, duration=0.1),)
    tick = None if on_tick is None else (lambda t: on_tick(min(t / seconds, 1.0)))
    try:
        res = rollout(world, seconds, controllers=controllers, impacts=impacts,
                      record_fps=fps, on_unstable="stop", on_tick=tick, tick_every=400)  # fmt: skip
    finally:
        runner.rig.release()
    log = runner.log.arrays()
    standing = float(ath.standing_qpos(stand_angles(ath))[2])
    report: dict[str, Any] = {
        "behaviour": "run", "body": ath.name, "mass_kg": round(ath.mass, 2),
        "speed_m_s": speed, "seconds": float(seconds),
        "path": path if isinstance(path, str) else type(path).__name__,
    }  # fmt: skip
    # a loop's entry is not scored: its cross-track error counts from the loop's start
    entered = course.entered_at if isinstance(course, EntryPath) else 0.0
    path_from = math.inf if entered is None else entered
    report.update(run_metrics(log, runner.log.touchdowns, speed, standing, path_from=path_from))
    if isinstance(course, EntryPath):
        report["path_entry_m"] = course.entry
        report["loop_from_s"] = entered
    # how far along a path the runner got (whether a figure eight was run through)
    report["path_progress_m"] = course.progress if isinstance(course, Polyline) else None
    report["path_length_m"] = course.total if isinstance(course, Polyline) else None
    if res.status != "ok":
        report["fell"] = True
        report["reason"] = res.reason
    # the engine stopped the run: a fall in the log before it has its own time, else none
    report["unstable_at_s"] = round(res.seconds, 3) if res.status == "unstable" else None
    if dress is not None:
        report.update(dress.report())
    report.update({
        "simulated_s": round(res.seconds, 3), "wall_s": round(res.wall_s, 3),
        "realtime_factor": round(res.seconds / max(res.wall_s, 1e-9), 2), "status": res.status,
    })  # fmt: skip
    report["notes"] = _notes(report)
    motion = res.motion(0, name=f"run_{ath.name}")
    return RunResult(motion, report, res, runner, log, course, dress)


def run_metrics(
    log: dict[str, NDArray],
    touchdowns: list[tuple[float, int, float, float]],
    speed: float,
    standing_pelvis: float,
    settle: float = SETTLE,
    path_from: float = 0.0,
) -> dict[str, Any]:
    """The run's figures from the runner's log, after ``settle`` seconds (or over the
    second half of a shorter run):

    * ``fell``: anything but the feet touched the floor, or the pelvis sank below
      :data:`~reactmocap.athletics.report.FALL_HEIGHT` of its standing height;
    * ``mean_speed_m_s``: the length of the COM's ground track over its duration;
    * ``speed_error_m_s``: RMS over strides (same-foot touchdown to touchdown) of the stride's
      mean speed (its ground-track length over its duration) minus the desired speed; the
      speed within a stride swings by design, so the stride is the unit a speed is held over;
    * ``path_error_m``: RMS cross-track distance from the path, from ``path_from`` s too (a
      loop's start after its entry; None without a path or before it);
    * ``cadence_steps_s``: touchdowns per second; ``stride_m``: same-foot touchdown spacing;
    * ``heading_deg``: the pelvis's mean heading over the last second.
    """
    t = log["t"]
    if t.size == 0:
        return {"fell": True, "mean_speed_m_s": None, "speed_error_m_s": None}
    down = np.flatnonzero(log["others"] | (log["pelvis"] < FALL_HEIGHT * standing_pelvis))
    fell_at = float(t[down[0]]) if down.size else None
    end = fell_at if fell_at is not None else float(t[-1])
    t0 = settle if end > settle + 1.0 else 0.5 * end
    sel = (t >= t0) & (t <= end)
    com = log["com"][sel, :2]
    seg = np.hypot(*np.diff(com, axis=0).T) if com.shape[0] > 1 else np.zeros(0)
    dur = float(t[sel][-1] - t[sel][0]) if sel.sum() > 1 else 0.0
    mean_speed = float(seg.sum() / dur) if dur > 0 else None
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    ts = t[sel]
    td = [(tt, leg, x, y) for tt, leg, x, y in touchdowns if t0 <= tt <= end]
    strides: list[float] = []
    lengths: list[float] = []
    for leg in (0, 1):
        mine = [r for r in td if r[1] == leg]
        for a, b in zip(mine, mine[1:]):
            i0 = int(np.searchsorted(ts, a[0]))
            i1 = min(int(np.searchsorted(ts, b[0])), ts.size - 1)
            if i1 > i0:
                strides.append(float(arc[i1] - arc[i0]) / float(ts[i1] - ts[i0]))
            lengths.append(float(math.hypot(b[2] - a[2], b[3] - a[3])))
    errs = np.asarray(strides) - speed
    times = [r[0] for r in td]
    cadence = (len(times) - 1) / (times[-1] - times[0]) if len(times) > 2 else None
    cross = log["cross_track"][sel & (t >= path_from)]
    path_error = (float(np.sqrt(np.mean(cross**2))) if cross.size and np.isfinite(cross).all()
                  else None)  # fmt: skip
    last = t >= end - 1.0
    heading = float(np.degrees(np.angle(np.mean(np.exp(1j * log["heading"][last])))))
    return {
        "fell": fell_at is not None,
        "fell_at_s": fell_at,
        "mean_speed_m_s": mean_speed,
        "speed_error_m_s": float(np.sqrt(np.mean(errs**2))) if errs.size else None,
        "strides_measured": int(errs.size),
        "path_error_m": path_error,
        "cadence_steps_s": cadence,
        "stride_m": float(np.mean(lengths)) if lengths else None,
        "step_length_m": float(np.mean(lengths)) / 2.0 if lengths else None,
        "heading_deg": heading,
        "figures_from_s": t0,
    }


def _notes(r: dict[str, Any]) -> list[str]:
    """Plain statements of where a run missed its goals."""
    notes = []
    at, unstable = r.get("fell_at_s"), r.get("unstable_at_s")
    if at is not None:
        notes.append(f"the runner fell at {at:.2f} s")
    if unstable is not None:
        notes.append(f"the simulation went unstable at {unstable:.2f} s and was stopped "
                     f"(counted as a fall)")  # fmt: skip
    elif r.get("fell") and at is None:
        notes.append("the runner fell")
    err = r.get("speed_error_m_s")
    if err is not None and err > SPEED_TOLERANCE:
        notes.append(f"poor speed control: RMS stride-speed error {err:.2f} m/s "
                     f"(goal <= {SPEED_TOLERANCE} m/s)")  # fmt: skip
    perr = r.get("path_error_m")
    if perr is not None and perr > PATH_TOLERANCE:
        notes.append(f"poor path following: RMS cross-track error {perr:.2f} m "
                     f"(goal <= {PATH_TOLERANCE} m)")  # fmt: skip
    pen = r.get("cloth_penetration_max_m")
    if pen is not None and pen > 0.01:
        notes.append(f"cloth penetrates the body by up to {100 * pen:.1f} cm (goal <= 1 cm)")
    rtf = r.get("realtime_factor")
    if rtf is not None and rtf < 2.0 and r.get("cloth_penetration_max_m") is None:
        notes.append(f"simulation ran {rtf:.1f}x real time (goal >= 2x)")
    return notes
