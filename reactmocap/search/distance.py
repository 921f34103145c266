"""The window distance ``D`` (with its six-term breakdown) and the Euclidean embedding whose
squared norm approximates it, so a KD-tree can propose candidates for the exact ``D``. Both
compare windows in their first frame's root frame; ``docs/design.md (Search)`` defines them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from reactmocap.rotations import quat_to_matrix
from reactmocap.search.config import SearchWeights
from reactmocap.search.features import FeatureSet

__all__ = [
    "BREAKDOWN_TERMS",
    "CHEAP_ANGLE_ERROR",
    "QueryWindow",
    "body_weights",
    "embed_local",
    "embedding_body_weights",
    "embedding_frame_weights",
    "frame_pose_steps",
    "group_matrix",
    "localize",
    "part_distances",
    "select_support",
    "StanceCost",
    "window_distances",
]

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

#: rad: how far the cheaper ``d_theta`` (``window_distances(precise=False)``) may be off the
#: precise one, so a cheap ``D`` is within this times the summed orientation weights of the
#: precise ``D`` (measured at most 4.2e-4 on 40 synthetic queries against every window)
CHEAP_ANGLE_ERROR = 1e-3

BREAKDOWN_TERMS = (
    "trunk_position",
    "trunk_orientation",
    "limbs_position",
    "limbs_orientation",
    "support_position",
    "support_orientation",
)


@dataclass(frozen=True)
class QueryWindow:
    """A query window in its own first-frame root frame, ready to compare."""

    positions: F32  # (L, P, 3)
    orientations: F32  # (L, P, 4)
    heading: float
    origin: F64  # (2,)
    support: int  # index into the feature set's parts
    support_part: str
    com: F64  # (3,) at the first frame, world


@dataclass(frozen=True)
class StanceCost:
    """The stance-mismatch term (``SearchWeights.stance_mismatch``): ``weight`` per foot whose
    contact at the window's first frame differs from the query's."""

    feet: NDArray[np.int64]  # indices into the feature set's parts
    weight: float
    height: float  # m above the ground
    step: float  # m of horizontal travel between the first two window frames

    @classmethod
    def of(cls, feature_set: FeatureSet, weights: SearchWeights, fps: float) -> StanceCost | None:
        if weights.stance_mismatch <= 0:
            return None
        feet = [
            feature_set.parts.index(p) for p in feature_set.support_always if p in feature_set.parts
        ]
        if not feet:
            return None
        return cls(np.asarray(feet, dtype=np.int64), float(weights.stance_mismatch),
                   float(weights.contact_height), float(weights.contact_speed) / fps)  # fmt: skip

    def contacts(self, p0: NDArray[np.floating], p1: NDArray[np.floating]) -> NDArray[np.bool_]:
        """``(..., F)`` feet in contact from their positions at two consecutive frames
        ``(..., F, 3)`` (horizontal travel is the same in any yaw frame)."""
        travel = np.hypot(p1[..., 0] - p0[..., 0], p1[..., 1] - p0[..., 1])
        return np.asarray((p0[..., 2] <= self.height) & (travel <= self.step))

    def frame_contacts(self, positions: NDArray[np.floating]) -> NDArray[np.bool_]:
        """``(N, F)`` feet in contact at each frame of ``(N, P, 3)`` positions (from the frame
        and the next: what a window starting there counts; the last frame counts as lifted)."""
        out = np.zeros((positions.shape[0], self.feet.size), dtype=bool)
        out[:-1] = self.contacts(positions[:-1, self.feet], positions[1:, self.feet])
        return out

    def columns(self, flags: NDArray[np.bool_]) -> F32:
        """KD-embedding columns of contact flags ``(..., F)``: ``sqrt(weight) / 2`` per foot in
        contact, after the PCA (which would drop them), so the embedding holds the term and
        the KD-tree proposes the windows it favours. A quarter of the weight per differing foot
        in the squared embedding distance had the best recall against brute force on the
        synthetic library (95-96%; the full weight 92-95%, twice it 87%; recall without the
        columns 60%: ``docs/benchmarks.md``)."""
        return (0.5 * np.sqrt(self.weight) * flags).astype(np.float32)

    def query_columns(self, query: QueryWindow) -> F32:
        """``(F,)`` the query's KD-embedding columns."""
        return self.columns(self.contacts(query.positions[0, self.feet],
                                          query.positions[1, self.feet]))  # fmt: skip

    def cost(self, positions: F32, starts: NDArray[np.int64], query: QueryWindow) -> F64:
        """``(C,)`` mismatch cost of the windows starting at ``starts``."""
        lib = self.contacts(positions[starts][:, self.feet], positions[starts + 1][:, self.feet])
        q = self.contacts(query.positions[0, self.feet], query.positions[1, self.feet])
        return self.weight * np.count_nonzero(lib != q[None], axis=1).astype(np.float64)


