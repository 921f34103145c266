"""Quaternion helpers in the glossary's ``(w, x, y, z)`` order, for unit quaternions, broadcasting
over any leading shape, and two small-array vector helpers (:func:`unit_rows`,
:func:`cross_rows`). float32 input gives float32 output (the search keeps its features in
float32); anything else is computed in float64. Products and conversions are plain numpy because
scipy's Rotation only stacks 1-D, allocates objects and works in float64; scipy does the Euler
angles' decomposition, and :func:`quat_from_euler` forms scipy's own values in numpy (equal to
the bit, tested: the athletic controllers call it at every tick)."""

from __future__ import annotations

import functools
import math
import warnings
from typing import Any, TypeVar, cast, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from reactmocap.errors import ConfigError

__all__ = [
    "cross_rows",
    "EulerQuats",
    "einsum",
    "quat_canonical",
    "quat_conj",
    "quat_continuous",
    "quat_exp",
    "quat_from_matrix",
    "quat_from_euler",
    "quat_log",
    "quat_mul",
    "quat_mul_rows",
    "quat_mul_table",
    "quat_normalize",
    "quat_rotate",
    "quat_slerp",
    "quat_slerp_path",
    "quat_to_euler",
    "quat_to_matrix",
    "quat_yaw",
    "quat_from_yaw",
    "rotation_from_wxyz",
    "unit_rows",
    "wrap_angle",
    "wxyz_from_rotation",
]

# np.einsum's C routine: what np.einsum calls (optimize off), less its Python wrapper; a
# private name, so a numpy that moves it falls back to np.einsum (the same values, slower)
try:
    from numpy._core.multiarray import c_einsum as _c_einsum
except ImportError:
    try:  # numpy 1.x
        from numpy.core.multiarray import c_einsum as _c_einsum  # type: ignore[no-redef]
    except ImportError:
        _c_einsum = np.einsum

F64 = NDArray[np.float64]
Floats = NDArray[np.floating[Any]]
#: ``np.einsum(subscripts, *operands, out=...)`` without optimisation: its own C routine, the
#: same values; a few microseconds less a call on the control ticks' small arrays
einsum: Any = _c_einsum
#: the dtypes kept as they are (overloads: float32 or float64 in, the same out)
_F = TypeVar("_F", np.float32, np.float64)
# quaternion component of each axis, and the right product with its unit quaternion,
# q (0, e_axis), as a signed permutation of q's (w, x, y, z)
_AXIS = {"X": 1, "Y": 2, "Z": 3}
_RIGHT_UNIT = {
    "X": (np.array([1, 0, 3, 2]), np.array([-1.0, 1.0, 1.0, -1.0])),
    "Y": (np.array([2, 3, 0, 1]), np.array([-1.0, -1.0, 1.0, 1.0])),
    "Z": (np.array([3, 2, 1, 0]), np.array([-1.0, 1.0, -1.0, 1.0])),
}
# e_k b for the units e_k = 1, i, j, k: signed permutations of b's (w, x, y, z)
_MUL_PERM = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_SIGNS = [[1, 1, 1, 1], [-1, 1, -1, 1], [-1, 1, 1, -1], [-1, -1, 1, 1]]
_MUL_SIGN = {c: np.array(_SIGNS, dtype=c) for c in "fd"}
#: quat_mul's small form up to this many entries of a and b together
_MUL_SMALL = 512
# cross_rows' component order
_C1 = np.array([1, 2, 0])
_C2 = np.array([2, 0, 1])


def _floats(a: ArrayLike, copy: bool = False) -> Floats:
    """``a`` as float32 when it is float32, else as float64 (a copy when ``copy``)."""
    arr = np.asarray(a)
    if arr.dtype != np.float32:
        arr = arr.astype(np.float64, copy=False)
    return arr.copy() if copy else arr


def _common(*arrays: ArrayLike) -> tuple[Floats, ...]:
    """The arrays in one dtype: float32 only when all of them are float32."""
    if all(type(a) is np.ndarray and a.dtype.char == "d" for a in arrays):
        return cast(tuple[Floats, ...], arrays)  # float64 already: a fifth of a small quat_mul
    out = tuple(_floats(a) for a in arrays)
    if any(a.dtype != np.float32 for a in out):
        out = tuple(a.astype(np.float64, copy=False) for a in out)
    return out


