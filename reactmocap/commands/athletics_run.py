"""``athletics run`` and ``athletics vault``: thin wrappers over
:func:`reactmocap.athletics.run_course.run_course` and :func:`reactmocap.athletics.vault.vault`
that write a BVH, and on request a JSON report, a PNG plot and a video, all or nothing (each
is written beside its destination and moved into place only when every one succeeded)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from reactmocap.commands import numbers, output_file
from reactmocap.errors import ConfigError

__all__ = ["motion_video", "output_args", "register_run", "write_all"]


def register_run(inner: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add ``run`` and ``vault`` to the ``athletics`` command's sub-commands."""
    from reactmocap.athletics.cloth import CLOTHES
    from reactmocap.athletics.running import SPEED_RANGE

    lo, hi = SPEED_RANGE
    p = inner.add_parser(
        "run", help=f"run at a speed ({lo:g}-{hi:g} m/s) along a line, circle or path",
        description="Hodgins et al. 1995 running: a state machine runner with foot placement, "
        "speed and facing control; optional cloth trousers driven by the runner.",
    )  # fmt: skip
    p.add_argument("--speed", type=float, required=True, help=f"desired speed ({lo:g}-{hi:g} m/s)")
    p.add_argument("--seconds", type=float, default=10.0, help="how long to run (s; default 10)")
    p.add_argument("--path", default="line",
                   help="line, circle:R (radius m), eight:R (figure eight) or FILE.csv of x,y "
                        "points (m); a loop with +entry:L (e.g. circle:10+entry:10) is entered "
                        "along a clothoid of L m (0-100), scored from the loop's start; an "
                        "eight with +turn:L (e.g. eight:10+turn:10) joins its loops by a "
                        "clothoid pair of L m (0-2R)")  # fmt: skip
    p.add_argument("--cloth", choices=sorted(CLOTHES), help="dress the runner (cloth driven by "
                   "the body; it does not act on the runner unless --cloth-feedback)")  # fmt: skip
    p.add_argument("--cloth-feedback", action="store_true",
                   help="the cloth's contact forces act on the runner")  # fmt: skip
    p.add_argument("--push", type=numbers(2, "TIME,IMPULSE", "s, N s"),
                   help="a sideways push on the chest: TIME,IMPULSE (s, N s; > 0 to the "
                   "runner's left) over 0.1 s")  # fmt: skip
    output_args(p, "male")
    p.set_defaults(func=_run)

    v = inner.add_parser(
        "vault", help="handspring vault over a horse from a springboard (Table 1 report)",
        description="Hodgins et al. 1995 handspring vault: hurdle step, springboard, first "
        "flight, horse, second flight, landing; the report compares Table 1's 16 rows.",
    )  # fmt: skip
    v.add_argument("--seconds", type=float, default=None,
                   help="how long to simulate (s; default: until 2 s after landing)")  # fmt: skip
    output_args(v, "female")
    v.set_defaults(func=_vault)


def output_args(p: argparse.ArgumentParser, body: str, *, plot: bool = True) -> None:
    """The athletics commands' body and output options."""
    p.add_argument("--body", default=body, help=f"male, female or a BVH file (default {body})")
    p.add_argument("--out", type=output_file, help="BVH of the motion (default: NAME_BODY.bvh)")
    p.add_argument("--report", type=output_file, help="JSON report")
    if plot:
        p.add_argument("--plot", type=output_file, help="PNG figure")
    p.add_argument("--video", type=output_file, help="MP4 (or GIF) of the motion")
    p.add_argument("--fps", type=float, default=60.0, help="BVH frame rate (default 60)")


def _push(values: tuple[float, float] | None) -> tuple[float, float, float] | None:
    """``--push``'s time and signed impulse as run_course's (time, impulse, direction)."""
    if values is None:
        return None
    when, impulse = values
    return (when, abs(impulse), math.copysign(math.pi / 2, impulse))


def _run(args: argparse.Namespace) -> int:
    from reactmocap.athletics.run_course import run_course
    from reactmocap.commands.athletics import SimProgress

    with SimProgress("run") as bar:
        result = run_course(args.speed, seconds=args.seconds, path=args.path,
                            body=str(args.body), cloth=args.cloth,
                            cloth_feedback=args.cloth_feedback, push=_push(args.push),
                            fps=args.fps, on_tick=bar.tick)  # fmt: skip
    out = args.out or Path(f"run_{result.report['body']}.bvh")

    def plot(path: Path) -> None:
        from reactmocap.athletics.running_plots import run_plot

        run_plot(result, path)

    def video(path: Path) -> str:
        if result.cloth is not None:
            from reactmocap.athletics.cloth import render_cloth_video
            from reactmocap.response.render import RenderUnavailable

            try:
                render_cloth_video(result.cloth, path)
                return "mujoco (cloth)"
            except RenderUnavailable as exc:
                return motion_video(result.motion, path, f"no cloth: {exc}")
        return motion_video(result.motion, path)

    written = write_all(args, out, result.motion, result.report_json, plot, video)
    _summary(result.report, written)
    return 0


