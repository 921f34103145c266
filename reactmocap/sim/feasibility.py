"""Can the ground produce a clip's motion? In single support all external force but gravity comes
through one foot, so the rate of whole-body angular momentum about the centre of mass must be
``(p - c) x f`` (``f = m (a_c + g)``, ``p`` the centre of pressure) up to what moving ``p`` over
the sole can add. :func:`support_feasibility` measures, per frame on the character built from the
clip, the horizontal moment left over with ``p`` at the sole's centre against that bound: where
it is well above (2x by default), no physical tracker follows the clip for long."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim.character import build_character
from reactmocap.sim.reference import reference_path
from reactmocap.sim.world import World

__all__ = ["SupportFeasibility", "support_feasibility"]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class SupportFeasibility:
    """Per frame of a clip: ``residual`` ``(T,)`` the horizontal moment (N m) a single ground
    force at the supporting sole's centre leaves unexplained, NaN outside single support;
    ``bound`` ``(T,)`` what the centre of pressure can add there (N m); ``foot`` ``(T,)`` the
    supporting foot (0 left, 1 right; -1 outside single support); ``fps`` the clip's rate."""

    residual: F64
    bound: F64
    foot: NDArray[np.int64]
    fps: float

    @property
    def single_support(self) -> NDArray[np.bool_]:
        return self.foot >= 0

    def infeasible(self, factor: float = 2.0) -> NDArray[np.bool_]:
        """``(T,)`` single-support frames whose residual exceeds ``factor`` times the bound."""
        if not (np.isfinite(factor) and factor > 0):
            raise ConfigError(f"factor must be > 0, got {factor!r}")
        out = np.zeros(len(self.foot), dtype=bool)
        s = self.single_support
        out[s] = self.residual[s] > factor * self.bound[s]
        return out

    def stretches(self, factor: float = 2.0, min_seconds: float = 0.1) -> list[tuple[float, float]]:
        """``(start, end)`` clip times (s) of runs of infeasible frames lasting at least
        ``min_seconds``."""
        mask = self.infeasible(factor).astype(np.int64)
        edges = np.flatnonzero(np.diff(np.r_[0, mask, 0]))
        runs = [(a / self.fps, b / self.fps) for a, b in zip(edges[::2], edges[1::2])]
        return [(a, b) for a, b in runs if b - a >= min_seconds - 1e-9]

    def infeasible_seconds(
        self, start: float = 0.0, seconds: float | None = None, factor: float = 2.0
    ) -> float:
        """Seconds of infeasible frames (:meth:`infeasible`) in ``[start, start + seconds)``
        of the clip (default: to its end)."""
        for name, value in (("start", start), ("seconds", 0.0 if seconds is None else seconds)):
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        bad = self.infeasible(factor)
        a = round(start * self.fps)
        b = len(bad) if seconds is None else round((start + seconds) * self.fps)
        return float(bad[a:b].sum() / self.fps)

    def summary(self, factor: float = 2.0, min_seconds: float = 0.1) -> dict[str, object]:
        """JSON-ready figures: shares of single-support and infeasible frames, the median
        residual/bound ratio, and each stretch with its largest residual and bound."""
        s = self.single_support
        bad = self.infeasible(factor)
        ratio = self.residual[s] / np.maximum(self.bound[s], 1e-9)
        stretches = []
        for a, b in self.stretches(factor, min_seconds):
            rows = slice(round(a * self.fps), round(b * self.fps))
            stretches.append(
                {
                    "start_s": round(a, 4),
                    "end_s": round(b, 4),
                    "max_residual_nm": float(np.nanmax(self.residual[rows])),
                    "max_bound_nm": float(np.nanmax(self.bound[rows])),
                }
            )
        return {
            "frames": len(self.foot),
            "fps": self.fps,
            "factor": float(factor),
            "single_support_fraction": float(s.mean()),
            "infeasible_fraction_of_single_support": float(bad.sum() / max(int(s.sum()), 1)),
            "median_residual_over_bound": float(np.median(ratio)) if ratio.size else None,
            "stretches": stretches,
        }


def support_feasibility(
    motion: Motion, *, total_mass: float = 75.0, reach: float = 0.05
) -> SupportFeasibility:
    """The single-support momentum check of ``motion`` on the character built from it
    (see the module docstring)."""
    if motion.num_frames < 3:
        raise ConfigError(
            f"support_feasibility needs at least 3 frames for accelerations, "
            f"{motion.name!r} has {motion.num_frames}"
        )
    world = World(build_character(motion, total_mass=total_mass, frame=0))
    # a foot dragged along the floor still carries weight: every foot near it supports
    ref = reference_path(world, 0, motion, reach=reach, slide_speed=None)
    m = world.model
    d = mujoco.MjData(m)
    wc = world.characters[0]
    root = wc.body_ids[0]
    mass = float(m.body_subtreemass[root])
    sole = np.asarray(wc.sole_ids)
    n = motion.num_frames
    com = np.empty((n, 3))
    mom = np.empty((n, 3))
    centre = np.empty((n, 2, 3))
    for i in range(n):  # once per frame of an offline analysis, not a step loop
        d.qpos[wc.qpos_slice] = ref.q[i]
        d.qvel[wc.qvel_slice] = ref.v[i]
        mujoco.mj_forward(m, d)
        mujoco.mj_subtreeVel(m, d)
        com[i] = d.subtree_com[root]
        mom[i] = d.subtree_angmom[root]
        rot = d.geom_xmat[sole].reshape(2, 3, 3)
        centre[i] = d.geom_xpos[sole] - rot[:, :, 2] * m.geom_size[sole, 2][:, None]
    dt = 1.0 / motion.fps
    acc = np.gradient(np.gradient(com, dt, axis=0), dt, axis=0)
    force = mass * (acc - m.opt.gravity)
    foot = np.where(ref.planted.sum(axis=1) == 1, np.argmax(ref.planted, axis=1), -1)
    lever = centre[np.arange(n), np.maximum(foot, 0)] - com
    moment = np.gradient(mom, dt, axis=0) - np.cross(lever, force)
    residual = np.linalg.norm(moment[:, :2], axis=1)
    half_diag = np.hypot(m.geom_size[sole, 0], m.geom_size[sole, 1])
    bound = np.maximum(force[:, 2], 0.0) * half_diag[np.maximum(foot, 0)]
    residual[foot < 0] = np.nan
    return SupportFeasibility(residual, bound, foot.astype(np.int64), float(motion.fps))
