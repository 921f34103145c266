"""The motion index: unique-frame preprocessing, a KD-tree over a PCA-reduced Euclidean embedding,
exact re-ranking with ``D`` and local refinement, and atomic, validated ``.npz`` persistence."""

from __future__ import annotations

import hashlib
import io
import itertools
import json
import time
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from reactmocap.errors import ConfigError, ReactMocapError, SearchError
from reactmocap.io import atomic_write_bytes
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.search.config import SearchWeights, WindowConfig, settings_hash
from reactmocap.search.distance import (
    BREAKDOWN_TERMS,
    QueryWindow,
    body_weights,
    embed_local,
    embedding_body_weights,
    embedding_frame_weights,
    frame_pose_steps,
    group_matrix,
    localize,
    select_support,
    window_distances,
)
from reactmocap.search.features import (
    FeatureSet,
    FrameFeatures,
    calibrate,
    calibrations_for,
    features_from_arrays,
    frame_features,
    get_feature_set,
    skeleton_key,
)

__all__ = [
    "FORMAT_VERSION",
    "Breakdown",
    "MotionIndex",
    "SearchResult",
    "brute_force",
    "library_fingerprint",
]

FORMAT_VERSION = 1
MIRROR_SUFFIX = "_mirror"
_CHUNK = 4096
#: frames per window in the coarse pre-ranking of KD candidates
COARSE_FRAMES = 10
#: KD candidates, exactly re-ranked candidates, candidates whose interval is refined
DEFAULT_K = 48
DEFAULT_EXACT = 6
DEFAULT_REFINE = 3
#: windows sampled to fit the PCA
PCA_SAMPLE = 8_000

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Breakdown:
    """``D`` split by body group and term; the six values sum to ``D``."""

    trunk_position: float
    trunk_orientation: float
    limbs_position: float
    limbs_orientation: float
    support_position: float
    support_orientation: float
    support_part: str

    @property
    def total(self) -> float:
        return float(sum(getattr(self, t) for t in BREAKDOWN_TERMS))

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {t: float(getattr(self, t)) for t in BREAKDOWN_TERMS}
        d["support_part"] = self.support_part
        return d


@dataclass(frozen=True)
class SearchResult:
    """One matching library window.

    ``frame`` is the start frame in the clip's own frame rate, ``index_frame`` at the index rate,
    ``time`` in seconds. ``yaw`` (radians) and ``translation`` (x, y metres) map the library clip
    onto the query: ``clip_motion.transformed(yaw, translation)`` overlays the query window.
    """

    clip: str
    frame: int
    index_frame: int
    time: float
    distance: float
    yaw: float
    translation: tuple[float, float]
    breakdown: Breakdown
    rank: int = 0

    @property
    def yaw_deg(self) -> float:
        return float(np.degrees(self.yaw))

    def to_dict(self) -> dict[str, Any]:
        return {
            "rank": self.rank,
            "clip": self.clip,
            "frame": self.frame,
            "index_frame": self.index_frame,
            "time": self.time,
            "distance": self.distance,
            "yaw": self.yaw,
            "yaw_deg": self.yaw_deg,
            "translation": list(self.translation),
            "breakdown": self.breakdown.to_dict(),
        }


def _breakdown(row: F64, support_part: str) -> Breakdown:
    v = [float(x) for x in row]
    return Breakdown(v[0], v[1], v[2], v[3], v[4], v[5], support_part=support_part)


@dataclass
class QueryStats:
    """What the last query did (for reports and benchmarks)."""

    candidates: int = 0
    refined_windows: int = 0  # windows of the refinement intervals (beyond the candidates)
    exact_windows: int = 0  # windows whose exact D was computed
    seconds: float = 0.0


# ----------------------------------------------------------------------------- fingerprint
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


def _clip_source(clips: Any) -> tuple[Mapping[str, Motion], str]:
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


#: frame rates within this relative tolerance of an integer multiple of the index rate are
#: taken as that multiple (BVH "Frame Time: 0.0333333" is 30.00003 fps), so such clips are
#: subsampled exactly instead of interpolated
RATE_TOLERANCE = 1e-4


def _rate_step(fps: float, index_fps: float) -> int | None:
    """Integer frame step from ``fps`` to ``index_fps``, or None when it is not a multiple."""
    ratio = fps / index_fps
    step = round(ratio)
    return step if step >= 1 and abs(ratio - step) <= RATE_TOLERANCE * ratio else None


def _to_rate(m: Motion, index_fps: float) -> Motion:
    step = _rate_step(m.fps, index_fps)
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


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


def _wrap(a: float) -> float:
    return float((a + np.pi) % (2 * np.pi) - np.pi)


