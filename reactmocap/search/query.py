"""Answering queries with a :class:`~reactmocap.search.index.MotionIndex`: cut and localise the
query window, take KD-tree candidates, pre-rank and refine them with ``D``, and return the best
windows with the alignment onto the query. A search returns its :class:`QueryStats` and leaves the
index untouched; what queries reuse (calibrations, constants) sits in an explicit
:class:`QueryCache`."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from reactmocap.errors import SearchError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import wrap_angle
from reactmocap.search.build import (
    EmbeddingWeights,
    embedding_weights,
    prerank_frames,
    rate_step,
)
from reactmocap.search.config import SearchWeights, WindowConfig
from reactmocap.search.distance import (
    CHEAP_ANGLE_ERROR,
    QueryWindow,
    StanceCost,
    body_weights,
    embed_local,
    group_matrix,
    localize,
    select_support,
    window_distances,
)
from reactmocap.search.features import (
    FeatureSet,
    SkeletonCalibration,
    calibrate,
    features_from_arrays,
    get_feature_set,
    skeleton_key,
)
from reactmocap.search.index import MotionIndex
from reactmocap.search.types import (
    COARSE_FRAMES,
    DEFAULT_EXACT,
    DEFAULT_K,
    DEFAULT_REFINE,
    F32,
    F64,
    I64,
    Breakdown,
    QueryStats,
    SearchResult,
)

__all__ = [
    "DEFAULT_CACHE",
    "QueryCache",
    "QueryConstants",
    "brute_force",
    "distances",
    "prepare_query",
    "query",
    "search_window",
    "top_k",
    "window_distance",
]

#: float32 embeddings of one window computed in different batches differ by about 1e-6
_EMBED_SLACK = 1e-4

_K = TypeVar("_K")
_V = TypeVar("_V")


@dataclass(frozen=True)
class QueryConstants:
    """What every query of an index with these settings shares."""

    feature_set: FeatureSet
    embedding: EmbeddingWeights
    window_weights: F64  # (L,)
    coarse_offsets: I64  # window frames of the coarse pre-ranking
    coarse_weights: F64  # their aggregated window weights
    wp: F64  # (P, P): row s = position weight per part when part s is the support body
    wq: F64  # (P, P): the same for orientation
    groups: F64  # (P, P, 3): row s = group_matrix with support s
    stance: StanceCost | None  # the stance-mismatch term, None when its weight is 0
    #: whether the pre-ranking uses the coarse frames (and the cheaper arithmetic)
    coarse: bool

    @classmethod
    def of(cls, weights: SearchWeights, window: WindowConfig) -> QueryConstants:
        fs = get_feature_set(weights.feature_set)
        ww = weights.window_weights(window.length)
        coarse, coarse_weights = prerank_frames(weights, window)
        per_support = [body_weights(fs, weights, s) for s in range(len(fs.parts))]
        c = cls(
            feature_set=fs,
            embedding=embedding_weights(weights, window),
            window_weights=ww,
            coarse_offsets=coarse,
            coarse_weights=coarse_weights,
            wp=np.stack([w[0] for w in per_support]),
            wq=np.stack([w[1] for w in per_support]),
            groups=np.stack([group_matrix(fs, s) for s in range(len(fs.parts))]),
            stance=StanceCost.of(fs, weights, window.fps),
            coarse=window.length > COARSE_FRAMES,
        )
        shared = (c.window_weights, c.coarse_offsets, c.coarse_weights, c.wp, c.wq, c.groups)
        for a in (*c.embedding, *shared):
            a.setflags(write=False)  # every query of the cache shares them
        return c


def _put(table: dict[_K, _V], key: _K, value: _V, limit: int) -> _V:
    if len(table) >= limit:
        table.clear()
    table[key] = value
    return value


class QueryCache:
    """Skeleton calibrations and :class:`QueryConstants`, reused across queries.

    Every query function takes one as ``cache=``; without it they share :data:`DEFAULT_CACHE`.
    Keys are contents (skeleton arrays, body-part map, settings), never object ids, so an entry
    cannot go stale; each table is emptied when it reaches ``max_entries``.
    """

    def __init__(self, max_entries: int = 64) -> None:
        self.max_entries = max_entries
        self._calibrations: dict[tuple[object, ...], SkeletonCalibration] = {}
        self._constants: dict[tuple[SearchWeights, WindowConfig], QueryConstants] = {}

    def calibration(
        self, skeleton: Skeleton, feature_set: FeatureSet, parts: BodyPartMap | None
    ) -> SkeletonCalibration:
        pkey = None if parts is None else tuple(sorted(parts.joints.items()))
        key = (skeleton_key(skeleton), feature_set.name, pkey)
        hit = self._calibrations.get(key)
        if hit is not None:
            return hit
        cal = calibrate(skeleton, feature_set, parts)
        return _put(self._calibrations, key, cal, self.max_entries)

    def constants(self, weights: SearchWeights, window: WindowConfig) -> QueryConstants:
        hit = self._constants.get((weights, window))
        if hit is not None:
            return hit
        c = QueryConstants.of(weights, window)
        return _put(self._constants, (weights, window), c, self.max_entries)

    def clear(self) -> None:
        self._calibrations.clear()
        self._constants.clear()


#: the cache of queries that are not given one
DEFAULT_CACHE = QueryCache()


def prepare_query(
    index: MotionIndex,
    motion: Motion,
    start_frame: int | None = None,
    *,
    parts: BodyPartMap | None = None,
    cache: QueryCache | None = None,
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
    L = index.length
    fps = index.window.fps
    step = rate_step(motion.fps, fps)
    t0 = f0 / motion.fps
    span = (L - 1) / fps
    if step is not None:
        fits = f0 + (L - 1) * step <= motion.num_frames - 1
    else:
        fits = t0 + span <= motion.duration + 1e-9
    if not fits:
        raise SearchError(
            f"the {L}-frame search window ({span:.3f} s at {fps:g} fps) starting at "
            f"frame {f0} ({t0:.3f} s) runs past the end of {motion.name or 'the query'} "
            f"({motion.duration:.3f} s, {motion.num_frames} frames)"
        )
    if step is not None:
        sl = slice(f0, f0 + (L - 1) * step + 1, step)
        root, rot = motion.root_positions[sl], motion.rotations[sl]
        tr = None if motion.translations is None else motion.translations[sl]
    else:
        sub = motion.sample(t0 + np.arange(L) / fps)
        root, rot, tr = sub.root_positions, sub.rotations, sub.translations
    fs = index.feature_set
    calib = (cache or DEFAULT_CACHE).calibration(motion.skeleton, fs, parts)
    ff = features_from_arrays(motion.skeleton, root, rot, tr, calib, com_frames=1)
    h0 = float(ff.heading[0])
    o0 = ff.origin[0]
    lp, lq = localize(ff.positions[None], ff.orientations[None], np.array([h0]), o0[None])
    sup = select_support(ff.positions[0], ff.com[0], fs, index.weights)
    return QueryWindow(
        positions=lp[0].astype(np.float32),
        orientations=lq[0].astype(np.float32),
        heading=h0,
        origin=np.asarray(o0, dtype=np.float64),
        support=sup,
        support_part=fs.parts[sup],
        com=ff.com[0],
    )


def _distances(
    index: MotionIndex,
    qw: QueryWindow,
    c: QueryConstants,
    starts: I64,
    breakdown: bool = False,
    coarse: bool = False,
    precise: bool | None = None,
) -> tuple[F64, F64 | None]:
    s = qw.support
    return window_distances(
        index.positions, index.orientations, index.heading, index.origin, starts, qw,
        c.coarse_weights if coarse else c.window_weights, c.wp[s], c.wq[s],
        c.groups[s] if breakdown else None, c.coarse_offsets if coarse else None,
        precise=(not coarse) if precise is None else precise, stance=c.stance,
    )  # fmt: skip


def distances(
    index: MotionIndex,
    qw: QueryWindow,
    starts: I64,
    *,
    breakdown: bool = False,
    coarse: bool = False,
    precise: bool | None = None,
    cache: QueryCache | None = None,
) -> tuple[F64, F64 | None]:
    """``D`` between a prepared query and the index windows starting at global frames
    ``starts``: ``(D (C,), breakdown (C, 6) or None)``. ``coarse``: on about
    ``COARSE_FRAMES`` window frames (pre-ranking); ``precise=False``: the cheaper, slightly less
    precise arithmetic (default: precise unless coarse)."""
    c = (cache or DEFAULT_CACHE).constants(index.weights, index.window)
    return _distances(index, qw, c, starts, breakdown, coarse, precise)


def _embed_query(index: MotionIndex, qw: QueryWindow, c: QueryConstants) -> F32:
    ew = c.embedding
    e = embed_local(
        qw.positions[None, ew.offsets], qw.orientations[None, ew.offsets], ew.frames, ew.wp, ew.wq
    )
    out = ((e - index.pca_mean) @ index.pca_components)[0]
    return out if c.stance is None else np.concatenate([out, c.stance.query_columns(qw)])


def search_window(
    index: MotionIndex,
    qw: QueryWindow,
    *,
    n: int = 1,
    k: int = DEFAULT_K,
    refine: int = DEFAULT_REFINE,
    exact: int = DEFAULT_EXACT,
    cache: QueryCache | None = None,
) -> tuple[list[SearchResult], QueryStats]:
    """Search with a prepared query window; returns the ``n`` best distinct windows and what the
    search did.

    1. ``k`` nearest indexed (unique-frame) windows in the PCA embedding (KD-tree), and every
       kept start whose ``interval_radius`` lets its interval hold a window as near as the
       nearest kept one;
    2. pre-rank them with ``D`` including the query's support weight: on about
       ``COARSE_FRAMES`` window frames (weights aggregated) when ``L > COARSE_FRAMES``,
       otherwise exactly;
    3. every window in the unique-frame intervals of the best ``refine`` and in those ending
       at them is tested too (the paper's local refinement), pre-ranked the same way, then
       that of every other candidate whose ``D`` minus ``interval_bound`` is not above the
       ``n``-th best so far;
    4. exact ``D`` with its breakdown for the best ``max(exact, n)`` of all of these; the ``n``
       best distinct ones are returned.

    A library window (any yaw and shift) is always found, at ``D`` ~0: its interval is among
    the candidates of step 1 and is refined in step 3. With ``L <= COARSE_FRAMES`` the best
    window of every candidate's interval is found.

    ``k = num_indexed`` and ``refine = num_indexed`` with ``L <= COARSE_FRAMES`` is an
    exhaustive search (equal to :func:`brute_force`).
    """
    t0 = time.perf_counter()
    if n < 1 or k < 1 or refine < 0 or exact < 1:
        raise SearchError(
            "need n >= 1, k >= 1, refine >= 0, exact >= 1 "
            f"(got n={n}, k={k}, refine={refine}, exact={exact})"
        )
    c = (cache or DEFAULT_CACHE).constants(index.weights, index.window)
    e = _embed_query(index, qw, c)
    k = min(k, index.num_indexed)
    dk, rows = index.tree.query(e, k=k)
    dk, rows = np.atleast_1d(dk), np.atleast_1d(np.asarray(rows, dtype=np.int64))
    # every kept start whose interval can hold a window as near in the embedding as the nearest
    # kept one (its interval_radius): a library window's own interval is always among them
    reach = float(dk[0]) + _EMBED_SLACK
    # the few wide intervals directly, the rest by their KD ball (float32 norms: a slack more)
    near = index.wide_rows
    ball = reach + index.wide_radius + _EMBED_SLACK
    if ball >= float(dk[-1]):
        inside = index.tree.query_ball_point(e, ball)
        near = np.union1d(np.asarray(inside, dtype=np.int64), near)
    # else the ball lies inside the k nearest, which are candidates anyway
    if near.size:
        gap = np.linalg.norm(index.embedding[near] - e, axis=1) - index.interval_radius[near]
        rows = np.union1d(rows[rows < index.num_indexed], near[gap <= reach])
    cand = index.kept[rows]
    coarse = c.coarse
    d, _ = _distances(index, qw, c, cand, coarse=coarse)
    order = np.argsort(d, kind="stable")
    m = max(exact, n)
    # the intervals of the best `refine` candidates (the paper's local refinement), then every
    # other one whose bound lets it hold a window better than the n-th best so far: a window's
    # D is at least its kept start's minus interval_bound (docs/design.md, Search)
    best = rows[order[:refine]]
    # around the best: their intervals and those that end at them (the starts before them)
    before = best[best > 0] - 1
    before = before[index.interval_hi[before] == index.kept[before + 1] - 1]
    pool, pd = _refine(index, qw, c, np.union1d(best, before), cand, d, coarse)
    tau = float(np.partition(pd, n - 1)[n - 1]) if pd.size >= n else np.inf
    # the cheaper arithmetic's error, on the kept start's side and the window's
    slack = (2 * _cheap_error(c, qw) if coarse else 0.0) + 1e-9
    rest = order[refine:]
    low = rest[d[rest] - index.interval_bound[rows[rest], qw.support] <= tau + slack]
    if low.size:
        pool, pd = _refine(index, qw, c, rows[low], pool, pd, coarse)
    extra = pool[cand.size :]
    starts = pool[np.argsort(pd, kind="stable")[:m]]
    dists, br = _distances(index, qw, c, starts, breakdown=True)
    if n > 1:
        # runners-up must be distinct windows: widen the exact set until n are found
        while _pick(index, starts, dists, n).size < n:
            if k < index.num_indexed and np.all(np.isin(cand, starts)):
                k = min(2 * k, index.num_indexed)
                _, rows = index.tree.query(e, k=k)
                cand = index.kept[np.asarray(rows, dtype=np.int64)]
            more = cand[~np.isin(cand, starts)][: 8 * n]  # nearest in the embedding first
            if more.size == 0:
                break
            d2, br2 = _distances(index, qw, c, more, breakdown=True)
            assert br is not None and br2 is not None
            starts = np.concatenate([starts, more])
            dists = np.concatenate([dists, d2])
            br = np.concatenate([br, br2])
    results = _results(index, qw, c, starts, dists, n, br)
    stats = QueryStats(
        candidates=int(cand.size),
        refined_windows=int(extra.size),
        exact_windows=int(starts.size),
        seconds=time.perf_counter() - t0,
    )
    return results, stats


def _cheap_error(c: QueryConstants, qw: QueryWindow) -> float:
    """How far a ``D`` from the cheaper arithmetic may be off the precise one."""
    return CHEAP_ANGLE_ERROR * float(c.wq[qw.support].sum())


def _refine(
    index: MotionIndex,
    qw: QueryWindow,
    c: QueryConstants,
    rows: I64,
    pool: I64,
    pd: F64,
    coarse: bool,
) -> tuple[I64, F64]:
    """``pool`` and its pre-ranking ``D`` with the windows of the intervals of kept starts
    ``rows`` added."""
    size = index.interval_hi[rows] - index.interval_lo[rows] + 1
    first = np.cumsum(size) - size
    spans = np.repeat(index.interval_lo[rows] - first, size) + np.arange(int(size.sum()))
    new = np.setdiff1d(spans, pool)
    if new.size == 0:
        return pool, pd
    dn, _ = _distances(index, qw, c, new, coarse=coarse)
    return np.concatenate([pool, new]), np.concatenate([pd, dn])


def _pick(index: MotionIndex, starts: I64, dists: F64, n: int) -> I64:
    """Positions (into ``starts``) of the ``n`` best windows, at least one window length apart
    within a clip."""
    order = np.argsort(dists, kind="stable")
    if n == 1:
        return order[:1]
    clips = index.clip_of(starts)
    picked: list[int] = []
    for i in order:
        s, ci = int(starts[i]), int(clips[i])
        if all(abs(s - int(starts[p])) >= index.length or ci != int(clips[p]) for p in picked):
            picked.append(int(i))
            if len(picked) == n:
                break
    return np.asarray(picked, dtype=np.int64)


def _results(
    index: MotionIndex,
    qw: QueryWindow,
    c: QueryConstants,
    starts: I64,
    dists: F64,
    n: int,
    breakdown: F64 | None = None,
) -> list[SearchResult]:
    sel = _pick(index, starts, dists, n)
    chosen = starts[sel]
    if breakdown is None:
        d, br = _distances(index, qw, c, chosen, breakdown=True)
    else:
        d, br = dists[sel], breakdown[sel]
    assert br is not None
    out = []
    for rank, (s, ci, dist, row) in enumerate(zip(chosen, index.clip_of(chosen), d, br)):
        fi = int(s - index.clip_offsets[ci])
        t = fi / index.window.fps
        yaw = float(wrap_angle(qw.heading - float(index.heading[s])))
        cy, sy = np.cos(yaw), np.sin(yaw)
        ox, oy = index.origin[s]
        tx = float(qw.origin[0] - (cy * ox - sy * oy))
        ty = float(qw.origin[1] - (sy * ox + cy * oy))
        out.append(
            SearchResult(
                clip=index.clip_names[ci],
                frame=round(t * index.clip_fps[ci]),
                index_frame=fi,
                time=t,
                distance=float(dist),
                yaw=yaw,
                translation=(tx, ty),
                breakdown=Breakdown.from_row(row, qw.support_part),
                rank=rank,
            )
        )
    return out


def query(
    index: MotionIndex,
    motion: Motion,
    start_frame: int | None = None,
    *,
    k: int = DEFAULT_K,
    refine: int = DEFAULT_REFINE,
    exact: int = DEFAULT_EXACT,
    parts: BodyPartMap | None = None,
    cache: QueryCache | None = None,
) -> SearchResult:
    """Best library window for the window of ``motion`` starting at ``start_frame`` (a frame
    of ``motion`` at its own rate). :func:`search_window` explains ``k``, ``refine``,
    ``exact``."""
    qw = prepare_query(index, motion, start_frame, parts=parts, cache=cache)
    return search_window(index, qw, n=1, k=k, refine=refine, exact=exact, cache=cache)[0][0]


def top_k(
    index: MotionIndex,
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
    """The ``n`` best distinct windows (at least a window length apart within a clip), each
    with its breakdown, so a user can see why the winner won."""
    qw = prepare_query(index, motion, start_frame, parts=parts, cache=cache)
    return search_window(
        index, qw, n=n, k=max(k, n), refine=max(refine, min(n, 8)), exact=exact, cache=cache
    )[0]


def window_distance(
    index: MotionIndex,
    motion: Motion,
    start_frame: int | None,
    clip: str,
    frame: int,
    *,
    parts: BodyPartMap | None = None,
    cache: QueryCache | None = None,
) -> SearchResult:
    """Exact ``D`` (with breakdown and alignment) between a query window and one library
    window, ``frame`` counted at the index rate."""
    qw = prepare_query(index, motion, start_frame, parts=parts, cache=cache)
    ci = index.clip_index(clip)
    a, b = int(index.clip_offsets[ci]), int(index.clip_offsets[ci + 1])
    if not 0 <= frame <= b - a - index.length:
        raise SearchError(
            f"index frame {frame} has no full window in clip {clip!r} ({b - a} frames)"
        )
    s = np.array([a + frame], dtype=np.int64)
    c = (cache or DEFAULT_CACHE).constants(index.weights, index.window)
    d, br = _distances(index, qw, c, s, breakdown=True)
    return _results(index, qw, c, s, d, 1, br)[0]


def brute_force(
    index: MotionIndex,
    motion: Motion | QueryWindow,
    start_frame: int | None = None,
    *,
    n: int = 1,
    parts: BodyPartMap | None = None,
    cache: QueryCache | None = None,
) -> list[SearchResult]:
    """Exact ``D`` against *every* valid window of the index (no KD-tree, no unique-frame
    reduction): the ground truth for tests and benchmarks."""
    qw = (
        motion
        if isinstance(motion, QueryWindow)
        else prepare_query(index, motion, start_frame, parts=parts, cache=cache)
    )
    c = (cache or DEFAULT_CACHE).constants(index.weights, index.window)
    valid = index.valid_starts()
    d = np.empty(valid.size)
    chunk = max(256, 2_000_000 // max(1, index.length * len(index.feature_set.parts)))
    for i in range(0, valid.size, chunk):
        # all frames, cheaper arithmetic (same D to ~1e-5); the shortlist is re-scored precisely
        d[i : i + chunk], _ = _distances(index, qw, c, valid[i : i + chunk], precise=False)
    m = min(d.size, max(50 * n, 64))
    if m < d.size:
        # and every window the cheaper arithmetic may have put behind the m-th
        dm = np.partition(d, m - 1)[m - 1]
        short = np.flatnonzero(d <= dm + 2 * _cheap_error(c, qw))
    else:
        short = np.arange(d.size)
    ds, br = _distances(index, qw, c, valid[short], breakdown=True)
    return _results(index, qw, c, valid[short], ds, n, br)