def _vault(args: argparse.Namespace) -> int:
    from reactmocap.athletics.vault import vault
    from reactmocap.commands.athletics import SimProgress

    with SimProgress("vault") as bar:
        result = vault(body=str(args.body), seconds=args.seconds, fps=args.fps, on_tick=bar.tick)
    out = args.out or Path(f"vault_{result.report['body']}.bvh")

    def plot(path: Path) -> None:
        from reactmocap.athletics.vault import vault_plot

        vault_plot(result, path)

    def video(path: Path) -> str:
        return motion_video(result.motion, path, scene=result.scene_video)

    written = write_all(args, out, result.motion, result.report_json, plot, video)
    _summary(result.report, written)
    return 0


def motion_video(motion: Any, path: Path, note: str = "", scene: Any = None) -> str:
    from reactmocap.response.plots import stick_figure_video
    from reactmocap.response.render import RenderUnavailable, render_video

    try:
        if scene is not None:
            scene(path)
        else:
            render_video([(motion, (0.35, 0.55, 0.85, 1.0))], path, fps=30.0)
        return "mujoco" + (f" ({note})" if note else "")
    except RenderUnavailable as exc:
        stick_figure_video([(motion, "C0")], path, fps=30.0)
        return f"stick figure ({exc})"


def write_all(
    args: argparse.Namespace, out: Path, motion: Any, report_json: Callable[[], str],
    plot: Callable[[Path], Any], video: Callable[[Path], str],
) -> dict[str, str]:  # fmt: skip
    """Write every requested file to a temporary sibling, then move them all into place; on
    any failure remove what was written and re-raise."""
    from reactmocap.io import staged_files
    from reactmocap.library.bvh import write_bvh

    jobs: list[tuple[str, Path, Callable[[Path], Any]]] = [
        ("bvh", out, lambda p: write_bvh(motion, p))
    ]
    if getattr(args, "plot", None) is not None:  # commands without a figure have no --plot
        jobs.append(("plot", args.plot, plot))
    if args.video is not None:
        if args.video.suffix.lower() not in (".mp4", ".gif"):
            raise ConfigError(f"--video must end in .mp4 or .gif, got {args.video}")
        jobs.append(("video", args.video, video))
    notes: dict[str, str] = {}
    with staged_files() as stage:
        for name, dest, fn in jobs:
            got = fn(stage(dest))
            if isinstance(got, str):
                notes[name] = got
        if args.report is not None:
            stage(args.report).write_text(report_json())
    written = {name: str(dest) for name, dest, _ in jobs}
    if args.report is not None:
        written["report"] = str(args.report)
    return written | {f"{k}_renderer": v for k, v in notes.items()}


def _summary(r: dict[str, Any], written: dict[str, str]) -> None:
    bits = [f"{r['behaviour']} ({r['body']})"]
    if r.get("mean_speed_m_s") is not None:
        bits.append(f"mean speed {r['mean_speed_m_s']:.2f} m/s (asked {r['speed_m_s']:g})")
    if r.get("speed_error_m_s") is not None:
        bits.append(f"stride speed RMS error {r['speed_error_m_s']:.3f} m/s")
    if r.get("path_error_m") is not None:
        bits.append(f"path error {r['path_error_m']:.2f} m")
    if r.get("cloth_penetration_max_m") is not None:
        bits.append(f"cloth penetration max {100 * r['cloth_penetration_max_m']:.1f} cm")
    if "table1" in r:
        bits.append(f"Table 1 rows inside the human range: {r.get('table1_inside', '?')}/16")
    for key in ("fell", "landed", "cleared"):
        if key in r:
            bits.append(f"{key}={r[key]}")
    if r.get("realtime_factor") is not None:
        bits.append(f"{r['realtime_factor']:.1f}x real time")
    print(", ".join(bits) + f" -> {written.get('bvh')}")
    for name in ("report", "plot", "video"):
        if name in written:
            extra = f" ({written[name + '_renderer']})" if name + "_renderer" in written else ""
            print(f"{name}: {written[name]}{extra}")
    for note in r.get("notes", []):
        print(f"note: {note}")
