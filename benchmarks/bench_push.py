"""Push recovery while tracking (prints figures; run ``.venv/bin/python benchmarks/bench_push.py``).

The largest chest push (``--duration`` s, 8 directions relative to the character's heading) that
a standing and a walking shared clip survive, by bisection on the force: upright (pelvis above
half its start height) until ``--after`` s past the push. Writes the figures as JSON and a polar
plot beside Wooten's standing figure (thesis Fig. 7.7, as far as the text gives it) and
SIMBICON's 350 N diagonal push while walking (Yin et al. 2007).

Survival is not monotonic in the force once the tracker steps (a harder push can land a better
step), so a bisection's answer is a value that was survived with every tested force below it
that the search probed, not a guaranteed threshold; ``--forces`` sweeps fixed forces instead.

"Upright to the window's end" counts a body still stepping, still falling or thrown into the
air when the window ends. ``--still`` also judges each push by the body's state at the window's
end (:func:`reactmocap.sim.end_state`: the centre of mass slower than 0.3 m/s, its capture point
within 5 cm of the feet on the floor, a sole within 5 cm of the floor): a sweep then prints ``x``
settled, ``m`` upright but still moving, ``A`` upright with no foot on the floor, ``.`` fell, and
counts both verdicts from the same runs; a bisection searches the settled verdict.
``--still-more`` tracks the pushes not settled at the window's end longer, up to the clip's end
(the clips end 0-2.4 s after the 2 s window), to tell a body still stepping toward a stand
("s") from one still falling ("f", "m").

A walk is never still: ``--still`` judges a walking push by :func:`reactmocap.sim.walk_state`
instead (upright and walking as the clip does over the window's last 0.6 s: the centre of
mass's speed within 30% of the clip's, its heading within 30 deg, the capture point within
0.6 m of the feet on the floor, each foot down in it): ``x`` walking, ``m`` upright but not.
A walking push whose clip (played faster after a push, ``warp_gain``) reaches its last frame
before the window ends is judged on a held clip pose: its mark is upper-case (``X``, ``M``, and
``:`` for a fall) and it is counted apart, never as recovered by the walking verdict. A window
past the clip's end is cut at it (at rate 1) and the sweep prints the window it ran.
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.errors import ConfigError
from reactmocap.io import atomic_write, atomic_write_text
from reactmocap.library.motion import Motion
from reactmocap.sim.controllers.registry import controller_spec

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT / ".." / "shared" / "mocap" / "bandai-namco-1"
LABELS = ("front", "front-left", "left", "back-left", "back", "back-right", "right", "front-right")
#: Wooten's standing figure as the brief summarises thesis Fig. 7.7 (the plotted values are not
#: in the text): about 200 N front and back, 100 N sideways, 0.25 s at the sternum
WOOTEN_STANDING_N = (200.0, 141.0, 100.0, 141.0, 200.0, 141.0, 100.0, 141.0)
#: SIMBICON's walking figure (Yin et al. 2007): 350 N for 0.2 s, diagonal, survived
SIMBICON_WALKING_N = 350.0
#: the walking pushes' duration (s), SIMBICON's
WALK_PUSH_S = 0.2


def _clip(name: str) -> Motion:
    from reactmocap.library.bvh import read_bvh

    return read_bvh(SHARED / f"dataset-1_{name}.bvh")


def heading(motion: Motion, time_s: float) -> float:
    """The character's heading at clip time ``time_s``: the mean of its soles' yaw (rad)."""
    from reactmocap.sim import World, build_character
    from reactmocap.sim.reference import reference_path

    world = World(build_character(motion, frame=0))
    path = reference_path(world, 0, motion)
    assert path.sole_yaw is not None
    yaw = path.sole_yaw[min(round(time_s * path.fps), path.num_frames - 1)]
    return float(np.arctan2(np.sin(yaw).sum(), np.cos(yaw).sum()))


@dataclass(frozen=True)
class Judge:
    """What counts as a recovered push: upright to the window's end; ``settled`` > 0: the
    pelvis within that many m of the mocap's there; ``still``: settled there
    (:func:`reactmocap.sim.end_state`); ``more`` > 0: a push upright but not settled there is
    tracked up to that many s longer (not past the clip's end) to see whether it settles."""

    settled: float = 0.0
    still: bool = False
    more: float = 0.0
    #: judge ``still`` by :func:`reactmocap.sim.walk_state` (a walk), not by ``end_state``
    walk: bool = False


Job = tuple[str, float, float, float, float, float, dict[str, Any], Judge]


def _clip_end_reached() -> list[float]:
    """Record, in this process, the earliest rollout time at which the anchored tracker's clip
    clock (which a pushed walk plays faster) reaches the clip's last frame: ``[inf]`` until
    it does; reset it to ``[inf]`` before each run. The tracker keeps its clock to itself, so
    its slow tick is wrapped here (a benchmark's probe, not the package's behaviour)."""
    from reactmocap.sim.controllers.anchoring import AnchoredReference

    reached = _REACHED
    if not getattr(AnchoredReference.update_ground, "_records_clip_end", False):
        plain = AnchoredReference.update_ground

        def update_ground(self: AnchoredReference, t: float) -> None:
            plain(self, t)
            if self.clock.frame(t) >= self.path.num_frames - 1 - 1e-9:
                reached[0] = min(reached[0], t)

        update_ground._records_clip_end = True  # type: ignore[attr-defined]
        setattr(AnchoredReference, "update_ground", update_ground)  # noqa: B010
    return reached


_REACHED = [float("inf")]


def verdict(job: Job) -> str:
    """One push's mark: "." fell in the window, "x" recovered (see :class:`Judge`); with
    ``still``, of the upright but not settled: "A" no foot on the floor, "m" still moving,
    and with ``more``: "s" settled later, "f" fell later; a walk (``judge.walk``): "x" walking
    as the clip does (:func:`reactmocap.sim.walk_state`), "m" not; upper-case ("X", "M") and
    ":" for a fall: the clip reached its last frame inside the window (a held clip pose)."""
    name, at, angle, force, duration, after, params, judge = job
    from reactmocap.sim import end_state, push_clip, walk_state

    motion = _clip(name)
    start = max(0.0, at - 0.5)
    window = at - start + duration + after

    def run(seconds: float) -> Any:
        return push_clip(
            motion, time=at, body="chest",
            force=[force * np.cos(angle), force * np.sin(angle), 0.0], duration=duration,
            start=start, seconds=min(motion.duration - start, seconds), params=params,
        )  # fmt: skip

    reached = _clip_end_reached()
    reached[0] = float("inf")
    res = run(window)
    # the clip held before the run's last frame (at rate 1 it reaches it only at the end)
    ran_out = reached[0] < res.report.seconds - 1.0 / motion.fps
    if res.report.status != "ok" or (judge.settled > 0 and res.errors.root[-1] >= judge.settled):
        return ":" if ran_out else "."
    if not judge.still:
        return "X" if ran_out else "x"
    if judge.walk:
        mark = "x" if walk_state(res).walking else "m"
        return mark.upper() if ran_out else mark
    end = end_state(res)
    if end.settled:
        return "x"
    mark = "A" if end.lowest_sole > 0.05 else "m"
    if judge.more > 0 and motion.duration - start > res.report.seconds + 1e-6:
        later = run(window + judge.more)
        if later.report.status != "ok":
            return "f"
        mark = "s" if end_state(later).settled else mark
    return mark


def survives(job: Job) -> bool:
    """Recovered by the job's :class:`Judge` (a push that settles only after the window, "s",
    is not)."""
    return verdict(job) == "x"


def largest(
    job: tuple[str, float, float, float, float, dict[str, Any], float, int, Judge],
) -> float:
    """Bisection on the force in ``[0, hi]`` (``steps`` halvings)."""
    name, at, angle, duration, after, params, hi, steps, judge = job
    if survives((name, at, angle, hi, duration, after, params, judge)):
        return hi
    lo = 0.0
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        if survives((name, at, angle, mid, duration, after, params, judge)):
            lo = mid
        else:
            hi = mid
    return lo


def sweep(
    job: tuple[str, float, float, float, float, dict[str, Any], list[float], Judge],
) -> str:
    """One direction at each fixed force: a :func:`verdict` mark per force (a bisection
    reports whichever path it took where survival is not monotonic in the force)."""
    name, at, angle, duration, after, params, forces, judge = job
    return "".join(verdict((name, at, angle, f, duration, after, params, judge)) for f in forces)


def measure(name: str, at: float, duration: float, args: argparse.Namespace) -> list[Any] | None:
    """The row's eight directions, or None where the clip falls unpushed."""
    motion = _clip(name)
    yaw = heading(motion, at)
    params = json.loads(args.params)
    judge = Judge(args.settled, args.still, args.still_more, walk=duration == WALK_PUSH_S)
    if not survives((name, at, yaw, 0.0, duration, args.after, params, judge)):
        # a clip that falls unpushed in the window measures the tracker, not the push
        print(f"{name} falls unpushed within {args.after} s after {at} s: choose another clip")
        return None
    dirs = [k for k in range(8) if LABELS[k] in args.dirs]
    if args.forces:
        sweeps = [(name, at, yaw + k * np.pi / 4, duration, args.after, params, args.forces,
                   judge) for k in dirs]  # fmt: skip
        with ProcessPoolExecutor(max_workers=args.jobs) as pool:
            marks = dict(zip(dirs, pool.map(sweep, sweeps)))
        return [marks.get(k, "") for k in range(8)]
    jobs = [(name, at, yaw + k * np.pi / 4, duration, args.after, params, args.max_force,
             args.steps, judge) for k in dirs]  # fmt: skip
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        found = dict(zip(dirs, pool.map(largest, jobs)))
    return [found.get(k, float("nan")) for k in range(8)]


def _label(params: dict[str, Any]) -> str:
    # balance steps: from the start with ``stepping``, after a standing push by default
    if params.get("stepping") or params.get("step_pushed", True):
        return "with balance steps"
    return "no balance steps"


def plot(out: Path, runs: list[dict[str, Any]]) -> None:
    """``runs``: this script's JSON outputs, one line each per panel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ang = np.arange(9) * np.pi / 4
    ring = lambda v: np.r_[v, v[:1]]  # noqa: E731
    fig, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(11, 5.2))
    for ax, title in zip(axes, ("standing (push 0.25 s)", "walking (push 0.2 s)")):
        ax.set_theta_zero_location("N")
        ax.set_xticks(ang[:8], ["front", "", "left", "", "back", "", "right", ""])
        ax.set_title(title, pad=14)
    for run in runs:
        for ax, key in zip(axes, ("standing", "walking")):
            if "max_force_n" not in run.get(key, {}):  # absent, or fell unpushed
                continue
            forces = np.array(run[key]["max_force_n"])
            # a walk's push never turns balance steps on
            how = f", {_label(run['params'])}" if key == "standing" else ""
            ax.plot(ang, ring(forces), "o-", label=f"{run[key]['clip']}{how}")
    axes[0].plot(ang, ring(np.array(WOOTEN_STANDING_N)), "--",
                 label="Wooten Fig. 7.7, approx. (no stepping)")  # fmt: skip
    axes[1].plot(ang, np.full(9, SIMBICON_WALKING_N), "--", label="SIMBICON goal 350 N")
    for ax in axes:
        ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.28), fontsize=8)
    fig.suptitle("Largest survived chest push (N), directions relative to the heading")
    fig.tight_layout()
    with atomic_write(out, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--standing", default="bye_normal_001:1.0", help="clip:push time (s)")
    ap.add_argument("--walking", default="walk_normal_001:2.0", help="clip:push time (s)")
    ap.add_argument("--after", type=float, default=2.0, help="seconds tracked after the push")
    ap.add_argument("--max-force", type=float, default=800.0)
    ap.add_argument("--steps", type=int, default=6, help="bisection halvings")
    ap.add_argument("--params", default="{}", help="controller parameters (JSON)")
    ap.add_argument("--settled", type=float, default=0.0,
                    help="also require the pelvis within this many m of the mocap's at the "
                         "window's end (0: upright is enough)")  # fmt: skip
    ap.add_argument("--still", action="store_true",
                    help="also require the body settled at the window's end (COM slower than "
                         "0.3 m/s, capture point over the feet on the floor, a foot down): "
                         "sweeps print x settled, m still moving, A in the air, . fell")  # fmt: skip
    ap.add_argument("--still-more", type=float, default=0.0,
                    help="with --still, track a push upright but not settled up to this many s "
                         "longer (not past the clip's end): s settled then, f fell")  # fmt: skip
    ap.add_argument("--forces", type=float, nargs="+",
                    help="instead of the bisection, try each of these forces (N) in each "
                         "direction and print x (survived) or . (fell) per force")  # fmt: skip
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", choices=("standing", "walking"), help="measure one clip only")
    ap.add_argument("--dirs", nargs="+", choices=LABELS, default=list(LABELS),
                    help="directions to measure (the others print nan)")  # fmt: skip
    ap.add_argument("--json", type=Path, help="write the figures here")
    ap.add_argument("--plot", type=Path, help="write the polar plot (PNG) here")
    ap.add_argument("--overlay", type=Path, nargs="*", default=[],
                    help="earlier --json outputs drawn in the same plot")  # fmt: skip
    ap.add_argument("--plot-only", action="store_true", help="plot --overlay files only")
    args = ap.parse_args(argv)
    try:  # here, not in a worker's traceback
        controller_spec("wholebody").params(json.loads(args.params))
    except (json.JSONDecodeError, ConfigError) as e:
        ap.error(f"--params: {e}")
    if not SHARED.is_dir():
        print(f"(no shared clips under {SHARED.resolve()}: nothing to measure)")
        return 0
    earlier = [json.loads(p.read_text()) for p in args.overlay]
    if args.plot_only:
        if args.plot:
            plot(args.plot, earlier)
        return 0
    out: dict[str, Any] = {"labels": LABELS, "params": json.loads(args.params)}
    for key, dur in (("standing", 0.25), ("walking", WALK_PUSH_S)):
        if args.only and key != args.only:
            continue
        name, at = getattr(args, key).split(":")
        t0 = time.perf_counter()
        forces = measure(name, float(at), dur, args)
        took = time.perf_counter() - t0
        if forces is None:  # nothing to measure: recorded, not a crash
            out[key] = {
                "clip": name,
                "time_s": float(at),
                "duration_s": dur,
                "falls_unpushed": True,
            }
            continue
        if args.forces:
            total = sum(len(m) for m in forces)
            upright = ["".join("." if c in ".:" else "x" for c in m) for m in forces]
            n = sum(m.count("x") for m in upright)
            out[key] = {"clip": name, "time_s": float(at), "duration_s": dur,
                        "forces_n": args.forces, "survived": upright}  # fmt: skip
            counts = f"; survived {n}/{total}"
            motion = _clip(name)
            start = max(0.0, float(at) - 0.5)
            full = float(at) - start + dur + args.after
            # notes printed after the counts: a cut window, pushes judged on a held clip pose
            notes = ""
            if motion.duration - start < full - 1e-9:
                notes += f" (window cut at the clip's end, {motion.duration - float(at):.2f} s after the push)"
            ran_out = sum(sum(c in "XM:" for c in m) for m in forces)
            if ran_out:  # upper-case marks and ":": never counted walking
                out[key]["clip_ran_out"] = ran_out
                notes += f"; {ran_out} reached the clip's last frame inside the window (X M :)"
            if args.still and key == "walking":
                out[key]["walking"] = forces
                counts += f" upright, walking {sum(m.count('x') for m in forces)}/{total}"
                print(f"{key} {name} @ {at} s, {dur} s pushes at {args.forces} N ({took:.0f} s): "
                      + ", ".join(f"{lab} {m}" for lab, m in zip(LABELS, forces) if m)
                      + counts + notes)  # fmt: skip
                continue
            if args.still:
                out[key]["settled"] = forces
                counts += f" upright, settled {sum(m.count('x') for m in forces)}/{total}"
                if args.still_more > 0:
                    later = sum(m.count("s") for m in forces)
                    counts += f" (+{later} settled up to {args.still_more} s later)"
            counts += notes
            print(f"{key} {name} @ {at} s, {dur} s pushes at {args.forces} N ({took:.0f} s): "
                  + ", ".join(f"{lab} {m}" for lab, m in zip(LABELS, forces) if m)
                  + counts)  # fmt: skip
            continue
        out[key] = {"clip": name, "time_s": float(at), "duration_s": dur, "max_force_n": forces}
        print(f"{key} {name} @ {at} s, {dur} s pushes ({took:.0f} s): "
              + ", ".join(f"{lab} {f:.0f} N" for lab, f in zip(LABELS, forces)))  # fmt: skip
    if args.json:
        atomic_write_text(args.json, json.dumps(out, indent=2) + "\n")
    if args.plot and not args.forces:
        plot(args.plot, [*earlier, out])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
