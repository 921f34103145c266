"""Per-frame body features of a Motion for the search: positions and canonical orientations of
the mapped body parts, the heading and ground origin of the body frame, and an approximate centre
of mass (to pick the support body). A simulated trajectory read back as a Motion goes through the
same code. The definitions are in ``docs/design.md (Search)``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import BodyPartMappingError, SearchError, UnknownKeyError
from reactmocap.library.anthropometry import MASS_FRACTIONS
from reactmocap.library.bodyparts import BodyPartMap, map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.placement import body_frame, body_heading, rest_pose
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import (
    quat_canonical,
    quat_conj,
    quat_from_matrix,
    quat_mul,
    quat_rotate,
    quat_to_matrix,
)

__all__ = [
    "FEATURE_SETS",
    "FeatureSet",
    "FrameFeatures",
    "SkeletonCalibration",
    "calibrate",
    "calibrations_for",
    "depth_levels",
    "features_from_arrays",
    "forward_kinematics_fast",
    "frame_features",
    "get_feature_set",
    "skeleton_key",
]

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class FeatureSet:
    """Which body parts enter ``D`` and how they are grouped."""

    name: str
    trunk: tuple[str, ...]
    limbs: tuple[str, ...]
    #: always ground-support candidates
    support_always: tuple[str, ...] = ("l_foot", "r_foot")
    #: support candidates only when near the ground (a fallen character)
    support_low: tuple[str, ...] = ("l_hand", "r_hand", "pelvis")

    @property
    def parts(self) -> tuple[str, ...]:
        return self.trunk + self.limbs

    def is_trunk(self) -> NDArray[np.bool_]:
        return np.array([p in self.trunk for p in self.parts])


FEATURE_SETS: dict[str, FeatureSet] = {
    # All required parts of the physics character: 4 trunk + 12 limb bodies.
    "paper": FeatureSet(
        "paper",
        trunk=("pelvis", "waist", "chest", "head"),
        limbs=tuple(
            f"{s}_{p}"
            for s in ("l", "r")
            for p in ("upper_arm", "forearm", "hand", "thigh", "shin", "foot")
        ),
    ),
    # Fewer bodies, for speed: end effectors and the middle joints of the limbs.
    "compact": FeatureSet(
        "compact",
        trunk=("pelvis", "chest", "head"),
        limbs=(
            "l_forearm",
            "l_hand",
            "r_forearm",
            "r_hand",
            "l_shin",
            "l_foot",
            "r_shin",
            "r_foot",
        ),
    ),
}


def get_feature_set(name: str) -> FeatureSet:
    try:
        return FEATURE_SETS[name]
    except (KeyError, TypeError):
        raise UnknownKeyError(
            f"unknown feature set {name!r}; valid feature sets are {sorted(FEATURE_SETS)}"
        ) from None


# Next part down each chain (bone direction and segment midpoint); the first present one is used.
_NEXT_PART: dict[str, tuple[str, ...]] = {
    "pelvis": ("waist", "chest"),
    "waist": ("chest",),
    "chest": ("neck", "head"),
    "neck": ("head",),
    "head": (),
    **{f"{s}_upper_arm": (f"{s}_forearm",) for s in "lr"},
    **{f"{s}_forearm": (f"{s}_hand",) for s in "lr"},
    **{f"{s}_hand": () for s in "lr"},
    **{f"{s}_thigh": (f"{s}_shin",) for s in "lr"},
    **{f"{s}_shin": (f"{s}_foot",) for s in "lr"},
    **{f"{s}_foot": (f"{s}_toe",) for s in "lr"},
    **{f"{s}_toe": () for s in "lr"},
}
_PARENT_PART: dict[str, str] = {c[0]: p for p, c in _NEXT_PART.items() if c}
_PARENT_PART.update({"head": "chest", "l_hand": "l_forearm", "r_hand": "r_forearm"})


def _canonical_direction(part: str) -> F64:
    """Bone direction of ``part`` in the body frame (x forward, y left, z up) in a T-pose."""
    kind = part[2:] if part[:2] in ("l_", "r_") else part
    if kind in ("upper_arm", "forearm", "hand"):
        return np.array([0.0, 1.0 if part.startswith("l_") else -1.0, 0.0])
    if kind in ("thigh", "shin"):
        return np.array([0.0, 0.0, -1.0])
    if kind in ("foot", "toe"):
        return np.array([1.0, 0.0, 0.0])
    return np.array([0.0, 0.0, 1.0])


def _swing(a: F64, b: F64) -> F64:
    """Minimal rotation (wxyz) taking unit vector ``a`` to unit vector ``b``; for opposite vectors
    the half turn is about the body's left axis (a sagittal unfold), or forward if a is along it."""
    c = float(np.dot(a, b))
    if c < -1 + 1e-9:
        axis = np.cross(a, [0.0, 1.0, 0.0])
        if np.linalg.norm(axis) < 1e-6:
            axis = np.cross(a, [1.0, 0.0, 0.0])
        axis /= np.linalg.norm(axis)
        return np.array([0.0, *axis])
    v = np.cross(a, b)
    q = np.array([1.0 + c, *v])
    return q / np.linalg.norm(q)


