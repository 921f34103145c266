"""Quaternion helpers in the glossary's ``(w, x, y, z)`` order, broadcasting over any leading
shape. scipy's Rotation is used for Euler angles and conversions; the few products below are
written by hand because Rotation only stacks 1-D and allocates objects, and these run on
``(T, J, 4)`` arrays in feature extraction, FK and blending."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

__all__ = [
    "quat_canonical",
    "quat_conj",
    "quat_continuous",
    "quat_exp",
    "quat_from_matrix",
    "quat_from_euler",
    "quat_identity",
    "quat_log",
    "quat_mul",
    "quat_normalize",
    "quat_rotate",
    "quat_slerp",
    "quat_to_euler",
    "quat_to_matrix",
    "quat_yaw",
    "quat_from_yaw",
    "rotation_from_wxyz",
    "wxyz_from_rotation",
]

F64 = NDArray[np.float64]


def rotation_from_wxyz(q: ArrayLike) -> Rotation:
    """scipy Rotation from ``(..., 4)`` wxyz quaternions (flattened to 1-D stack)."""
    arr = np.asarray(q, dtype=np.float64)
    return Rotation.from_quat(arr.reshape(-1, 4), scalar_first=True)


def wxyz_from_rotation(r: Rotation) -> F64:
    """wxyz quaternions ``(N, 4)`` from a scipy Rotation stack."""
    return np.asarray(r.as_quat(scalar_first=True), dtype=np.float64).reshape(-1, 4)


def quat_identity(shape: tuple[int, ...] = ()) -> F64:
    q = np.zeros((*shape, 4))
    q[..., 0] = 1.0
    return q


def quat_normalize(q: ArrayLike) -> F64:
    arr = np.asarray(q, dtype=np.float64)
    return arr / np.linalg.norm(arr, axis=-1, keepdims=True)


def quat_canonical(q: ArrayLike) -> F64:
    """Same rotation with ``w >= 0``."""
    arr = np.array(q, dtype=np.float64)
    return np.where(arr[..., :1] < 0.0, -arr, arr)


def quat_conj(q: ArrayLike) -> F64:
    arr = np.array(q, dtype=np.float64)
    arr[..., 1:] *= -1.0
    return arr


def quat_mul(a: ArrayLike, b: ArrayLike) -> F64:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def quat_rotate(q: ArrayLike, v: ArrayLike) -> F64:
    """Rotate vectors ``v (..., 3)`` by unit quaternions ``q (..., 4)``."""
    q = np.asarray(q, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_log(q: ArrayLike) -> F64:
    """Rotation vector (axis * angle, radians) of unit quaternions; sign-safe (angle <= pi)."""
    q = quat_canonical(q)
    v = q[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    # angle/s -> 2 as s -> 0 (first-order Taylor term)
    scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-12), 2.0)
    return v * scale


def quat_exp(r: ArrayLike) -> F64:
    """Unit quaternion of a rotation vector."""
    r = np.asarray(r, dtype=np.float64)
    angle = np.linalg.norm(r, axis=-1, keepdims=True)
    half = 0.5 * angle
    k = np.where(angle > 1e-12, np.sin(half) / np.maximum(angle, 1e-12), 0.5)
    return np.concatenate([np.cos(half), r * k], axis=-1)


def quat_slerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F64:
    """Spherical interpolation along the short arc; ``t`` broadcasts against ``(...,)``."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)[..., None]
    dot = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(dot < 0.0, -b, b)
    dot = np.abs(dot)
    rel = quat_mul(quat_conj(a), b)
    return quat_normalize(quat_mul(a, quat_exp(quat_log(rel) * t)))


def quat_continuous(q: ArrayLike, axis: int = 0) -> F64:
    """Flip signs along ``axis`` so consecutive quaternions lie in the same hemisphere."""
    arr = np.array(q, dtype=np.float64)
    arr = np.moveaxis(arr, axis, 0)
    if arr.shape[0] > 1:
        dots = np.sum(arr[1:] * arr[:-1], axis=-1)
        flips = np.cumsum(dots < 0.0, axis=0) % 2
        sign = np.concatenate([np.ones_like(flips[:1]), 1 - 2 * flips], axis=0)
        arr = arr * sign[..., None]
    return np.moveaxis(arr, 0, axis)


def quat_from_euler(angles_rad: ArrayLike, order: str) -> F64:
    """Quaternions from intrinsic Euler angles ``(..., 3)``; ``order`` like ``"ZXY"`` means
    ``R = Rz @ Rx @ Ry`` (the BVH channel order)."""
    a = np.asarray(angles_rad, dtype=np.float64)
    r = Rotation.from_euler(order.upper(), a.reshape(-1, 3))
    return wxyz_from_rotation(r).reshape(*a.shape[:-1], 4)


def quat_to_euler(q: ArrayLike, order: str) -> F64:
    """Intrinsic Euler angles (radians) in ``order``; inverse of :func:`quat_from_euler`."""
    arr = np.asarray(q, dtype=np.float64)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: still a valid decomposition
        e = rotation_from_wxyz(arr).as_euler(order.upper())
    return np.asarray(e).reshape(*arr.shape[:-1], 3)


def quat_to_matrix(q: ArrayLike) -> F64:
    arr = np.asarray(q, dtype=np.float64)
    return rotation_from_wxyz(arr).as_matrix().reshape(*arr.shape[:-1], 3, 3)


def quat_from_matrix(m: ArrayLike) -> F64:
    arr = np.asarray(m, dtype=np.float64)
    r = Rotation.from_matrix(arr.reshape(-1, 3, 3))
    return wxyz_from_rotation(r).reshape(*arr.shape[:-2], 4)


def quat_yaw(q: ArrayLike, forward: ArrayLike = (1.0, 0.0, 0.0)) -> F64:
    """Heading (radians about +Z) of the body axis ``forward`` rotated by ``q``."""
    f = quat_rotate(q, np.broadcast_to(np.asarray(forward, float), np.shape(q)[:-1] + (3,)))
    return np.arctan2(f[..., 1], f[..., 0])


def quat_from_yaw(yaw: ArrayLike) -> F64:
    """Rotation about +Z by ``yaw`` radians."""
    y = np.asarray(yaw, dtype=np.float64)
    q = np.zeros((*y.shape, 4))
    q[..., 0] = np.cos(0.5 * y)
    q[..., 3] = np.sin(0.5 * y)
    return q
