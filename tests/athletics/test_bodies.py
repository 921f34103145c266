"""The thesis bodies as Characters: masses and inertias from the listing, the explicit-inertial
option of build_character, the anatomical frames, and a mocap skeleton as an athlete."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from reactmocap.athletics.bodies import athlete, thesis_character, thesis_skeleton
from reactmocap.athletics.scene import stand_angles
from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.library.anthropometry import SEXES
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_log
from reactmocap.sim.character import SegmentInertia, build_character
from reactmocap.sim.reference_bodies import reference_body_model, reference_total_mass


def _whole_body(
    model: mujoco.MjModel, qpos: np.ndarray | None = None
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, COM and inertia about the COM (world) of everything but the world body."""
    data = mujoco.MjData(model)
    if qpos is not None:
        data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    mass = float(model.body_mass[1:].sum())
    com = (model.body_mass[1:, None] * data.xipos[1:]).sum(axis=0) / mass
    inertia = np.zeros((3, 3))
    for b in range(1, model.nbody):
        rot = data.ximat[b].reshape(3, 3)
        d = data.xipos[b] - com
        inertia += rot @ np.diag(model.body_inertia[b]) @ rot.T
        inertia += model.body_mass[b] * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


@pytest.mark.parametrize("sex", SEXES)
def test_thesis_character_keeps_the_listing_mass_and_inertia(sex: str) -> None:
    ch = thesis_character(sex)
    assert ch.total_mass == pytest.approx(reference_total_mass(sex), abs=1e-9)
    ref = reference_body_model(sex, floor=False)
    m_ref, c_ref, i_ref = _whole_body(ref)
    q = ch.model.qpos0.copy()
    q[:3] = ch.body_pos[0]  # the listing pose: root at the hips' midpoint, all joints zero
    m, c, inertia = _whole_body(ch.model, q)
    assert m == pytest.approx(m_ref, abs=1e-9)
    # the listing prints each COM to 1 um; the reference model chains its joint vectors
    assert np.allclose(c, c_ref, atol=2e-6)
    assert np.allclose(inertia, i_ref, atol=1e-5)  # the parallel-axis merge


def test_explicit_inertials_replace_the_geometry_mass() -> None:
    skel, parts = thesis_skeleton("male")
    seg = {b: SegmentInertia(2.0, (0.0, 0.0, 1.0), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)))
           for b in ("pelvis", "waist", "chest", "head") + tuple(
               f"{s}_{p}" for s in "lr" for p in ("upper_arm", "forearm", "hand", "thigh",
                                                  "shin", "foot"))}  # fmt: skip
    ch = build_character(skel, parts, inertials=seg)
    assert ch.total_mass == pytest.approx(32.0)
    assert all(v == pytest.approx(2.0) for v in ch.segment_masses().values())
    plain = build_character(skel, parts)  # backwards compatible: geometry mass by default
    assert plain.inertials is None
    assert plain.total_mass == pytest.approx(75.0)
    with pytest.raises(SimulationError, match="lack bodies"):
        build_character(skel, parts, inertials={"pelvis": seg["pelvis"]})


def test_anatomical_frames_stand_the_thesis_body_as_modelled() -> None:
    ath = athlete("male")
    # legs and trunk are neutral as the listing has them; the T-posed arms are turned down
    legs = [ath.neutral[i] for i in (0, 10, 11, 12)]
    assert max(np.linalg.norm(quat_log(q)) for q in legs) < 1e-3
    assert np.linalg.norm(quat_log(ath.neutral[4])) == pytest.approx(np.pi / 2, abs=0.1)
    angles = stand_angles(ath)
    assert np.allclose(ath.joint_angles(ath.joint_quats(angles)), angles, atol=1e-9)
    q = ath.standing_qpos(angles)
    model = ath.character.model
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_forward(model, data)
    assert data.subtree_com[1][2] == pytest.approx(1.03, abs=0.03)  # standing COM height


def test_a_mocap_skeleton_becomes_an_athlete(guard: Motion) -> None:
    ath = athlete(guard)
    assert ath.mass == pytest.approx(75.0)
    q = ath.standing_qpos(stand_angles(ath))
    model = ath.character.model
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_forward(model, data)
    # standing upright: head above the pelvis above the feet
    head, pelvis = data.xpos[model.body("head").id], data.xpos[model.body("pelvis").id]
    assert head[2] > pelvis[2] > 0.7
    assert np.hypot(*(head[:2] - pelvis[:2])) < 0.15


def test_unknown_bodies_list_the_valid_ones(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(UnknownKeyError, match="male"):
        athlete("robot")
    with pytest.raises(ConfigError, match="does not exist"):
        athlete(tmp_path / "missing.bvh")


def test_joint_quats_buffered_path_equals_the_plain_one_to_the_bit() -> None:
    # the control ticks' (15, 3) float64 angles go through buffers; anything else through
    # quat_from_euler and the plain products: the same values and zero signs
    ath = athlete("male")
    rng = np.random.default_rng(7)
    for _ in range(100):
        angles = rng.uniform(-2.0, 2.0, (15, 3))
        angles[rng.random((15, 3)) < 0.15] = -0.0
        fast = ath.joint_quats(angles)
        plain = ath.joint_quats(angles.tolist())  # type: ignore[arg-type]
        np.testing.assert_array_equal(fast, plain)
        np.testing.assert_array_equal(np.signbit(fast), np.signbit(plain))
    assert ath.joint_quats(angles) is not ath.joint_quats(angles)  # a new array each call


def test_senses_sole_corners_equal_sole_corners_world() -> None:
    from reactmocap.athletics.running import running_start
    from reactmocap.athletics.scene import athletics_world
    from reactmocap.athletics.senses import Senses
    from reactmocap.sim.feet import SoleCorners, foot_soles, sole_corners_world

    ath = athlete("male")
    world = athletics_world(ath)
    qpos, qvel = running_start(ath, 3.0)
    world.set_pose(0, qpos, qvel)
    senses = Senses(world, ath)
    _, soles, local = foot_soles(world, 0, "test")
    corners = SoleCorners(world.data, soles, local)
    for k in range(5):
        world.step(40)
        senses.update(float(k))
        d = world.data  # the oracle: each corner rotated and moved by its sole geom's frame
        rot = d.geom_xmat[soles].reshape(2, 3, 3)
        want = np.einsum("fij,fkj->fki", rot, local) + d.geom_xpos[soles][:, None]
        np.testing.assert_array_equal(sole_corners_world(d, soles, local), want)
        np.testing.assert_array_equal(corners(), want)
        np.testing.assert_array_equal(senses.sole_corners(), want)
        low = float((want - world.data.geom_xpos[senses.floor]).reshape(-1, 3)[:, 2].min())
        assert senses.clearance == low  # the level floor's shortcut: the product's value
    assert corners() is not corners()  # a new array each call
