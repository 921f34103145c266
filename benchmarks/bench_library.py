"""Library loading speed: all shared clips cold (parse) and from the .npz cache.

    python benchmarks/bench_library.py [--repeats 5] [PATH]

Targets (issue 2): cold load of the 19 shared clips < 3 s, cached < 0.3 s.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from reactmocap.library.clip_library import load_library

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "mocap" / "bandai-namco-1"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("path", nargs="?", type=Path, default=DEFAULT)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    cold, warm = [], []
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as cache:
            t0 = time.perf_counter()
            lib = load_library(args.path, cache_dir=cache, strict=True)
            cold.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            lib2 = load_library(args.path, cache_dir=cache, strict=True)
            warm.append(time.perf_counter() - t0)
            assert lib2.stats() == lib.stats()
    st = lib.stats()
    c, w = statistics.median(cold), statistics.median(warm)
    print(f"library: {args.path} ({st.clips} clips, {st.frames} frames, {st.seconds:.1f} s)")
    print(f"cold load   median {c:.3f} s  ({st.frames / c:,.0f} frames/s)  target < 3 s")
    print(f"cached load median {w:.3f} s  ({st.frames / w:,.0f} frames/s)  target < 0.3 s")
    print(f"cache speed-up {c / w:.1f}x over {args.repeats} repeats")


if __name__ == "__main__":
    main()
