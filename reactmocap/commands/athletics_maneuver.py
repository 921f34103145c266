"""``athletics maneuver FILE.toml``, ``athletics somersault``, ``athletics dive`` and
``athletics handspring``: thin
wrappers over :func:`reactmocap.athletics.maneuvers.run_maneuver`,
:func:`~reactmocap.athletics.routines.somersault` and :func:`~reactmocap.athletics.routines.dive`
that write a BVH, a JSON report and
optionally a video (each written atomically)."""

from __future__ import annotations

import argparse
from pathlib import Path

from reactmocap.commands import output_dir, output_file

__all__ = ["register_maneuvers"]


def register_maneuvers(inner: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add ``maneuver``, ``somersault``, ``dive`` and ``handspring`` to the ``athletics`` command's
    sub-commands."""
    from reactmocap.athletics.maneuvers import describe
    from reactmocap.athletics.routines import DIRECTIONS
    from reactmocap.athletics.tumble import POSITIONS
    from reactmocap.commands.athletics import contact_arg
    from reactmocap.commands.athletics_run import output_args

    m = inner.add_parser(
        "maneuver", help="run a maneuver file: phases of basis controllers with exit events",
        description="Runs a TOML maneuver (examples/athletics/maneuvers/*.toml): phases, each "
        "naming a basis controller, its parameters and the event that ends it.\n\n" + describe(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )  # fmt: skip
    m.add_argument("file", type=Path, help="MANEUVER.toml")
    m.add_argument("--out", type=output_dir, required=True,
                   help="folder for NAME.bvh and NAME.json (the report)")  # fmt: skip
    m.add_argument("--body", help="male, female or a BVH file (default: the file's body)")
    m.add_argument("--video", type=output_file, help="MP4 (or GIF) of the motion")
    m.add_argument("--fps", type=float, default=60.0, help="BVH frame rate (default 60)")
    contact_arg(m)
    m.set_defaults(func=_maneuver)

    s = inner.add_parser(
        "somersault", help="standing somersault: leap, tumble, land, balance (thesis 8.4-8.5)",
        description="A standing somersault composed of the leap, tumble, land and balance basis "
        "controllers. Tuned: the backward tuck (male, female), the backward pike and layout (male; "
        "the layout also with --twist 1) and the forward tuck (male); the other combinations run "
        "untuned and their reports say what happened.",
    )  # fmt: skip
    s.add_argument("--position", choices=sorted(POSITIONS), default="tuck")
    s.add_argument("--direction", choices=list(DIRECTIONS), default="backward")
    s.add_argument("--twist", type=float, default=0.0,
                   help="twist turns: 0, or 1 for the male back layout (--position layout; a "
                   "tilt twist, thesis 5.2); anything else is refused with the reason")  # fmt: skip
    s.add_argument("--backpack", type=float, default=0.0, help="kg on the chest (thesis 8.5.2)")
    output_args(s, "male", plot=False)
    contact_arg(s)
    s.set_defaults(func=_somersault)

    from reactmocap.athletics.routines import DIVE_DIRECTIONS, PLATFORM_MAX

    d = inner.add_parser(
        "dive", help="platform dive: leap, somersault, stretch, enter the water (thesis ch. 8)",
        description="A backward dive from a platform, judged at the water (a plane at the "
        "platform's foot): `landed` is a clean, head-first entry.",
    )  # fmt: skip
    d.add_argument("--position", choices=sorted(POSITIONS), default=None,
                   help="default pike, or layout with --twist")  # fmt: skip
    d.add_argument("--direction", choices=list(DIVE_DIRECTIONS), default="backward")
    d.add_argument("--height", type=float, default=5.0,
                   help=f"platform height over the water (1-{PLATFORM_MAX:g} m; default 5)")  # fmt: skip
    d.add_argument("--turns", type=float, default=None,
                   help="somersaults (default 1.5, or 0.5 with --twist: head first)")  # fmt: skip
    d.add_argument("--twist", type=float, default=0.0,
                   help="twist turns: 0, 0.5 or 1 (a tilt twist, built for the layout back "
                   "dive: --position layout --turns 0.5, the defaults with --twist)")  # fmt: skip
    output_args(d, "male", plot=False)
    d.set_defaults(func=_dive)

    h = inner.add_parser(
        "handspring", help="back handspring: leap, hands on the floor, push, land (thesis 8.3)",
        description="A standing back handspring composed of the leap, handspring (hand support), "
        "land and balance basis controllers. The report adds hands_contact_s (time the hands "
        "were on the floor); `fell` ignores the hands' own contacts. --out: a BVH file, or a "
        "folder (anything not ending in .bvh) for back_handspring_BODY.bvh.",
    )  # fmt: skip
    output_args(h, "male", plot=False)
    contact_arg(h)
    h.set_defaults(func=_handspring)


def _maneuver(args: argparse.Namespace) -> int:
    from reactmocap.athletics.maneuvers import load_maneuver, run_maneuver
    from reactmocap.commands.athletics import SimProgress

    maneuver = load_maneuver(args.file)
    with SimProgress(maneuver.name) as bar:
        result = run_maneuver(maneuver, args.body, on_tick=bar.tick, fps=args.fps,
                              contact=args.contact)  # fmt: skip
    out: Path = args.out
    files = argparse.Namespace(**{**vars(args), "report": out / f"{maneuver.name}.json"})
    _finish(result, files, out / f"{maneuver.name}.bvh")
    return 0


def _somersault(args: argparse.Namespace) -> int:
    from reactmocap.athletics.routines import somersault
    from reactmocap.commands.athletics import SimProgress

    with SimProgress("somersault") as bar:
        result = somersault(args.position, args.direction, str(args.body), twist=args.twist,
                            backpack=args.backpack, on_tick=bar.tick, fps=args.fps,
                            contact=args.contact)  # fmt: skip
    _finish(result, args, args.out or Path(f"{result.behaviour}_{result.body}.bvh"))
    return 0


def _dive(args: argparse.Namespace) -> int:
    from reactmocap.athletics.routines import dive
    from reactmocap.commands.athletics import SimProgress

    with SimProgress("dive") as bar:
        result = dive(args.position, args.direction, str(args.body), height=args.height,
                      turns=args.turns, twist=args.twist, on_tick=bar.tick, fps=args.fps)  # fmt: skip
    _finish(result, args, args.out or Path(f"{result.behaviour}_{result.body}.bvh"))
    return 0


def _handspring(args: argparse.Namespace) -> int:
    from reactmocap.athletics.routines import handspring
    from reactmocap.commands.athletics import SimProgress

    with SimProgress("handspring") as bar:
        result = handspring(str(args.body), on_tick=bar.tick, fps=args.fps, contact=args.contact)
    name = Path(f"{result.behaviour}_{result.body}.bvh")
    out: Path | None = args.out
    if out is None:
        out = name
    elif out.suffix.lower() != ".bvh":  # a folder
        out = out / name
    _finish(result, args, out)
    r = result.report
    print(f"hands on the floor {r['hands_contact_s']:.2f} s")
    return 0


def _finish(result, args: argparse.Namespace, out: Path) -> None:  # type: ignore[no-untyped-def]
    """Write the BVH, the report and the video all or nothing, then say how it went."""
    from reactmocap.commands.athletics_run import motion_video, write_all

    written = write_all(args, out, result.motion, result.report_json, lambda _p: None,
                         lambda p: motion_video(result.motion, p))  # fmt: skip
    if "video" in written:
        print(f"video: {written['video']} ({written['video_renderer']})")
    r = result.report
    print(f"{r['behaviour']} ({r['body']}): rotation {r['rotation_deg']:.0f} deg, twist "
          f"{r['twist_deg']:.0f} deg, landed={r['landed']}, fell={r['fell']} -> {out}")  # fmt: skip
    if r.get("status") != "ok":
        print(f"note: the simulation stopped early: {r.get('reason')}")
    if "entry_angle_deg" in r:
        print(f"entry: {r['entry_angle_deg']:.0f} deg from head first, straight down "
              f"({'clean' if r['landed'] else 'not clean'})")  # fmt: skip
    elif not r["landed"] or r["fell"]:
        print("note: the athlete did not end balanced on its feet")
    if r.get("human_plausible") is False:
        print("note: this needs more joint torque than the strength model allows "
              "(docs/athletics.md)")  # fmt: skip
