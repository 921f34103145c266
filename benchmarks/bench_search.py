"""Motion-search benchmark: build time, query time (median / p95, refinement included), memory,
recall against brute force and the brute-force time for the same queries.

Library: every shared real clip (../shared/mocap) plus the synthetic clips, resampled to 120 fps,
mirrored, and repeated with small smooth perturbations until it holds >= 100k frames (and a 1M
variant). Queries: library windows moved by a random yaw/shift with rotation noise added (so they
are not verbatim library windows), plus held-out perturbed copies.

    .venv/bin/python benchmarks/bench_search.py                # 100k + 1M, 120 fps index
    .venv/bin/python benchmarks/bench_search.py --sizes 100000 --queries 200
    .venv/bin/python benchmarks/bench_search.py --window-study  # which window length works best
"""

from __future__ import annotations

import argparse
import gc
import resource
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from reactmocap.library.motion import Motion  # noqa: E402
from reactmocap.rotations import quat_exp, quat_mul  # noqa: E402
from reactmocap.search import (  # noqa: E402
    MotionIndex,
    SearchWeights,
    WindowConfig,
    brute_force,
    prepare_query,
    search_window,
)

SHARED = REPO.parent / "shared" / "mocap"


def rss_mb() -> float:
    """Peak resident memory of this process so far (MB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def current_rss_mb() -> float:
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def load_base_clips(fps: float) -> tuple[dict[str, Motion], str]:
    clips: dict[str, Motion] = {}
    notes = []
    try:
        from reactmocap.library.clip_library import load_library

        for d in sorted(p for p in SHARED.glob("*") if p.is_dir()):
            lib = load_library(d)
            for name, m in lib.clips.items():
                clips[f"{d.name}/{name}"] = m
            notes.append(f"{len(lib.clips)} real clips from {d.name}")
    except Exception as exc:
        notes.append(f"real clips unavailable ({type(exc).__name__}: {exc})")
    from reactmocap.library.synth import synthetic_clips

    syn = synthetic_clips(60.0)
    clips.update({f"synthetic/{k}": v for k, v in syn.items()})
    notes.append(f"{len(syn)} synthetic clips")
    out = {k: (m if abs(m.fps - fps) < 1e-9 else m.resample(fps)) for k, m in clips.items()}
    mirrored = {k + "_mirror": m.mirror().replace(name=k + "_mirror") for k, m in out.items()}
    out.update(mirrored)
    return out, ", ".join(notes)


def smooth_noise(
    rng: np.random.Generator, shape: tuple[int, ...], sigma: float, knots: int = 8
) -> np.ndarray:
    """Low-frequency noise along axis 0 (piecewise-linear through random knots)."""
    t = shape[0]
    n = max(2, t // knots + 2)
    k = rng.normal(0.0, sigma, (n, *shape[1:]))
    x = np.linspace(0, n - 1, t)
    i0 = np.floor(x).astype(int).clip(0, n - 2)
    a = (x - i0).reshape(-1, *([1] * (len(shape) - 1)))
    return k[i0] * (1 - a) + k[i0 + 1] * a


def perturb(m: Motion, rng: np.random.Generator, sigma: float) -> Motion:
    noise = smooth_noise(rng, (*m.rotations.shape[:-1], 3), sigma, knots=int(m.fps * 0.25) or 1)
    return m.replace(rotations=quat_mul(m.rotations, quat_exp(0.5 * noise)))


def build_library(
    base: dict[str, Motion], frames: int, rng: np.random.Generator
) -> dict[str, Motion]:
    lib = dict(base)
    total = sum(m.num_frames for m in lib.values())
    copy = 1
    while total < frames:
        for k, m in base.items():
            if total >= frames:
                break
            lib[f"{k}#p{copy}"] = perturb(m, rng, 0.03)  # ~1.7 deg smooth noise per joint
            total += m.num_frames
        copy += 1
    return lib


def make_queries(
    lib: dict[str, Motion], n: int, length: int, rng: np.random.Generator, sigma: float
):
    names = [k for k, m in lib.items() if m.num_frames > length + 2]
    out = []
    for _ in range(n):
        name = names[int(rng.integers(len(names)))]
        m = lib[name]
        f = int(rng.integers(0, m.num_frames - length))
        seg = m.slice(f, f + length)
        seg = perturb(seg, rng, sigma) if sigma > 0 else seg
        seg = seg.transformed(float(rng.uniform(-np.pi, np.pi)), rng.uniform(-10, 10, 2))
        out.append((name, f, seg))
    return out


def pct(a: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(a), q))


def run_size(
    base: dict[str, Motion], frames: int, args: argparse.Namespace, rng: np.random.Generator
) -> dict[str, float]:
    lib = build_library(base, frames, rng)
    nframes = sum(m.num_frames for m in lib.values())
    window = WindowConfig(fps=args.fps, duration=args.duration, pca_dims=args.pca_dims)
    weights = SearchWeights()
    gc.collect()
    mem0 = current_rss_mb()
    t = time.perf_counter()
    index = MotionIndex.build(lib, weights, window)
    build_s = time.perf_counter() - t
    mem1 = current_rss_mb()
    L = window.length
    span = round((L - 1) * 120.0 / window.fps) + 1  # query frames at the library's 120 fps
    queries = make_queries(lib, args.queries, span, rng, args.noise)
    del lib
    gc.collect()
    # warm-up
    index.query(queries[0][2], 0, k=args.k, refine=args.refine)
    q_ms, prep_ms, search_ms, cpu_ms, refined, exact_d = [], [], [], [], [], []
    found = []
    for _, _, seg in queries:
        c0 = time.process_time()
        t0 = time.perf_counter()
        qw = prepare_query(index, seg, 0)
        t1 = time.perf_counter()
        res, stats = search_window(index, qw, k=args.k, refine=args.refine, exact=args.exact)
        t2 = time.perf_counter()
        r = res[0]
        refined.append(stats.refined_windows)
        exact_d.append(stats.exact_windows)
        cpu_ms.append((time.process_time() - c0) * 1e3)
        q_ms.append((t2 - t0) * 1e3)
        prep_ms.append((t1 - t0) * 1e3)
        search_ms.append((t2 - t1) * 1e3)
        found.append(r)
    nb = min(args.brute if nframes <= 200_000 else args.brute_large, len(queries))
    bf_ms, exact, ratios = [], [], []
    for (_, _, seg), r in zip(queries[:nb], found[:nb]):
        t0 = time.perf_counter()
        b = brute_force(index, seg, 0)[0]
        bf_ms.append((time.perf_counter() - t0) * 1e3)
        exact.append(r.distance <= b.distance * (1 + 1e-5) + 1e-9)
        ratios.append(r.distance / max(b.distance, 1e-12))
    out = {
        "frames": nframes,
        "windows": index.num_windows,
        "indexed": index.num_indexed,
        "L": L,
        "build_s": build_s,
        "query_median_ms": pct(q_ms, 50),
        "query_p95_ms": pct(q_ms, 95),
        "query_cpu_median_ms": pct(cpu_ms, 50),
        "query_cpu_p95_ms": pct(cpu_ms, 95),
        "prepare_median_ms": pct(prep_ms, 50),
        "search_median_ms": pct(search_ms, 50),
        "search_p95_ms": pct(search_ms, 95),
        "refined_median": pct(refined, 50),
        "exact_median": pct(exact_d, 50),
        "recall_at_1": float(np.mean(exact)),
        "d_ratio_p95": pct(ratios, 95),
        "d_ratio_max": float(np.max(ratios)),
        "brute_median_ms": pct(bf_ms, 50),
        "brute_queries": nb,
        "speedup": pct(bf_ms, 50) / pct(q_ms, 50),
        "index_mb": index.nbytes() / 2**20,
        "rss_build_delta_mb": mem1 - mem0,
        "peak_rss_mb": rss_mb(),
        "pca_variance": float(index.info.get("pca_explained_variance", 1.0)),
    }
    return out


def window_study(base: dict[str, Motion], args: argparse.Namespace) -> None:
    """Self-retrieval robustness vs window length. Queries: base-library windows (random yaw and
    shift) with smooth rotation noise on every joint. A hit is a window equivalent to the source:
    the same clip within one frame, or any window whose exact D to the *clean* source window is
    below 0.02 (stationary stretches and mirrored/synthetic duplicates have many equal windows).
    ``D_true`` is the median exact D between the clean source window and the returned window:
    how far the noise pushed the answer from the truth (D is a per-frame average, so it is
    comparable across window lengths)."""
    print("\nwindow length study (index at 30 fps, library = base clips with mirrors)")
    print(f"{'duration':>8} {'L':>3} {'noise':>6} {'hit':>6} {'D_true':>8} {'query ms':>8}")
    base30 = {k: m.resample(30.0) for k, m in base.items()}
    for dur in (0.1, 0.2, 0.3, 0.5, 0.8):
        window = WindowConfig(fps=30.0, duration=dur)
        index = MotionIndex.build(base30, SearchWeights(), window)
        for sigma in (0.03, 0.1):
            qrng = np.random.default_rng(7)
            hits, times, dtrue = 0, [], []
            names = [k for k, m in base30.items() if m.num_frames > 26]
            for _ in range(args.study_queries):
                name = names[int(qrng.integers(len(names)))]
                m = base30[name]
                f = int(qrng.integers(0, m.num_frames - 25))
                seg = perturb(m.slice(f, f + window.length), qrng, sigma)
                seg = seg.transformed(float(qrng.uniform(-np.pi, np.pi)), qrng.uniform(-5, 5, 2))
                t0 = time.perf_counter()
                r = index.query(seg, 0)
                times.append((time.perf_counter() - t0) * 1e3)
                d = index.window_distance(m.slice(f, f + window.length), 0, r.clip, r.index_frame)
                dtrue.append(d.distance)
                hits += (r.clip == name and abs(r.index_frame - f) <= 1) or d.distance < 0.02
            print(
                f"{dur:>8.2f} {window.length:>3d} {sigma:>6.2f} {hits / args.study_queries:>6.2f} "
                f"{np.median(dtrue):>8.4f} {np.median(times):>8.2f}"
            )


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    ap.add_argument(
        "--fps", type=float, default=120.0, help="index rate (default: the library's 120)"
    )
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--pca-dims", type=int, default=32)
    ap.add_argument("--queries", type=int, default=300)
    ap.add_argument("--brute", type=int, default=50, help="queries also answered by brute force")
    ap.add_argument(
        "--brute-large", type=int, default=12, help="the same for libraries > 200k frames"
    )
    ap.add_argument("--k", type=int, default=48)
    ap.add_argument("--refine", type=int, default=3)
    ap.add_argument("--exact", type=int, default=6)
    ap.add_argument("--noise", type=float, default=0.05, help="query rotation noise (rad)")
    ap.add_argument("--window-study", action="store_true")
    ap.add_argument("--study-queries", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    t = time.perf_counter()
    base, note = load_base_clips(120.0)
    nbase = sum(m.num_frames for m in base.values())
    print(
        f"base library: {note}; {len(base)} clips with mirrors, {nbase} frames at 120 fps "
        f"(loaded in {time.perf_counter() - t:.1f} s)"
    )
    if args.window_study:
        window_study(base, args)
        return
    for size in args.sizes:
        r = run_size(base, size, args, rng)
        print(
            f"\n== library {r['frames']} frames at 120 fps, index at {args.fps:g} fps, window L={r['L']} "
            f"({args.duration:g} s), {r['windows']} windows, {r['indexed']} indexed"
        )
        print(f"build              {r['build_s']:.2f} s")
        print(
            f"query (total)      median {r['query_median_ms']:.2f} ms, "
            f"p95 {r['query_p95_ms']:.2f} ms"
        )
        print(
            f"query CPU time     median {r['query_cpu_median_ms']:.2f} ms, "
            f"p95 {r['query_cpu_p95_ms']:.2f} ms  (wall time suffers from other processes)"
        )
        print(f"  features         median {r['prepare_median_ms']:.2f} ms")
        print(
            f"  search+refine    median {r['search_median_ms']:.2f} ms, "
            f"p95 {r['search_p95_ms']:.2f} ms; "
            f"median {r['refined_median']:.0f} refinement windows, exact D on {r['exact_median']:.0f}"
        )
        print(
            f"brute force        median {r['brute_median_ms']:.1f} ms  "
            f"(speed-up x{r['speedup']:.0f})"
        )
        print(
            f"recall@1 vs brute  {r['recall_at_1']:.3f} over {r['brute_queries']} queries  "
            f"(D ratio p95 {r['d_ratio_p95']:.4f}, "
            f"max {r['d_ratio_max']:.4f})"
        )
        print(
            f"memory             index arrays {r['index_mb']:.0f} MB, "
            f"build RSS +{r['rss_build_delta_mb']:.0f} MB, "
            f"peak RSS {r['peak_rss_mb']:.0f} MB; PCA variance kept {r['pca_variance']:.3f}"
        )
        gc.collect()


if __name__ == "__main__":
    main()
