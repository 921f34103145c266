"""Cloth trousers driven by the runner: finite throughout, touching the body, and one-way (the
runner's motion is the same with and without them) unless feedback is asked for."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.athletics.cloth import CLOTHES, Cloth, ClothSpec
from reactmocap.athletics.run_course import run_course
from reactmocap.errors import ConfigError

SECONDS = 1.2


@pytest.fixture(scope="module")
def dressed():  # type: ignore[no-untyped-def]
    return run_course(3.5, seconds=SECONDS, cloth="pants", fps=30.0)


def test_cloth_never_goes_non_finite(dressed) -> None:  # type: ignore[no-untyped-def]
    rep = dressed.report
    assert rep["status"] == "ok", rep.get("reason")
    assert rep["cloth_finite"] is True
    frames = np.array(dressed.cloth.frames)
    assert frames.shape[0] >= 30 and frames.shape[1] == rep["cloth_vertices"] > 100
    assert np.isfinite(frames).all()
    assert np.isfinite(dressed.cloth.data.qvel).all()


def test_cloth_is_worn(dressed) -> None:  # type: ignore[no-untyped-def]
    """The trousers stay on: the vertices stay near the pelvis and legs (within a leg's
    length of the pelvis) and they touch the body (contacts happened)."""
    rep = dressed.report
    frames = np.array(dressed.cloth.frames)
    pelvis = np.array(dressed.cloth.frame_bodies)[:, 0, :3]
    dist = np.linalg.norm(frames - pelvis[:, None], axis=2)
    assert dist.max() < 1.0
    assert np.isfinite(rep["cloth_penetration_max_m"]) and rep["cloth_penetration_max_m"] > 0
    assert rep["cloth_penetration_mean_m"] < 0.02


def test_cloth_does_not_act_on_the_runner(dressed) -> None:  # type: ignore[no-untyped-def]
    bare = run_course(3.5, seconds=SECONDS, fps=30.0)
    assert np.array_equal(bare.rollout.qpos, dressed.rollout.qpos)


def test_cloth_options_are_checked() -> None:
    from reactmocap.athletics.bodies import athlete
    from reactmocap.athletics.scene import athletics_world

    world = athletics_world(athlete("male"))
    with pytest.raises(
        ConfigError, match=r"valid clothes are \['pants', 'pants-light', 'shorts'\]"
    ):
        Cloth(world, "kilt")
    with pytest.raises(ConfigError, match="slack"):
        ClothSpec(slack=-1.0)
    assert set(CLOTHES) == {"pants", "pants-light", "shorts"}
