"""Building a :class:`~reactmocap.search.index.MotionIndex`: per-frame features of every clip at
the index rate, the unique-frame window starts, and a PCA-reduced embedding of those windows for
the KD-tree. Also the library fingerprint an index records so a stale one can be detected."""

from __future__ import annotations

import hashlib
import itertools
import time
from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SearchError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.search.config import SearchWeights, WindowConfig, settings_hash
from reactmocap.search.distance import (
    StanceCost,
    body_weights,
    embed_local,
    embedding_body_weights,
    embedding_frame_weights,
    frame_pose_steps,
    localize,
    part_distances,
)
from reactmocap.search.features import calibrations_for, frame_features, get_feature_set
from reactmocap.search.index import MotionIndex, valid_starts
from reactmocap.search.types import (
    CHUNK,
    COARSE_FRAMES,
    F32,
    F64,
    I64,
    MIRROR_SUFFIX,
    PCA_SAMPLE,
)

__all__ = [
    "RATE_TOLERANCE",
    "EmbeddingWeights",
    "build_index",
    "clip_source",
    "embedding_weights",
    "library_fingerprint",
    "prerank_frames",
    "rate_step",
    "to_rate",
]

#: frame rates within this relative tolerance of an integer multiple of the index rate are
#: taken as that multiple (BVH "Frame Time: 0.0333333" is 30.00003 fps), so such clips are
#: subsampled exactly instead of interpolated
RATE_TOLERANCE = 1e-4


def rate_step(fps: float, index_fps: float) -> int | None:
    """Integer frame step from ``fps`` to ``index_fps``, or None when it is not a multiple."""
    ratio = fps / index_fps
    step = round(ratio)
    return step if step >= 1 and abs(ratio - step) <= RATE_TOLERANCE * ratio else None


def to_rate(m: Motion, index_fps: float) -> Motion:
    """``m`` at ``index_fps``: subsampled when its rate is a multiple, else resampled."""
    step = rate_step(m.fps, index_fps)
    if step is None:
        return m.resample(index_fps)
    if step == 1:
        return m
    return m.replace(
        fps=m.fps / step,
        root_positions=m.root_positions[::step],
        rotations=m.rotations[::step],
        translations=None if m.translations is None else m.translations[::step],
    )


def library_fingerprint(clips: Mapping[str, Motion]) -> str:
    """Content hash of clip names, frame rates, skeletons and motion arrays."""
    h = hashlib.sha256()
    for name in sorted(clips):
        m = clips[name]
        h.update(f"{name}\0{m.fps!r}\0{'|'.join(m.skeleton.names)}\0".encode())
        for a in (m.skeleton.parents, m.skeleton.offsets, m.root_positions, m.rotations):
            h.update(np.ascontiguousarray(a).tobytes())
        if m.translations is not None:
            h.update(np.ascontiguousarray(m.translations).tobytes())
    return h.hexdigest()


def clip_source(clips: Any) -> tuple[Mapping[str, Motion], str]:
    """``(name -> Motion, fingerprint)`` of a ClipLibrary (fingerprint of its *files*, stable
    across the clip cache) or of a plain mapping of Motions (fingerprint of the arrays)."""
    if hasattr(clips, "fingerprint") and hasattr(clips, "clips"):
        return clips.clips, "files:" + str(clips.fingerprint())
    if not isinstance(clips, Mapping):
        raise SearchError(
            "clips must be a mapping of name -> Motion or a ClipLibrary, "
            f"got {type(clips).__name__}"
        )
    return clips, "arrays:" + library_fingerprint(clips)


class EmbeddingWeights(NamedTuple):
    """Query-independent weights of the KD embedding (``docs/design.md (Search)``)."""

    wp: F64  # (P,) position weight per part
    wq: F64  # (P,) orientation weight per part
    frames: F64  # (E,) window weight of each embedded frame
    offsets: I64  # (E,) embedded frames within the window


def embedding_weights(weights: SearchWeights, window: WindowConfig) -> EmbeddingWeights:
    wp, wq = embedding_body_weights(get_feature_set(weights.feature_set), weights)
    offs = window.embed_offsets()
    fw = embedding_frame_weights(weights.window_weights(window.length), offs)
    return EmbeddingWeights(wp, wq, fw, offs)


