"""Stand-ins for the response pipeline, for tests of the batch machinery only (worker crashes
cannot be provoked through the real pipeline)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from reactmocap.response.scenario import Scenario


def fake_report(scenario: Scenario, out_dir: Path | None = None) -> dict[str, Any]:
    f = scenario.recipient.facing_deg
    return {
        "scenario": scenario.name,
        "matched": {"clip": "guard", "frame": int(f), "distance": f / 100},
        "quality": {
            "match_distance": f / 100,
            "blend_root_offset_max_m": 0.01,
            "blend_joint_correction_max_rad": f / 1000,
            "stitch_velocity_jump_rad_s": 1.0,
            "foot_skate_m": 0.02,
            "penetration_max_m": 0.0,
            "fell": False,
            "intended_fall": False,
        },
        "timings_s": {
            "scan": 0.0,
            "sim1": 0.0,
            "search": 0.0,
            "sim2": 0.0,
            "blend": 0.0,
            "total": 0.0,
        },
    }


def crash_at_90(scenario: Scenario, out_dir: Path | None = None) -> dict[str, Any]:
    """Kills its worker process (no exception, no cleanup) for the 90 degree scenario."""
    if scenario.recipient.facing_deg == 90:
        os._exit(3)
    return fake_report(scenario, out_dir)
