"""Figures of a response: the chest path from above beside the paper's Figure 1 pelvis height,
and a stick-figure video.

matplotlib and imageio are optional extras (``pip install reactmocap[plot,video]``); a missing
one raises a ReactMocapError that says which extra to install.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ReactMocapError
from reactmocap.io import atomic_write_bytes, save_png
from reactmocap.library.motion import Motion

__all__ = ["imageio_v3", "pyplot", "response_plot", "stick_figure_video", "write_video"]


def pyplot():  # type: ignore[no-untyped-def]
    """matplotlib's ``pyplot`` on the ``MPLBACKEND`` backend (Agg unless set), or a clear
    error naming the extra to install."""
    try:
        import matplotlib

        matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
        import matplotlib.pyplot as plt
    except ImportError:
        raise ReactMocapError("plots need matplotlib: pip install 'reactmocap[plot]'") from None
    return plt


def imageio_v3():  # type: ignore[no-untyped-def]
    try:
        import imageio.v3 as iio
    except ImportError:
        raise ReactMocapError("videos need imageio: pip install 'reactmocap[video]'") from None
    return iio


def write_video(frames: NDArray[np.uint8], path: str | Path, fps: float) -> Path:
    """Write ``(T, H, W, 3)`` frames as a GIF or MP4 (by ``path``'s suffix), encoded in
    memory and written atomically: never a half-written video."""
    iio = imageio_v3()
    out = Path(path)
    ext = out.suffix.lower()
    if ext == ".gif":
        data = iio.imwrite("<bytes>", frames, extension=".gif", duration=1000 / fps, loop=0)
    else:
        data = iio.imwrite("<bytes>", frames, extension=ext, fps=fps)
    atomic_write_bytes(out, data)
    return out


def response_plot(
    paths: Mapping[str, NDArray[np.float64]],
    curves: Mapping[str, tuple[NDArray[np.float64], NDArray[np.float64]]],
    path: str | Path,
    *,
    impact_time: float,
    transition: tuple[float, float],
    hit: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    title: str = "",
) -> Path:
    """Left: the horizontal chest path of each labelled motion seen from above ``(T, 2)``, with
    the hit as an arrow (``hit``: point and impulse, 0.02 m per N s); right: pelvis height over
    time (like the paper's Figure 1) with the impact and the transition marked."""
    plt = pyplot()
    fig, (top, ax) = plt.subplots(1, 2, figsize=(12, 4.5), dpi=100,
                                  gridspec_kw={"width_ratios": [1, 1.4]})  # fmt: skip
    styles = {"mocap before": "b-", "found clip": "g-", "final blend": "r-",
              "simulation 1": "k:", "simulation 2": "m--", "undisturbed clip": "c:",
              "output": "r-"}  # fmt: skip
    for label, xy in paths.items():
        top.plot(xy[:, 0], xy[:, 1], styles.get(label, "-"), label=label, lw=1.5)
        top.plot(xy[-1, 0], xy[-1, 1], styles.get(label, "-")[0] + "o", ms=4)
    if hit is not None:
        (px, py), (jx, jy) = hit[0][:2], 0.02 * np.asarray(hit[1])[:2]
        top.annotate("", xy=(px, py), xytext=(px - jx, py - jy),
                     arrowprops={"arrowstyle": "->", "color": "orange", "lw": 2})  # fmt: skip
        top.plot([px - jx, px], [py - jy, py], color="orange", alpha=0.0)  # in the limits
        top.plot([], [], color="orange", label="impulse (0.02 m per N s)")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m)")
    top.set_ylabel("y (m)")
    top.set_title("chest path, top view")
    top.legend(loc="best", fontsize=7)
    for label, (t, h) in curves.items():
        ax.plot(t, h, styles.get(label, "-"), label=label, lw=2 if label == "final blend" else 1.2)
    ax.axvline(impact_time, color="orange", lw=1, label="impact")
    ax.axvspan(transition[0], transition[1], color="0.9", label="transition")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("pelvis height (m)")
    ax.set_title("pelvis height")
    ax.legend(loc="best", fontsize=7)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_png(fig, path)


def stick_figure_video(
    motions: Sequence[tuple[Motion, str]],
    path: str | Path,
    *,
    fps: float = 30.0,
    size: tuple[int, int] = (480, 360),
) -> Path:
    """Render motions as coloured stick figures from a fixed 3/4 view into a GIF or MP4
    (by ``path``'s suffix). Used when no GL context is available for MuJoCo's renderer."""
    plt = pyplot()
    imageio_v3()  # fail before drawing if the writer is missing
    sampled = []
    n = 0
    for motion, color in motions:
        m = motion.resample(fps)
        n = max(n, m.num_frames)
        sampled.append((m.global_positions(), m.skeleton.parents, color))
    allp = np.concatenate([p.reshape(-1, 3) for p, _, _ in sampled])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre = (lo + hi) / 2
    half = max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 2.0) / 2
    fig = plt.figure(figsize=(size[0] / 100, size[1] / 100), dpi=100)
    ax = fig.add_subplot(projection="3d")
    frames = []
    for i in range(n):
        ax.cla()
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(0, 2 * half)
        ax.set_axis_off()
        ax.view_init(elev=15, azim=-60)
        for pos, parents, color in sampled:
            p = pos[min(i, len(pos) - 1)]
            for j, par in enumerate(parents):
                if par >= 0:
                    ax.plot(*zip(p[par], p[j]), color=color, lw=2)
        fig.canvas.draw()
        frames.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
    plt.close(fig)
    return write_video(np.stack(frames), path, fps)