def prerank_frames(weights: SearchWeights, window: WindowConfig) -> tuple[I64, F64]:
    """Window frames of the candidates' pre-ranking and their aggregated window weights: about
    ``COARSE_FRAMES`` evenly spaced frames, the last one included (every frame when
    ``L <= COARSE_FRAMES``)."""
    L = window.length
    step = max(1, int(np.ceil((L - 1) / (COARSE_FRAMES - 1))))
    offsets = np.unique(np.append(np.arange(0, L, step), L - 1)).astype(np.int64)
    return offsets, embedding_frame_weights(weights.window_weights(L), offsets)


class _Frames(NamedTuple):
    """Features of every library frame at the index rate, clips concatenated."""

    positions: F32
    orientations: F32
    heading: F64
    origin: F64


def _embed_starts(fr: _Frames, starts: I64, ew: EmbeddingWeights) -> F32:
    idx = starts[:, None] + ew.offsets[None, :]
    lp, lq = localize(
        fr.positions[idx], fr.orientations[idx], fr.heading[starts], fr.origin[starts]
    )
    return embed_local(lp, lq, ew.frames, ew.wp, ew.wq)


def _unique_starts(
    fr: _Frames,
    clip_offsets: I64,
    weights: SearchWeights,
    window: WindowConfig,
    planted: NDArray[np.bool_] | None = None,
) -> tuple[I64, I64, I64]:
    """Kept window starts and their refinement intervals (inclusive: from the kept start to the
    last start before the next kept one, so each window is in one interval), clip by clip: a
    start is kept whenever the pose path length since the last kept one crosses another
    multiple of ``window.unique_tolerance``, at least every ``window.max_gap`` seconds, and
    (with ``planted``, ``(N, F)`` feet in contact per frame) wherever a foot's contact changes,
    so that each kept start's contacts hold until the next one."""
    wp, wq = body_weights(get_feature_set(weights.feature_set), weights, None)
    step = frame_pose_steps(fr.positions, fr.orientations, fr.heading, fr.origin, wp, wq)
    kept_list, lo_list, hi_list = [], [], []
    tol = window.unique_tolerance
    gap = window.max_gap_frames
    for a, b in zip(clip_offsets[:-1], clip_offsets[1:]):
        m = int(b - a - window.length + 1)
        if m <= 0:
            continue
        st = step[a : a + m].astype(np.float64)
        st[0] = 0.0
        if tol > 0:
            bucket = np.floor(np.cumsum(st) / tol).astype(np.int64)
            local = np.flatnonzero(np.diff(bucket, prepend=-1) != 0)
        else:
            local = np.arange(m)
        if planted is not None:
            seg = planted[a : a + m]
            local = np.union1d(local, np.flatnonzero(np.any(seg[1:] != seg[:-1], axis=1)) + 1)
        ends = np.append(local, m)
        fill = [np.arange(x + gap, y, gap) for x, y in itertools.pairwise(ends) if y - x > gap]
        if fill:
            local = np.unique(np.concatenate([local, *fill]))
        kept_list.append(a + local)
        lo_list.append(a + local)
        hi_list.append(a + np.concatenate([local[1:] - 1, [m - 1]]))
    return (
        np.concatenate(kept_list).astype(np.int64),
        np.concatenate(lo_list).astype(np.int64),
        np.concatenate(hi_list).astype(np.int64),
    )