def rotation_from_wxyz(q: ArrayLike) -> Rotation:
    """scipy Rotation from ``(..., 4)`` wxyz quaternions (flattened to 1-D stack)."""
    arr = np.asarray(q, dtype=np.float64)
    return Rotation.from_quat(arr.reshape(-1, 4), scalar_first=True)


def wxyz_from_rotation(r: Rotation) -> F64:
    """wxyz quaternions ``(N, 4)`` from a scipy Rotation stack."""
    return np.asarray(r.as_quat(scalar_first=True), dtype=np.float64).reshape(-1, 4)


@overload
def quat_normalize(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_normalize(q: ArrayLike) -> F64: ...
def quat_normalize(q: ArrayLike) -> Floats:
    arr = _floats(q)
    return arr / np.linalg.norm(arr, axis=-1, keepdims=True)


@overload
def quat_canonical(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_canonical(q: ArrayLike) -> F64: ...
def quat_canonical(q: ArrayLike) -> Floats:
    """Same rotation with ``w >= 0``."""
    arr = _floats(q)
    return np.where(arr[..., :1] < 0.0, -arr, arr)


@overload
def quat_conj(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_conj(q: ArrayLike) -> F64: ...
def quat_conj(q: ArrayLike) -> Floats:
    arr = _floats(q, copy=True)
    arr[..., 1:] *= -1.0
    return arr


@overload
def quat_mul(a: NDArray[_F], b: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_mul(a: ArrayLike, b: ArrayLike) -> F64: ...
def quat_mul(a: ArrayLike, b: ArrayLike) -> Floats:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    qa, qb = _common(a, b)
    if qa.size + qb.size <= _MUL_SMALL:
        # a * b = sum_k a_k (e_k b): the same products summed in the same order as below (to
        # the bit, test) in 4 numpy calls, not 30: 3x faster on the control ticks' 15
        # joints, 9x slower on 1e5 quaternions
        return quat_mul_rows(qa, quat_mul_table(qb))
    aw, ax, ay, az = qa[..., 0], qa[..., 1], qa[..., 2], qa[..., 3]
    bw, bx, by, bz = qb[..., 0], qb[..., 1], qb[..., 2], qb[..., 3]
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_mul_table(b: NDArray[_F], out: NDArray[_F] | None = None) -> NDArray[_F]:
    """``(..., 4, 4)``: the products ``e_k b`` of the units ``e_k`` = 1, i, j, k with float
    quaternions ``b``, for :func:`quat_mul_rows`; made once for a ``b`` that does not change
    (a body's joint frames), or into ``out`` (the same values)."""
    if out is None:
        return b[..., _MUL_PERM] * _MUL_SIGN[b.dtype.char]
    b.take(_MUL_PERM, axis=-1, out=out)
    return np.multiply(out, _MUL_SIGN[b.dtype.char], out=out)


def quat_mul_rows(
    a: NDArray[_F], table: NDArray[_F], work: NDArray[_F] | None = None
) -> NDArray[_F]:
    """``a * b`` from ``b``'s :func:`quat_mul_table` (same dtype): :func:`quat_mul`'s values
    to the bit. ``work``: a buffer of the products' shape ``(..., 4, 4)`` (the same values)."""
    if work is None:
        return np.add.reduce(a[..., :, None] * table, axis=-2)
    np.multiply(a[..., :, None], table, out=work)
    return np.add.reduce(work, axis=-2)


@overload
def quat_rotate(q: NDArray[_F], v: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_rotate(q: ArrayLike, v: ArrayLike) -> F64: ...
def quat_rotate(q: ArrayLike, v: ArrayLike) -> Floats:
    """Rotate vectors ``v (..., 3)`` by unit quaternions ``q (..., 4)``."""
    qq, vv = _common(q, v)
    # v + w t + u x t with t = 2 u x v, by components: np.cross's axis handling costs 3x more
    # on the small arrays of forward kinematics (its hot path)
    w, x, y, z = qq[..., 0], qq[..., 1], qq[..., 2], qq[..., 3]
    vx, vy, vz = vv[..., 0], vv[..., 1], vv[..., 2]
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    return np.stack(
        [
            vx + w * tx + (y * tz - z * ty),
            vy + w * ty + (z * tx - x * tz),
            vz + w * tz + (x * ty - y * tx),
        ],
        axis=-1,
    )


@overload
def quat_log(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_log(q: ArrayLike) -> F64: ...
def quat_log(q: ArrayLike) -> Floats:
    """Rotation vector (axis * angle, radians) of unit quaternions; sign-safe (angle <= pi)."""
    qc = quat_canonical(_floats(q))
    v = qc[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, qc[..., :1])
    # angle/s -> 2 as s -> 0 (first-order Taylor term)
    scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-12), 2.0)
    return v * scale


@overload
def quat_exp(r: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_exp(r: ArrayLike) -> F64: ...
def quat_exp(r: ArrayLike) -> Floats:
    """Unit quaternion of a rotation vector."""
    rv = _floats(r)
    angle = np.linalg.norm(rv, axis=-1, keepdims=True)
    half = 0.5 * angle
    k = np.where(angle > 1e-12, np.sin(half) / np.maximum(angle, 1e-12), 0.5)
    return np.concatenate([np.cos(half), rv * k], axis=-1)


@overload
def quat_slerp(a: NDArray[_F], b: NDArray[_F], t: ArrayLike) -> NDArray[_F]: ...
@overload
def quat_slerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F64: ...
def quat_slerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> Floats:
    """Spherical interpolation along the short arc; ``t`` broadcasts against ``(...,)``."""
    qa, qb = _common(a, b)
    tt = np.asarray(t, dtype=qa.dtype)[..., None]
    dot = np.sum(qa * qb, axis=-1, keepdims=True)
    qb = np.where(dot < 0.0, -qb, qb)
    rel = quat_mul(quat_conj(qa), qb)
    return quat_normalize(quat_mul(qa, quat_exp(quat_log(rel) * tt)))


@overload
def quat_continuous(q: NDArray[_F], axis: int = 0) -> NDArray[_F]: ...
@overload
def quat_continuous(q: ArrayLike, axis: int = 0) -> F64: ...
def quat_continuous(q: ArrayLike, axis: int = 0) -> Floats:
    """Flip signs along ``axis`` so consecutive quaternions lie in the same hemisphere."""
    arr = np.moveaxis(_floats(q, copy=True), axis, 0)
    if arr.shape[0] > 1:
        dots = np.sum(arr[1:] * arr[:-1], axis=-1)
        flips = np.cumsum(dots < 0.0, axis=0) % 2
        sign = np.concatenate([np.ones_like(flips[:1]), 1 - 2 * flips], axis=0)
        arr = arr * sign[..., None].astype(arr.dtype)
    return np.moveaxis(arr, 0, axis)


def quat_slerp_path(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F64:
    """Slerp of two frame sequences ``(T, ..., 4)`` with weights ``t`` broadcasting against
    ``(T, ...)``, along one arc per sequence: the first frame's short arc, followed over the
    frames. Frame-wise short-arc slerp jumps to the other side when the turn between the two
    passes half a turn (a spin); this follows it continuously and still ends exactly on ``b``
    where ``t`` is 1."""
    qa, qb = _common(a, b)
    rel = quat_continuous(quat_mul(quat_conj(qa), qb), axis=0)
    rel = rel * np.where(rel[:1, ..., :1] < 0.0, -1.0, 1.0)  # the first frame's short arc
    v = rel[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    half = np.arctan2(s, rel[..., :1]) * np.asarray(t, dtype=np.float64)[..., None]
    axis = np.where(s > 1e-12, v / np.maximum(s, 1e-12), 0.0)
    step = np.concatenate([np.cos(half), axis * np.sin(half)], axis=-1)
    return np.asarray(quat_normalize(quat_mul(qa, step)), dtype=np.float64)


def quat_from_euler(angles_rad: ArrayLike, order: str) -> F64:
    """Quaternions from intrinsic Euler angles ``(..., 3)``; ``order`` like ``"ZXY"`` means
    ``R = Rz @ Rx @ Ry`` (the BVH channel order). Always float64. The elementary rotations'
    product as scipy's ``Rotation.from_euler`` forms it: each component is one rounding of the
    same one or two products, so the values equal scipy's to the bit (test), at a fraction of
    its cost on the control ticks' 15 joints (no Rotation object)."""
    a = np.asarray(angles_rad, dtype=np.float64)
    seq = order.upper()
    if len(seq) != 3 or not set(seq) <= set("XYZ") or seq[0] == seq[1] or seq[1] == seq[2]:
        raise ConfigError(f"Euler order must be 3 axes of XYZ, none twice in a row; got {order!r}")
    idx, sign = _euler_terms(seq)
    half = a / 2
    cs = np.empty((*a.shape, 2))  # (..., 3, 2): cosines and sines (np.stack cost as much again)
    np.cos(half, out=cs[..., 0])
    np.sin(half, out=cs[..., 1])
    # the eight products (x1 x2) x3 of each angle's half-angle cosine or sine, in the order
    # the elementary products make them
    t = cs[..., 0, :, None, None] * cs[..., 1, None, :, None] * cs[..., 2, None, None, :]
    terms = t.reshape(*a.shape[:-1], 8)[..., idx] * sign
    return terms[..., 0] + terms[..., 1]


class EulerQuats:
    """:func:`quat_from_euler` of ``(n, 3)`` float64 angles in one ``order``, into buffers
    made once: the same operations in the same order, so the same values to the bit (test),
    without the checks, the allocations and their Python calls (the athletic controllers
    convert their 15 joints at every tick). The result is a buffer the next call overwrites."""

    def __init__(self, order: str, n: int) -> None:
        quat_from_euler(np.zeros(3), order)  # the order's check
        self._idx, self._sign = _euler_terms(order.upper())
        self._half = np.empty((n, 3))
        cs = np.empty((n, 3, 2))
        self._cos, self._sin = cs[..., 0], cs[..., 1]
        # the three angles' (cos, sin) pairs as the products broadcast them
        self._x1, self._x2, self._x3 = cs[:, 0, :, None], cs[:, 1, None, :], cs[:, 2, None, None, :]
        self._x12 = np.empty((n, 2, 2))
        self._x12_col = self._x12[..., None]
        t = np.empty((n, 2, 2, 2))
        self._t, self._t8 = t, t.reshape(n, 8)
        terms = np.empty((n, 4, 2))
        self._terms, self._first, self._second = terms, terms[..., 0], terms[..., 1]
        self.out = np.empty((n, 4))

    def __call__(self, angles: F64) -> F64:
        np.divide(angles, 2, out=self._half)
        np.cos(self._half, out=self._cos)
        np.sin(self._half, out=self._sin)
        np.multiply(self._x1, self._x2, out=self._x12)
        np.multiply(self._x12_col, self._x3, out=self._t)
        self._t8.take(self._idx, axis=1, out=self._terms)
        np.multiply(self._terms, self._sign, out=self._terms)
        return np.add(self._first, self._second, out=self.out)


@functools.cache
def _euler_terms(seq: str) -> tuple[NDArray[np.intp], F64]:
    """The elementary product ``(c1 + s1 u1)(c2 + s2 u2)(c3 + s3 u3)`` run on symbols: each
    component of the result is one or two signed terms, each one of the eight products of
    :func:`quat_from_euler` (index ``4 b1 + 2 b2 + b3``, ``b`` 1 for a sine). Returns ``(4, 2)``
    indices and signs (0: no second term)."""
    q: list[list[tuple[float, int]]] = [[(1.0, 0)], [], [], []]
    q[_AXIS[seq[0]]] = [(1.0, 4)]
    for k, bit in ((1, 2), (2, 1)):
        # q (cos + sin u) = cos q + sin (q u), q u a signed permutation of q's components
        perm, sgn = _RIGHT_UNIT[seq[k]]
        q = [q[c] + [(s * float(sgn[c]), b | bit) for s, b in q[int(perm[c])]] for c in range(4)]
    assert all(1 <= len(terms) <= 2 for terms in q)
    pad = [terms + [(0.0, 0)] * (2 - len(terms)) for terms in q]
    return (np.array([[b for _, b in terms] for terms in pad]),
            np.array([[s for s, _ in terms] for terms in pad]))  # fmt: skip


def quat_to_euler(q: ArrayLike, order: str) -> F64:
    """Intrinsic Euler angles (radians) in ``order``; inverse of :func:`quat_from_euler`.
    Always float64 (scipy)."""
    arr = np.asarray(q, dtype=np.float64)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: still a valid decomposition
        e = rotation_from_wxyz(arr).as_euler(order.upper())
    return np.asarray(e).reshape(*arr.shape[:-1], 3)


@overload
def quat_to_matrix(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_to_matrix(q: ArrayLike) -> F64: ...
def quat_to_matrix(q: ArrayLike) -> Floats:
    """``(..., 3, 3)`` rotation matrices of unit quaternions (not normalised here)."""
    arr = _floats(q)
    w, x, y, z = arr[..., 0], arr[..., 1], arr[..., 2], arr[..., 3]
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    m = np.empty((*arr.shape[:-1], 3, 3), dtype=arr.dtype)
    m[..., 0, 0] = 1 - 2 * (yy + zz)
    m[..., 0, 1] = 2 * (xy - wz)
    m[..., 0, 2] = 2 * (xz + wy)
    m[..., 1, 0] = 2 * (xy + wz)
    m[..., 1, 1] = 1 - 2 * (xx + zz)
    m[..., 1, 2] = 2 * (yz - wx)
    m[..., 2, 0] = 2 * (xz - wy)
    m[..., 2, 1] = 2 * (yz + wx)
    m[..., 2, 2] = 1 - 2 * (xx + yy)
    return m


@overload
def quat_from_matrix(m: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_from_matrix(m: ArrayLike) -> F64: ...
def quat_from_matrix(m: ArrayLike) -> Floats:
    """Unit quaternions (``w >= 0``) of rotation matrices ``(..., 3, 3)`` (Shepperd's method:
    the largest of the four candidate components sets the others, so no cancellation)."""
    a = _floats(m)
    m00, m11, m22 = a[..., 0, 0], a[..., 1, 1], a[..., 2, 2]
    tr = m00 + m11 + m22
    s21, d21 = a[..., 2, 1] + a[..., 1, 2], a[..., 2, 1] - a[..., 1, 2]
    s02, d02 = a[..., 0, 2] + a[..., 2, 0], a[..., 0, 2] - a[..., 2, 0]
    s10, d10 = a[..., 1, 0] + a[..., 0, 1], a[..., 1, 0] - a[..., 0, 1]
    # row c: the quaternion scaled by 4 q_c, computed from the diagonal entry of component c
    cands = np.empty((*a.shape[:-2], 4, 4), dtype=a.dtype)
    rows = (
        (1 + tr, d21, d02, d10),
        (d21, 1 + m00 - m11 - m22, s10, s02),
        (d02, s10, 1 - m00 + m11 - m22, s21),
        (d10, s02, s21, 1 - m00 - m11 + m22),
    )
    for c, row in enumerate(rows):
        for k, value in enumerate(row):
            cands[..., c, k] = value
    choice = np.argmax(np.stack([tr, m00, m11, m22], -1), axis=-1)
    q = np.take_along_axis(cands, choice[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


@overload
def quat_yaw(q: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_yaw(q: ArrayLike) -> F64: ...
def quat_yaw(q: ArrayLike) -> Floats:
    """Twist angle about world +Z (radians, in ``[-pi, pi)``) of ``q = twist_z * swing``, the
    swing about a horizontal axis. Inverse of :func:`quat_from_yaw`; unlike the projection of a
    body axis onto the ground it stays defined when that axis is vertical (singular only for a
    half turn about a horizontal axis)."""
    arr = _floats(q)
    return wrap_angle(2.0 * np.arctan2(arr[..., 3], arr[..., 0]))


@overload
def wrap_angle(a: float) -> float: ...
@overload
def wrap_angle(a: NDArray[_F]) -> NDArray[_F]: ...
def wrap_angle(a: float | Floats) -> float | Floats:
    """Angle(s) ``a`` (radians) wrapped to ``[-pi, pi)``: a float stays a float (the control
    ticks' scalars), an array keeps its dtype."""
    return (a + math.pi) % (2 * math.pi) - math.pi


@overload
def quat_from_yaw(yaw: NDArray[_F]) -> NDArray[_F]: ...
@overload
def quat_from_yaw(yaw: ArrayLike) -> F64: ...
def quat_from_yaw(yaw: ArrayLike) -> Floats:
    """Rotation about +Z by ``yaw`` radians."""
    y = _floats(yaw)
    q = np.zeros((*y.shape, 4), dtype=y.dtype)
    q[..., 0] = np.cos(0.5 * y)
    q[..., 3] = np.sin(0.5 * y)
    return q


def unit_rows(v: F64) -> F64:
    """Vectors ``(..., 3)`` scaled to unit length; a zero vector stays zero."""
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def cross_rows(a: F64, b: F64) -> F64:
    """Row-wise cross product of ``(..., 3)`` arrays (np.cross's axis handling costs 25-40 us
    a call on the small arrays of the rider's and the cloth's ticks, this 5-10 us)."""
    return a.take(_C1, -1) * b.take(_C2, -1) - a.take(_C2, -1) * b.take(_C1, -1)
