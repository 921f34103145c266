"""``respond SCENARIO.toml`` and ``demo``."""

from __future__ import annotations

import argparse
from pathlib import Path

from reactmocap.commands import output_dir
from reactmocap.errors import ConfigError

__all__ = ["register"]

DEMO_SCENARIO = Path(__file__).resolve().parents[2] / "examples" / "front_kick.toml"
#: a chest displacement (``reaction_displacement_m``) below this (m) is printed as no visible
#: reaction: its direction against the impulse is noise then
NO_REACTION_M = 0.01


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    rsp = sub.add_parser(
        "respond", help="run one response scenario (TOML)", description=_OUTPUTS,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )  # fmt: skip
    rsp.add_argument("scenario", type=Path)
    rsp.add_argument("--out", type=output_dir, required=True, help="output folder")
    rsp.add_argument("--parts", type=Path, help="body-part rules TOML (over the scenario's)")
    _flags(rsp)
    rsp.set_defaults(func=_respond)

    demo = sub.add_parser(
        "demo", help="run the bundled demo scenario (a front kick) on the synthetic clips",
        description=_OUTPUTS, formatter_class=argparse.RawDescriptionHelpFormatter,
    )  # fmt: skip
    demo.add_argument("--out", type=output_dir, default=Path("out/demo"), help="output folder")
    _flags(demo)
    demo.set_defaults(func=_demo)


_OUTPUTS = """Simulates the hit, finds the continuation in the library, and writes into --out:
  recipient.bvh   the hit character: its clip, the physical reaction, the found clip
  attacker.bvh    the attacking character (with an [attacker])
  report.json     the match, the impact (time, peak force, impulse), quality figures and
                  warnings (every field: docs/report.md)
  plot.png        (--plot) top view of the chest's path and the pelvis height over time
  video.mp4       (--video) a MuJoCo render with the found clip as a ghost and the impact
                  marked; a stick-figure GIF where no GL context can be made
Warnings (overlap, large blend corrections, an attacker that never touched...) are printed;
--strict makes them an error (exit 3)."""


def _flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plot", action="store_true", help="also write plot.png")
    p.add_argument("--video", action="store_true", help="also write a video")
    p.add_argument("--strict", action="store_true", help="exit 3 when the report has warnings")


def _run(scenario_path: Path, out: Path, plot: bool, video: bool, strict: bool,
         parts: Path | None = None) -> int:  # fmt: skip
    from reactmocap.response.pipeline import run_scenario
    from reactmocap.response.scenario import load_scenario

    scenario = load_scenario(scenario_path)
    if parts is not None:
        from dataclasses import replace

        from reactmocap.library.bodyparts import load_rules

        load_rules(parts)
        scenario = replace(scenario, parts=parts.resolve())
    report = run_scenario(scenario, out, plot=plot, video=video)
    m = report["matched"]
    q = report["quality"]
    print(
        f"matched {m['clip']} frame {m['frame']} (D={m['distance']:.3f}, "
        f"yaw {m['yaw_deg']:.1f} deg) in {report['timings_s']['total']:.2f} s; "
        f"fell={q['fell']} penetration={q['penetration_max_m']:.3f} m"
    )
    shift, impulse = q["reaction_displacement_m"], q["contact_impulse_Ns"]
    if shift < NO_REACTION_M:
        what = f"no visible reaction (chest {shift:.3f} m off its clip; impulse {impulse:.1f} N s)"
    else:
        what = (f"reaction {shift:.2f} m ({q['reaction_direction_error_deg']:.0f} deg off the "
                f"impulse of {impulse:.1f} N s)")  # fmt: skip
    print(f"{what}, transition {q['transition_s']:.2f} s")
    for key, path in report["outputs"].items():
        print(f"  {key:10s} {path}")
    for w in report["warnings"]:
        print(f"warning: {w}")
    return 3 if strict and report["warnings"] else 0


def _respond(args: argparse.Namespace) -> int:
    return _run(args.scenario, args.out, args.plot, args.video, args.strict, args.parts)


def _demo(args: argparse.Namespace) -> int:
    if not DEMO_SCENARIO.is_file():
        # the demo's scenario and clips are the repository's, not the installed package's
        raise ConfigError(
            f"the demo scenario {DEMO_SCENARIO} is missing: `demo` runs from a source checkout "
            "installed as the README says (pip install -e .); elsewhere run `respond "
            "SCENARIO.toml --out DIR` on your own scenario"
        )
    return _run(DEMO_SCENARIO, args.out, args.plot, args.video, args.strict)