def _interval_bounds(
    fr: _Frames,
    kept: I64,
    lo: I64,
    hi: I64,
    project: Callable[[I64], F32],
    kept_rows: F32,
    weights: SearchWeights,
    window: WindowConfig,
    stance: StanceCost | None,
    planted: NDArray[np.bool_] | None,
) -> tuple[F32, F32]:
    """Per kept start, how far the windows of its refinement interval can be from it:
    ``(radius (K,) in the KD embedding, bound (K, P) on the pre-ranking D)``, the bound's column
    ``s`` for a query whose support body is part ``s``. The pre-ranking ``D`` (its frames and
    weights, the stance term) is a sum of metrics, so a query's ``D`` to any window of the
    interval is at least its ``D`` to the kept start minus the bound; likewise in the embedding
    with the radius (``docs/design.md``, Search)."""
    fs = get_feature_set(weights.feature_set)
    offsets, fw = prerank_frames(weights, window)
    fw32 = fw.astype(np.float32)
    wp, wq = body_weights(fs, weights, None)
    # the support body's raise, per part: column s of the bound adds part s's
    up_p = np.maximum(wp, weights.support_position) - wp
    up_q = np.maximum(wq, weights.support_orientation) - wq
    K, P = kept.size, len(fs.parts)
    radius = np.zeros(K, dtype=np.float32)
    bound = np.zeros((K, P), dtype=np.float64)
    sizes = hi - lo + 1
    chunk = max(1, CHUNK // (2 * window.max_gap_frames))
    for i in range(0, K, chunk):
        j = np.arange(i, min(K, i + chunk))
        a = int(lo[j[0]])
        starts = np.arange(a, int(hi[j[-1]]) + 1, dtype=np.int64)
        owner = np.repeat(j, sizes[j])  # one row per (kept start, window of its interval)
        first = np.concatenate([[0], np.cumsum(sizes[j])[:-1]])
        ps = lo[owner] - a + np.arange(owner.size) - np.repeat(first, sizes[j])
        pk = kept[owner] - a
        de = np.linalg.norm(project(starts)[ps] - kept_rows[owner], axis=1)
        idx = starts[:, None] + offsets[None, :]
        lp, lq = localize(
            fr.positions[idx], fr.orientations[idx], fr.heading[starts], fr.origin[starts]
        )
        dp, da = part_distances(lp[ps], lq[ps], lp[pk], lq[pk])
        sp = np.einsum("clp,l->cp", dp, fw32).astype(np.float64)
        sa = np.einsum("clp,l->cp", da, fw32).astype(np.float64)
        d = (sp @ wp + sa @ wq)[:, None] + sp * up_p + sa * up_q
        if stance is not None and planted is not None:
            d += (
                stance.weight
                * np.count_nonzero(planted[a + ps] != planted[kept[owner]], axis=1)[:, None]
            )
        radius[j] = np.maximum.reduceat(de, first)
        bound[j] = np.maximum.reduceat(d, first, axis=0)
    # float32 rounded up, so it stays a bound
    return radius, np.nextafter(bound.astype(np.float32), np.float32(np.inf))


def _fit_pca(
    fr: _Frames, kept: I64, ew: EmbeddingWeights, dims: int, rng: np.random.Generator
) -> tuple[F32, F32, float, int]:
    """PCA of the embedding on a random sample of kept windows (covariance + eigh: exact, fast
    for ~1k dimensions): ``(mean, components, explained variance, embedding dimensions)``."""
    sample = (
        kept if kept.size <= PCA_SAMPLE else np.sort(rng.choice(kept, PCA_SAMPLE, replace=False))
    )
    x = np.concatenate(
        [_embed_starts(fr, sample[i : i + CHUNK], ew) for i in range(0, sample.size, CHUNK)]
    )
    mean = x.mean(axis=0, dtype=np.float64)
    de = x.shape[1]
    if dims <= 0 or dims >= de:
        comps = np.eye(de)
        explained = 1.0
    else:
        xc = x - mean.astype(np.float32)
        cov = (xc.T @ xc).astype(np.float64) / max(1, xc.shape[0] - 1)
        evals, evecs = scipy.linalg.eigh(cov, subset_by_index=[de - dims, de - 1])
        comps = evecs[:, np.argsort(evals)[::-1]]
        explained = float(evals.sum() / max(np.trace(cov), 1e-300))
    return mean.astype(np.float32), np.ascontiguousarray(comps.astype(np.float32)), explained, de


def build_index(
    clips: Mapping[str, Motion] | Any,
    weights: SearchWeights | None = None,
    window: WindowConfig | None = None,
    mirror: bool = False,
    *,
    parts: Mapping[str, BodyPartMap] | None = None,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> MotionIndex:
    """Index every window of ``clips`` (resampled to ``window.fps``).

    ``clips`` is a mapping of name -> Motion or a ``ClipLibrary``. The index remembers a
    fingerprint of it: of the files for a ClipLibrary (stable across the clip cache), of the
    motion arrays for a mapping; loading and :func:`~reactmocap.search.store.stale_reason`
    compare it with the same kind of argument.
    ``mirror=True`` adds a left/right mirrored copy of every clip, named ``NAME_mirror``.
    ``parts`` optionally gives each clip's body-part map (default: automatic mapping).

    Raises:
        SearchError: no clips, unmappable skeleton, or no clip long enough for one window.
    """
    t_start = time.perf_counter()
    weights = weights if weights is not None else SearchWeights()
    window = window if window is not None else WindowConfig()
    if not isinstance(weights, SearchWeights) or not isinstance(window, WindowConfig):
        raise ConfigError("build() takes a SearchWeights and a WindowConfig")
    clips, lib_hash = clip_source(clips)
    if not clips:
        raise SearchError("cannot build a search index from an empty library")
    motions: dict[str, Motion] = dict(clips)
    part_maps = dict(parts) if parts else {}
    if mirror:
        for name, m in clips.items():
            mname = name + MIRROR_SUFFIX
            if mname not in motions:
                motions[mname] = m.mirror().replace(name=mname)
                if name in part_maps:
                    part_maps[mname] = part_maps[name]  # names are kept by Motion.mirror
    calibs = calibrations_for(motions, get_feature_set(weights.feature_set), part_maps or None)
    fps, L = window.fps, window.length
    names, native_fps, feats = [], [], []
    for name, m in motions.items():
        ff = frame_features(to_rate(m, fps), calibs[name])
        names.append(name)
        native_fps.append(m.fps)
        # float32 as we go: the 1M-frame library must not hold float64 copies of everything
        feats.append(
            (
                ff.positions.astype(np.float32),
                ff.orientations.astype(np.float32),
                ff.heading,
                ff.origin,
            )
        )
    counts = np.array([f[0].shape[0] for f in feats], dtype=np.int64)
    if not np.any(counts >= L):
        raise SearchError(
            f"no clip is long enough for one {L}-frame window at {fps:g} fps "
            f"({window.duration:g} s); longest has {counts.max()} frames"
        )
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    fr = _Frames(*(np.concatenate([f[k] for f in feats]) for k in range(4)))
    del feats
    if progress:
        progress(f"features: {len(names)} clips, {offsets[-1]} frames at {fps:g} fps")

    ew = embedding_weights(weights, window)
    stance = StanceCost.of(get_feature_set(weights.feature_set), weights, fps)
    planted = None if stance is None else stance.frame_contacts(fr.positions)
    kept, lo, hi = _unique_starts(fr, offsets, weights, window, planted)
    mean, comps, explained, de = _fit_pca(
        fr, kept, ew, window.pca_dims, np.random.default_rng(seed)
    )

    def project(starts: I64) -> F32:
        rows = (_embed_starts(fr, starts, ew) - mean) @ comps
        if stance is None or planted is None:
            return np.asarray(rows, dtype=np.float32)
        return np.concatenate([rows, stance.columns(planted[starts])], axis=1)

    proj = np.concatenate([project(kept[i : i + CHUNK]) for i in range(0, kept.size, CHUNK)])
    radius, bound = _interval_bounds(
        fr, kept, lo, hi, project, proj, weights, window, stance, planted
    )
    nvalid = int(valid_starts(offsets, L).size)
    if progress:
        progress(
            f"indexed {kept.size} unique windows of {nvalid} "
            f"({comps.shape[1]} PCA dims, {explained:.3f} variance)"
        )
    index = MotionIndex(
        weights=weights,
        window=window,
        mirror=bool(mirror),
        clip_names=tuple(names),
        clip_fps=np.asarray(native_fps, dtype=np.float64),
        clip_offsets=offsets,
        positions=fr.positions,
        orientations=fr.orientations,
        heading=fr.heading,
        origin=fr.origin,
        kept=kept,
        interval_lo=lo,
        interval_hi=hi,
        interval_radius=radius,
        interval_bound=bound,
        pca_mean=mean,
        pca_components=comps,
        embedding=proj,
        library_hash=lib_hash,
        settings_hash=settings_hash(weights, window, mirror),
        info={"pca_explained_variance": explained, "embedding_dims": int(de)},
    )
    index.info.update(
        build_seconds=time.perf_counter() - t_start,
        frames=int(offsets[-1]),
        windows=nvalid,
        indexed=index.num_indexed,
    )
    return index