def localize(
    positions: NDArray[np.floating],
    orientations: NDArray[np.floating],
    heading: NDArray[np.floating],
    origin: NDArray[np.floating],
) -> tuple[NDArray[np.floating], NDArray[np.floating]]:
    """Express windows in their first frame's root frame.

    ``positions (C, L, P, 3)``, ``orientations (C, L, P, 4)``, ``heading (C,)``, ``origin (C, 2)``.
    """
    dt = positions.dtype
    # Rz(-h) (p - o) on x and y only: cheaper than quat_rotate or a 3x3 product
    c = np.cos(heading).astype(dt)[:, None, None]
    s = np.sin(heading).astype(dt)[:, None, None]
    dx = positions[..., 0] - origin[:, 0].astype(dt)[:, None, None]
    dy = positions[..., 1] - origin[:, 1].astype(dt)[:, None, None]
    lp = np.empty_like(positions)
    lp[..., 0] = c * dx + s * dy
    lp[..., 1] = -s * dx + c * dy
    lp[..., 2] = positions[..., 2]
    # q_yaw(-h) * q written out: quat_mul(quat_from_yaw(-h), q) is 35% slower on these arrays
    ch = np.cos(0.5 * heading).astype(dt)[:, None, None]
    sh = np.sin(0.5 * heading).astype(dt)[:, None, None]
    w, x, y, z = (orientations[..., k] for k in range(4))
    lq = np.empty_like(orientations)
    lq[..., 0] = ch * w + sh * z
    lq[..., 1] = ch * x + sh * y
    lq[..., 2] = ch * y - sh * x
    lq[..., 3] = ch * z - sh * w
    return lp, lq


def select_support(
    positions0: NDArray[np.floating],
    com0: NDArray[np.floating],
    feature_set: FeatureSet,
    weights: SearchWeights,
) -> int:
    """Index (into ``feature_set.parts``) of the ground-support body nearest the centre of mass.

    Candidates: the feet always; hands and pelvis when within ``weights.support_height`` of the
    lowest feature part (a character on the ground). Nearest = smallest horizontal distance from
    the centre of mass.
    """
    parts = feature_set.parts
    z = positions0[:, 2]
    low = float(np.min(z))
    cands = [parts.index(p) for p in feature_set.support_always if p in parts]
    cands += [
        parts.index(p)
        for p in feature_set.support_low
        if p in parts and z[parts.index(p)] <= low + weights.support_height
    ]
    if not cands:
        return int(np.argmin(z))
    d = np.linalg.norm(positions0[cands, :2] - com0[None, :2], axis=1)
    return int(cands[int(np.argmin(d))])


def body_weights(
    feature_set: FeatureSet, weights: SearchWeights, support: int | None
) -> tuple[F64, F64]:
    """Per-part ``(wp, wq)``; the support part gets ``max(base, support_*)``."""
    trunk = feature_set.is_trunk()
    wp = np.where(trunk, weights.trunk_position, weights.limb_position).astype(np.float64)
    wq = np.where(trunk, weights.trunk_orientation, weights.limb_orientation).astype(np.float64)
    if support is not None:
        wp[support] = max(wp[support], weights.support_position)
        wq[support] = max(wq[support], weights.support_orientation)
    return wp, wq


def embedding_body_weights(feature_set: FeatureSet, weights: SearchWeights) -> tuple[F64, F64]:
    """Query-independent weights for the KD embedding: the always-support parts (feet) sit halfway
    between their base and support weights, since the query will usually up-weight one of them."""
    wp, wq = body_weights(feature_set, weights, None)
    for p in feature_set.support_always:
        if p in feature_set.parts:
            i = feature_set.parts.index(p)
            wp[i] = 0.5 * (wp[i] + max(wp[i], weights.support_position))
            wq[i] = 0.5 * (wq[i] + max(wq[i], weights.support_orientation))
    return wp, wq


