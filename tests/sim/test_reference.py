"""What controllers follow: the reference path of a clip on a character, its clock, and the one
velocity-from-poses function (checked against MuJoCo's own ``mj_differentiatePos``)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim import ClipClock, World, build_character, qvel_from_qpos, reference_path


def test_reference_path_is_the_clip_on_the_character(step_forward: Motion) -> None:
    """The path's poses are the clip's (MuJoCo body positions match the character's forward
    kinematics), its velocities integrate back to the poses, its arrays are read-only, and
    its stance is a single-support step: each foot lifts while the other stays planted."""
    world = World(build_character(step_forward))
    path = reference_path(world, 0, step_forward)
    n = step_forward.num_frames
    assert path.q.shape == (n, 67) and path.v.shape == path.a.shape == (n, 51)
    assert path.planted.shape == path.pivoting.shape == (n, 2) and path.fps == step_forward.fps
    for arr in (path.q, path.v, path.a, path.planted, path.pivoting):
        assert not arr.flags.writeable
    # central differences: the root moves by v dt between neighbouring frames
    dx = (path.q[2:, :3] - path.q[:-2, :3]) * step_forward.fps / 2
    assert np.allclose(dx, path.v[1:-1, :3])
    # a frame samples exactly; half-way is the mean (positions) with unit quaternions
    q5, v5, a5, planted5 = path.sample(5.0)
    assert np.allclose(q5, path.q[5], rtol=0, atol=1e-12)
    assert np.array_equal(v5, path.v[5]) and np.array_equal(a5, path.a[5])
    assert np.array_equal(planted5, path.planted[5])
    qh = path.sample(5.5)[0]
    assert np.allclose(qh[:3], (path.q[5, :3] + path.q[6, :3]) / 2)
    assert np.allclose(np.linalg.norm(qh[3:].reshape(-1, 4), axis=1), 1.0)
    assert path.planted.all(axis=1).any() and not path.planted.all()
    assert not (~path.planted).all(axis=1).any()  # a step: never both feet up
    assert np.array_equal(path.sample(-3.0)[0], path.sample(0.0)[0])  # clamped to the clip
    assert np.array_equal(path.sample(n + 5.0)[1], path.v[-1])
    with pytest.raises(ConfigError, match="pivot_rate"):
        reference_path(world, 0, step_forward, pivot_rate=float("nan"))
    # a controller follows its path on the rollout's clock (time 0 = its start frame)
    clock = path.clock(20 / step_forward.fps)
    for t, frame in ((0.0, 20.0), (0.5 / step_forward.fps, 20.5), (-1.0, 0.0), (1e3, n - 1.0)):
        assert clock.frame(t) == pytest.approx(frame, abs=1e-9)


def test_qpos_path_gives_the_same_reference(step_forward: Motion) -> None:
    world = World(build_character(step_forward))
    a = reference_path(world, 0, step_forward)
    q = world.characters[0].character.qpos_from_motion(step_forward)
    b = reference_path(world, 0, q, fps=step_forward.fps)
    for x, y in ((a.q, b.q), (a.v, b.v), (a.a, b.a), (a.planted, b.planted)):
        assert np.array_equal(x, y)
    with pytest.raises(ConfigError, match="fps"):
        reference_path(world, 0, q)
    with pytest.raises(ConfigError, match="qpos path"):
        reference_path(world, 0, q[:, :10], fps=30.0)


def test_qvel_from_qpos_is_mujocos_difference(step_forward: Motion) -> None:
    """Central differences in MuJoCo's conventions (free joint linear in the world, angular in
    the local frames): the same as ``mj_differentiatePos`` over the neighbouring frames."""
    ch = build_character(step_forward)
    q = ch.qpos_from_motion(step_forward)
    fps = step_forward.fps
    v = qvel_from_qpos(q, fps)
    m = ch.model
    ref = np.zeros(m.nv)
    for i in (0, 7, len(q) - 1):
        lo, hi = max(i - 1, 0), min(i + 1, len(q) - 1)
        mujoco.mj_differentiatePos(m, ref, (hi - lo) / fps, q[lo], q[hi])
        np.testing.assert_allclose(v[i], ref, atol=1e-9)
    np.testing.assert_allclose(ch.qvel_from_motion(step_forward, [7])[0], v[7], atol=1e-12)
    np.testing.assert_allclose(ch.qvel_from_motion(step_forward)[7], v[7], atol=1e-12)


def test_clip_clock_clamps_and_brackets() -> None:
    clock = ClipClock(fps=30.0, frames=10, start=0.1)
    assert clock.frame(0.0) == pytest.approx(3.0)
    assert clock.frame(-5.0) == 0.0 and clock.frame(5.0) == 9.0
    i0, i1, w = clock.bracket(0.05)
    assert (i0, i1) == (4, 5) and w == pytest.approx(0.5)
    assert clock.nearest(0.06) == 5
    assert clock.bracket(100.0) == (9, 9, 0.0)
    with pytest.raises(ConfigError):
        ClipClock(fps=0.0, frames=10)
