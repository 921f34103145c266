"""Frohlich's backdrop (thesis 5.1.1, Fig. 5.4): a loop of limb motions with zero angular
momentum turns the body; the controls (hips alone, arms alone) show the loop is what does it."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from reactmocap.athletics.backdrop import Backdrop, backdrop, backdrop_keyframes
from reactmocap.athletics.maneuvers import Phase, load_maneuver, run_maneuver
from reactmocap.errors import ConfigError, ReactMocapError


@pytest.fixture(scope="module")
def back_one():  # type: ignore[no-untyped-def]
    return backdrop("male", "backward", 1)


def test_the_backdrop_turns_the_body_backward_with_no_momentum(back_one) -> None:  # type: ignore[no-untyped-def]
    r = back_one
    assert r["status"] == "ok"
    # one loop (pike, arms circled backward, open): ~51 deg backward, the body back in its
    # starting shape; the angular momentum stays under 1% of the moving limbs'
    assert r["rotation_deg"] <= -40.0
    assert r["momentum_drift"] < 0.01 and r["max_limb_momentum"] > 5.0
    # the loop the other way round turns it forward as far
    fwd = backdrop("male", "forward", 1)
    assert fwd["rotation_deg"] == pytest.approx(-r["rotation_deg"], abs=3.0)


def test_the_controls_turn_little_or_less(back_one) -> None:  # type: ignore[no-untyped-def]
    turn = 2.0 * math.pi
    # the hips alone (pike and open, arms still): a loop with no area, no turn
    hips = backdrop("male", keyframes=[(0, 0), (0, -2.2), (0, -2.2), (0, 0)])
    assert abs(hips["rotation_deg"]) < 2.0 and hips["momentum_drift"] < 0.01
    # the arms alone (the same circle in the layout): the windmill's ~22 deg, well under the
    # backdrop's, where the piked body's smaller inertia lets the circle turn it further
    arms = backdrop("male", keyframes=[(0, 0), (0, 0), (turn, 0), (turn, 0)])
    assert -30.0 < arms["rotation_deg"] < -10.0
    assert back_one["rotation_deg"] < 1.8 * arms["rotation_deg"]


@pytest.mark.parametrize("body", ["male", "female"])
def test_two_loops_turn_nearly_90_degrees(body: str) -> None:
    # thesis: "a partial somersault of nearly 90 degrees"; the turns add up loop by loop
    r = backdrop(body, "backward", 2)
    assert r["status"] == "ok" and r["momentum_drift"] < 0.01
    assert -110.0 <= r["rotation_deg"] <= -80.0
    one = backdrop(body, "backward", 1)["rotation_deg"]
    assert r["rotation_deg"] == pytest.approx(2 * one, rel=0.05)


def test_bad_backdrop_input_is_refused() -> None:
    with pytest.raises(ConfigError, match="direction"):
        backdrop_keyframes("sideways")
    with pytest.raises(ConfigError, match="pairs"):
        Backdrop([(0.0, 0.0, 0.0)])
    with pytest.raises(ConfigError, match="finite"):
        Backdrop([(0.0, 0.0), (math.nan, 0.0)])
    with pytest.raises(ConfigError, match="loops a whole number"):
        Backdrop(loops=1.5)  # type: ignore[arg-type]
    with pytest.raises(ReactMocapError, match="segment"):
        backdrop("male", segment=0.0)
    assert Backdrop(loops=3, segment=0.4).seconds == pytest.approx(3 * 3 * 0.4)


EXAMPLE = Path(__file__).resolve().parents[2] / "examples/athletics/torque_free/backdrop_drop.toml"


def test_the_backdrop_phase_runs_from_toml_in_a_drop() -> None:
    # a feet-first drop off the platform with no spin: the backdrop turns the body backward
    # in the air (-49.5 deg at the water), the forward loop forward
    m = load_maneuver(EXAMPLE)
    back = run_maneuver(m).report
    assert back["status"] == "ok" and back["entry_s"] is not None
    assert abs(back["liftoff_pitch_momentum"]) < 5.0  # next to none (the tuck's is ~50)
    assert back["rotation_deg"] <= -40.0
    # the forward loop, handing over when done (exit "done") to the entry's stretch
    bd = m.phases[-1]
    fwd = replace(bd, params={**bd.params, "direction": "forward"}, exit="done")
    res = run_maneuver(replace(m, phases=(*m.phases[:-1], fwd, Phase("stretch", "never"))))
    start = next(t for t, _, target in res.transitions if target.startswith("backdrop."))
    done = next(t for t, _, target in res.transitions if target.startswith("stretch."))
    assert done - start == pytest.approx(3 * 0.35, abs=0.02)
    # over the loop itself it turned forward (41 deg; the leap's small backward spin takes some,
    # and the stretch then turns it back)
    t, rotation = res.log["t"], res.log["rotation"]
    turned = math.degrees(rotation[np.searchsorted(t, done)] - rotation[np.searchsorted(t, start)])
    assert turned >= 30.0


def test_bad_backdrop_phases_are_refused_naming_the_field(tmp_path: Path) -> None:
    text = EXAMPLE.read_text()
    for bad, field in (('direction = "backward"', 'direction = "sideways"'),
                       ("loops = 1,", "loops = 1.5,"), ("loops = 1,", 'loops = "one",')):  # fmt: skip
        path = tmp_path / "bad.toml"
        path.write_text(text.replace(bad, field))
        with pytest.raises(ConfigError, match=r"phase\[3\]\.params"):
            load_maneuver(path)