def embedding_frame_weights(window_weights: F64, offsets: NDArray[np.int64]) -> F64:
    """Window weight of each embedded frame: the summed weights of the frames nearest to it."""
    i = np.arange(len(window_weights))
    owner = np.argmin(np.abs(i[:, None] - offsets[None, :]), axis=1)
    return np.asarray(
        np.bincount(owner, weights=window_weights, minlength=len(offsets)), dtype=np.float64
    )


def group_matrix(feature_set: FeatureSet, support: int | None) -> F64:
    """``(P, 3)`` one-hot: trunk, limbs, support."""
    trunk = feature_set.is_trunk()
    g = np.zeros((len(trunk), 3))
    g[trunk, 0] = 1.0
    g[~trunk, 1] = 1.0
    if support is not None:
        g[support] = (0.0, 0.0, 1.0)
    return g


def embed_local(
    local_positions: NDArray[np.floating],
    local_orientations: NDArray[np.floating],
    frame_weights: F64,
    wp: F64,
    wq: F64,
) -> F32:
    """Embedding rows ``(C, E*P*12)`` of windows in local coordinates, ``(C, E, P, 3|4)``."""
    c, e, p = local_positions.shape[:3]
    sp = np.sqrt(frame_weights[:, None] * wp[None, :]).astype(np.float32)  # (E, P)
    sq = np.sqrt(frame_weights[:, None] * wq[None, :] * 0.5).astype(np.float32)
    out = np.empty((c, e, p, 12), dtype=np.float32)
    out[..., :3] = local_positions * sp[None, :, :, None]
    rm = quat_to_matrix(local_orientations.astype(np.float32, copy=False))
    out[..., 3:] = rm.reshape(c, e, p, 9) * sq[None, :, :, None]
    return out.reshape(c, -1)


def part_distances(
    lp: NDArray[np.floating],
    lq: NDArray[np.floating],
    qp: NDArray[np.floating],
    qq: NDArray[np.floating],
) -> tuple[NDArray[np.floating], NDArray[np.floating]]:
    """Per body and frame ``(|dp|, d_theta)`` between local windows ``lp (C, L, P, 3)``, ``lq
    (C, L, P, 4)`` and ``qp``, ``qq`` (broadcast against them); ``lp`` is overwritten."""
    lp -= qp
    dpos = np.sqrt(np.einsum("clpk,clpk->clp", lp, lp))  # (C, L, P)
    # vec(conj(a) * b) = a_w b_v - b_w a_v - a_v x b_v, a = library (local), b = query;
    # only the vector part is needed, so not quat_mul (which also forms w)
    aw, ax, ay, az = lq[..., 0], lq[..., 1], lq[..., 2], lq[..., 3]
    bw, bx, by, bz = qq[..., 0], qq[..., 1], qq[..., 2], qq[..., 3]
    vx = aw * bx - bw * ax - (ay * bz - az * by)
    vy = aw * by - bw * ay - (az * bx - ax * bz)
    vz = aw * bz - bw * az - (ax * by - ay * bx)
    return dpos, 2.0 * np.sqrt(vx * vx + vy * vy + vz * vz)


