"""``athletics leap|broad-jump|land|balance``: thin wrappers over
:func:`reactmocap.athletics.run` that write a BVH, a report and optional plot and video."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from reactmocap.commands import numbers, output_file
from reactmocap.progress import Progress

__all__ = ["SimProgress", "contact_arg", "register"]

#: CLI flag -> (behaviour parameter, in degrees at the CLI)
_FLAGS: dict[str, list[tuple[str, str, bool]]] = {
    "leap": [("--height", "height", False), ("--effort", "effort", False),
             ("--spin", "spin", False), ("--backpack", "backpack", False)],
    "broad-jump": [("--distance", "distance", False), ("--effort", "effort", False),
                   ("--spin", "spin", False), ("--backpack", "backpack", False)],
    "land": [("--drop", "drop", False), ("--vx", "vx", False), ("--backpack", "backpack", False)],
    "balance": [("--seconds", "seconds", False), ("--push", "push", False),
                ("--push-dir", "push_dir", True), ("--push-duration", "push_duration", False),
                ("--push-time", "push_time", False), ("--slope", "slope", True),
                ("--slope-dir", "slope_dir", True), ("--pitch", "pitch", True),
                ("--pelvis-height", "pelvis_height", False), ("--backpack", "backpack", False)],
}  # fmt: skip
_HELP = {
    "leap": "vertical leap to a COM rise (m), land and balance",
    "broad-jump": "standing broad jump over a COM distance (m), land and balance",
    "land": "drop from a height (m), optionally moving, and land",
    "balance": "stand balanced; optional push, slope, posture and backpack",
}


def contact_arg(p: argparse.ArgumentParser) -> None:
    """``--contact NAME``: the athletics contact model (``scene.CONTACT_MODELS``)."""
    from reactmocap.athletics.scene import CONTACT_MODELS, DEFAULT_CONTACT

    p.add_argument("--contact", choices=list(CONTACT_MODELS), default=DEFAULT_CONTACT,
                   help=f"contact model (default {DEFAULT_CONTACT}; the measured tables and "
                   "supported ranges are the default's)")  # fmt: skip


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    from reactmocap.athletics.behaviours import BEHAVIOURS

    ath = sub.add_parser(
        "athletics",
        help="athletic controllers: leap, broad-jump, land, balance, run, vault, maneuver, "
        "somersault, dive, handspring, bicycle, group",
    )
    inner = ath.add_subparsers(dest="behaviour", metavar="BEHAVIOUR", required=True)
    for name, flags in _FLAGS.items():
        b = BEHAVIOURS[name]
        params = {p.name: p for p in b.params}
        p = inner.add_parser(name, help=_HELP[name], description=b.description)
        p.add_argument("--body", default="male", help="male, female or a BVH file (CLIP.bvh)")
        for flag, key, deg in flags:
            par = params[key]
            unit = "deg" if deg else par.unit
            default = par.default
            if deg and isinstance(default, float):
                default = math.degrees(default)
            notes = [n for n in (unit, None if default is None else f"default {default}") if n]
            p.add_argument(flag, type=float, default=None,
                           help=f"{par.help} ({'; '.join(notes)})" if notes else par.help)  # fmt: skip
        if name == "leap":
            push = params["push"]
            p.add_argument("--push", dest="push_off", choices=list(push.choices or ()),
                           default=None, help=f"{push.help} (default {push.default})")  # fmt: skip
        if name == "balance":
            p.add_argument("--com-offset", type=numbers(2, "X,Y", "m"),
                           help="desired COM offset X,Y (m) from the support")  # fmt: skip
            p.add_argument("--step", action="store_true",
                           help=f"{params['step'].help}; the report lists the steps taken")  # fmt: skip
        p.add_argument("--out", type=output_file, help="BVH of the motion (default: NAME_BODY.bvh)")
        p.add_argument("--report", type=output_file, help="JSON report")
        p.add_argument("--plot", type=output_file, help="PNG of COM height and ground force")
        p.add_argument("--video", type=output_file, help="MP4 (or GIF) of the motion")
        p.add_argument("--fps", type=float, default=60.0, help="BVH frame rate")
        contact_arg(p)
        p.add_argument("--any-range", action="store_true",
                       help="run outside the measured supported range (reported honestly)")  # fmt: skip
        p.set_defaults(func=_run, flags=flags)
    from reactmocap.commands.athletics_run import register_run

    register_run(inner)  # run, vault

    from reactmocap.commands.athletics_maneuver import register_maneuvers

    register_maneuvers(inner)  # maneuver, somersault, dive, handspring

    from reactmocap.commands.athletics_bicycle import register as register_bicycle

    register_bicycle(inner)


def _run(args: argparse.Namespace) -> int:
    from reactmocap.athletics.behaviours import run

    params: dict[str, Any] = {"fps": args.fps, "contact": args.contact}
    for flag, key, deg in args.flags:
        v = getattr(args, flag.lstrip("-").replace("-", "_"))
        if v is not None:
            params[key] = math.radians(v) if deg else v
    if getattr(args, "push_off", None):
        params["push"] = args.push_off
    if getattr(args, "step", False):
        params["step"] = "on"
    if getattr(args, "com_offset", None):
        x, y = args.com_offset
        params.update(com_offset_x=x, com_offset_y=y)
    body = str(args.body)
    bar = SimProgress(args.behaviour)
    with bar:
        result = run(args.behaviour, body, on_tick=bar.tick, check_range=not args.any_range,
                     **params)  # fmt: skip
    out = args.out or Path(f"{args.behaviour}_{result.body}.bvh")
    from reactmocap.athletics.plots import run_plot
    from reactmocap.commands.athletics_run import motion_video, write_all

    # all or nothing, like the other athletics commands
    written = write_all(args, out, result.motion, result.report_json,
                         lambda p: run_plot(result, p), lambda p: motion_video(result.motion, p))  # fmt: skip
    if "video" in written:
        print(f"video: {written['video']} ({written['video_renderer']})")
    _summary(result.report, out)
    return 0


def _summary(r: dict[str, Any], out: Path) -> None:
    name = r["behaviour"]
    bits = [f"{name} ({r['body']})"]
    for what in ("height", "distance"):
        if f"achieved_{what}_m" in r:
            asked = r[f"commanded_{what}_m"]
            asked = f"effort {r['effort']:g}" if asked is None else f"asked {asked:.3f}"
            bits.append(f"{what} {r[f'achieved_{what}_m']:.3f} m ({asked})")
    for key in ("landed", "balanced", "fell"):
        if key in r:
            bits.append(f"{key}={r[key]}")
    if r.get("peak_grf_bw") is not None:
        bits.append(f"push-off peak {r['peak_grf_bw']:.1f} BW")
    if "steps" in r:
        bits.append(f"steps {len(r['steps'])}")
    if "max_com_offset_m" in r:
        bits.append(f"max COM offset {r['max_com_offset_m']:.3f} m")
    bits.append(f"{r['realtime_factor_cpu']:.1f}x real time ({r['realtime_factor']:.1f}x wall)")
    print(", ".join(bits) + f" -> {out}")
    if r.get("status") != "ok":
        print(f"note: the simulation stopped early: {r.get('reason')}")
    if r.get("human_plausible") is False:
        over = ", ".join(f"{k} {v:.2f}x" for k, v in r.get("strength_exceeded", {}).items())
        print(f"note: this needs more joint torque than the strength model allows ({over}); "
              "a person could not do it (docs/athletics.md)")  # fmt: skip
    if r.get("landed") is False or r.get("balanced") is False or r.get("fell"):
        print("note: the athlete did not end balanced on its feet")
    elif r.get("on_both_feet") is False:
        print("note: the athlete ended still but on one foot, the other in the air")


class SimProgress:
    """Progress over the simulated fraction (quiet unless stderr is a terminal)."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.bar: Progress | None = None

    def tick(self, fraction: float) -> None:
        if self.bar is None:
            self.bar = Progress(100, f"{self.label} (% simulated)")
        self.bar.update(round(100 * fraction) - self.bar.done)

    def __enter__(self) -> SimProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