@dataclass(frozen=True)
class SkeletonCalibration:
    """Per-skeleton constants: part joints, the body frame ``B`` (pelvis-local), each part's
    canonical-frame offset ``c_b``, the centre-of-mass segments and the joints grouped by depth
    for the batched forward kinematics."""

    feature_set: FeatureSet
    joints: NDArray[np.int64]  # (P,) joint index of each feature part
    pelvis: int
    body_frame: F64  # (4,) B, pelvis-local
    offsets: F64  # (P, 4) c_b
    com_joints: NDArray[np.int64]  # (M,) joint of each massed part
    com_next: NDArray[np.int64]  # (M,) joint of the next part (== com_joints when none)
    com_mass: F64  # (M,) normalised mass fractions
    levels: tuple[NDArray[np.int64], ...]  # non-root joints by depth (for the FK)


def calibrate(
    skeleton: Skeleton, feature_set: FeatureSet, parts: BodyPartMap | None = None
) -> SkeletonCalibration:
    """Work out the body frame and canonical part frames of ``skeleton``.

    Raises:
        SearchError: when a feature part cannot be mapped or the rest pose is degenerate.
    """
    try:
        bp = parts if parts is not None else map_body_parts(skeleton)
        joints = bp.indices(list(feature_set.parts))
        body = body_frame(skeleton, bp)
    except BodyPartMappingError as exc:
        raise SearchError(f"cannot compute search features: {exc}") from None
    pos, grot = rest_pose(skeleton)
    jm = bp.joints
    pelvis = jm["pelvis"]
    w_rest = quat_mul(grot[pelvis], body)  # the body frame in the rest pose, world

    def bone_dir(part: str) -> F64 | None:
        for nxt in _NEXT_PART.get(part, ()):
            if nxt in jm:
                d = pos[jm[nxt]] - pos[jm[part]]
                if np.linalg.norm(d) > 1e-6:
                    return d / np.linalg.norm(d)
        j = jm[part]
        kids = skeleton.children(j)
        cands = [pos[k] - pos[j] for k in kids]
        site = skeleton.layout.end_sites.get(j)
        if site is not None:
            cands.append(quat_rotate(grot[j], np.asarray(site, float)))
        for d in cands:
            if np.linalg.norm(d) > 1e-6:
                return d / np.linalg.norm(d)
        par = _PARENT_PART.get(part)
        return bone_dir(par) if par is not None and par in jm else None

    offs = np.empty((len(feature_set.parts), 4))
    w_inv = quat_conj(w_rest)
    for i, part in enumerate(feature_set.parts):
        j = jm[part]
        if part == "pelvis":
            s = np.array([1.0, 0.0, 0.0, 0.0])
        else:
            d = bone_dir(part)
            if d is None:
                s = np.array([1.0, 0.0, 0.0, 0.0])
            else:
                r = quat_rotate(w_inv, d)  # rest bone direction in body-frame coordinates
                s = _swing(r, _canonical_direction(part))  # S_b: r -> canonical
        offs[i] = quat_mul(quat_mul(quat_conj(grot[j]), w_rest), quat_conj(s))

    massed = [p for p in MASS_FRACTIONS if p in jm]
    com_j, com_n, mass = [], [], []
    for p in massed:
        com_j.append(jm[p])
        nxt = next((jm[n] for n in _NEXT_PART.get(p, ()) if n in jm), jm[p])
        if p in ("l_hand", "r_hand", "l_foot", "r_foot", "head"):
            nxt = jm[p]
        com_n.append(nxt)
        mass.append(MASS_FRACTIONS[p])
    mass_arr = np.asarray(mass) / np.sum(mass)
    return SkeletonCalibration(
        feature_set=feature_set,
        joints=joints,
        pelvis=pelvis,
        body_frame=body,
        offsets=offs,
        com_joints=np.asarray(com_j, dtype=np.int64),
        com_next=np.asarray(com_n, dtype=np.int64),
        com_mass=mass_arr,
        levels=depth_levels(skeleton.parents),
    )


@dataclass(frozen=True)
class FrameFeatures:
    """World-frame features of every frame of a motion (P = parts of the feature set)."""

    positions: NDArray[np.floating]  # (T, P, 3) part joint positions, metres
    orientations: NDArray[np.floating]  # (T, P, 4) canonical part frames, wxyz, w >= 0
    heading: F64  # (T,) radians
    origin: F64  # (T, 2) pelvis ground position
    com: F64  # (T, 3) approximate centre of mass

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])


