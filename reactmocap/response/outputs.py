"""The files of a response: ``recipient.bvh``, ``attacker.bvh``, ``report.json``, and on request
``plot.png`` and a video. They are written into a hidden staging folder and moved into place
only when all succeeded, so a failure leaves none of them behind."""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.io import output_errors
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.bvh import write_bvh
from reactmocap.library.motion import Motion
from reactmocap.response.pipeline import ResponseResult
from reactmocap.response.scenario import Scenario

__all__ = ["jsonable", "write_outputs"]

F64 = NDArray[np.float64]


def write_outputs(
    result: ResponseResult, scenario: Scenario, out: Path, *, plot: bool, video: bool
) -> dict[str, Any]:
    """Write a response's files into ``out`` (see the module docstring); returns the report
    with ``outputs`` filled in."""
    with output_errors(out / "report.json"):
        out.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=".partial-", dir=out))
    try:
        names: dict[str, str] = {}
        write_bvh(result.recipient, stage / "recipient.bvh")
        names["recipient"] = "recipient.bvh"
        if result.attacker is not None:
            write_bvh(result.attacker, stage / "attacker.bvh")
            names["attacker"] = "attacker.bvh"
        if plot:
            names["plot"] = _plot(result, stage / "plot.png", scenario).name
        extra: dict[str, str] = {}
        if video:
            path, renderer = _video(result, stage)
            names["video"] = path.name
            extra["video_renderer"] = renderer
        names["report"] = "report.json"
        report = result.report
        report["outputs"] = {k: str(out / v) for k, v in names.items()} | extra
        (stage / "report.json").write_text(json.dumps(jsonable(report), indent=2))
        for name in names.values():
            (stage / name).replace(out / name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return report


def _video(result: ResponseResult, out: Path) -> tuple[Path, str]:
    """MuJoCo-rendered MP4 with a translucent ghost of the found clip; the matplotlib stick
    figure GIF where no GL context can be made (the second value says which)."""
    from reactmocap.response.render import RenderUnavailable, render_video

    fps = result.recipient.fps
    t = result.recipient.times
    # the found clip on the scenario clock: its matched frame falls on the transition's end
    ghost = result.found.sample(np.clip(result.matched.time + t - result.transition_end, 0, None))
    try:
        path = render_video(
            [(result.recipient, (0.25, 0.45, 0.85, 1.0))]
            + ([(result.attacker, (0.85, 0.3, 0.25, 1.0))] if result.attacker is not None else []),
            out / "video.mp4",
            fps=min(fps, 30.0),
            ghost=(ghost.replace(fps=fps), (0.3, 0.8, 0.35, 0.3)),
            hit=result.hit,
        )
        return Path(path), "mujoco"
    except RenderUnavailable as exc:
        from reactmocap.response.plots import stick_figure_video

        motions = [(result.recipient, "tab:blue")]
        if result.attacker is not None:
            motions.append((result.attacker, "tab:red"))
        return Path(stick_figure_video(motions, out / "video.gif")), (
            f"matplotlib stick figure ({exc})"
        )


def _plot(result: ResponseResult, path: Path, scenario: Scenario) -> Path:
    from reactmocap.response.plots import response_plot

    parts = result.parts or map_body_parts(result.recipient.skeleton)
    pj, cj = parts.joint_of("pelvis"), parts.joint_of("chest")

    def curve(m: Motion, t0: float) -> tuple[F64, F64]:
        return m.times + t0, m.global_positions()[:, pj, 2]

    t_imp = result.impact_time
    t_end = result.transition_end
    fps = result.recipient.fps
    found_t = result.matched.time + (np.arange(0, int((t_end + 1.0) * fps)) / fps - t_end)
    found_m = result.found.sample(np.clip(found_t, 0, None))
    rewind = result.report["impact"]["rewind_time"]
    curves = {
        "mocap before": curve(result.before, 0.0),
        "simulation 1": curve(result.sim1, rewind),
        "simulation 2": curve(result.sim2, rewind),
        "final blend": curve(result.blended, np.ceil(t_imp * fps - 1e-9) / fps),
        "found clip": (np.arange(found_m.num_frames) / fps, found_m.global_positions()[:, pj, 2]),
    }
    paths = {"output": result.recipient.global_positions()[:, cj, :2]}
    if result.undisturbed is not None:
        paths["undisturbed clip"] = result.undisturbed.global_positions()[:, cj, :2]
    paths["simulation 1"] = result.sim1.global_positions()[:, cj, :2]
    hit = None
    if result.hit is not None and len(result.hit[0]):
        times, points, forces = result.hit
        dt = float(np.median(np.diff(times))) if len(times) > 1 else 1.0 / fps
        hit = (points[int(np.argmax(np.linalg.norm(forces, axis=1)))], forces.sum(axis=0) * dt)
    return Path(response_plot(paths, curves, path, impact_time=t_imp, transition=(t_imp, t_end),
                              hit=hit, title=f"{scenario.name}: matched {result.matched.clip}"))  # fmt: skip


def jsonable(x: Any) -> Any:
    """``x`` with numpy scalars, tuples and paths turned into JSON types."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [jsonable(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, Path):
        return str(x)
    return x
