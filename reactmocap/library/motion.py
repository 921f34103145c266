"""Motion: a skeleton animated by dense arrays.

Shapes (T frames, J joints), all Z-up metres and wxyz quaternions:

* ``root_positions``: ``(T, 3)`` position of joint 0 in the world.
* ``rotations``: ``(T, J, 4)`` local rotation of each joint relative to its parent.
* ``translations``: optional ``(T, J, 3)`` local translation of each joint (overrides the
  skeleton offset; BVH files with position channels on non-root joints need it). Row 0 of each
  frame is ignored in favour of ``root_positions``.

Motions are immutable: arrays are read-only and every operation returns a new Motion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from reactmocap.errors import MotionError
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import (
    quat_canonical,
    quat_conj,
    quat_continuous,
    quat_from_yaw,
    quat_log,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_slerp,
)

__all__ = ["Motion"]

F64 = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Motion:
    skeleton: Skeleton
    fps: float
    root_positions: F64
    rotations: F64
    translations: F64 | None = None
    name: str = ""

    def __post_init__(self) -> None:
        fps = float(self.fps)
        if not np.isfinite(fps) or fps <= 0:
            raise MotionError(f"fps must be a positive number, got {self.fps!r}")
        j = self.skeleton.num_joints
        root = np.array(self.root_positions, dtype=np.float64)
        rot = np.array(self.rotations, dtype=np.float64)
        if rot.ndim != 3 or rot.shape[1:] != (j, 4):
            raise MotionError(f"rotations must have shape (T, {j}, 4), got {rot.shape}")
        t = rot.shape[0]
        if t == 0:
            raise MotionError("a Motion needs at least one frame")
        if root.shape != (t, 3):
            raise MotionError(f"root_positions must have shape ({t}, 3), got {root.shape}")
        if not (np.all(np.isfinite(root)) and np.all(np.isfinite(rot))):
            raise MotionError("root_positions or rotations contain NaN or inf")
        norms = np.linalg.norm(rot, axis=-1)
        if np.any(norms < 1e-6):
            raise MotionError("rotations contain zero quaternions")
        if np.any(np.abs(norms - 1.0) > 1e-12):  # keep unit inputs bit-exact
            rot = rot / norms[..., None]
        trans = None
        if self.translations is not None:
            trans = np.array(self.translations, dtype=np.float64)
            if trans.shape != (t, j, 3):
                raise MotionError(f"translations must have shape ({t}, {j}, 3), got {trans.shape}")
            if not np.all(np.isfinite(trans)):
                raise MotionError("translations contain NaN or inf")
            trans.setflags(write=False)
        root.setflags(write=False)
        rot.setflags(write=False)
        object.__setattr__(self, "fps", fps)
        object.__setattr__(self, "root_positions", root)
        object.__setattr__(self, "rotations", rot)
        object.__setattr__(self, "translations", trans)

    # ------------------------------------------------------------------ basics
    @property
    def num_frames(self) -> int:
        return int(self.rotations.shape[0])

    @property
    def num_joints(self) -> int:
        return self.skeleton.num_joints

    @property
    def dt(self) -> float:
        return 1.0 / self.fps

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.num_frames - 1) / self.fps

    @property
    def times(self) -> F64:
        return np.arange(self.num_frames) / self.fps

    def replace(self, **changes: object) -> Motion:
        fields = {
            "skeleton": self.skeleton,
            "fps": self.fps,
            "root_positions": self.root_positions,
            "rotations": self.rotations,
            "translations": self.translations,
            "name": self.name,
        }
        unknown = set(changes) - set(fields)
        if unknown:
            raise MotionError(f"unknown Motion fields {sorted(unknown)}")
        fields.update(changes)
        return Motion(**fields)  # type: ignore[arg-type]

    def local_translations(self) -> F64:
        """``(T, J, 3)`` local translations: per-frame where stored, else skeleton offsets."""
        if self.translations is not None:
            return np.asarray(self.translations)
        return np.broadcast_to(self.skeleton.offsets, (self.num_frames, self.num_joints, 3))

    # ---------------------------------------------------------------- kinematics
    def forward_kinematics(self) -> tuple[F64, F64]:
        """Global joint positions ``(T, J, 3)`` and rotations ``(T, J, 4)``.

        Vectorised over frames; the loop over joints follows the hierarchy (parents precede
        children), J Python iterations per call whatever T is.
        """
        t, j = self.num_frames, self.num_joints
        local_t = self.local_translations()
        pos = np.empty((t, j, 3))
        rot = np.empty((t, j, 4))
        pos[:, 0] = self.root_positions
        rot[:, 0] = self.rotations[:, 0]
        parents = self.skeleton.parents
        for k in range(1, j):
            p = parents[k]
            rot[:, k] = quat_mul(rot[:, p], self.rotations[:, k])
            pos[:, k] = pos[:, p] + quat_rotate(rot[:, p], local_t[:, k])
        return pos, rot

    def global_positions(self) -> F64:
        return self.forward_kinematics()[0]

    def end_site_positions(self) -> F64:
        """``(T, E, 3)`` world positions of the BVH end sites (E may be 0)."""
        sites = self.skeleton.layout.end_sites
        pos, rot = self.forward_kinematics()
        if not sites:
            return np.zeros((self.num_frames, 0, 3))
        idx = np.array(list(sites.keys()))
        off = np.array(list(sites.values()))
        return pos[:, idx] + quat_rotate(rot[:, idx], off[None])

    def linear_velocities(self) -> F64:
        """``(T, J, 3)`` world joint velocities (m/s) by central differences."""
        pos = self.global_positions()
        if self.num_frames < 2:
            return np.zeros_like(pos)
        return np.gradient(pos, self.dt, axis=0)

    def angular_velocities(self, local: bool = True) -> F64:
        """``(T, J, 3)`` angular velocities (rad/s).

        ``local=True``: of each joint relative to its parent, in the parent's frame (what a ball
        joint's qvel holds, rotated to the parent frame); ``local=False``: world frame.
        """
        q = self.rotations if local else self.forward_kinematics()[1]
        if self.num_frames < 2:
            return np.zeros(q.shape[:-1] + (3,))
        # omega = log(q[t+1] q[t]^-1) / dt, forward differences averaged to central ones
        w = quat_log(quat_mul(q[1:], quat_conj(q[:-1]))) * self.fps
        out = np.empty(q.shape[:-1] + (3,))
        out[0] = w[0]
        out[-1] = w[-1]
        out[1:-1] = 0.5 * (w[1:] + w[:-1])
        return out

    # ---------------------------------------------------------------- editing
    def slice(self, start: int, stop: int | None = None) -> Motion:
        """Frames ``[start, stop)``; negative indices count from the end."""
        s = slice(start, stop)
        idx = range(self.num_frames)[s]
        if len(idx) == 0:
            raise MotionError(
                f"slice [{start}:{stop}] of {self.num_frames}-frame motion {self.name!r} is empty"
            )
        tr = None if self.translations is None else self.translations[s]
        return self.replace(
            root_positions=self.root_positions[s], rotations=self.rotations[s], translations=tr
        )

    @staticmethod
    def concatenate(motions: Sequence[Motion], name: str | None = None) -> Motion:
        """Join motions end to end. They must share skeleton structure and fps."""
        if not motions:
            raise MotionError("concatenate needs at least one motion")
        first = motions[0]
        for m in motions[1:]:
            if not m.skeleton.same_structure(first.skeleton):
                raise MotionError(f"cannot concatenate {m.name!r}: different skeleton")
            if abs(m.fps - first.fps) > 1e-9:
                raise MotionError(f"cannot concatenate {m.name!r}: fps {m.fps} != {first.fps}")
        has_tr = any(m.translations is not None for m in motions)
        tr = np.concatenate([m.local_translations() for m in motions]) if has_tr else None
        return first.replace(
            root_positions=np.concatenate([m.root_positions for m in motions]),
            rotations=np.concatenate([m.rotations for m in motions]),
            translations=tr,
            name=first.name if name is None else name,
        )

    def sample(self, times: ArrayLike) -> Motion:
        """Motion at arbitrary times (seconds, clamped to the clip): slerp rotations, lerp
        positions. The result keeps this motion's fps."""
        tt = np.clip(np.asarray(times, dtype=np.float64).reshape(-1), 0.0, self.duration)
        x = tt * self.fps
        i0 = np.minimum(np.floor(x).astype(np.int64), self.num_frames - 1)
        i1 = np.minimum(i0 + 1, self.num_frames - 1)
        a = x - i0
        rot = quat_slerp(self.rotations[i0], self.rotations[i1], a[:, None])
        root = self.root_positions[i0] * (1 - a[:, None]) + self.root_positions[i1] * a[:, None]
        tr = None
        if self.translations is not None:
            w = a[:, None, None]
            tr = self.translations[i0] * (1 - w) + self.translations[i1] * w
        return self.replace(root_positions=root, rotations=rot, translations=tr)

    def resample(self, fps: float) -> Motion:
        """Same motion at another frame rate (slerp for rotations)."""
        fps = float(fps)
        if not np.isfinite(fps) or fps <= 0:
            raise MotionError(f"fps must be positive, got {fps}")
        n = int(np.floor(self.duration * fps + 1e-6)) + 1
        return self.sample(np.arange(n) / fps).replace(fps=fps)

    def transformed(self, yaw: float = 0.0, translation: ArrayLike = (0.0, 0.0, 0.0)) -> Motion:
        """Rotate the whole motion by ``yaw`` radians about the world Z axis through the origin,
        then translate by ``translation`` (3 values, or 2 for the ground plane)."""
        tr = np.zeros(3)
        tvals = np.asarray(translation, dtype=np.float64).reshape(-1)
        tr[: tvals.size] = tvals
        qy = quat_from_yaw(yaw)
        rot = np.array(self.rotations)
        rot[:, 0] = quat_mul(qy, rot[:, 0])
        root = quat_rotate(qy, self.root_positions) + tr
        return self.replace(root_positions=root, rotations=rot)

    def mirror(self, axis: str = "x") -> Motion:
        """Mirror across the world plane ``axis = 0`` and swap left/right joints.

        Joint j of the result follows what its counterpart did, reflected, so the result is a
        valid motion on a skeleton with reflected, swapped offsets.
        """
        k = "xyz".index(axis)
        perm = self.skeleton.mirror_permutation()
        refl = np.ones(3)
        refl[k] = -1.0
        # reflection M R M of rotation (w, v): (w, -M v)
        qsign = np.concatenate([[1.0], -refl])
        rot = self.rotations[:, perm] * qsign
        offsets = self.skeleton.offsets[perm] * refl
        layout = self.skeleton.layout
        sites = {int(j): tuple(np.asarray(o) * refl) for j, o in layout.end_sites.items()}
        # end sites move with their joint's counterpart
        inv = {int(perm[j]): j for j in range(len(perm))}
        sites = {inv.get(j, j): tuple(float(c) for c in o) for j, o in sites.items()}
        from dataclasses import replace as dc_replace

        skel = Skeleton(
            self.skeleton.names,
            self.skeleton.parents,
            offsets,
            dc_replace(layout, end_sites=sites),  # type: ignore[arg-type]
        )
        tr = None if self.translations is None else self.translations[:, perm] * refl
        return Motion(
            skel,
            self.fps,
            self.root_positions * refl,
            rot,
            tr,
            name=f"{self.name}_mirror" if self.name else "mirror",
        )

    def canonical(self) -> Motion:
        """Rotations with w >= 0 (compare poses without sign ambiguity)."""
        return self.replace(rotations=quat_canonical(self.rotations))

    def continuous(self) -> Motion:
        """Rotations sign-continuous in time (for interpolation and differences)."""
        return self.replace(rotations=quat_continuous(self.rotations, axis=0))

    def normalized(self) -> Motion:
        return self.replace(rotations=quat_normalize(self.rotations))

    def height(self) -> float:
        """Largest vertical extent of joints and end sites over the frames (m): the standing
        height reached in the clip, less any head-top the skeleton lacks an end site for."""
        pos = self.global_positions()
        ends = self.end_site_positions()
        allp = np.concatenate([pos, ends], axis=1)
        return float(np.max(allp[..., 2].max(axis=1) - allp[..., 2].min(axis=1)))
