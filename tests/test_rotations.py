"""Property tests for the wxyz quaternion helpers against scipy, and their float32 path."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from reactmocap.errors import ConfigError
from reactmocap.rotations import (
    EulerQuats,
    quat_canonical,
    quat_conj,
    quat_continuous,
    quat_exp,
    quat_from_euler,
    quat_from_matrix,
    quat_from_yaw,
    quat_log,
    quat_mul,
    quat_mul_rows,
    quat_mul_table,
    quat_normalize,
    quat_rotate,
    quat_slerp,
    quat_to_euler,
    quat_to_matrix,
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


@given(quats)
def test_matrix_round_trip_matches_scipy(q: np.ndarray) -> None:
    m = quat_to_matrix(q)
    np.testing.assert_allclose(m, rotation_from_wxyz(q).as_matrix()[0], atol=1e-12)
    back = quat_from_matrix(m)
    assert back[0] >= 0.0 and same_rotation(back, q, tol=1e-12)


@given(st.floats(-3.0, 3.0), quats)
def test_yaw_is_the_twist_about_z(yaw: float, q: np.ndarray) -> None:
    assert abs(quat_yaw(quat_from_yaw(yaw)) - yaw) < 1e-9
    assert abs(quat_yaw(-quat_from_yaw(yaw)) - yaw) < 1e-9  # sign-safe
    # a swing about any horizontal axis does not change it, whichever side it is applied on
    axis = np.array([q[1], q[2], 0.0])
    if np.linalg.norm(axis) > 0.1 and abs(yaw) < 3.0:
        swing = quat_exp(0.6 * axis / np.linalg.norm(axis))
        for turned in (quat_mul(quat_from_yaw(yaw), swing), quat_mul(swing, quat_from_yaw(yaw))):
            assert abs(quat_yaw(turned) - yaw) < 1e-9


def test_yaw_stays_defined_with_the_body_axis_vertical() -> None:
    # facing +Y, then pitched 90 degrees nose down: forward points at the floor, the twist is +90
    pitched = quat_mul(quat_from_yaw(np.pi / 2), quat_exp(np.array([0.0, np.pi / 2, 0.0])))
    np.testing.assert_allclose(quat_rotate(pitched, [1.0, 0.0, 0.0]), [0, 0, -1], atol=1e-12)
    assert quat_yaw(pitched) == pytest.approx(np.pi / 2)


def _random_quats(n: int, seed: int = 0) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


@pytest.mark.parametrize(
    ("name", "call"),
    [
        ("mul", lambda a, b: quat_mul(a, b)),
        ("conj", lambda a, b: quat_conj(a)),
        ("normalize", lambda a, b: quat_normalize(2 * a)),
        ("canonical", lambda a, b: quat_canonical(a)),
        ("rotate", lambda a, b: quat_rotate(a, b[:, 1:])),
        ("log", lambda a, b: quat_log(a)),
        ("exp", lambda a, b: quat_exp(b[:, 1:])),
        ("slerp", lambda a, b: quat_slerp(a, b, 0.3)),
        ("continuous", lambda a, b: quat_continuous(a)),
        ("to_matrix", lambda a, b: quat_to_matrix(a)),
        ("from_matrix", lambda a, b: quat_from_matrix(quat_to_matrix(a))),
        ("yaw", lambda a, b: quat_yaw(a)),
        ("from_yaw", lambda a, b: quat_from_yaw(b[:, 0])),
    ],
)
def test_float32_in_float32_out(name: str, call) -> None:  # type: ignore[no-untyped-def]
    a, b = _random_quats(500, 1), _random_quats(500, 2)
    a[:, 0] = np.abs(a[:, 0]) + 0.05  # keep yaw and sign choices away from their +-pi / w=0 ties
    b[:, 0] = np.abs(b[:, 0]) + 0.05
    a, b = quat_normalize(a), quat_normalize(b)
    exact = call(a, b)
    single = call(a.astype(np.float32), b.astype(np.float32))
    assert exact.dtype == np.float64, name
    assert single.dtype == np.float32, name
    np.testing.assert_allclose(single, exact, atol=2e-6, err_msg=name)


def test_other_input_is_computed_in_float64() -> None:
    assert quat_mul([1, 0, 0, 0], [0, 1, 0, 0]).dtype == np.float64  # ints and lists
    mixed = quat_mul(np.float32([1, 0, 0, 0]), np.array([0.0, 1.0, 0.0, 0.0]))
    assert mixed.dtype == np.float64
    assert quat_to_matrix(np.float16([1, 0, 0, 0])).dtype == np.float64
    assert quat_from_euler(np.float32([0.1, 0.2, 0.3]), "ZXY").dtype == np.float64  # always


_EULER_ORDERS = [a + b + c for a in "XYZ" for b in "XYZ" for c in "XYZ" if a != b and b != c]


@pytest.mark.parametrize("order", _EULER_ORDERS)
def test_euler_equals_scipy_to_the_bit(order: str) -> None:
    # numpy's own product of the elementary rotations (the control ticks' converter) gives
    # scipy's Rotation.from_euler values exactly: the simulated motions stay bit-identical
    rng = np.random.default_rng(len(order) + sum(map(ord, order)))
    angles = rng.uniform(-4.0, 4.0, (3000, 3)) * rng.choice([1e-3, 1.0, 10.0], (3000, 1))
    angles[:100] = 0.0
    angles[100:200, 1] = 0.0
    angles[200:300, 0] = np.pi
    expected = Rotation.from_euler(order, angles).as_quat(scalar_first=True)
    np.testing.assert_array_equal(quat_from_euler(angles, order), expected)
    np.testing.assert_array_equal(quat_from_euler(angles, order.lower()), expected)
    assert quat_from_euler(angles[0], order).shape == (4,)
    assert quat_from_euler(angles[:10].reshape(2, 5, 3), order).shape == (2, 5, 4)


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX",
                                   "XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"])  # fmt: skip
def test_euler_quats_into_buffers_equal_quat_from_euler_to_the_bit(order: str) -> None:
    # the control ticks' buffered converter makes the same products in the same order: the
    # same values and zero signs, call after call on the same buffers
    rng = np.random.default_rng(sum(map(ord, order)))
    convert = EulerQuats(order, 15)
    for _ in range(200):
        angles = rng.uniform(-4.0, 4.0, (15, 3)) * rng.choice([1e-3, 1.0, 10.0], (15, 1))
        angles[rng.random((15, 3)) < 0.1] = 0.0
        angles[rng.random((15, 3)) < 0.1] = -0.0
        got, want = convert(angles), quat_from_euler(angles, order)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(np.signbit(got), np.signbit(want))
    with pytest.raises(ConfigError, match="Euler order"):
        EulerQuats("XXY", 15)


def test_quat_mul_rows_into_buffers_equal_the_plain_form_to_the_bit() -> None:
    a, b = _random_quats(15, 5), _random_quats(15, 6)
    a[:4, 2] = -0.0
    table = np.empty((15, 4, 4))
    assert quat_mul_table(b, table) is table
    np.testing.assert_array_equal(table, quat_mul_table(b))
    got, want = quat_mul_rows(a, table, np.empty((15, 4, 4))), quat_mul_rows(a, quat_mul_table(b))
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(np.signbit(got), np.signbit(want))
    np.testing.assert_array_equal(want, quat_mul(a, b))


@pytest.mark.parametrize("order", ["XY", "XXY", "XYZX", "XYW"])
def test_euler_order_must_be_three_axes(order: str) -> None:
    with pytest.raises(ConfigError, match="Euler order"):
        quat_from_euler([0.1, 0.2, 0.3], order)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_small_mul_equals_the_large_form_to_the_bit(dtype: type) -> None:
    # quat_mul's small-array form (4 numpy calls) sums the same products in the same order as
    # its component form (zeros' signs included): the control ticks stay bit-identical
    a, b = _random_quats(2000, 3).astype(dtype), _random_quats(2000, 4).astype(dtype)
    a[:300, 1] = 0.0
    b[200:500, 2] = -0.0
    large = quat_mul(a, b)  # 16000 entries: the component form
    small = np.concatenate([quat_mul(a[i : i + 16], b[i : i + 16]) for i in range(0, 2000, 16)])
    assert small.dtype == large.dtype == dtype
    np.testing.assert_array_equal(small, large)
    np.testing.assert_array_equal(np.signbit(small), np.signbit(large))
    one = quat_mul(a[5], b[:7])  # broadcasting one against several, against the large form
    np.testing.assert_array_equal(one, quat_mul(np.tile(a[5], (2000, 1)), b)[:7])


def test_slerp_path_follows_a_spin_past_half_a_turn_where_framewise_slerp_jumps() -> None:
    from reactmocap.rotations import quat_from_yaw, quat_slerp, quat_slerp_path

    n = 61
    a = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    b = quat_from_yaw(np.linspace(0.0, 1.5 * np.pi, n))  # b spins on past half a turn
    w = np.full(n, 0.5)
    path = quat_slerp_path(a, b, w)
    yaw_path = np.unwrap(2 * np.arctan2(path[:, 3], path[:, 0]))
    np.testing.assert_allclose(yaw_path, 0.5 * np.linspace(0.0, 1.5 * np.pi, n), atol=1e-9)
    framewise = quat_slerp(a, b, w)
    yaw_fw = np.unwrap(2 * np.arctan2(framewise[:, 3], framewise[:, 0]))
    assert np.max(np.abs(np.diff(yaw_fw))) > 1.0  # the short arc flips sides: a jump
    # ends exactly on b, starts on a, and agrees with slerp for small turns
    np.testing.assert_allclose(np.abs(np.sum(quat_slerp_path(a, b, np.ones(n)) * b, axis=1)), 1.0,
                               atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(quat_slerp_path(a, b, np.zeros(n)), a, atol=1e-12)
    small = quat_from_yaw(np.linspace(0.0, 1.0, n))
    np.testing.assert_allclose(quat_slerp_path(a, small, w), quat_slerp(a, small, w), atol=1e-12)


def test_wrap_angle_keeps_floats_and_dtypes() -> None:
    from reactmocap.rotations import wrap_angle

    assert wrap_angle(3 * np.pi / 2) == -np.pi / 2 and isinstance(wrap_angle(4.0), float)
    assert wrap_angle(np.pi) == -np.pi  # [-pi, pi)
    a = np.linspace(-20.0, 20.0, 401)
    w = wrap_angle(a)
    assert w.dtype == np.float64 and np.all((w >= -np.pi) & (w < np.pi))
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-12)
    np.testing.assert_allclose(np.sin(w), np.sin(a), atol=1e-12)
    assert wrap_angle(a.astype(np.float32)).dtype == np.float32
