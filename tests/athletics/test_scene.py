"""The athletics scene's contact models (issue 18: the -X slope's friction cone)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from reactmocap.athletics import run
from reactmocap.athletics.bodies import athlete
from reactmocap.athletics.maneuvers import Maneuver, Phase, run_maneuver
from reactmocap.athletics.scene import (
    ATHLETICS_WORLD,
    CONTACT_MODELS,
    SOLE_TORSION,
    athletics_world,
    contact_model,
    shins_off_floor,
)
from reactmocap.cli import main
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.world import World


def test_each_contact_model_sets_the_cone_and_the_soles_torsion() -> None:
    ath = athlete("male")
    worlds = {name: athletics_world(ath, contact=name) for name in CONTACT_MODELS}
    cones = {name: int(w.model.opt.cone) for name, w in worlds.items()}
    assert cones == {
        "pyramidal": int(mujoco.mjtCone.mjCONE_PYRAMIDAL),
        "elliptic": int(mujoco.mjtCone.mjCONE_ELLIPTIC),
        "elliptic+torsion": int(mujoco.mjtCone.mjCONE_ELLIPTIC),
    }
    soles = worlds["pyramidal"].characters[0].sole_ids
    for name in ("pyramidal", "elliptic"):
        assert (worlds[name].model.geom_condim[soles] == 3).all()
    torsion = worlds["elliptic+torsion"].model
    np.testing.assert_array_equal(torsion.geom_condim[soles], [4, 4])
    np.testing.assert_allclose(torsion.geom_friction[soles, 1], SOLE_TORSION)
    # only the soles change: every other geom as the elliptic world's
    others = np.setdiff1d(np.arange(torsion.ngeom), soles)
    np.testing.assert_array_equal(
        torsion.geom_condim[others], worlds["elliptic"].model.geom_condim[others]
    )


def test_the_default_contact_model_is_the_world_as_before() -> None:
    ath = athlete("female")
    before = World(ath.character, ATHLETICS_WORLD)  # what athletics_world built before
    shins_off_floor(before)
    now = athletics_world(ath).model
    assert now.opt.cone == before.model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL
    np.testing.assert_array_equal(now.geom_condim, before.model.geom_condim)
    np.testing.assert_array_equal(now.geom_friction, before.model.geom_friction)


def test_an_unknown_contact_model_names_the_valid_ones() -> None:
    with pytest.raises(UnknownKeyError, match=r"'cone'.*pyramidal.*elliptic\+torsion"):
        contact_model("cone")
    with pytest.raises(UnknownKeyError, match="valid models"):
        athletics_world(athlete("male"), contact="coulomb")
    with pytest.raises(ConfigError, match=r"contact must be one of \['pyramidal', 'elliptic'"):
        run("balance", "male", seconds=0.1, contact="coulomb")


def test_a_maneuver_and_the_cli_run_on_the_contact_model_asked_for(tmp_path: Path) -> None:
    m = Maneuver("stand", (Phase("balance", "never", {}),), "male", 0.2)
    r = run_maneuver(m, contact="elliptic", fps=10.0)
    assert r.rollout.world.model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert r.report["contact"] == "elliptic"
    assert "contact" not in run_maneuver(m, fps=10.0).report  # the default's report as before
    rep = tmp_path / "r.json"
    args = ["athletics", "balance", "--seconds", "0.2", "--out", str(tmp_path / "m.bvh")]
    assert main([*args, "--report", str(rep), "--contact", "elliptic+torsion"]) == 0
    assert json.loads(rep.read_text())["contact"] == "elliptic+torsion"


def test_on_the_elliptic_cone_he_stands_on_a_slope_rising_behind_where_the_pyramid_slides() -> None:
    # issue 18's -X slope (thesis 38.6 deg; ours 37.5 on the default pyramidal cone): at 41 deg
    # his feet slid off down the slope (4 m) on the pyramid and held on the exact cone (the
    # same coefficient 1.0; 2026-12-03, docs/athletics.md "The elliptic cone, opt-in")
    def rising_behind(contact: str) -> dict[str, object]:
        return run("balance", "male", check_range=False, seconds=3.0, slope=math.radians(41.0),
                   slope_dir=math.radians(180.0), contact=contact).report  # fmt: skip

    assert not rising_behind("pyramidal")["balanced"]
    held = rising_behind("elliptic")
    assert held["balanced"] and not held["fell"]
