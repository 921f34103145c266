"""Figures of rides: the top view of every rider's path with the obstacles and the route, and
speed and heading against their commands (``--plot``); a video of the world, bicycles included
(MuJoCo's renderer, or a top-view animation where no GL context exists)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from reactmocap.io import save_png
from reactmocap.response.plots import pyplot, write_video
from reactmocap.response.render import free_camera

if TYPE_CHECKING:
    from reactmocap.athletics.cycling import CyclingResult

__all__ = ["paths_plot", "ride_video"]


def paths_plot(result: CyclingResult, path: str | Path) -> Path:
    """Top view of the paths (obstacles as circles, the route dashed), and speed and heading
    over time against their commands (rider 0 bold)."""
    plt = pyplot()
    fig = plt.figure(figsize=(11, 5), dpi=100)
    top = fig.add_subplot(1, 2, 1)
    sp = fig.add_subplot(2, 2, 2)
    hd = fig.add_subplot(2, 2, 4, sharex=sp)
    for k, log in enumerate(result.logs):
        lw = 1.6 if k == 0 else 0.9
        top.plot(log["x"], log["y"], lw=lw, label=f"rider {k}" if len(result.logs) <= 8 else None)
        sp.plot(log["t"], log["speed"], lw=lw)
        hd.plot(log["t"], np.degrees(np.unwrap(log["heading"])), lw=lw)
    if result.logs:
        lg = result.logs[0]
        sp.plot(lg["t"], lg["speed_cmd"], "k--", lw=0.8, label="command (rider 0)")
        hd.plot(lg["t"], np.degrees(np.unwrap(lg["heading_cmd"])), "k--", lw=0.8)
    for o in result.obstacles:
        top.add_patch(plt.Circle((o.x, o.y), o.radius, color="tab:orange", alpha=0.8))
    if result.route is not None:
        r = result.route.points
        top.plot(r[:, 0], r[:, 1], "k:", lw=0.8, label="route")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    top.set_title(f"{result.kind}: paths (top view)")
    top.legend(fontsize=7, loc="best")
    sp.set_ylabel("speed (m/s)")
    sp.legend(fontsize=7)
    hd.set_ylabel("heading (deg)")
    hd.set_xlabel("time (s)")
    fig.tight_layout()
    return save_png(fig, path)


def ride_video(result: CyclingResult, path: str | Path, fps: float = 30.0,
               size: tuple[int, int] = (640, 400)) -> tuple[Path, str]:  # fmt: skip
    """The ride as a video: MuJoCo's renderer of the world (riders, bicycles, obstacles, the
    hill) from a camera following the riders; where no GL context exists, a top-view GIF. Returns
    the path written and the renderer used."""
    model, q = result.team.world.model, result.rollout.frames()[1]
    step = max(1, int(round(result.rollout.fps[0] / fps)))
    q = q[::step]
    rate = result.rollout.fps[0] / step
    try:
        renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    except Exception as exc:  # each GL backend fails in its own way
        gif = Path(path).with_suffix(".gif")
        return _top_view(result, gif, rate), (
            f"top-view animation (no GL: MUJOCO_GL={os.environ.get('MUJOCO_GL', 'unset')!r}, {exc})"
        )
    data = mujoco.MjData(model)
    n = len(result.team.riders)
    # the azimuth follows the lead bicycle's heading (set every frame)
    cam = free_camera(4.5 if n == 1 else 6.0 + 1.5 * math.sqrt(n), -20.0 if n == 1 else -35.0, 0.0)
    roots = [result.team.bicycles[k].qpos_adr for k in range(n)]
    frames = np.empty((len(q), size[1], size[0], 3), dtype=np.uint8)
    look = None
    try:
        for i, row in enumerate(q):
            data.qpos[:] = row
            mujoco.mj_kinematics(model, data)
            centre = np.mean([row[a : a + 3] for a in roots], axis=0)
            look = centre if look is None else look + 0.15 * (centre - look)
            cam.lookat[:] = look
            yaw = math.degrees(math.atan2(data.xmat[result.team.bicycles[0].frame_id][3],
                                          data.xmat[result.team.bicycles[0].frame_id][0]))  # fmt: skip
            cam.azimuth = yaw + 140.0 if n == 1 else 225.0
            renderer.update_scene(data, camera=cam)
            frames[i] = renderer.render()
    finally:
        renderer.close()
    return write_video(frames, path, rate), "mujoco"


def _top_view(result: CyclingResult, path: Path, fps: float) -> Path:
    plt = pyplot()
    logs = result.logs
    t_end = max(float(lg["t"][-1]) for lg in logs if lg["t"].size)
    times = np.arange(0.0, t_end, 1.0 / min(fps, 10.0))
    xs = np.array([np.interp(times, lg["t"], lg["x"]) for lg in logs])
    ys = np.array([np.interp(times, lg["t"], lg["y"]) for lg in logs])
    fig, ax = plt.subplots(figsize=(5, 5), dpi=80)
    frames = []
    for i in range(times.size):
        ax.cla()
        for o in result.obstacles:
            ax.add_patch(plt.Circle((o.x, o.y), o.radius, color="tab:orange"))
        ax.plot(xs[:, : i + 1].T, ys[:, : i + 1].T, lw=0.6, color="0.7")
        ax.plot(xs[:, i], ys[:, i], "o", ms=4)
        ax.set_xlim(xs.min() - 3, xs.max() + 3)
        ax.set_ylim(ys.min() - 3, ys.max() + 3)
        ax.set_aspect("equal")
        ax.set_title(f"t = {times[i]:.1f} s")
        fig.canvas.draw()
        frames.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
    plt.close(fig)
    return write_video(np.stack(frames), path, min(fps, 10.0))
