"""``track`` and ``push``: thin wrappers over :func:`reactmocap.sim.track_clip` and
:func:`reactmocap.sim.push_clip`."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from reactmocap.commands import numbers, output_file
from reactmocap.errors import ConfigError
from reactmocap.progress import Progress

if TYPE_CHECKING:
    from reactmocap.library.motion import Motion
    from reactmocap.sim.tracking import TrackReport, TrackResult

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    track = sub.add_parser(
        "track",
        help="track a clip physically on a simulated character (default: the whole-body tracker)",
    )
    track.add_argument("clip", type=Path, help="input BVH")
    track.add_argument("--start", type=float, default=0.0, help="clip time to start at (s)")
    track.add_argument("--seconds", type=float, help="how long to track (default: to the end)")
    track.add_argument("--out", type=output_file, help="simulated motion as BVH")
    track.add_argument("--report", type=output_file, help="JSON report")
    _common(track)
    track.set_defaults(func=_track)

    push = sub.add_parser("push", help="push a tracking character and write the response")
    push.add_argument("clip", type=Path, help="input BVH")
    push.add_argument("--time", type=float, required=True, help="clip time of the push (s)")
    push.add_argument("--body", required=True, help="body part, e.g. chest, head, l_forearm")
    push.add_argument(
        "--force",
        required=True,
        type=numbers(3, "FX,FY,FZ", "N"),
        help="world force FX,FY,FZ in N (Z up); write --force=-300,0,0 for a leading minus",
    )
    push.add_argument("--duration", type=float, default=0.1, help="push duration (s)")
    push.add_argument("--seconds", type=float, help="how long to simulate after the start")
    push.add_argument("--out", type=output_file, required=True, help="simulated motion as BVH")
    push.add_argument("--report", type=output_file, help="JSON report")
    _common(push)
    push.set_defaults(func=_push)
    _register_feasibility(sub)


def _register_feasibility(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    feas = sub.add_parser(
        "feasibility",
        help="can the ground produce a clip? stretches of single support needing more moment "
        "than a foot can give (reactmocap.sim.support_feasibility)",
    )
    feas.add_argument("clip", type=Path, help="input BVH")
    feas.add_argument(
        "--factor", type=float, default=2.0, help="flag residuals above this times the bound"
    )
    feas.add_argument("--min-seconds", type=float, default=0.1, help="shortest stretch to list (s)")
    feas.add_argument("--mass", type=float, default=75.0, help="character mass (kg)")
    feas.add_argument("--report", type=output_file, help="JSON report")
    feas.set_defaults(func=_feasibility)


def _feasibility(args: argparse.Namespace) -> int:
    from reactmocap.io import atomic_write_text
    from reactmocap.sim.feasibility import support_feasibility

    motion = _read(args.clip)
    if not (math.isfinite(args.min_seconds) and args.min_seconds >= 0):
        raise ConfigError(f"--min-seconds must be >= 0, got {args.min_seconds!r}")
    check = support_feasibility(motion, total_mass=args.mass)
    data = {"clip": motion.name, **check.summary(args.factor, args.min_seconds)}
    if args.report is not None:
        atomic_write_text(args.report, json.dumps(data, indent=2) + "\n")
    ratio = data["median_residual_over_bound"]
    print(
        f"{motion.name}: single support {data['single_support_fraction']:.0%} of frames, "
        f"median residual/bound {'-' if ratio is None else f'{ratio:.2f}'}, "
        f"{data['infeasible_fraction_of_single_support']:.0%} above {args.factor:g}x the bound"
    )
    for st in data["stretches"]:  # type: ignore[attr-defined]
        print(
            f"  {st['start_s']:.2f}-{st['end_s']:.2f} s: residual up to "
            f"{st['max_residual_nm']:.0f} N m, bound up to {st['max_bound_nm']:.0f} N m"
        )
    return 0


#: the controllers ``track`` and ``push`` offer (the registry's tracking controllers)
TRACKERS = ("wholebody", "predictive", "balance", "pd")


def _common(p: argparse.ArgumentParser) -> None:
    from reactmocap.sim.controllers import controller_help

    p.add_argument(
        "--controller",
        default="wholebody",
        help="tracking controller (default: wholebody): " + controller_help(TRACKERS),
    )
    p.add_argument("--kp", type=float, help="joint stiffness (1/s^2; default: the controller's)")
    p.add_argument("--kv", type=float, help="joint damping (1/s; default: critical)")
    p.add_argument("--friction", type=float, default=1.0, help="ground friction coefficient")
    p.add_argument("--fps", type=float, default=60.0, help="output frame rate")
    p.add_argument("--parts", type=Path, help="body-part rules TOML ([parts], [aliases])")
    p.add_argument("--mass", type=float, default=75.0, help="character mass (kg)")
    p.add_argument("--stepping", action="store_true",
                   help="let the whole-body tracker take capture-point balance steps from "
                   "the start (a push while the clip stands turns them on anyway; see "
                   "docs/tracking.md)")  # fmt: skip
    p.add_argument("--strict", action="store_true",
                   help="exit 3 unless the character stayed up and stable (status ok)")  # fmt: skip
    p.add_argument(
        "--root-assist",
        type=float,
        default=0.0,
        help="NON-PHYSICAL pelvis stabilisation gain (0 = off); only with --controller pd",
    )


def _read(path: Path) -> Motion:
    from reactmocap.library.bvh import read_bvh

    return read_bvh(path)


#: seconds of a tracked span needing more moment than a foot can give that earn a printed note
#: (the default ``--min-seconds`` of ``reactmocap feasibility``)
FEASIBILITY_NOTE_S = 0.1


def _infeasible_seconds(
    clip: Motion, report: TrackReport, mass: float, tracked: float
) -> float | None:
    """Seconds of the tracked span where the clip asks for more moment than a foot can give
    (``support_feasibility``, 2x its bound); None for clips too short to differentiate. A run
    that fell or diverged counts only the ``tracked`` seconds it ran."""
    from reactmocap.sim.feasibility import support_feasibility

    if clip.num_frames < 3:
        return None
    check = support_feasibility(clip, total_mass=mass)
    seconds = report.seconds if report.status == "ok" else min(tracked, report.seconds)
    return check.infeasible_seconds(report.start, seconds)


def _at_end(result: TrackResult) -> dict[str, Any] | None:
    """Whether the pushed body has recovered at the run's end, not only stayed upright
    (:func:`~reactmocap.sim.recovery`: a standing clip stands still over its feet, a walking
    one walks as its clip does)."""
    from reactmocap.sim.tracking import WalkState, recovery

    try:
        state = recovery(result)
    except ConfigError:  # a run too short to judge
        return None
    walks = isinstance(state, WalkState)
    outside = state.capture_outside
    out: dict[str, Any] = {
        "judged_as": "walk" if walks else "stand",
        "recovered": state.walking if isinstance(state, WalkState) else state.settled,
        "capture_outside_m": round(outside, 3) if math.isfinite(outside) else None,
        "why": state.why,
    }
    if isinstance(state, WalkState):
        out["speed_ratio"] = round(state.speed_ratio, 3)
        out["heading_error_rad"] = round(state.heading_error, 3)
    else:
        out["com_speed_m_s"] = round(state.com_speed, 3)
        out["lowest_sole_m"] = round(state.lowest_sole, 3)
    return out


def _write_outputs(
    args: argparse.Namespace,
    clip: Motion,
    motion: Motion,
    report: TrackReport,
    at_end: dict[str, Any] | None = None,
) -> None:
    from reactmocap.io import atomic_write_text

    if args.out is not None:
        from reactmocap.library.bvh import write_bvh

        write_bvh(motion, args.out)  # atomic: never a half-written output
    data: dict[str, Any] = report.to_dict()
    infeasible = _infeasible_seconds(clip, report, args.mass, motion.duration)
    data["infeasible_single_support_s"] = infeasible
    if at_end is not None:
        data["at_end"] = at_end
    if args.report is not None:
        clean = {
            k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in data.items()
        }
        atomic_write_text(args.report, json.dumps(clean, indent=2) + "\n")
    tracked = f"{data['seconds']:.2f} s"
    if data["status"] != "ok":
        print(f"{data['clip']}: {data['status'].upper()}: {data['reason']}; the outputs stop "
              "there")  # fmt: skip
        tracked = f"{motion.duration:.2f} of {tracked}"  # the run ended early: say how early
    print(
        f"{data['clip']}: {tracked} tracked, fell={data['fell']}, "
        f"mean joint error {data['mean_joint_error_rad']:.3f} rad, root error "
        f"{data['root_error_m']:.3f} m, {data['realtime_factor']:.2f}x real time"
    )
    if at_end is not None and data["status"] == "ok":
        done = "walking as the clip does" if at_end["judged_as"] == "walk" else "standing still"
        if at_end["recovered"]:
            print(f"at the end: recovered, {done}")
        else:
            print(f"at the end: NOT recovered, upright but not {done} ({at_end['why']}); it "
                  "may still fall (--seconds to run longer)")  # fmt: skip
    if infeasible is not None and infeasible >= FEASIBILITY_NOTE_S:
        print(
            f"note: for {infeasible:.2f} s of this span the clip asks for more moment than one "
            "foot can give this character (`reactmocap feasibility`): no physical tracker "
            "holds the mocap exactly there"
        )


def _kwargs(args: argparse.Namespace) -> dict[str, object]:
    return {
        "kp": args.kp,
        "kv": args.kv,
        "friction": args.friction,
        "record_fps": args.fps,
        "total_mass": args.mass,
        "root_assist": args.root_assist,
        "controller": args.controller,
        "params": {"stepping": True} if args.stepping else None,
    }


class _SimProgress:
    """Progress bar over simulated milliseconds (quiet unless stderr is a terminal)."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.bar: Progress | None = None

    def __enter__(self) -> Callable[[float, float], None]:
        return self.tick

    def tick(self, t: float, seconds: float) -> None:
        if self.bar is None:
            self.bar = Progress(round(1000 * seconds), f"{self.label} (ms simulated)")
        self.bar.update(round(1000 * t) - self.bar.done)

    def __exit__(self, exc_type: type[BaseException] | None, *exc: object) -> None:
        if self.bar is not None:
            if exc_type is None:
                self.bar.update(self.bar.total - self.bar.done)
            self.bar.__exit__(None, None, None)


def _simulate(args: argparse.Namespace, label: str, run: Callable[..., Any], **call: object) -> int:
    """Read the clip, run ``run`` (``track_clip`` or ``push_clip``) on it with a progress bar
    and the shared flags, write the outputs."""
    from reactmocap.library.bodyparts import load_rules, parts_for

    motion = _read(args.clip)
    parts = parts_for(motion.skeleton, load_rules(args.parts)) if args.parts else None
    with _SimProgress(label) as tick:
        result = run(motion, on_tick=tick, parts=parts, **call, **_kwargs(args))
    at_end = _at_end(result) if label == "push" else None
    _write_outputs(args, motion, result.motion, result.report, at_end)
    return 3 if args.strict and result.report.status != "ok" else 0


def _track(args: argparse.Namespace) -> int:
    from reactmocap.sim.tracking import track_clip

    return _simulate(args, "track", track_clip, start=args.start, seconds=args.seconds)


def _push(args: argparse.Namespace) -> int:
    from reactmocap.sim.tracking import push_clip

    return _simulate(
        args, "push", push_clip, time=args.time, body=args.body, force=list(args.force),
        duration=args.duration, seconds=args.seconds,
    )  # fmt: skip