def frame_features(motion: Motion, calib: SkeletonCalibration) -> FrameFeatures:
    """Features of every frame of ``motion`` (at its own rate)."""
    return features_from_arrays(
        motion.skeleton,
        motion.root_positions,
        motion.rotations,
        motion.translations,
        calib,
    )


def depth_levels(parents: NDArray[np.int64]) -> tuple[NDArray[np.int64], ...]:
    """Non-root joints grouped by depth (parents precede children, so depth is one pass)."""
    depth = np.zeros(len(parents), dtype=np.int64)
    for k in range(1, len(parents)):
        depth[k] = depth[parents[k]] + 1
    return tuple(np.flatnonzero(depth == d) for d in range(1, int(depth.max(initial=0)) + 1))


def forward_kinematics_fast(
    skeleton: Skeleton,
    root_positions: F64,
    rotations: F64,
    translations: F64 | None,
    levels: tuple[NDArray[np.int64], ...] | None = None,
) -> tuple[F64, F64]:
    """Global joint positions ``(T, J, 3)`` and rotation matrices ``(T, J, 3, 3)``.

    Same result as :meth:`Motion.forward_kinematics` but with batched 3x3 products, all joints of
    one depth at once, which is several times faster for the short windows a query needs.
    ``levels``: :func:`depth_levels` of the skeleton, when already known.
    """
    t, j = rotations.shape[:2]
    local_r = quat_to_matrix(np.asarray(rotations, dtype=np.float64))
    local_t = (
        np.asarray(translations, dtype=np.float64)
        if translations is not None
        else np.broadcast_to(skeleton.offsets, (t, j, 3))
    )
    pos = np.empty((t, j, 3))
    rot = np.empty((t, j, 3, 3))
    pos[:, 0] = root_positions
    rot[:, 0] = local_r[:, 0]
    parents = skeleton.parents
    for lvl in levels if levels is not None else depth_levels(parents):
        par = parents[lvl]
        prot = rot[:, par]
        rot[:, lvl] = prot @ local_r[:, lvl]
        pos[:, lvl] = pos[:, par] + (prot @ local_t[:, lvl, :, None])[..., 0]
    return pos, rot


def features_from_arrays(
    skeleton: Skeleton,
    root_positions: F64,
    rotations: F64,
    translations: F64 | None,
    calib: SkeletonCalibration,
    com_frames: int | None = None,
) -> FrameFeatures:
    """:func:`frame_features` on raw motion arrays (no Motion construction in the query path).
    ``com_frames``: compute the centre of mass for the first frames only (a query needs one)."""
    pos, grot = forward_kinematics_fast(
        skeleton, root_positions, rotations, translations, calib.levels
    )
    gq = quat_from_matrix(grot[:, np.append(calib.joints, calib.pelvis)])
    ori = quat_canonical(quat_mul(gq[:, :-1], calib.offsets[None]))
    heading = body_heading(gq[:, -1], calib.body_frame)
    origin = pos[:, calib.pelvis, :2].copy()
    cp = pos[:com_frames]
    seg = 0.5 * (cp[:, calib.com_joints] + cp[:, calib.com_next])
    com = np.einsum("tmk,m->tk", seg, calib.com_mass)
    return FrameFeatures(pos[:, calib.joints], ori, heading, origin, com)


def skeleton_key(skeleton: Skeleton) -> tuple[object, ...]:
    """Hashable content of everything :func:`calibrate` reads from a skeleton."""
    return (
        skeleton.names,
        skeleton.parents.tobytes(),
        np.asarray(skeleton.offsets).tobytes(),
        tuple((int(j), *map(float, o)) for j, o in sorted(skeleton.layout.end_sites.items())),
    )


def calibrations_for(
    motions: Mapping[str, Motion],
    feature_set: FeatureSet,
    parts: Mapping[str, BodyPartMap] | None = None,
) -> dict[str, SkeletonCalibration]:
    """One calibration per distinct skeleton, shared by the clips that use it."""
    cache: dict[tuple[object, ...], SkeletonCalibration] = {}
    out: dict[str, SkeletonCalibration] = {}
    for name, m in motions.items():
        bp = parts.get(name) if parts else None
        key = skeleton_key(m.skeleton)
        if bp is None and key in cache:
            out[name] = cache[key]
            continue
        try:
            cal = calibrate(m.skeleton, feature_set, bp)
        except SearchError as exc:
            raise SearchError(f"clip {name!r}: {exc}") from None
        if bp is None:
            cache[key] = cal
        out[name] = cal
    return out
