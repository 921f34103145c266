"""The index: self-retrieval, agreement with brute force, weights, persistence, bad input."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from reactmocap.errors import SearchError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_exp, quat_mul
from reactmocap.search import (
    MotionIndex,
    QueryCache,
    QueryStats,
    SearchWeights,
    WindowConfig,
    brute_force,
    get_feature_set,
    prepare_query,
    search_window,
)
from reactmocap.search.config import settings_hash
from reactmocap.search.distance import StanceCost
from reactmocap.search.query import _EMBED_SLACK, DEFAULT_CACHE, _embed_query, distances
from reactmocap.search.types import COARSE_FRAMES, DEFAULT_K


def _wrap(a: float) -> float:
    return float((a + np.pi) % (2 * np.pi) - np.pi)


def _distinctive_windows(index: MotionIndex, clips: dict[str, Motion], n: int, rng, step: int = 1):
    """Random (clip, frame) whose window has no near-duplicate elsewhere in the library (the
    synthetic clips share identical stationary stretches, where any copy is a correct answer)."""
    names = sorted(clips)
    out = []
    tries = 0
    while len(out) < n and tries < 50 * n:
        tries += 1
        name = names[int(rng.integers(len(names)))]
        m = clips[name]
        span = int(np.ceil((index.length - 1) * m.fps / index.window.fps))
        if m.num_frames <= span + step:
            continue
        f = int(rng.integers(0, (m.num_frames - span) // step)) * step
        top = brute_force(index, m, f, n=2)
        if len(top) == 2 and top[0].clip == name and top[1].distance > 0.02:
            out.append((name, f))
    assert len(out) == n, "not enough distinctive windows in the test library"
    return out


def _check_self_retrieval(index: MotionIndex, clips: dict[str, Motion], queries, rng) -> None:
    for name, f in queries:
        m = clips[name]
        yaw = float(rng.uniform(-np.pi, np.pi))
        shift = rng.uniform(-20, 20, 2)
        r = index.query(m.transformed(yaw, shift), f)
        assert (r.clip, r.frame) == (name, f), (name, f, r)
        assert r.distance < 1e-4
        assert abs(_wrap(r.yaw - yaw)) < 1e-4
        np.testing.assert_allclose(r.translation, shift, atol=1e-4)
        # the returned alignment maps the library clip onto the query
        found = m.transformed(r.yaw, r.translation)
        span = round((index.length - 1) * m.fps / index.window.fps) + 1
        qpos = m.transformed(yaw, shift).slice(f, f + span).global_positions()
        np.testing.assert_allclose(found.slice(f, f + span).global_positions(), qpos, atol=1e-4)


def test_self_retrieval_synthetic(synth_index: MotionIndex, synth_clips: dict[str, Motion]) -> None:
    rng = np.random.default_rng(11)
    clips = dict(synth_clips)
    clips.update({n + "_mirror": m.mirror() for n, m in synth_clips.items()})
    # 60 fps clips, 30 Hz index: even frames fall on index frames
    queries = _distinctive_windows(synth_index, clips, 40, rng, step=2)
    assert any(n.endswith("_mirror") for n, _ in queries)
    _check_self_retrieval(synth_index, clips, queries, rng)


def test_self_retrieval_synthetic_at_clip_rate(synth_clips: dict[str, Motion]) -> None:
    index = MotionIndex.build(synth_clips, window=WindowConfig(fps=60.0, duration=0.25))
    # seed 5 draws guard frame 116, between kept starts 110 and 122 whose own D (0.047, 0.051)
    # ranked them out: step_back_1 frame 76 at 0.036 came back before the interval bounds
    rng = np.random.default_rng(5)
    _check_self_retrieval(
        index, synth_clips, _distinctive_windows(index, synth_clips, 15, rng), rng
    )


def test_self_retrieval_real_clips(real_clips: dict[str, Motion]) -> None:
    index = MotionIndex.build(real_clips, window=WindowConfig(fps=30.0), mirror=True)
    clips = dict(real_clips)
    clips.update({n + "_mirror": m.mirror() for n, m in real_clips.items()})
    rng = np.random.default_rng(3)
    _check_self_retrieval(index, clips, _distinctive_windows(index, clips, 40, rng), rng)


def _noisy(m: Motion, rng, sigma: float) -> Motion:
    noise = quat_exp(0.5 * rng.normal(0.0, sigma, (*m.rotations.shape[:-1], 3)))
    return m.replace(rotations=quat_mul(m.rotations, noise))


def _check_against_brute_force(index: MotionIndex, clips: dict[str, Motion], n: int, rng) -> None:
    """Random library windows, moved by a random yaw and shift, half of them also bent by a
    small constant rotation per joint: the index's best D equals brute force over every window
    (a library window's own D is float32 round-off, ~1e-7, as are its exact duplicates')."""
    valid = index.valid_starts()
    for i in range(n):
        s = int(valid[rng.integers(valid.size)])
        ci = int(index.clip_of(np.array([s]))[0])
        name = index.clip_names[ci]
        m = clips[name] if name in clips else clips[name.removesuffix("_mirror")].mirror()
        f = round((s - int(index.clip_offsets[ci])) * m.fps / index.window.fps)
        q = m.transformed(float(rng.uniform(-np.pi, np.pi)), rng.uniform(-20, 20, 2))
        if i % 2:
            bend = quat_exp(0.5 * rng.normal(0.0, 0.01, (q.rotations.shape[1], 3)))
            q = q.replace(rotations=quat_mul(q.rotations, bend[None]))
        qw = prepare_query(index, q, f)
        got = search_window(index, qw)[0][0]
        best = brute_force(index, qw)[0]
        if i % 2 == 0:
            assert got.distance < 1e-5, (name, f, got)
            assert got.distance <= best.distance + 1e-6, (name, f, got, best)
        elif index.length <= COARSE_FRAMES:  # pre-ranked with the exact D: exact
            assert got.distance == pytest.approx(best.distance, rel=0, abs=1e-9), (name, f)
        else:  # pre-ranked on COARSE_FRAMES frames, which can swap windows within 0.1%
            assert got.distance <= best.distance * 1.001 + 1e-9, (name, f, got, best)


@pytest.mark.parametrize("fps,duration", [(30.0, 0.3), (60.0, 0.25), (60.0, 0.5)])
def test_index_against_brute_force(
    synth_clips: dict[str, Motion], fps: float, duration: float
) -> None:
    """Exact windows and near ones are never missed, with the exhaustive pre-ranking
    (L <= COARSE_FRAMES, 30 Hz) and the coarse one (60 Hz, L 16 and 31)."""
    index = MotionIndex.build(
        synth_clips, window=WindowConfig(fps=fps, duration=duration), mirror=True
    )
    _check_against_brute_force(index, synth_clips, 120, np.random.default_rng(7))


def test_index_against_brute_force_real(real_clips: dict[str, Motion]) -> None:
    index = MotionIndex.build(real_clips, window=WindowConfig(fps=30.0), mirror=True)
    _check_against_brute_force(index, real_clips, 80, np.random.default_rng(8))


@pytest.mark.parametrize("stance", [None, 0.2])
def test_agreement_with_brute_force(synth_clips: dict[str, Motion], stance: float | None) -> None:
    """Indexed search vs exact D over *all* windows, 240 perturbed queries. The embedding is
    approximate, so recall is measured: the indexed D must equal the brute-force optimum for
    >= 90% of queries and never exceed it by more than 10%. Exhaustive settings must be exact.
    With a stance-mismatch weight, the feet's contacts are in the embedding (without them the
    KD-tree missed the optimum in 40% of these queries)."""
    rng = np.random.default_rng(2024)
    weights = SearchWeights() if stance is None else SearchWeights(stance_mismatch=stance)
    synth_index = MotionIndex.build(synth_clips, weights)  # small: 1.3k windows
    names = sorted(synth_clips)
    hits, ratios = 0, []
    n = 240
    for i in range(n):
        m = synth_clips[names[i % len(names)]]
        f = int(rng.integers(0, m.num_frames - 20))
        q = _noisy(m.transformed(float(rng.uniform(-3, 3)), rng.uniform(-5, 5, 2)), rng, 0.1)
        best = brute_force(synth_index, q, f)[0]
        got = synth_index.query(q, f)
        assert got.distance >= best.distance - 1e-9  # brute force is the optimum
        hits += got.distance <= best.distance * (1 + 1e-6) + 1e-12
        ratios.append(got.distance / best.distance)
        if i < 20:  # exhaustive: every indexed window and every interval -> exactly brute force
            ex = synth_index.query(q, f, k=synth_index.num_indexed, refine=synth_index.num_indexed)
            assert ex.distance == pytest.approx(best.distance, rel=1e-9, abs=1e-12)
            if (
                synth_index.window_distance(q, f, best.clip, best.index_frame).distance
                < ex.distance - 1e-12
            ):
                pytest.fail("exhaustive search missed the brute-force optimum")  # ties are fine
    recall = hits / n
    assert recall >= 0.9, f"recall@1 {recall:.3f}"
    assert max(ratios) < 1.1, f"worst D ratio {max(ratios):.3f}"


def test_weights_matter(synth_index: MotionIndex, synth_clips: dict[str, Motion]) -> None:
    """Moving one limb body moves D less than moving one trunk body by the same amount; the
    support body counts more than the other foot."""
    m = synth_clips["side_kick"]
    qw = synth_index.prepare_query(m, 20)
    start = np.array([synth_index.clip_offsets[synth_index.clip_index("side_kick")] + 10])
    parts = get_feature_set("paper").parts
    assert distances(synth_index, qw, start)[0][0] < 1e-6

    def moved(part: str, dp=(0.0, 0.0, 0.0), turn: float = 0.0) -> float:
        b = parts.index(part)
        pos = np.array(qw.positions)
        pos[:, b] += np.asarray(dp, dtype=np.float32)
        ori = np.array(qw.orientations)
        q = np.array([np.cos(turn / 2), np.sin(turn / 2), 0, 0], dtype=np.float32)
        ori[:, b] = quat_mul(ori[:, b], q)
        return float(
            distances(synth_index, replace(qw, positions=pos, orientations=ori), start)[0][0]
        )

    for trunk, limb in (("chest", "l_forearm"), ("head", "r_hand"), ("waist", "l_shin")):
        assert moved(limb, dp=(0.05, 0, 0)) < moved(trunk, dp=(0.05, 0, 0))
        assert moved(limb, turn=0.3) < moved(trunk, turn=0.3)
    support = qw.support_part
    assert support in ("l_foot", "r_foot")
    other = "r_foot" if support == "l_foot" else "l_foot"
    assert 4 * moved(other, dp=(0.05, 0, 0)) < moved(support, dp=(0.05, 0, 0))  # 0.25 vs 2.0

    # and at the Motion level: bend the head joint vs the same bend of a wrist
    def bent(joint: str, angle: float) -> float:
        j = m.skeleton.index(joint)
        rot = np.array(m.rotations)
        rot[:, j] = quat_mul(rot[:, j], quat_exp(np.array([angle / 2, 0, 0])))
        return synth_index.window_distance(m.replace(rotations=rot), 20, "side_kick", 10).distance

    head = next(n for n in m.skeleton.names if n.lower().endswith("head"))
    hand = next(
        n for n in m.skeleton.names if n.lower() in ("lefthand", "lhand", "hand_l", "lwrist")
    )
    assert 0 < bent(hand, 0.4) < bent(head, 0.4)


def test_breakdown_and_top_k(synth_index: MotionIndex, synth_clips: dict[str, Motion]) -> None:
    m = _noisy(synth_clips["push"], np.random.default_rng(0), 0.05)
    res = synth_index.top_k(m, 30, n=5)
    assert len(res) == 5
    assert [r.rank for r in res] == list(range(5))
    d = [r.distance for r in res]
    assert d == sorted(d)
    assert res[0].distance == pytest.approx(synth_index.query(m, 30).distance)
    for r in res:
        assert r.breakdown.total == pytest.approx(r.distance, rel=1e-6)
        assert r.breakdown.support_part in ("l_foot", "r_foot")
        assert abs(r.yaw_deg - np.degrees(r.yaw)) < 1e-9
    for i, a in enumerate(res):  # runners-up are distinct windows
        for b in res[:i]:
            assert a.clip != b.clip or abs(a.index_frame - b.index_frame) >= synth_index.length
    d = res[0].to_dict()
    assert {"clip", "frame", "distance", "yaw_deg", "translation", "breakdown"} <= set(d)


def test_save_load_round_trip(
    tmp_path: Path, synth_index: MotionIndex, synth_clips: dict[str, Motion]
) -> None:
    path = synth_index.save(tmp_path / "idx.npz")
    assert [p.name for p in tmp_path.iterdir()] == ["idx.npz"]  # no temporary left behind
    loaded = MotionIndex.load(
        path, clips=synth_clips, weights=SearchWeights(), window=WindowConfig(), mirror=True
    )
    assert loaded.fingerprint == synth_index.fingerprint
    q = synth_clips["sway"].transformed(1.0, (2.0, 3.0))
    a, b = synth_index.top_k(q, 12, n=3), loaded.top_k(q, 12, n=3)
    assert [(r.clip, r.frame, r.distance) for r in a] == [(r.clip, r.frame, r.distance) for r in b]
    for arr in (loaded.positions, loaded.embedding, loaded.kept, synth_index.orientations):
        with pytest.raises(ValueError):
            arr[0] = 0


def test_stale_index_is_rejected_or_rebuilt(tmp_path: Path, synth_clips: dict[str, Motion]) -> None:
    small = {k: synth_clips[k] for k in ("guard", "punch", "push")}
    path = tmp_path / "small.npz"
    MotionIndex.build(small).save(path)
    MotionIndex.load(
        path, clips=small, weights=SearchWeights(), window=WindowConfig(), mirror=False
    )
    with pytest.raises(SearchError, match="weights differ"):
        MotionIndex.load(path, weights=SearchWeights(limb_position=0.3))
    with pytest.raises(SearchError, match="window settings differ"):
        MotionIndex.load(path, window=WindowConfig(duration=0.5))
    with pytest.raises(SearchError, match="mirroring differs"):
        MotionIndex.load(path, mirror=True)
    edited = dict(small)
    g = small["guard"]
    lifted = np.asarray(g.root_positions) + np.array([0, 0, 0.001])
    edited["guard"] = g.replace(root_positions=lifted)
    with pytest.raises(SearchError, match=r"small\.npz.*clips changed"):
        MotionIndex.load(path, clips=edited)
    renamed = {("x_" + k): v for k, v in small.items()}
    with pytest.raises(SearchError, match="clips changed"):
        MotionIndex.load(path, clips=renamed)
    # load_or_build: reuses a matching file, rebuilds a stale one
    before = path.stat().st_mtime_ns
    MotionIndex.load_or_build(path, small)
    assert path.stat().st_mtime_ns == before
    rebuilt = MotionIndex.load_or_build(path, edited, window=WindowConfig(duration=0.2))
    assert path.stat().st_mtime_ns != before
    assert rebuilt.window.duration == 0.2
    MotionIndex.load(path, clips=edited, window=WindowConfig(duration=0.2))


@pytest.mark.parametrize(
    ("content", "match"),
    [
        (b"", "not a readable search index"),
        (b"this is not a zip file at all", "not a readable search index"),
        (None, "no such index file"),
    ],
)
def test_bad_index_file(tmp_path: Path, content: bytes | None, match: str) -> None:
    path = tmp_path / "bad.npz"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(SearchError, match=match) as err:
        MotionIndex.load(path)
    assert "bad.npz" in str(err.value)


def test_corrupt_and_foreign_npz(tmp_path: Path, synth_clips: dict[str, Motion]) -> None:
    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, a=np.zeros(3))
    with pytest.raises(SearchError, match=r"foreign\.npz: not a reactmocap search index"):
        MotionIndex.load(foreign)
    good = MotionIndex.build({"guard": synth_clips["guard"]}).save(tmp_path / "good.npz")
    data = good.read_bytes()
    trunc = tmp_path / "truncated.npz"
    trunc.write_bytes(data[: len(data) // 2])
    with pytest.raises(SearchError, match=r"truncated\.npz"):
        MotionIndex.load(trunc)
    with np.load(good) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["kept"] = arrays["kept"][:-3]
    bad = tmp_path / "inconsistent.npz"
    np.savez(bad, **arrays)
    with pytest.raises(SearchError, match=r"inconsistent\.npz: corrupt search index"):
        MotionIndex.load(bad)


def test_bad_queries(synth_index: MotionIndex, synth_clips: dict[str, Motion]) -> None:
    m = synth_clips["punch"]
    with pytest.raises(SearchError, match="out of range"):
        synth_index.query(m, m.num_frames)
    with pytest.raises(SearchError, match="out of range"):
        synth_index.query(m, -1)
    with pytest.raises(SearchError, match="runs past the end"):
        synth_index.query(m, m.num_frames - 3)
    with pytest.raises(SearchError, match="runs past the end"):
        synth_index.query(m.slice(0, 5), 0)  # window longer than the clip
    with pytest.raises(SearchError, match="no clip named 'nope'"):
        synth_index.clip_index("nope")
    with pytest.raises(SearchError, match="no clip named"):
        synth_index.window_distance(m, 0, "nope", 0)
    with pytest.raises(SearchError, match="long enough"):
        MotionIndex.build({"short": m.slice(0, 8)})
    with pytest.raises(SearchError, match="empty"):
        MotionIndex.build({})


def test_no_leftover_temp_files_on_failed_save(tmp_path: Path, synth_index: MotionIndex) -> None:
    target = tmp_path / "dir_not_file"
    target.mkdir()
    with pytest.raises(SearchError):
        synth_index.save(target)  # cannot replace a directory
    assert [p.name for p in tmp_path.iterdir()] == ["dir_not_file"]
    assert not os.listdir(target)


def test_the_candidates_are_the_k_nearest_and_every_interval_that_may_hold_a_nearer_window(
    synth_index: MotionIndex, synth_clips: dict[str, Motion]
) -> None:
    """The KD candidates, with the widest intervals tested directly and the ball skipped when
    it lies inside the k nearest, are exactly the k nearest and every kept start whose
    ``interval_radius`` lets its interval hold a window as near as the nearest one (all rows
    scanned here)."""
    index = synth_index
    c = DEFAULT_CACHE.constants(index.weights, index.window)
    rng = np.random.default_rng(3)
    names = sorted(synth_clips)
    paths, wide_added = set(), 0
    for _ in range(150):
        m = synth_clips[names[int(rng.integers(len(names)))]]
        span = int(np.ceil((index.length - 1) * m.fps / index.window.fps))
        q = m.transformed(float(rng.uniform(-np.pi, np.pi)), rng.uniform(-5, 5, 2))
        qw = prepare_query(index, q, int(rng.integers(0, m.num_frames - span)))
        e = _embed_query(index, qw, c)
        dk, rows = index.tree.query(e, k=min(DEFAULT_K, index.num_indexed))
        reach = float(dk[0]) + _EMBED_SLACK
        gap = np.linalg.norm(index.embedding - e, axis=1) - index.interval_radius
        added = np.setdiff1d(np.flatnonzero(gap <= reach), rows)
        assert search_window(index, qw)[1].candidates == rows.size + added.size
        paths.add(bool(reach + index.wide_radius + _EMBED_SLACK < dk[-1]))
        wide_added += int(np.isin(added, index.wide_rows).any())
    # both ways (ball skipped and not) were taken, and wide intervals did add candidates
    assert paths == {True, False} and wide_added > 0
    assert 0 < index.wide_rows.size <= 0.02 * index.num_indexed


def test_a_search_returns_its_stats_and_leaves_the_index_alone(
    synth_index: MotionIndex, synth_clips: dict[str, Motion]
) -> None:
    def state() -> dict[str, object]:
        return {k: np.array(v) if isinstance(v, np.ndarray) else repr(v)
                for k, v in vars(synth_index).items() if k != "tree"}  # fmt: skip

    before = state()
    objects = {k: id(v) for k, v in vars(synth_index).items()}
    m = _noisy(synth_clips["push"], np.random.default_rng(1), 0.05)
    qw = prepare_query(synth_index, m, 30)
    results, stats = search_window(synth_index, qw, n=3)
    again, stats2 = search_window(synth_index, qw, n=3)
    assert isinstance(stats, QueryStats)
    assert stats.candidates == min(DEFAULT_K, synth_index.num_indexed)
    assert stats.exact_windows >= 3 and stats.refined_windows >= 0 and stats.seconds > 0
    assert (stats.candidates, stats.exact_windows) == (stats2.candidates, stats2.exact_windows)
    assert [r.to_dict() for r in results] == [r.to_dict() for r in again]
    # every other way in, too
    synth_index.query(m, 30)
    synth_index.top_k(m, 30, n=4)
    synth_index.window_distance(m, 30, "push", 10)
    brute_force(synth_index, qw, n=2)
    assert {k: id(v) for k, v in vars(synth_index).items()} == objects
    after = state()
    assert after.keys() == before.keys()
    for k, v in after.items():
        np.testing.assert_array_equal(v, before[k], err_msg=k)  # type: ignore[arg-type]
    assert not hasattr(synth_index, "last_stats")
    with pytest.raises(dataclasses.FrozenInstanceError):
        synth_index.kept = synth_index.kept  # type: ignore[misc]


def test_an_explicit_query_cache(synth_index: MotionIndex, synth_clips: dict[str, Motion]) -> None:
    m = synth_clips["side_kick"].transformed(0.5, (1.0, 2.0))
    cache = QueryCache()
    assert synth_index.query(m, 12, cache=cache) == synth_index.query(m, 12)
    fs = synth_index.feature_set
    # keyed by content: an equal skeleton (another object) reuses the calibration
    twin = replace(m.skeleton)
    assert twin is not m.skeleton
    assert cache.calibration(twin, fs, None) is cache.calibration(m.skeleton, fs, None)
    assert cache.constants(synth_index.weights, synth_index.window) is cache.constants(
        synth_index.weights, synth_index.window
    )
    cache.clear()
    assert synth_index.top_k(m, 12, n=2, cache=cache) == synth_index.top_k(m, 12, n=2)


def test_a_stance_mismatch_costs_each_foot_whose_contact_differs(
    synth_clips: dict[str, Motion],
) -> None:
    """``stance_mismatch`` adds its weight to ``D`` once per foot planted in one window and not
    in the other (issue 15: a continuation on the other foot drags the feet in the blend)."""
    w = 0.7
    off = MotionIndex.build(synth_clips, SearchWeights(stance_mismatch=0.0), WindowConfig())
    on = MotionIndex.build(synth_clips, SearchWeights(stance_mismatch=w), WindowConfig())
    m = synth_clips["side_kick"]  # index frame 20: the right foot kicks, the left is planted

    def starts(index: MotionIndex, clip: str, frames: list[int]) -> np.ndarray:
        return np.asarray(frames, dtype=np.int64) + index.clip_offsets[index.clip_index(clip)]

    def extra(clip: str, frames: list[int]) -> np.ndarray:
        d_on, br = distances(on, prepare_query(on, m, 40), starts(on, clip, frames), breakdown=True)
        d_off, _ = distances(off, prepare_query(off, m, 40), starts(off, clip, frames))
        assert br is not None
        np.testing.assert_allclose(br.sum(axis=1), d_on, rtol=1e-6)  # the breakdown holds it
        return d_on - d_off

    ci = on.clip_index("guard")
    guard = list(range(0, int(np.diff(on.clip_offsets)[ci]) - on.length, 7))
    np.testing.assert_allclose(extra("guard", guard), w, atol=1e-5)  # both feet planted there
    np.testing.assert_allclose(extra("side_kick", [20, 25]), 0.0, atol=1e-5)  # the same stance
    np.testing.assert_allclose(extra("side_kick", [5]), 2 * w, atol=1e-5)  # left up, right down
    # the index keeps a start wherever a foot lands or lifts (each kept start's contacts hold
    # through its interval) and holds the contacts beside the PCA dimensions
    stance = StanceCost.of(on.feature_set, on.weights, on.window.fps)
    assert stance is not None
    planted = stance.frame_contacts(on.positions)
    v = on.valid_starts()
    v = v[v > 0]
    lands = v[np.any(planted[v] != planted[v - 1], axis=1) & (on.clip_of(v) == on.clip_of(v - 1))]
    assert lands.size and np.isin(lands, on.kept).all()
    np.testing.assert_array_equal(on.embedding[:, -2:], stance.columns(planted[on.kept]))
    # with the term off, indexes saved before it existed keep their settings hash
    no_term = SearchWeights(stance_mismatch=0.0, contact_height=0.3)
    assert settings_hash(no_term, WindowConfig(), False) == off.settings_hash
    assert on.settings_hash != off.settings_hash
