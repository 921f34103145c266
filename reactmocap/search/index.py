"""The motion index: a frozen container of per-frame window features, the unique-frame window
starts with their refinement intervals, the PCA embedding and its KD-tree. Building
(:mod:`~reactmocap.search.build`), searching (:mod:`~reactmocap.search.query`) and persistence
(:mod:`~reactmocap.search.store`) live in their own modules; the methods here delegate to them."""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.spatial import cKDTree

from reactmocap.errors import SearchError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.search.config import SearchWeights, WindowConfig
from reactmocap.search.distance import QueryWindow, StanceCost
from reactmocap.search.features import FeatureSet, get_feature_set
from reactmocap.search.types import (
    DEFAULT_EXACT,
    DEFAULT_K,
    DEFAULT_REFINE,
    F32,
    F64,
    FORMAT_VERSION,
    I64,
    MIRROR_SUFFIX,
    Breakdown,
    QueryStats,
    SearchResult,
)

if TYPE_CHECKING:
    from reactmocap.search.query import QueryCache

__all__ = [
    "ARRAYS",
    "FORMAT_VERSION",
    "MIRROR_SUFFIX",
    "Breakdown",
    "MotionIndex",
    "QueryStats",
    "SearchResult",
    "valid_starts",
]

#: the array fields of :class:`MotionIndex`, in the order they are saved
ARRAYS = (
    "clip_fps", "clip_offsets", "positions", "orientations", "heading", "origin", "kept",
    "interval_lo", "interval_hi", "interval_radius", "interval_bound", "pca_mean",
    "pca_components", "embedding",
)  # fmt: skip


