"""A finished ride (:class:`CyclingResult`): the team, the rollout, the logs and the report, and
its outputs (a BVH per rider and per bicycle, the JSON report, a top-view plot, a video), written
all or nothing; :func:`bicycle_motion`, the bicycle's recorded motion as a BVH-ready Motion."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bicycle import Bicycle
from reactmocap.athletics.course import Route
from reactmocap.athletics.cycling_scene import Obstacle
from reactmocap.athletics.report import report_json
from reactmocap.io import staged_files
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import BVHLayout, Skeleton
from reactmocap.sim.rollout import RolloutResult

if TYPE_CHECKING:
    from reactmocap.athletics.cycling import Team

__all__ = ["CyclingResult", "bicycle_motion"]

F64 = NDArray[np.float64]


@dataclass
class CyclingResult:
    """A finished ride: the team, the rollout, per-rider logs and the report."""

    kind: str
    team: Team
    rollout: RolloutResult
    report: dict[str, Any]
    logs: list[dict[str, F64]]
    route: Route | None = None
    obstacles: tuple[Obstacle, ...] = ()
    cpu_s: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)

    def rider_motion(self, k: int) -> Motion:
        return self.rollout.motion(k, name=f"rider{k}")

    def bicycle_motion(self, k: int) -> Motion:
        return bicycle_motion(self.rollout, self.team.bicycles[k], name=f"bicycle{k}")

    def report_json(self) -> str:
        return report_json(self.report)

    def write(self, out: str | Path, *, report: str | Path | None = None,
              plot: str | Path | None = None, video: str | Path | None = None) -> dict[str, str]:  # fmt: skip
        """Write ``rider{k}.bvh`` and ``bicycle{k}.bvh`` into ``out``, and the report, plot
        and video where asked; all staged and moved into place only when all succeeded."""
        from reactmocap.library.bvh import write_bvh

        out = Path(out)
        written: dict[str, str] = {}
        with staged_files() as stage:
            for k in range(len(self.team.riders)):
                write_bvh(self.rider_motion(k), stage(out / f"rider{k}.bvh"))
                write_bvh(self.bicycle_motion(k), stage(out / f"bicycle{k}.bvh"))
            written["bvh"] = str(out)
            if plot is not None:
                from reactmocap.athletics.cycling_plots import paths_plot

                paths_plot(self, stage(plot))
                written["plot"] = str(plot)
            if video is not None:
                from reactmocap.athletics.cycling_plots import ride_video

                target = Path(video)
                made, renderer = ride_video(self, stage(target))
                final = target if made.suffix == target.suffix else target.with_suffix(made.suffix)
                if final != target:
                    stage.rename(target, final)
                written["video"] = str(final)
                written["video_renderer"] = renderer
            if report is not None:
                self.report["outputs"] = written
                stage(report).write_text(self.report_json())
                written["report"] = str(report)
        return written


def bicycle_motion(res: RolloutResult, bike: Bicycle, name: str = "bicycle") -> Motion:
    """The bicycle's recorded motion as a Motion on a five-joint skeleton: the rear frame
    (root, at the rear wheel's centre), the rear wheel, the fork (turning about the steer
    axis), the front wheel and the crank."""
    p = bike.params
    m = res.world.model
    rr = p.rear.radius
    head = p.steer_foot + p.steer_axis * (p.front.radius / p.steer_axis[2]) - [0.0, 0.0, rr]
    names = ["frame", "rear_wheel", "fork", "front_wheel"]
    parents = [-1, 0, 0, 2]
    offsets = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], head.tolist(),
               [p.wheelbase - (head[0]), 0.0, p.front.radius - rr - head[2]]]  # fmt: skip
    if bike.has_crank:
        dt = p.drivetrain
        assert dt is not None
        names.append("crank")
        parents.append(0)
        offsets.append([dt.bottom_bracket[0], 0.0, dt.bottom_bracket[1] - rr])
    rot = ("Zrotation", "Xrotation", "Yrotation")
    chans = (("Xposition", "Yposition", "Zposition", *rot),) + (rot,) * (len(names) - 1)
    ends = {1: (0.0, 0.0, rr), 3: (0.0, 0.0, p.front.radius)}
    skel = Skeleton(
        tuple(names), np.array(parents), np.array(offsets), BVHLayout(chans, "m", "z", ends)
    )
    _, q = res.frames()
    qa = bike.qpos_adr
    t = q.shape[0]
    rots = np.zeros((t, len(names), 4))
    rots[:, 0] = q[:, qa + 3 : qa + 7]

    def about(axis: F64, angle: F64) -> F64:
        return np.column_stack([np.cos(angle / 2), np.sin(angle / 2)[:, None] * axis[None]])

    y = np.array([0.0, 1.0, 0.0])
    rots[:, 1] = about(y, q[:, int(m.jnt_qposadr[bike.joint["rear_spin"].id])])
    rots[:, 2] = about(p.steer_axis, q[:, int(m.jnt_qposadr[bike.joint["steer"].id])])
    rots[:, 3] = about(y, q[:, int(m.jnt_qposadr[bike.joint["front_spin"].id])])
    if bike.has_crank:
        rots[:, 4] = about(y, q[:, int(m.jnt_qposadr[bike.joint["crank"].id])])
    return Motion(skel, res.fps[0], q[:, qa : qa + 3], rots, name=name)
