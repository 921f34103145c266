"""The final blend lands exactly on the target; the transition schedule holds, then eases."""

from __future__ import annotations

import numpy as np

from reactmocap.library.motion import Motion
from reactmocap.response.blend import blend_poses, final_blend, smoothstep, transition_weights
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from tests.library.test_motion import random_motion


def angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(quat_log(quat_mul(quat_conj(a), b)), axis=-1)


def test_final_blend_starts_on_simulation_and_lands_on_target() -> None:
    sim = random_motion(t=40, seed=1)
    target = random_motion(t=40, seed=2).transformed(0.4, (0.3, -0.2))
    out = final_blend(sim, target)
    assert np.max(angle(out.rotations[0], sim.rotations[0])) < 1e-9
    assert np.max(angle(out.rotations[-1], target.rotations[-1])) < 1e-9
    np.testing.assert_allclose(out.global_positions()[-1], target.global_positions()[-1], atol=1e-9)
    np.testing.assert_allclose(out.root_positions[0], sim.root_positions[0], atol=1e-12)
    # root offset grows linearly: the midpoint carries half the final error
    err = target.root_positions[-1] - sim.root_positions[-1]
    mid_offset = out.root_positions[20] - sim.root_positions[20]
    np.testing.assert_allclose(mid_offset, err * 20 / 39, atol=1e-12)


def test_a_delayed_root_keeps_its_simulated_place_then_still_lands() -> None:
    sim = random_motion(t=40, seed=1)
    target = random_motion(t=40, seed=2).transformed(0.4, (0.3, -0.2))
    out = final_blend(sim, target, root_start=15.0)
    np.testing.assert_allclose(out.root_positions[:16], sim.root_positions[:16], atol=1e-12)
    np.testing.assert_allclose(out.root_positions[-1], target.root_positions[-1], atol=1e-12)
    err = target.root_positions[-1] - sim.root_positions[-1]
    np.testing.assert_allclose(out.root_positions[27] - sim.root_positions[27], err * 12 / 24,
                               atol=1e-12)  # fmt: skip


def test_blend_poses_weight_limits() -> None:
    a, b = random_motion(seed=3), random_motion(seed=4)
    w = np.linspace(0, 1, a.num_frames)
    out = blend_poses(a, b, w)
    assert np.max(angle(out.rotations[0], a.rotations[0])) < 1e-9
    assert np.max(angle(out.rotations[-1], b.rotations[-1])) < 1e-9
    # monotone progress: the distance to b shrinks as the weight grows
    d = angle(out.rotations, b.rotations).mean(axis=1) / np.maximum(
        angle(a.rotations, b.rotations).mean(axis=1), 1e-12
    )
    np.testing.assert_allclose(d, 1 - w, atol=1e-9)


def test_transition_weights_hold_then_ease() -> None:
    t = np.linspace(0, 1, 101)
    w = transition_weights(t, start=0.2, delay=0.15, end=0.8)
    assert np.all(w[t <= 0.35] == 0.0)
    assert np.all(w[t >= 0.8] == 1.0)
    assert np.all(np.diff(w) >= 0)
    mid = (0.35 + 0.8) / 2
    assert abs(transition_weights([mid], 0.2, 0.15, 0.8)[0] - 0.5) < 1e-12
    # ease-in/ease-out: zero slope at both ends (finite differences)
    h = 1e-6
    assert abs((smoothstep(h) - smoothstep(0)) / h) < 1e-5
    assert abs((smoothstep(1) - smoothstep(1 - h)) / h) < 1e-5


def test_blend_rejects_mismatched_motions() -> None:
    import pytest

    from reactmocap.errors import MotionError

    a = random_motion(t=10)
    with pytest.raises(MotionError, match="frames"):
        final_blend(a, random_motion(t=12))
    other = Motion(
        a.skeleton.with_offsets(a.skeleton.offsets),
        a.fps,
        a.root_positions,
        a.rotations,
    )
    assert final_blend(a, other).num_frames == 10
