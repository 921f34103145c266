"""``athletics bicycle`` and ``athletics group``: thin wrappers over
:func:`reactmocap.athletics.cycling.ride` and :func:`~reactmocap.athletics.cycling.group_ride`
that write a BVH per rider and per bicycle, and on request a report, a top-view plot and a
video (all or nothing)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from reactmocap.commands import numbers, output_dir, output_file
from reactmocap.commands.athletics import SimProgress

__all__ = ["register"]


def register(inner: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add ``bicycle`` and ``group`` to the ``athletics`` subcommands."""
    b = inner.add_parser(
        "bicycle",
        help="ride a bicycle: speed, heading or path, grade",
        description="One rider (Hodgins et al. 1995, eqs. 7-11) on a bicycle from the origin "
        "facing +X: hold a speed, turn to a heading or follow a path, up a grade.",
    )
    b.add_argument("--speed", type=float, required=True, help="speed command (m/s; 1.5-12)")
    b.add_argument("--seconds", type=float, default=10.0, help="ride length (s; default 10)")
    way = b.add_mutually_exclusive_group()
    way.add_argument("--heading", type=float, help="turn to this heading (deg, 0 = +X, left > 0)")
    way.add_argument("--path", nargs="+", type=numbers(2, "X,Y", "m"), metavar="X,Y",
                     help="waypoints to follow (m)")  # fmt: skip
    b.add_argument("--heading-at", type=float, default=1.0,
                   help="when the heading command starts (s; default 1)")  # fmt: skip
    b.add_argument("--grade", type=float, default=0.0, help="ground rise along +X (percent)")
    b.add_argument("--gear", type=float, help="rear-wheel turns per crank turn (default 2.8)")
    _common(b, "bicycle_out")
    b.set_defaults(func=_run_bicycle)
    g = inner.add_parser(
        "group",
        help="a group of riders around a course (eq. 13)",
        description="N riders around a course (TOML: terrain, obstacles, the group's global "
        "velocity along a route); each sees only the others' positions and velocities.",
    )
    g.add_argument("--riders", type=int, required=True, help="number of riders (1-26)")
    g.add_argument("--course", type=Path, required=True, help="course file (TOML)")
    g.add_argument("--seconds", type=float, help="ride length (s; default the course's)")
    _common(g, "group_out")
    g.set_defaults(func=_run_group)


def _common(p: argparse.ArgumentParser, out: str) -> None:
    p.add_argument("--body", default="male", help="male, female or a BVH file (CLIP.bvh)")
    p.add_argument("--out", type=output_dir, default=Path(out),
                   help=f"folder for rider{{k}}.bvh and bicycle{{k}}.bvh (default {out}/)")  # fmt: skip
    p.add_argument("--report", type=output_file, help="JSON report")
    p.add_argument("--plot", type=output_file, help="PNG: top-view paths, speed and heading")
    p.add_argument("--video", type=output_file, help="MP4 (or GIF) of the ride")
    p.add_argument("--fps", type=float, default=30.0, help="BVH frame rate (default 30)")


def _run_bicycle(args: argparse.Namespace) -> int:
    from reactmocap.athletics.cycling import ride

    heading = None if args.heading is None else math.radians(args.heading)
    path = None if args.path is None else list(args.path)
    with SimProgress("bicycle") as bar:
        res = ride(args.speed, args.seconds, heading=heading, heading_at=args.heading_at,
                   path=path, grade=args.grade / 100.0, gear=args.gear, body=args.body,
                   fps=args.fps, on_tick=bar.tick)  # fmt: skip
    written = res.write(args.out, report=args.report, plot=args.plot, video=args.video)
    r = res.report
    bits = [f"bicycle ({r['body']}): mean speed {_f(r['mean_speed_m_s'])} m/s "
            f"(asked {r['speed_cmd_m_s']:g}), speed error {_f(r['speed_error_m_s'])} m/s"]  # fmt: skip
    if r.get("heading_cmd_deg") is not None:
        bits.append(f"heading error {_f(r['heading_error_deg'], 1)} deg, settled in "
                    f"{_f(r.get('settle_time_s'), 1)} s, overshoot {_f(r.get('overshoot_deg'), 1)} deg")  # fmt: skip
    bits.append(f"fell={r['fell']}, {r['realtime_factor']:.1f}x real time")
    _print(bits, r, written)
    return 0


def _run_group(args: argparse.Namespace) -> int:
    from reactmocap.athletics.course import load_course
    from reactmocap.athletics.cycling import group_ride

    course = load_course(args.course)
    with SimProgress("group") as bar:
        res = group_ride(course, args.riders, seconds=args.seconds, body=args.body, fps=args.fps,
                         on_tick=bar.tick)  # fmt: skip
    written = res.write(args.out, report=args.report, plot=args.plot, video=args.video)
    r = res.report
    done = [t for t in r["finish_times_s"] if t is not None]
    bits = [f"group of {r['riders']} on {r['course']!r}: {r['collisions']} collision(s), "
            f"min separation {_f(r['min_separation_m'])} m, {r['fell']} fell, "
            f"{len(done)} finished" + (f" ({min(done):.1f}-{max(done):.1f} s)" if done else ""),
            f"{r['realtime_factor']:.2f}x real time"]  # fmt: skip
    _print(bits, r, written)
    return 0


def _f(v: Any, digits: int = 2) -> str:
    return "n/a" if v is None else f"{v:.{digits}f}"


def _print(bits: list[str], r: dict[str, Any], written: dict[str, str]) -> None:
    print(", ".join(bits) + f" -> {written.get('bvh')}")
    if "video" in written:
        print(f"video: {written['video']} ({written.get('video_renderer')})")
    for note in r.get("notes", []):
        print(f"note: {note} (docs/athletics.md)")
