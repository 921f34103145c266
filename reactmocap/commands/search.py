"""``search build`` and ``search query``: thin wrappers over :mod:`reactmocap.search`."""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

from reactmocap.commands import numbers, output_file
from reactmocap.errors import ReactMocapError, SearchError

__all__ = ["register"]


def _degrees(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):  # NaN reached the query as "rotations contain NaN or inf"
        raise argparse.ArgumentTypeError(f"expected a finite angle in degrees, got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    p = sub.add_parser("search", help="build and query the motion-search index")
    ssub = p.add_subparsers(dest="search_command", metavar="ACTION", required=True)

    b = ssub.add_parser("build", help="index every window of a clip library")
    b.add_argument("library", type=Path, metavar="LIBRARY_DIR")
    b.add_argument(
        "--out", type=output_file, required=True, metavar="INDEX", help="index file (.npz)"
    )
    b.add_argument("--mirror", action="store_true", help="also index left/right mirrored clips")
    b.add_argument("--fps", type=float, default=None, help="index rate (default 30)")
    b.add_argument("--duration", type=float, default=None, help="window length in s (default 0.3)")
    b.add_argument("--feature-set", default=None, help="feature set key (default 'paper')")
    b.add_argument("--parts", type=Path, help="body-part rules TOML ([parts], [aliases])")
    b.set_defaults(func=_build)

    q = ssub.add_parser(
        "query",
        help="cut a query window from a library clip, move it, and search",
        description="Cut the window at --frame of --clip, rotate it by --yaw about Z and shift it "
        "by --shift, then print the best matches. Negative shifts: --shift=-1,2.",
    )
    q.add_argument("index", type=Path, metavar="INDEX")
    q.add_argument("--clip", required=True, metavar="NAME")
    q.add_argument(
        "--frame", type=int, required=True, metavar="F", help="start frame (clip's own fps)"
    )
    q.add_argument("--yaw", type=_degrees, default=0.0, metavar="DEG")
    q.add_argument("--shift", type=numbers(2, "X,Y", "m; e.g. 1.5,-2"), default=(0.0, 0.0),
                   metavar="X,Y")  # fmt: skip
    q.add_argument("--top", type=int, default=5, metavar="K")
    q.add_argument(
        "--library", type=Path, default=None, help="library folder (default: the one indexed)"
    )
    q.add_argument("--json", action="store_true", help="print one JSON object")
    q.set_defaults(func=_query)


def _build(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from reactmocap.library.bodyparts import load_rules, parts_for
    from reactmocap.library.clip_library import load_library
    from reactmocap.search import MotionIndex, SearchWeights, WindowConfig

    lib = load_library(args.library)
    window = WindowConfig()
    if args.fps is not None:
        window = replace(window, fps=args.fps)
    if args.duration is not None:
        window = replace(window, duration=args.duration)
    weights = (
        SearchWeights() if args.feature_set is None else SearchWeights(feature_set=args.feature_set)
    )
    t0 = time.perf_counter()
    rules = load_rules(args.parts) if args.parts else None
    parts, skipped = {}, []
    for name, m in lib.clips.items():
        try:
            parts[name] = parts_for(m.skeleton, rules)
        except ReactMocapError as exc:
            skipped.append(f"skipped {lib.paths.get(name, name)}: {exc}")
    if skipped:
        lib = replace(lib, clips={n: m for n, m in lib.clips.items() if n in parts})
    index = MotionIndex.build(lib, weights, window, mirror=args.mirror, parts=parts)
    index.info["source"] = str(Path(args.library).resolve())
    index.save(args.out)
    print(
        f"indexed {len(index.clip_names)} clips ({index.num_frames} frames at {window.fps:g} fps), "
        f"{index.num_indexed} of {index.num_windows} windows (L={index.length}) in "
        f"{time.perf_counter() - t0:.2f} s -> {args.out}"
    )
    for fail in lib.failures:
        print(f"skipped {fail.path}: {fail.reason}")
    for line in skipped:
        print(line)
    return 0


def _query(args: argparse.Namespace) -> int:
    from reactmocap.search import MotionIndex
    from reactmocap.search.index import MIRROR_SUFFIX

    index = MotionIndex.load(args.index)
    if args.top < 1:
        raise SearchError(f"--top must be >= 1, got {args.top}")
    index.clip_index(args.clip)  # unknown clip -> SearchError listing clips
    source = args.library or (Path(index.info["source"]) if index.info.get("source") else None)
    if source is None:
        raise SearchError(f"{args.index}: no library folder recorded; pass --library")
    from reactmocap.library.clip_library import load_library

    lib = load_library(source)
    problem = index.stale_reason(clips=lib)
    if problem:
        raise SearchError(f"{args.index}: stale search index: {problem}; rebuild it")
    name = args.clip
    if name in lib.clips:
        motion = lib.clips[name]
    elif name.endswith(MIRROR_SUFFIX) and name[: -len(MIRROR_SUFFIX)] in lib.clips:
        motion = lib.clips[name[: -len(MIRROR_SUFFIX)]].mirror().replace(name=name)
    else:
        raise SearchError(f"clip {name!r} is indexed but not in library {source}")
    moved = motion.transformed(math.radians(args.yaw), args.shift)
    t0 = time.perf_counter()
    results = index.top_k(moved, args.frame, n=args.top)
    query_ms = (time.perf_counter() - t0) * 1e3
    best = results[0]
    if args.json:
        out = {
            "query": {
                "clip": name,
                "frame": args.frame,
                "yaw_deg": args.yaw,
                "shift": list(args.shift),
            },
            "clip": best.clip,
            "frame": best.frame,
            "time": best.time,
            "distance": best.distance,
            "yaw_deg": best.yaw_deg,
            "translation": list(best.translation),
            "breakdown": best.breakdown.to_dict(),
            "query_ms": query_ms,
            "candidates": [r.to_dict() for r in results],
        }
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"query: {name} frame {args.frame}, moved by yaw {args.yaw:g} deg, shift "
        f"({args.shift[0]:g}, {args.shift[1]:g}) m; support body {best.breakdown.support_part}; "
        f"{query_ms:.2f} ms"
    )
    w = max(4, *(len(r.clip) for r in results))
    print(
        f"{'#':>2}  {'clip':<{w}}  {'frame':>5}  {'D':>8}  {'yaw_deg':>8}  {'tx':>7}  {'ty':>7}  "
        f"{'trunk_p':>7}  {'trunk_o':>7}  {'limb_p':>7}  {'limb_o':>7}  "
        f"{'supp_p':>7}  {'supp_o':>7}"
    )
    for r in results:
        b = r.breakdown
        print(
            f"{r.rank:>2}  {r.clip:<{w}}  {r.frame:>5d}  {r.distance:>8.4f}  {r.yaw_deg:>8.2f}  "
            f"{r.translation[0]:>7.3f}  {r.translation[1]:>7.3f}  {b.trunk_position:>7.4f}  "
            f"{b.trunk_orientation:>7.4f}  {b.limbs_position:>7.4f}  {b.limbs_orientation:>7.4f}  "
            f"{b.support_position:>7.4f}  {b.support_orientation:>7.4f}"
        )
    return 0