# ----------------------------------------------------------------------------- the index
@dataclass(eq=False)
class MotionIndex:
    """A searchable library of motion windows. Build with :meth:`build`, persist with
    :meth:`save` / :meth:`load` / :meth:`load_or_build`, search with :meth:`query` /
    :meth:`top_k`. Every array is read-only."""

    weights: SearchWeights
    window: WindowConfig
    mirror: bool
    clip_names: tuple[str, ...]
    clip_fps: F64  # (C,) native fps of each clip
    clip_offsets: I64  # (C+1,) global frame offsets at the index rate
    positions: F32  # (N, P, 3)
    orientations: F32  # (N, P, 4)
    heading: F64  # (N,)
    origin: F64  # (N, 2)
    kept: I64  # (K,) global starts of the indexed (unique) windows
    interval_lo: I64  # (K,) refinement interval, inclusive
    interval_hi: I64  # (K,)
    pca_mean: F32  # (De,)
    pca_components: F32  # (De, d)
    embedding: F32  # (K, d)
    library_hash: str
    settings_hash: str
    info: dict[str, Any] = field(default_factory=dict)
    _tree: cKDTree | None = field(default=None, repr=False)
    last_stats: QueryStats = field(default_factory=QueryStats, repr=False)

    # ------------------------------------------------------------------ derived
    @property
    def feature_set(self) -> FeatureSet:
        return get_feature_set(self.weights.feature_set)

    @property
    def length(self) -> int:
        return self.window.length

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])

    @property
    def num_windows(self) -> int:
        """Valid window starts (every frame with a full window after it)."""
        return int(self._valid_starts().size)

    @property
    def num_indexed(self) -> int:
        return int(self.kept.size)

    @property
    def fingerprint(self) -> str:
        return hashlib.sha256(f"{self.library_hash}|{self.settings_hash}".encode()).hexdigest()

    @property
    def tree(self) -> cKDTree:
        if self._tree is None:
            self._tree = cKDTree(self.embedding, leafsize=32, balanced_tree=False)
        return self._tree

    def nbytes(self) -> int:
        arrays = (
            self.positions, self.orientations, self.heading, self.origin, self.kept,
            self.interval_lo, self.interval_hi, self.pca_mean, self.pca_components, self.embedding,
        )  # fmt: skip
        return int(sum(a.nbytes for a in arrays))

    def _valid_starts(self) -> I64:
        L = self.length
        parts = [
            np.arange(a, b - L + 1, dtype=np.int64)
            for a, b in zip(self.clip_offsets[:-1], self.clip_offsets[1:])
            if b - a >= L
        ]
        return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)

    def clip_index(self, name: str) -> int:
        try:
            return self.clip_names.index(name)
        except ValueError:
            shown = list(self.clip_names[:20])
            more = f" (+{len(self.clip_names) - 20} more)" if len(self.clip_names) > 20 else ""
            raise SearchError(
                f"no clip named {name!r} in the index; clips are {shown}{more}"
            ) from None

    # ------------------------------------------------------------------ build
    @classmethod
    def build(
        cls,
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
        motion arrays for a mapping; :meth:`load` and :meth:`stale_reason` compare it with the same
        kind of argument.
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
        clips, lib_hash = _clip_source(clips)
        if not clips:
            raise SearchError("cannot build a search index from an empty library")
        fs = get_feature_set(weights.feature_set)
        motions: dict[str, Motion] = dict(clips)
        part_maps = dict(parts) if parts else {}
        if mirror:
            for name, m in clips.items():
                mname = name + MIRROR_SUFFIX
                if mname not in motions:
                    motions[mname] = m.mirror().replace(name=mname)
                    if name in part_maps:
                        part_maps[mname] = part_maps[name]  # names are kept by Motion.mirror
        calibs = calibrations_for(motions, fs, part_maps or None)
        fps = window.fps
        L = window.length
        names: list[str] = []
        native_fps: list[float] = []
        feats: list[FrameFeatures] = []
        for name, m in motions.items():
            mr = _to_rate(m, fps)
            names.append(name)
            native_fps.append(m.fps)
            ff = frame_features(mr, calibs[name])
            # float32 as we go: the 1M-frame library must not hold float64 copies of everything
            feats.append(
                FrameFeatures(
                    ff.positions.astype(np.float32),
                    ff.orientations.astype(np.float32),
                    ff.heading,
                    ff.origin,
                    ff.com[:0],
                )
            )
        counts = np.array([f.num_frames for f in feats], dtype=np.int64)
        if not np.any(counts >= L):
            raise SearchError(
                f"no clip is long enough for one {L}-frame window at {fps:g} fps "
                f"({window.duration:g} s); longest has {counts.max()} frames"
            )
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        positions = np.concatenate([f.positions for f in feats]).astype(np.float32)
        orientations = np.concatenate([f.orientations for f in feats]).astype(np.float32)
        heading = np.concatenate([f.heading for f in feats])
        origin = np.concatenate([f.origin for f in feats])
        del feats
        if progress:
            progress(f"features: {len(names)} clips, {offsets[-1]} frames at {fps:g} fps")

        index = cls(
            weights=weights,
            window=window,
            mirror=bool(mirror),
            clip_names=tuple(names),
            clip_fps=np.asarray(native_fps, dtype=np.float64),
            clip_offsets=offsets,
            positions=positions,
            orientations=orientations,
            heading=heading,
            origin=origin,
            kept=np.zeros(0, np.int64),
            interval_lo=np.zeros(0, np.int64),
            interval_hi=np.zeros(0, np.int64),
            pca_mean=np.zeros(0, np.float32),
            pca_components=np.zeros((0, 0), np.float32),
            embedding=np.zeros((0, 0), np.float32),
            library_hash=lib_hash,
            settings_hash=settings_hash(weights, window, mirror),
        )
        index._build_embedding(np.random.default_rng(seed), progress)
        index.info.update(
            build_seconds=time.perf_counter() - t_start,
            frames=int(offsets[-1]),
            windows=index.num_windows,
            indexed=index.num_indexed,
        )
        index._freeze()
        return index

    def _embed_starts(self, starts: I64, wp: F64, wq: F64, fw: F64, offs: I64) -> F32:
        idx = starts[:, None] + offs[None, :]
        lp, lq = localize(
            self.positions[idx], self.orientations[idx], self.heading[starts], self.origin[starts]
        )
        return embed_local(lp, lq, fw, wp, wq)

    def _embedding_weights(self) -> tuple[F64, F64, F64, I64]:
        def make() -> tuple[F64, F64, F64, I64]:
            wp, wq = embedding_body_weights(self.feature_set, self.weights)
            offs = self.window.embed_offsets()
            fw = embedding_frame_weights(self.weights.window_weights(self.length), offs)
            return wp, wq, fw, offs

        return self._memo("embed", make)  # type: ignore[no-any-return]

    def _unique_starts(self, valid: I64) -> tuple[I64, I64, I64]:
        """Kept window starts and their refinement intervals (inclusive), clip by clip.

        The paper keeps a frame when it differs from the previous kept frame by more than a
        tolerance. We measure the per-frame pose distance (``D`` of a one-frame window, base
        weights, each frame in its own root frame) between consecutive frames and keep a frame
        whenever the *path length* since the last kept one crosses another multiple of the
        tolerance. Path length bounds the direct distance, so every dropped frame is within the
        tolerance of the previous kept frame (vectorised; no sequential scan). A frame is also
        kept at least every ``max_gap`` seconds, which bounds the refinement interval.
        """
        fs = self.feature_set
        wp, wq = body_weights(fs, self.weights, None)
        step = frame_pose_steps(
            self.positions, self.orientations, self.heading, self.origin, wp, wq
        )
        kept_list, lo_list, hi_list = [], [], []
        tol = self.window.unique_tolerance
        gap = self.window.max_gap_frames
        for a, b in zip(self.clip_offsets[:-1], self.clip_offsets[1:]):
            m = int(b - a - self.length + 1)
            if m <= 0:
                continue
            st = step[a : a + m].astype(np.float64)
            st[0] = 0.0
            if tol > 0:
                bucket = np.floor(np.cumsum(st) / tol).astype(np.int64)
                local = np.flatnonzero(np.diff(bucket, prepend=-1) != 0)
            else:
                local = np.arange(m)
            ends = np.append(local, m)
            fill = [np.arange(x + gap, y, gap) for x, y in itertools.pairwise(ends) if y - x > gap]
            if fill:
                local = np.unique(np.concatenate([local, *fill]))
            kept_list.append(a + local)
            lo_list.append(a + np.concatenate([[0], local[:-1] + 1]))
            hi_list.append(a + np.concatenate([local[1:] - 1, [m - 1]]))
        kept = np.concatenate(kept_list).astype(np.int64)
        return (
            kept,
            np.concatenate(lo_list).astype(np.int64),
            np.concatenate(hi_list).astype(np.int64),
        )

    def _build_embedding(
        self, rng: np.random.Generator, progress: Callable[[str], None] | None
    ) -> None:
        wp, wq, fw, offs = self._embedding_weights()
        valid = self._valid_starts()
        kept, lo, hi = self._unique_starts(valid)
        # PCA fitted on a random sample of kept windows (covariance + eigh: exact, fast for De ~ 1k)
        sample = (
            kept
            if kept.size <= PCA_SAMPLE
            else np.sort(rng.choice(kept, PCA_SAMPLE, replace=False))
        )
        x = np.concatenate(
            [
                self._embed_starts(sample[i : i + _CHUNK], wp, wq, fw, offs)
                for i in range(0, sample.size, _CHUNK)
            ]
        )
        mean = x.mean(axis=0, dtype=np.float64)
        de = x.shape[1]
        d = self.window.pca_dims
        if d <= 0 or d >= de:
            comps = np.eye(de)
            explained = 1.0
        else:
            xc = x - mean.astype(np.float32)
            cov = (xc.T @ xc).astype(np.float64) / max(1, xc.shape[0] - 1)
            evals, evecs = scipy.linalg.eigh(cov, subset_by_index=[de - d, de - 1])
            order = np.argsort(evals)[::-1]
            comps = evecs[:, order]
            explained = float(evals.sum() / max(np.trace(cov), 1e-300))
        del x
        mean32 = mean.astype(np.float32)
        comps32 = np.ascontiguousarray(comps.astype(np.float32))
        proj = np.empty((kept.size, comps32.shape[1]), dtype=np.float32)
        for i in range(0, kept.size, _CHUNK):
            e = self._embed_starts(kept[i : i + _CHUNK], wp, wq, fw, offs)
            proj[i : i + e.shape[0]] = (e - mean32) @ comps32
        self.kept, self.interval_lo, self.interval_hi = kept, lo, hi
        self.embedding = proj
        self.pca_mean = mean32
        self.pca_components = comps32
        self.info["pca_explained_variance"] = explained
        self.info["embedding_dims"] = int(de)
        self._tree = None
        _ = self.tree
        if progress:
            progress(
                f"indexed {kept.size} unique windows of {valid.size} "
                f"({d} PCA dims, {explained:.3f} variance)"
            )

    def _freeze(self) -> None:
        for name in (
            "clip_fps", "clip_offsets", "positions", "orientations", "heading", "origin", "kept",
            "interval_lo", "interval_hi", "pca_mean", "pca_components", "embedding",
        ):  # fmt: skip
            setattr(self, name, _readonly(getattr(self, name)))

    # ------------------------------------------------------------------ queries
    def prepare_query(
        self, motion: Motion, start_frame: int | None = None, *, parts: BodyPartMap | None = None
    ) -> QueryWindow:
        """Cut, resample and localise the query window of ``motion`` starting at ``start_frame``
        (a frame of ``motion`` at its own rate; default 0).

        Raises:
            SearchError: frame out of range, or the motion too short for a window.
        """
        if not isinstance(motion, Motion):
            raise SearchError(f"a query must be a Motion, got {type(motion).__name__}")
        f0 = 0 if start_frame is None else start_frame
        if isinstance(f0, bool) or not isinstance(f0, (int, np.integer)):
            raise SearchError(f"start frame must be an integer, got {start_frame!r}")
        f0 = int(f0)
        if not 0 <= f0 < motion.num_frames:
            raise SearchError(
                f"start frame {f0} is out of range for {motion.name or 'the query'} "
                f"({motion.num_frames} frames, 0..{motion.num_frames - 1})"
            )
        L = self.length
        step = _rate_step(motion.fps, self.window.fps)
        t0 = f0 / motion.fps
        span = (L - 1) / self.window.fps
        if step is not None:
            fits = f0 + (L - 1) * step <= motion.num_frames - 1
        else:
            fits = t0 + span <= motion.duration + 1e-9
        if not fits:
            raise SearchError(
                f"the {L}-frame search window ({span:.3f} s at {self.window.fps:g} fps) "
                f"starting at "
                f"frame {f0} ({t0:.3f} s) runs past the end of {motion.name or 'the query'} "
                f"({motion.duration:.3f} s, {motion.num_frames} frames)"
            )
        if step is not None:
            sl = slice(f0, f0 + (L - 1) * step + 1, step)
            root, rot = motion.root_positions[sl], motion.rotations[sl]
            tr = None if motion.translations is None else motion.translations[sl]
        else:
            sub = motion.sample(t0 + np.arange(L) / self.window.fps)
            root, rot, tr = sub.root_positions, sub.rotations, sub.translations
        calib = self._calibration(motion, parts)
        ff = features_from_arrays(motion.skeleton, root, rot, tr, calib, com_frames=1)
        h0 = float(ff.heading[0])
        o0 = ff.origin[0]
        lp, lq = localize(ff.positions[None], ff.orientations[None], np.array([h0]), o0[None])
        fs = self.feature_set
        sup = select_support(ff.positions[0], ff.com[0], fs, self.weights)
        return QueryWindow(
            positions=lp[0].astype(np.float32),
            orientations=lq[0].astype(np.float32),
            heading=h0,
            origin=np.asarray(o0, dtype=np.float64),
            support=sup,
            support_part=fs.parts[sup],
            com=ff.com[0],
        )

    def _memo(self, key: Any, make: Callable[[], Any]) -> Any:
        """Per-index cache of query-independent constants (weights, offsets, calibrations)."""
        memo: dict[Any, Any] = self.__dict__.setdefault("_memo_cache", {})
        if key not in memo:
            if len(memo) > 256:
                memo.clear()
            memo[key] = make()
        return memo[key]

    def _calibration(self, motion: Motion, parts: BodyPartMap | None):  # type: ignore[no-untyped-def]
        skel = motion.skeleton
        # fast path: the very same Skeleton object (kept alive by the entry, so ids stay unique)
        hit = self._memo(("calib-id", id(skel), id(parts)), lambda: None)
        if hit is not None and hit[0] is skel and hit[1] is parts:
            return hit[2]
        key = ("calib", skeleton_key(skel), id(parts) if parts is not None else None)
        cal = self._memo(key, lambda: calibrate(skel, self.feature_set, parts))
        self.__dict__["_memo_cache"][("calib-id", id(skel), id(parts))] = (skel, parts, cal)
        return cal

    def _distances(
        self,
        qw: QueryWindow,
        starts: I64,
        breakdown: bool = False,
        coarse: bool = False,
        precise: bool | None = None,
    ) -> tuple[F64, F64 | None]:
        def consts() -> tuple[Any, ...]:
            fs = self.feature_set
            wp, wq = body_weights(fs, self.weights, qw.support)
            ww = self.weights.window_weights(self.length)
            offsets = None
            if coarse:
                offsets = self._coarse_offsets()
                ww = embedding_frame_weights(ww, offsets)
            return wp, wq, ww, offsets, group_matrix(fs, qw.support)

        wp, wq, ww, offsets, groups = self._memo(("dist", qw.support, coarse), consts)
        return window_distances(
            self.positions, self.orientations, self.heading, self.origin, starts, qw,
            ww, wp, wq, groups if breakdown else None, offsets,
            precise=(not coarse) if precise is None else precise,
        )  # fmt: skip

    def _coarse_offsets(self) -> I64:
        """Window frames of the coarse pre-ranking: about ``COARSE_FRAMES`` evenly spaced."""
        L = self.length
        step = max(1, int(np.ceil((L - 1) / (COARSE_FRAMES - 1))))
        return np.unique(np.append(np.arange(0, L, step), L - 1)).astype(np.int64)

    def _embed_query(self, qw: QueryWindow) -> F32:
        wp, wq, fw, offs = self._embedding_weights()
        e = embed_local(qw.positions[None, offs], qw.orientations[None, offs], fw, wp, wq)
        return ((e - self.pca_mean) @ self.pca_components)[0]

    def search_window(
        self,
        qw: QueryWindow,
        *,
        n: int = 1,
        k: int = DEFAULT_K,
        refine: int = DEFAULT_REFINE,
        exact: int = DEFAULT_EXACT,
    ) -> list[SearchResult]:
        """Search with a prepared query window.

        1. ``k`` nearest indexed (unique-frame) windows in the PCA embedding (KD-tree);
        2. pre-rank them with ``D`` including the query's support weight: on about
           ``COARSE_FRAMES`` window frames (weights aggregated) when ``L > COARSE_FRAMES``,
           otherwise exactly;
        3. every window in the surrounding unique-frame interval of the best ``refine`` is tested
           too (the paper's local refinement), pre-ranked the same way;
        4. exact ``D`` with its breakdown for the best ``max(exact, n)`` of all of these (every
           tested window when ``L <= COARSE_FRAMES``); the ``n`` best distinct ones are returned.

        ``k = num_indexed`` and ``refine = num_indexed`` with ``L <= COARSE_FRAMES`` is an
        exhaustive search (equal to :func:`brute_force`).
        """
        t0 = time.perf_counter()
        if n < 1 or k < 1 or refine < 0 or exact < 1:
            raise SearchError(
                "need n >= 1, k >= 1, refine >= 0, exact >= 1 "
                f"(got n={n}, k={k}, refine={refine}, exact={exact})"
            )
        k = min(k, self.num_indexed)
        _, rows = self.tree.query(self._embed_query(qw), k=k)
        rows = np.atleast_1d(np.asarray(rows, dtype=np.int64))
        rows = rows[rows < self.num_indexed]
        cand = self.kept[rows]
        coarse = self.length > COARSE_FRAMES
        d, _ = self._distances(qw, cand, coarse=coarse)
        order = np.argsort(d, kind="stable")
        spans = [
            np.arange(self.interval_lo[r], self.interval_hi[r] + 1, dtype=np.int64)
            for r in rows[order[:refine]]
        ]
        extra = np.setdiff1d(np.concatenate(spans), cand) if spans else np.zeros(0, np.int64)
        m = max(exact, n)
        if coarse:
            # the interval windows are pre-ranked like the candidates; exact D for the best m
            if extra.size:
                de, _ = self._distances(qw, extra, coarse=True)
                pool, pd = np.concatenate([cand, extra]), np.concatenate([d, de])
            else:
                pool, pd = cand, d
            starts = pool[np.argsort(pd, kind="stable")[:m]]
        else:
            starts = np.unique(np.concatenate([cand[order[:m]], extra]))
        dists, br = self._distances(qw, starts, breakdown=True)
        if n > 1:
            # runners-up must be distinct windows: widen the exact set until n are found
            while self._pick(starts, dists, n).size < n:
                if k < self.num_indexed and np.all(np.isin(cand, starts)):
                    k = min(2 * k, self.num_indexed)
                    _, rows = self.tree.query(self._embed_query(qw), k=k)
                    cand = self.kept[np.asarray(rows, dtype=np.int64)]
                more = cand[~np.isin(cand, starts)][: 8 * n]  # nearest in the embedding first
                if more.size == 0:
                    break
                d2, br2 = self._distances(qw, more, breakdown=True)
                starts = np.concatenate([starts, more])
                dists = np.concatenate([dists, d2])
                br = np.concatenate([br, br2])
        results = self._results(qw, starts, dists, n, br)
        self.last_stats = QueryStats(
            candidates=int(cand.size),
            refined_windows=int(extra.size),
            exact_windows=int(starts.size),
            seconds=time.perf_counter() - t0,
        )
        return results

    def _pick(self, starts: I64, dists: F64, n: int) -> I64:
        """Positions (into ``starts``) of the ``n`` best windows, at least one window length
        apart within a clip."""
        order = np.argsort(dists, kind="stable")
        if n == 1:
            return order[:1]
        clips = np.searchsorted(self.clip_offsets, starts, side="right") - 1
        picked: list[int] = []
        for i in order:
            s, c = int(starts[i]), int(clips[i])
            if all(abs(s - int(starts[p])) >= self.length or c != int(clips[p]) for p in picked):
                picked.append(int(i))
                if len(picked) == n:
                    break
        return np.asarray(picked, dtype=np.int64)

    def _clip_of(self, start: int) -> int:
        return int(np.searchsorted(self.clip_offsets, start, side="right") - 1)

    def _results(
        self, qw: QueryWindow, starts: I64, dists: F64, n: int, breakdown: F64 | None = None
    ) -> list[SearchResult]:
        sel = self._pick(starts, dists, n)
        chosen = starts[sel]
        if breakdown is None:
            d, br = self._distances(qw, chosen, breakdown=True)
        else:
            d, br = dists[sel], breakdown[sel]
        assert br is not None
        out = []
        for rank, (s, dist, row) in enumerate(zip(chosen, d, br)):
            c = self._clip_of(int(s))
            fi = int(s - self.clip_offsets[c])
            t = fi / self.window.fps
            yaw = _wrap(qw.heading - float(self.heading[s]))
            cy, sy = np.cos(yaw), np.sin(yaw)
            ox, oy = self.origin[s]
            tx = float(qw.origin[0] - (cy * ox - sy * oy))
            ty = float(qw.origin[1] - (sy * ox + cy * oy))
            out.append(
                SearchResult(
                    clip=self.clip_names[c],
                    frame=round(t * self.clip_fps[c]),
                    index_frame=fi,
                    time=t,
                    distance=float(dist),
                    yaw=yaw,
                    translation=(tx, ty),
                    breakdown=_breakdown(row, qw.support_part),
                    rank=rank,
                )
            )
        return out

    def query(
        self,
        motion: Motion,
        start_frame: int | None = None,
        *,
        k: int = DEFAULT_K,
        refine: int = DEFAULT_REFINE,
        exact: int = DEFAULT_EXACT,
        parts: BodyPartMap | None = None,
    ) -> SearchResult:
        """Best library window for the window of ``motion`` starting at ``start_frame`` (a frame
        of ``motion`` at its own rate). :meth:`search_window` explains ``k``, ``refine``,
        ``exact``."""
        qw = self.prepare_query(motion, start_frame, parts=parts)
        return self.search_window(qw, n=1, k=k, refine=refine, exact=exact)[0]

    def top_k(
        self,
        motion: Motion,
        start_frame: int | None = None,
        *,
        n: int = 5,
        k: int = DEFAULT_K,
        refine: int = DEFAULT_REFINE,
        exact: int = DEFAULT_EXACT,
        parts: BodyPartMap | None = None,
    ) -> list[SearchResult]:
        """The ``n`` best distinct windows (at least a window length apart within a clip), each
        with its breakdown, so a user can see why the winner won."""
        qw = self.prepare_query(motion, start_frame, parts=parts)
        return self.search_window(qw, n=n, k=max(k, n), refine=max(refine, min(n, 8)), exact=exact)

    def window_distance(
        self, motion: Motion, start_frame: int | None, clip: str, frame: int
    ) -> SearchResult:
        """Exact ``D`` (with breakdown and alignment) between a query window and one library
        window, ``frame`` counted at the index rate."""
        qw = self.prepare_query(motion, start_frame)
        c = self.clip_index(clip)
        a, b = int(self.clip_offsets[c]), int(self.clip_offsets[c + 1])
        if not 0 <= frame <= b - a - self.length:
            raise SearchError(
                f"index frame {frame} has no full window in clip {clip!r} ({b - a} frames)"
            )
        s = np.array([a + frame], dtype=np.int64)
        d, _ = self._distances(qw, s)
        return self._results(qw, s, d, 1)[0]

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | Path) -> Path:
        """Write the index atomically as ``.npz`` (arrays + JSON metadata, no pickle)."""
        p = Path(path)
        meta = {
            "format": "reactmocap-search-index",
            "version": FORMAT_VERSION,
            "weights": self.weights.to_dict(),
            "window": self.window.to_dict(),
            "mirror": self.mirror,
            "clip_names": list(self.clip_names),
            "library_hash": self.library_hash,
            "settings_hash": self.settings_hash,
            "info": self.info,
        }
        arrays = {
            "meta": np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8),
            **{name: getattr(self, name) for name in _ARRAYS},
        }
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        try:
            atomic_write_bytes(p, buf.getvalue())
        except OSError as exc:
            raise SearchError(f"{p}: cannot write index: {exc}") from None
        return p

    @classmethod
    def load(
        cls,
        path: str | Path,
        *,
        clips: Mapping[str, Motion] | Any | None = None,
        weights: SearchWeights | None = None,
        window: WindowConfig | None = None,
        mirror: bool | None = None,
    ) -> MotionIndex:
        """Read an index written by :meth:`save`.

        When ``clips``/``weights``/``window``/``mirror`` are given, the index must have been built
        from exactly those (content fingerprint); otherwise it is stale.

        Raises:
            SearchError: naming the file, when it is missing, not an index, corrupt, of another
                format version, or stale.
        """
        p = Path(path)
        try:
            with np.load(p, allow_pickle=False) as z:
                if "meta" not in z.files:
                    raise SearchError(f"{p}: not a reactmocap search index (no metadata)")
                meta = json.loads(bytes(z["meta"]).decode())
                missing = [a for a in _ARRAYS if a not in z.files]
                if missing:
                    raise SearchError(f"{p}: corrupt search index, missing arrays {missing}")
                arrays = {a: z[a] for a in _ARRAYS}
        except SearchError:
            raise
        except FileNotFoundError:
            raise SearchError(f"{p}: no such index file") from None
        except (
            OSError,
            ValueError,
            KeyError,
            zipfile.BadZipFile,
            EOFError,
            UnicodeDecodeError,
        ) as exc:
            raise SearchError(
                f"{p}: not a readable search index ({type(exc).__name__}: {exc})"
            ) from None
        if not isinstance(meta, dict) or meta.get("format") != "reactmocap-search-index":
            raise SearchError(f"{p}: not a reactmocap search index")
        if meta.get("version") != FORMAT_VERSION:
            raise SearchError(
                f"{p}: search index format version {meta.get('version')} is not "
                f"{FORMAT_VERSION}; rebuild it"
            )
        try:
            w = SearchWeights.from_dict(meta["weights"])
            win = WindowConfig.from_dict(meta["window"])
            index = cls(
                weights=w,
                window=win,
                mirror=bool(meta["mirror"]),
                clip_names=tuple(str(n) for n in meta["clip_names"]),
                library_hash=str(meta["library_hash"]),
                settings_hash=str(meta["settings_hash"]),
                info=dict(meta.get("info", {})),
                **arrays,
            )
        except (KeyError, TypeError, ReactMocapError) as exc:
            raise SearchError(f"{p}: corrupt search index metadata ({exc})") from None
        index._validate(p)
        index._freeze()
        problem = index.stale_reason(clips=clips, weights=weights, window=window, mirror=mirror)
        if problem:
            raise SearchError(f"{p}: stale search index: {problem}; rebuild it")
        return index

    def _validate(self, p: Path) -> None:
        P = len(self.feature_set.parts)
        N = self.positions.shape[0] if self.positions.ndim == 3 else -1
        K = self.kept.shape[0] if self.kept.ndim == 1 else -1
        de = self.pca_mean.shape[0] if self.pca_mean.ndim == 1 else -1
        dims = self.pca_components.shape[1] if self.pca_components.ndim == 2 else -1
        checks = [
            (self.positions.ndim == 3 and self.positions.shape[1:] == (P, 3), "positions"),
            (self.orientations.shape == (N, P, 4), "orientations"),
            (self.heading.shape == (N,), "heading"),
            (self.origin.shape == (N, 2), "origin"),
            (self.clip_offsets.shape == (len(self.clip_names) + 1,), "clip_offsets"),
            (self.clip_fps.shape == (len(self.clip_names),), "clip_fps"),
            (self.kept.ndim == 1 and self.interval_lo.shape == (K,), "kept"),
            (self.interval_hi.shape == (K,), "intervals"),
            (self.pca_components.ndim == 2 and self.pca_components.shape[0] == de, "pca"),
            (self.embedding.shape == (K, dims), "embedding"),
        ]  # fmt: skip
        bad = [name for ok, name in checks if not ok]
        if not bad:
            if (
                self.clip_offsets[0] != 0
                or self.clip_offsets[-1] != N
                or np.any(np.diff(self.clip_offsets) < 0)
            ):
                bad.append("clip_offsets")
            elif K and (self.kept.min() < 0 or self.kept.max() + self.length > N):
                bad.append("kept")
            elif K and (
                np.any(self.interval_lo > self.kept) or np.any(self.interval_hi < self.kept)
            ):
                bad.append("intervals")
            elif not all(
                np.all(np.isfinite(a)) for a in (self.positions, self.orientations, self.embedding)
            ):
                bad.append("non-finite values")
        if bad or K == 0:
            raise SearchError(
                f"{p}: corrupt search index (inconsistent {', '.join(bad) or 'kept'})"
            )

    def stale_reason(
        self,
        *,
        clips: Mapping[str, Motion] | Any | None = None,
        weights: SearchWeights | None = None,
        window: WindowConfig | None = None,
        mirror: bool | None = None,
    ) -> str | None:
        """Why this index does not match the given library/settings, or ``None``."""
        if clips is not None and _clip_source(clips)[1] != self.library_hash:
            return "the library's clips changed since it was built"
        if weights is not None and weights != self.weights:
            return f"weights differ (index built with {self.weights})"
        if window is not None and window != self.window:
            return f"window settings differ (index built with {self.window})"
        if mirror is not None and bool(mirror) != self.mirror:
            return f"mirroring differs (index built with mirror={self.mirror})"
        return None

    @classmethod
    def load_or_build(
        cls,
        path: str | Path,
        clips: Mapping[str, Motion] | Any,
        weights: SearchWeights | None = None,
        window: WindowConfig | None = None,
        mirror: bool = False,
        **build_kwargs: Any,
    ) -> MotionIndex:
        """Load ``path`` if it was built from exactly these clips and settings; otherwise (missing,
        corrupt or stale) build the index, save it atomically and return it."""
        weights = weights if weights is not None else SearchWeights()
        window = window if window is not None else WindowConfig()
        p = Path(path)
        if p.exists():
            try:
                return cls.load(p, clips=clips, weights=weights, window=window, mirror=mirror)
            except SearchError:
                pass
        index = cls.build(clips, weights, window, mirror, **build_kwargs)
        index.save(p)
        return index