def valid_starts(clip_offsets: I64, length: int) -> I64:
    """Global start frames with a full ``length``-frame window inside their clip."""
    parts = [
        np.arange(a, b - length + 1, dtype=np.int64)
        for a, b in zip(clip_offsets[:-1], clip_offsets[1:])
        if b - a >= length
    ]
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class MotionIndex:
    """A searchable library of motion windows. Build with :meth:`build`, persist with
    :meth:`save` / :meth:`load` / :meth:`load_or_build`, search with :meth:`query` /
    :meth:`top_k`. Every array is read-only and a query changes nothing here; ``info`` is free
    metadata (build statistics, the library folder) saved with the index.

    Raises:
        SearchError: on construction, when the arrays are inconsistent with each other.
    """

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
    #: per kept start, the farthest window of its interval: in the KD embedding, and in the
    #: pre-ranking D for each support body (build._interval_bounds)
    interval_radius: F32  # (K,)
    interval_bound: F32  # (K, P): column s for a query whose support body is part s
    pca_mean: F32  # (De,)
    pca_components: F32  # (De, d)
    embedding: F32  # (K, d)
    library_hash: str
    settings_hash: str
    info: dict[str, Any] = field(default_factory=dict)
    #: KD-tree over ``embedding``, built on construction
    tree: cKDTree = field(init=False, repr=False)
    #: rows whose ``interval_radius`` is above ``wide_radius`` (about 1%): a query tests them
    #: directly, so its KD ball around the nearest kept start reaches ``wide_radius`` only
    wide_rows: I64 = field(init=False, repr=False)
    wide_radius: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "clip_names", tuple(self.clip_names))
        for name in ARRAYS:
            object.__setattr__(self, name, _readonly(getattr(self, name)))
        self._validate()
        object.__setattr__(self, "tree", cKDTree(self.embedding, leafsize=32, balanced_tree=False))
        cut = float(np.quantile(self.interval_radius, 0.99))
        object.__setattr__(self, "wide_radius", cut)
        object.__setattr__(self, "wide_rows", _readonly(np.flatnonzero(self.interval_radius > cut)))

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
        return int(self.valid_starts().size)

    @property
    def num_indexed(self) -> int:
        return int(self.kept.size)

    @property
    def fingerprint(self) -> str:
        return hashlib.sha256(f"{self.library_hash}|{self.settings_hash}".encode()).hexdigest()

    def _stance_columns(self) -> int:
        """Columns after the PCA dimensions in :attr:`embedding`: each foot's contact
        (``SearchWeights.stance_mismatch``; none when it is 0)."""
        stance = StanceCost.of(self.feature_set, self.weights, self.window.fps)
        return 0 if stance is None else int(stance.feet.size)

    def nbytes(self) -> int:
        return int(sum(getattr(self, a).nbytes for a in ARRAYS))

    def valid_starts(self) -> I64:
        """Global start frames of every window (:attr:`num_windows` of them)."""
        return valid_starts(self.clip_offsets, self.length)

    def clip_of(self, starts: I64) -> I64:
        """Clip number of each global frame in ``starts``."""
        return np.searchsorted(self.clip_offsets, starts, side="right") - 1

    def clip_index(self, name: str) -> int:
        try:
            return self.clip_names.index(name)
        except ValueError:
            shown = list(self.clip_names[:20])
            more = f" (+{len(self.clip_names) - 20} more)" if len(self.clip_names) > 20 else ""
            raise SearchError(
                f"no clip named {name!r} in the index; clips are {shown}{more}"
            ) from None

    def _validate(self) -> None:
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
            (self.interval_radius.shape == (K,), "interval radius"),
            (self.interval_bound.shape == (K, P), "interval bound"),
            (self.pca_components.ndim == 2 and self.pca_components.shape[0] == de, "pca"),
            (self.embedding.shape == (K, dims + self._stance_columns()), "embedding"),
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
            elif K and (self.interval_radius.min() < 0 or self.interval_bound.min() < 0):
                bad.append("interval bounds")
            elif not all(
                np.all(np.isfinite(a))
                for a in (self.positions, self.orientations, self.embedding, self.interval_radius,
                          self.interval_bound)
            ):  # fmt: skip
                bad.append("non-finite values")
        if bad or K == 0:
            raise SearchError(f"corrupt search index (inconsistent {', '.join(bad) or 'kept'})")

    # ------------------------------------------------------------------ build and persistence
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
        """Index every window of ``clips`` (:func:`.build.build_index`)."""
        from reactmocap.search.build import build_index

        return build_index(
            clips, weights, window, mirror, parts=parts, seed=seed, progress=progress
        )

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
        """Read a saved index, checked against what is given (:func:`.store.load`)."""
        from reactmocap.search.store import load

        return load(path, clips=clips, weights=weights, window=window, mirror=mirror)

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
        """Load if up to date, else build and save (:func:`.store.load_or_build`)."""
        from reactmocap.search.store import load_or_build

        return load_or_build(path, clips, weights, window, mirror, **build_kwargs)

    def save(self, path: str | Path) -> Path:
        """Write atomically as ``.npz`` (:func:`.store.save`)."""
        from reactmocap.search.store import save

        return save(self, path)

    def stale_reason(
        self,
        *,
        clips: Mapping[str, Motion] | Any | None = None,
        weights: SearchWeights | None = None,
        window: WindowConfig | None = None,
        mirror: bool | None = None,
    ) -> str | None:
        """Why the index does not match these inputs, or None (:func:`.store.stale_reason`)."""
        from reactmocap.search.store import stale_reason

        return stale_reason(self, clips=clips, weights=weights, window=window, mirror=mirror)

    # ------------------------------------------------------------------ queries
    def prepare_query(
        self,
        motion: Motion,
        start_frame: int | None = None,
        *,
        parts: BodyPartMap | None = None,
        cache: QueryCache | None = None,
    ) -> QueryWindow:
        """The localised query window (:func:`.query.prepare_query`)."""
        from reactmocap.search.query import prepare_query

        return prepare_query(self, motion, start_frame, parts=parts, cache=cache)

    def query(
        self,
        motion: Motion,
        start_frame: int | None = None,
        *,
        k: int = DEFAULT_K,
        refine: int = DEFAULT_REFINE,
        exact: int = DEFAULT_EXACT,
        parts: BodyPartMap | None = None,
        cache: QueryCache | None = None,
    ) -> SearchResult:
        """Best library window (:func:`.query.query`)."""
        from reactmocap.search.query import query

        return query(
            self, motion, start_frame, k=k, refine=refine, exact=exact, parts=parts, cache=cache
        )

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
        cache: QueryCache | None = None,
    ) -> list[SearchResult]:
        """The ``n`` best distinct windows (:func:`.query.top_k`)."""
        from reactmocap.search.query import top_k

        return top_k(
            self, motion, start_frame, n=n, k=k, refine=refine, exact=exact, parts=parts,
            cache=cache,
        )  # fmt: skip

    def window_distance(
        self,
        motion: Motion,
        start_frame: int | None,
        clip: str,
        frame: int,
        *,
        parts: BodyPartMap | None = None,
        cache: QueryCache | None = None,
    ) -> SearchResult:
        """Exact ``D`` to one library window (:func:`.query.window_distance`)."""
        from reactmocap.search.query import window_distance

        return window_distance(self, motion, start_frame, clip, frame, parts=parts, cache=cache)