def window_distances(
    positions: F32,
    orientations: F32,
    heading: F64,
    origin: F64,
    starts: NDArray[np.int64],
    query: QueryWindow,
    window_weights: F64,
    wp: F64,
    wq: F64,
    groups: F64 | None = None,
    offsets: NDArray[np.int64] | None = None,
    precise: bool = True,
    stance: StanceCost | None = None,
) -> tuple[F64, F64 | None]:
    """``D`` between ``query`` and the library windows starting at ``starts``.

    With ``offsets`` (a subset of window frames) and ``window_weights`` given per offset, this is
    the coarse version of ``D`` used to pre-rank candidates; without, the exact ``D``.
    ``precise=False`` computes the same quantities in a cheaper form that loses precision near
    zero (about 1e-3 rad in ``d_theta``), which is fine for pre-ranking only.
    Returns ``(D (C,), breakdown (C, 6) or None)``; the breakdown (when ``groups`` is given)
    follows :data:`BREAKDOWN_TERMS` and sums to ``D``; ``stance``'s cost, when given, is in
    ``D`` and in the support position term.
    """
    if offsets is None:
        offsets = np.arange(query.positions.shape[0])
        qp, qq = query.positions, query.orientations
    else:
        qp, qq = query.positions[offsets], query.orientations[offsets]
    idx = starts[:, None] + offsets[None, :]
    h = heading[starts]
    if precise:
        lp, lq = localize(positions[idx], orientations[idx], h, origin[starts])
        dpos, dang = part_distances(lp, lq, qp[None], qq[None])
    else:
        # cheaper form for pre-ranking: move the query into each library window's frame and use
        # d_theta = 2 sqrt(1 - (qa.qb)^2) (same value, less precise near 0)
        dt = positions.dtype
        c = np.cos(h).astype(dt)[:, None, None]
        s = np.sin(h).astype(dt)[:, None, None]
        pw = positions[idx]
        ex = (
            pw[..., 0]
            - origin[starts, 0].astype(dt)[:, None, None]
            - (c * qp[None, ..., 0] - s * qp[None, ..., 1])
        )
        ey = (
            pw[..., 1]
            - origin[starts, 1].astype(dt)[:, None, None]
            - (s * qp[None, ..., 0] + c * qp[None, ..., 1])
        )
        ez = pw[..., 2] - qp[None, ..., 2]
        dpos = np.sqrt(ex * ex + ey * ey + ez * ez)
        a = orientations[idx]
        aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
        bw, bx, by, bz = qq[None, ..., 0], qq[None, ..., 1], qq[None, ..., 2], qq[None, ..., 3]
        d1 = aw * bw + ax * bx + ay * by + az * bz
        d2 = aw * bz - az * bw + ax * by - ay * bx
        ch = np.cos(0.5 * h).astype(dt)[:, None, None]
        sh = np.sin(0.5 * h).astype(dt)[:, None, None]
        dot = ch * d1 - sh * d2
        dang = 2.0 * np.sqrt(np.maximum(1.0 - dot * dot, 0.0))
    wi = np.asarray(window_weights, dtype=np.float32)
    sp = np.einsum("clp,l->cp", dpos, wi).astype(np.float64)  # per part, time-weighted
    sa = np.einsum("clp,l->cp", dang, wi).astype(np.float64)
    total = sp @ wp + sa @ wq
    extra = None if stance is None else stance.cost(positions, starts, query)
    if extra is not None:
        total = total + extra
    if groups is None:
        return total, None
    bp = (sp * wp[None]) @ groups  # (C, 3)
    if extra is not None:
        bp[:, 2] += extra
    ba = (sa * wq[None]) @ groups
    br = np.stack([bp[:, 0], ba[:, 0], bp[:, 1], ba[:, 1], bp[:, 2], ba[:, 2]], axis=1)
    return total, br


def frame_pose_steps(
    positions: F32,
    orientations: F32,
    heading: F64,
    origin: F64,
    wp: F64,
    wq: F64,
    chunk: int = 65536,
) -> F32:
    """``(N,)`` pose distance between each frame and the previous one (0 for frame 0), each in its
    own root frame: ``sum_b wp_b |dp_b| + wq_b d_theta_b`` (``D`` of a one-frame window).
    Differences across clip boundaries are meaningless; callers ignore them."""
    n = positions.shape[0]
    out = np.zeros(n, dtype=np.float32)
    prev_p = prev_q = None
    for i in range(0, n, chunk):
        sl = slice(i, min(n, i + chunk))
        lp, lq = localize(
            positions[sl][:, None], orientations[sl][:, None], heading[sl], origin[sl]
        )
        lp, lq = lp[:, 0], lq[:, 0]
        if prev_p is not None:
            lp = np.concatenate([prev_p, lp])
            lq = np.concatenate([prev_q, lq])
        dp = np.sqrt(((lp[1:] - lp[:-1]) ** 2).sum(-1))
        dot = np.abs((lq[1:] * lq[:-1]).sum(-1))
        da = 2.0 * np.sqrt(np.maximum(1.0 - dot * dot, 0.0))
        d = dp @ wp.astype(np.float32) + da @ wq.astype(np.float32)
        if prev_p is None:
            out[sl.start + 1 : sl.stop] = d
        else:
            out[sl] = d
        prev_p, prev_q = lp[-1:], lq[-1:]
    return out