_ARRAYS = (
    "clip_fps", "clip_offsets", "positions", "orientations", "heading", "origin", "kept",
    "interval_lo", "interval_hi", "pca_mean", "pca_components", "embedding",
)  # fmt: skip


# ----------------------------------------------------------------------------- brute force
def brute_force(
    index: MotionIndex,
    motion: Motion | QueryWindow,
    start_frame: int | None = None,
    *,
    n: int = 1,
    parts: BodyPartMap | None = None,
) -> list[SearchResult]:
    """Exact ``D`` against *every* valid window of the index (no KD-tree, no unique-frame
    reduction): the ground truth for tests and benchmarks."""
    qw = (
        motion
        if isinstance(motion, QueryWindow)
        else index.prepare_query(motion, start_frame, parts=parts)
    )
    valid = index._valid_starts()
    d = np.empty(valid.size)
    chunk = max(256, 2_000_000 // max(1, index.length * len(index.feature_set.parts)))
    for i in range(0, valid.size, chunk):
        # all frames, cheaper arithmetic (same D to ~1e-5); the shortlist is re-scored precisely
        d[i : i + chunk], _ = index._distances(qw, valid[i : i + chunk], precise=False)
    m = min(d.size, max(50 * n, 64))
    short = np.argpartition(d, m - 1)[:m] if m < d.size else np.arange(d.size)
    ds, br = index._distances(qw, valid[short], breakdown=True)
    return index._results(qw, valid[short], ds, n, br)
