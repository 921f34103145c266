"""``library info|check``, ``convert`` and ``synth``."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from reactmocap.commands import output_dir, output_file
from reactmocap.errors import ConfigError, ReactMocapError

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    lib = sub.add_parser("library", help="inspect and lint clip libraries")
    lsub = lib.add_subparsers(dest="library_command", metavar="ACTION", required=True)

    info = lsub.add_parser("info", help="table of clips, frames, seconds and fps, with totals")
    info.add_argument("path", type=Path)
    info.add_argument("--no-cache", action="store_true", help="parse without the .npz cache")
    info.add_argument("--unit", choices=["m", "cm", "mm", "in"], help="override unit detection")
    info.add_argument("--up", choices=["y", "z"], default="y", help="source up axis")
    info.set_defaults(func=_info)

    check = lsub.add_parser(
        "check", help="lint BVH files (non-zero exit on any bad file or on none found); warn "
        "about clips whose skeleton cannot be mapped onto body parts",
    )  # fmt: skip
    check.add_argument("paths", type=Path, nargs="+")
    check.add_argument("--parts", type=Path, help="body-part rules TOML ([parts], [aliases])")
    check.set_defaults(func=_check)

    conv = sub.add_parser("convert", help="read a BVH and write it back (resample, mirror)")
    conv.add_argument("input", type=Path)
    conv.add_argument("output", type=output_file)
    conv.add_argument("--fps", type=float, help="resample to this frame rate")
    conv.add_argument("--mirror", action="store_true", help="mirror left/right")
    conv.add_argument("--unit", choices=["m", "cm", "mm", "in"], help="override unit detection")
    conv.add_argument("--up", choices=["y", "z"], default="y", help="source up axis")
    conv.set_defaults(func=_convert)

    synth = sub.add_parser("synth", help="generate the synthetic default clip library")
    synth.add_argument("out_dir", type=output_dir)
    synth.add_argument("--fps", type=float, default=60.0, help="frame rate (default 60)")
    synth.set_defaults(func=_synth)


def _info(args: argparse.Namespace) -> int:
    from reactmocap.library.clip_library import load_library

    lib = load_library(args.path, cache=not args.no_cache, unit=args.unit, up=args.up)
    rows = [
        (name, m.num_frames, m.num_frames / m.fps, m.fps) for name, m in sorted(lib.clips.items())
    ]
    width = max([len("clip")] + [len(r[0]) for r in rows])
    print(f"{'clip':<{width}}  {'frames':>7}  {'seconds':>8}  {'fps':>6}")
    for name, frames, secs, fps in rows:
        print(f"{name:<{width}}  {frames:>7d}  {secs:>8.2f}  {fps:>6.1f}")
    st = lib.stats()
    fps_txt = ",".join(f"{f:g}" for f in st.fps)
    print(f"{'total':<{width}}  {st.frames:>7d}  {st.seconds:>8.2f}  {fps_txt:>6}")
    print(f"{st.clips} clips, {st.skeletons} skeleton(s)")
    for fail in lib.failures:
        print(f"skipped {fail.path}: {fail.reason}", file=sys.stderr)
    return 0


def _check(args: argparse.Namespace) -> int:
    from reactmocap.library.bodyparts import load_rules, parts_for
    from reactmocap.library.bvh import read_bvh
    from reactmocap.library.clip_library import find_bvh_files

    rules = load_rules(args.parts) if args.parts else None
    ok = bad = unmapped = 0
    for path in args.paths:
        try:
            files = find_bvh_files(path)
        except ReactMocapError as exc:
            print(f"error: {exc}")
            bad += 1
            continue
        if not files:
            print(f"error: {path}: no .bvh files found")
            bad += 1
        for f in files:
            try:
                m = read_bvh(f)
            except ReactMocapError as exc:
                bad += 1
                print(f"error: {exc}")
                continue
            ok += 1
            print(f"ok: {f} ({m.num_frames} frames, {m.fps:g} fps)")
            try:
                parts_for(m.skeleton, rules)
            except ReactMocapError as exc:
                unmapped += 1
                print(f"warning: {f}: {exc}")
    print(f"{ok} ok, {bad} bad, {unmapped} not mappable onto body parts")
    return 1 if bad or ok == 0 else 0


def _convert(args: argparse.Namespace) -> int:
    from reactmocap.library.bvh import read_bvh, write_bvh

    if args.fps is not None and not (math.isfinite(args.fps) and args.fps > 0):
        raise ConfigError(f"--fps must be a positive frame rate, got {args.fps!r}")
    motion = read_bvh(args.input, unit=args.unit, up=args.up)
    if args.fps:
        motion = motion.resample(args.fps)
    if args.mirror:
        motion = motion.mirror()
    write_bvh(motion, args.output)
    print(f"wrote {args.output} ({motion.num_frames} frames, {motion.fps:g} fps)")
    return 0


def _synth(args: argparse.Namespace) -> int:
    from reactmocap.library.synth import write_synthetic_library

    paths = write_synthetic_library(args.out_dir, fps=args.fps)
    print(f"wrote {len(paths)} synthetic clips to {args.out_dir}")
    return 0
