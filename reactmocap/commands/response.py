"""``respond SCENARIO.toml`` and ``demo``."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["register"]

DEMO_SCENARIO = Path(__file__).resolve().parents[2] / "examples" / "front_kick.toml"


def register(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    rsp = sub.add_parser("respond", help="run one response scenario (TOML)")
    rsp.add_argument("scenario", type=Path)
    rsp.add_argument("--out", type=Path, required=True, help="output folder")
    rsp.add_argument("--plot", action="store_true", help="also write plot.png")
    rsp.add_argument("--video", action="store_true", help="also write a video")
    rsp.set_defaults(func=_respond)

    demo = sub.add_parser("demo", help="run the bundled demo scenario on the synthetic clips")
    demo.add_argument("--out", type=Path, default=Path("out/demo"))
    demo.add_argument("--plot", action="store_true")
    demo.add_argument("--video", action="store_true")
    demo.set_defaults(func=_demo)


def _run(scenario_path: Path, out: Path, plot: bool, video: bool) -> int:
    from reactmocap.response.pipeline import run_scenario
    from reactmocap.response.scenario import load_scenario

    scenario = load_scenario(scenario_path)
    report = run_scenario(scenario, out, plot=plot, video=video)
    m = report["matched"]
    q = report["quality"]
    print(
        f"matched {m['clip']} frame {m['frame']} (D={m['distance']:.3f}, "
        f"yaw {m['yaw_deg']:.1f} deg) in {report['timings_s']['total']:.2f} s; "
        f"fell={q['fell']} penetration={q['penetration_max_m']:.3f} m"
    )
    for key, path in report["outputs"].items():
        print(f"  {key:10s} {path}")
    return 0


def _respond(args: argparse.Namespace) -> int:
    return _run(args.scenario, args.out, args.plot, args.video)


def _demo(args: argparse.Namespace) -> int:
    return _run(DEMO_SCENARIO, args.out, args.plot, args.video)
