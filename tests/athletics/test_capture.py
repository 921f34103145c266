"""Perturbed starts (issue 19's capture regions): the vertical leap maneuver lands with the
vertical leap's own landing. Starts from ``capture_region``'s full-size distribution, seed 0."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from reactmocap.athletics import tables
from reactmocap.athletics.maneuvers import Perturbation, load_maneuver, run_maneuver

VERTICAL_LEAP = (
    Path(__file__).resolve().parents[2] / "examples/athletics/maneuvers/vertical_leap.toml"
)
FULL = {"joint_sd": math.radians(3.0), "pitch_sd": math.radians(2.0), "velocity_sd": 0.05,
        "spin_sd": 0.1}  # fmt: skip


def _starts(n: int) -> list[Perturbation]:
    rng = np.random.default_rng(0)
    return [Perturbation.sample(rng, **FULL) for _ in range(n)]


def test_the_vertical_leap_lands_with_the_vertical_leaps_own_delta() -> None:
    """Start 9 takes off with almost no pitch momentum (-0.3 kg m^2/s; the nominal -2): with
    the drops' delta (-0.04) its feet land 9 cm behind the COM and it falls forward off its
    toes; with the vertical leap's (-0.01) it lands."""
    m = load_maneuver(VERTICAL_LEAP)
    land = next(i for i, p in enumerate(m.phases) if p.controller == "land")
    assert m.phases[land].params["delta"] == tables.VERTICAL_LANDING["male"][1]
    start = _starts(10)[9]
    r = run_maneuver(m, perturbation=start, fps=10.0).report
    assert r["landed"] and not r["fell"]
    phases = list(m.phases)
    phases[land] = dataclasses.replace(phases[land], params={})
    old = run_maneuver(dataclasses.replace(m, phases=tuple(phases)), perturbation=start, fps=10.0)
    assert old.report["fell"]
