"""Property tests for the wxyz quaternion helpers against scipy."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from reactmocap.rotations import (
    quat_canonical,
    quat_conj,
    quat_continuous,
    quat_exp,
    quat_from_euler,
    quat_from_yaw,
    quat_log,
    quat_mul,
    quat_rotate,
    quat_slerp,
    quat_to_euler,
    quat_yaw,
    rotation_from_wxyz,
    wxyz_from_rotation,
)

finite = st.floats(-1.0, 1.0, allow_nan=False)
quats = (
    arrays(np.float64, (4,), elements=finite)
    .filter(lambda q: np.linalg.norm(q) > 0.1)
    .map(lambda q: q / np.linalg.norm(q))
)
vecs = arrays(np.float64, (3,), elements=st.floats(-5, 5, allow_nan=False))


def same_rotation(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> bool:
    return bool(abs(abs(np.dot(a, b)) - 1.0) < tol)


@given(quats, quats)
def test_mul_matches_scipy(a: np.ndarray, b: np.ndarray) -> None:
    expected = wxyz_from_rotation(rotation_from_wxyz(a) * rotation_from_wxyz(b))[0]
    assert same_rotation(quat_mul(a, b), expected)


@given(quats, vecs)
def test_rotate_matches_scipy(q: np.ndarray, v: np.ndarray) -> None:
    np.testing.assert_allclose(quat_rotate(q, v), rotation_from_wxyz(q).apply(v)[0], atol=1e-9)


@given(quats)
def test_log_exp_round_trip_and_sign_safety(q: np.ndarray) -> None:
    r = quat_log(q)
    assert np.linalg.norm(r) <= np.pi + 1e-9
    assert same_rotation(quat_exp(r), q)
    if np.linalg.norm(r) < np.pi - 1e-6:  # at exactly pi, +axis and -axis are both right
        np.testing.assert_allclose(quat_log(-q), r, atol=1e-9)  # q and -q: one rotation
        expected = Rotation.from_quat(q, scalar_first=True).as_rotvec()
        np.testing.assert_allclose(r, expected, atol=1e-7)


@given(quats, quats, st.floats(0.0, 1.0))
def test_slerp_endpoints_and_constant_speed(a: np.ndarray, b: np.ndarray, t: float) -> None:
    assert same_rotation(quat_slerp(a, b, 0.0), a)
    assert same_rotation(quat_slerp(a, b, 1.0), b)
    mid = quat_slerp(a, b, t)
    total = np.linalg.norm(quat_log(quat_mul(quat_conj(a), b)))
    part = np.linalg.norm(quat_log(quat_mul(quat_conj(a), mid)))
    assert abs(part - t * total) < 1e-7


@given(
    arrays(np.float64, (3,), elements=st.floats(-1.5, 1.5)),
    st.sampled_from(["ZXY", "XYZ", "YZX", "ZYX"]),
)
def test_euler_round_trip(angles: np.ndarray, order: str) -> None:
    q = quat_from_euler(angles, order)
    assert same_rotation(quat_from_euler(quat_to_euler(q, order), order), q)
    # intrinsic order: R = R1 R2 R3
    mats = {ax: Rotation.from_euler(ax.lower(), a).as_matrix() for ax, a in zip(order, angles)}
    expected = mats[order[0]] @ mats[order[1]] @ mats[order[2]]
    np.testing.assert_allclose(rotation_from_wxyz(q).as_matrix()[0], expected, atol=1e-9)


@settings(max_examples=30)
@given(
    arrays(np.float64, (20, 4), elements=finite).filter(
        lambda a: np.all(np.linalg.norm(a, axis=1) > 0.1)
    )
)
def test_continuous_and_canonical(seq: np.ndarray) -> None:
    seq = seq / np.linalg.norm(seq, axis=1, keepdims=True)
    cont = quat_continuous(seq)
    assert np.all(np.sum(cont[1:] * cont[:-1], axis=1) >= 0)
    assert np.all(np.abs(np.abs(np.sum(cont * seq, axis=1)) - 1) < 1e-9)
    assert np.all(quat_canonical(seq)[:, 0] >= 0)


@given(st.floats(-3.0, 3.0))
def test_yaw_round_trip(yaw: float) -> None:
    assert abs(quat_yaw(quat_from_yaw(yaw)) - yaw) < 1e-9
