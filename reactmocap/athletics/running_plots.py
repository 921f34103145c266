"""Figures and gait measures of runs: the hip-knee phase plot of Hodgins et al.'s Fig. 6
(hip and knee flexion over the strides, ours beside a motion-capture run), the ground track
against the course, and the speed over time. Hip and knee angles are measured the same way
on any Motion (the simulated run's or a clip's) from its joints' world positions: hip flexion
is the thigh's angle forward of the trunk's downward axis in the body's sagittal plane, knee
flexion the angle between thigh and shank. Figures are written atomically."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import MotionError
from reactmocap.io import save_png
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.motion import Motion

__all__ = ["clip_gait", "hip_knee_angles", "phase_plot", "run_plot"]

F64 = NDArray[np.float64]


def hip_knee_angles(motion: Motion) -> tuple[F64, F64]:
    """``(T, 2)`` hip flexion and ``(T, 2)`` knee flexion (rad, left then right) of a Motion
    of any mapped skeleton, from its joints' world positions (see the module docstring)."""
    parts = map_body_parts(motion.skeleton)
    pos = motion.global_positions()
    try:
        pelvis = pos[:, parts.joint_of("pelvis")]
        chest = pos[:, parts.joint_of("chest")]
        legs = [[pos[:, parts.joint_of(f"{s}_{p}")] for p in ("thigh", "shin", "foot")]
                for s in "lr"]  # fmt: skip
    except Exception as exc:
        raise MotionError(f"hip-knee angles need a trunk and two legs: {exc}") from exc
    up = chest - pelvis
    up /= np.linalg.norm(up, axis=1, keepdims=True)
    left = legs[0][0] - legs[1][0]
    # sagittal plane: the trunk's axis and the forward direction (left x up)
    fwd = np.cross(left, up)
    fwd /= np.linalg.norm(fwd, axis=1, keepdims=True)
    hip = np.empty((pos.shape[0], 2))
    knee = np.empty((pos.shape[0], 2))
    for k, (h, kn, an) in enumerate(legs):
        thigh = kn - h
        shank = an - kn
        # hip flexion: the thigh forward of the trunk's downward axis, in the sagittal plane
        hip[:, k] = np.arctan2(np.einsum("ij,ij->i", thigh, fwd), -np.einsum("ij,ij->i", thigh, up))
        cos = np.einsum("ij,ij->i", thigh, shank) / (
            np.linalg.norm(thigh, axis=1) * np.linalg.norm(shank, axis=1)
        )
        knee[:, k] = np.arccos(np.clip(cos, -1.0, 1.0))
    return hip, knee


def clip_gait(motion: Motion) -> dict[str, float | None]:
    """A run clip's speed (m/s, the root's ground travel over the clip), cadence (steps/s)
    and stride (m, same-foot step spacing): touchdowns are where a foot's height comes within
    3 cm of its lowest after being higher, the steps counted from the first to the last."""
    parts = map_body_parts(motion.skeleton)
    pos = motion.global_positions()
    t = motion.times
    root = pos[:, parts.joint_of("pelvis"), :2]
    dur = float(t[-1] - t[0])
    speed = float(np.linalg.norm(root[-1] - root[0]) / dur) if dur > 0 else None
    events: list[tuple[float, int, F64]] = []
    for k, side in enumerate("lr"):
        foot = pos[:, parts.joint_of(f"{side}_foot")]
        z = foot[:, 2]
        low = z < z.min() + 0.03
        for i in range(1, len(z)):
            if low[i] and not low[i - 1]:
                events.append((float(t[i]), k, foot[i, :2]))
    events.sort(key=lambda e: e[0])
    times = [e[0] for e in events]
    cadence = (len(times) - 1) / (times[-1] - times[0]) if len(times) >= 2 else None
    strides = []
    for k in (0, 1):
        mine = [e for e in events if e[1] == k]
        strides += [float(np.linalg.norm(b[2] - a[2])) for a, b in zip(mine, mine[1:])]
    stride = float(np.mean(strides)) if strides else None
    if stride is None and cadence and speed:
        stride = 2.0 * speed / cadence
    return {"speed_m_s": speed, "cadence_steps_s": cadence, "stride_m": stride,
            "duration_s": dur, "touchdowns": len(events)}  # fmt: skip


def phase_plot(curves: Mapping[str, tuple[F64, F64]], path: str | Path, title: str = "") -> Path:
    """Knee flexion against hip flexion (degrees), one panel per curve set (e.g.
    ``{"simulated": (hip, knee), "motion capture": (hip, knee)}``, each ``(T,)``), as
    Fig. 6 of Hodgins et al."""
    from reactmocap.response.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, len(curves), figsize=(4.5 * len(curves), 4), dpi=100,
                             sharex=True, sharey=True)  # fmt: skip
    axes = np.atleast_1d(axes)
    for ax, (name, (hip, knee)) in zip(axes, curves.items()):
        ax.plot(np.degrees(hip), np.degrees(knee), "-", lw=1.2)
        ax.set_title(name)
        ax.set_xlabel("hip flexion (deg)")
        ax.set_ylabel("knee flexion (deg)")
        ax.grid(True, lw=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_png(fig, path)


def run_plot(result: Any, path: str | Path) -> Path:
    """A run's figure: the ground track with the course, the speed over time (per stride and
    desired), and the hip-knee phase plot of its last strides."""
    from reactmocap.athletics.paths import Circle, Polyline
    from reactmocap.response.plots import pyplot

    plt = pyplot()
    log = result.log
    rep = result.report
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 4.2), dpi=100)
    com = log["com"]
    a1.plot(com[:, 0], com[:, 1], "k-", lw=1.0, label="COM")
    course = result.course
    if isinstance(course, Circle):
        th = np.linspace(0, 2 * math.pi, 200)
        a1.plot(course.centre[0] + course.radius * np.cos(th),
                course.centre[1] + course.radius * np.sin(th), "C1--", lw=1, label="path")  # fmt: skip
    elif isinstance(course, Polyline):
        travelled = float(np.hypot(*np.diff(com[:, :2], axis=0).T).sum())
        s = np.linspace(0.0, min(course.total, travelled + 2.0), 400)
        a1.plot(*np.array([course.point_at(x) for x in s]).T, "C1--", lw=1, label="path")
    a1.set_aspect("equal", adjustable="datalim")
    a1.set_xlabel("x (m)")
    a1.set_ylabel("y (m)")
    a1.legend(fontsize=8)
    a1.set_title("ground track")
    t = log["t"]
    v = np.hypot(log["com_vel"][:, 0], log["com_vel"][:, 1])
    a2.plot(t, v, color="0.6", lw=0.6, label="COM speed")
    a2.axhline(rep["speed_m_s"], color="C3", ls="--", lw=1, label="desired")
    a2.set_xlabel("time (s)")
    a2.set_ylabel("speed (m/s)")
    a2.legend(fontsize=8)
    err = rep.get("speed_error_m_s")
    a2.set_title("speed" + (f" (stride RMS error {err:.2f} m/s)" if err is not None else ""))
    hip, knee = hip_knee_angles(result.motion)
    last = result.motion.times >= max(result.motion.duration - 2.0, 0.0)
    a3.plot(np.degrees(hip[last, 0]), np.degrees(knee[last, 0]), "-", lw=1.0)
    a3.set_xlabel("hip flexion (deg)")
    a3.set_ylabel("knee flexion (deg)")
    a3.set_title("hip-knee phase plot (left leg, last 2 s)")
    fig.suptitle(f"run at {rep['speed_m_s']:g} m/s ({rep['body']})")
    fig.tight_layout()
    return save_png(fig, path)
