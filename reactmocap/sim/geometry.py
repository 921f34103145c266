"""The character's collision and mass geometry: capsules along the bones, a sphere for the head,
boxes for the feet (soles placed from the clip so a standing character neither floats nor sinks)
and a ball-of-foot contact patch, sized from human proportions scaled by leg length."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import SimulationError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import quat_conj, quat_from_matrix, quat_rotate
from reactmocap.sim.bodies import SIM_BODIES

__all__ = ["BALL_PATCH_HALF_SIZE", "PATCH_GEOM_GROUP", "GeomSpec", "make_geoms"]

F64 = NDArray[np.float64]

# Human proportions (fractions of a 0.85 m hip-to-ankle leg, i.e. a 1.75 m adult).
_LEG_REF = 0.85
_RADIUS = {
    "pelvis": 0.095, "waist": 0.09, "chest": 0.105, "neck": 0.05, "head": 0.1,
    "upper_arm": 0.045, "forearm": 0.037, "hand": 0.03, "thigh": 0.075, "shin": 0.05,
}  # fmt: skip
_FOOT = {"heel": 0.06, "toe": 0.05, "half_width": 0.04, "half_height": 0.025}
_HAND_LEN = 0.10
#: half-size (m) of the ball-of-foot contact patch each foot carries switched off: a tracking
#: controller turns it on, and the foot box off, while the actor pivots on that foot (a box's
#: corners hold a yaw torque of mu N times half its width; a pivoting forefoot holds little)
BALL_PATCH_HALF_SIZE = 0.005
#: MuJoCo geom group of the patch: hidden by the default visualisation (groups 0-2)
PATCH_GEOM_GROUP = 3


def _unit(v: F64) -> F64:
    n = float(np.linalg.norm(v))
    if n < 1e-9:
        raise SimulationError("degenerate geometry: zero-length axis while building the character")
    return v / n


def _perp(v: F64) -> F64:
    a = np.array([1.0, 0.0, 0.0]) if abs(v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    return np.cross(v, a)


@dataclass(frozen=True)
class GeomSpec:
    body: str
    kind: Literal["capsule", "sphere", "box"]
    size: tuple[float, ...]
    fromto: tuple[float, ...] | None = None  # capsule, body-local
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    #: a massless, hidden contact geom (see :data:`BALL_PATCH_HALF_SIZE`); compiled colliding
    #: (MuJoCo leaves geoms that cannot collide at compile time out of the body's collision
    #: tree for good), and switched off by the World
    patch: bool = False


def make_geoms(
    skel: Skeleton,
    parts: BodyPartMap,
    anchors: NDArray[np.int64],
    ref: Motion,
    frame: int,
    P: F64,
    G: F64,
) -> tuple[GeomSpec, ...]:
    """Collision/mass geometry, computed in the reference pose's world frame and converted to
    each body's local frame."""
    idx = {b: i for i, b in enumerate(SIM_BODIES)}

    def at(b: str) -> F64:
        return P[idx[b]]

    leg = 0.5 * sum(
        np.linalg.norm(at(f"{s}_thigh") - at(f"{s}_shin"))
        + np.linalg.norm(at(f"{s}_shin") - at(f"{s}_foot"))
        for s in "lr"
    )
    s = float(leg) / _LEG_REF
    if not 0.3 < s < 3.0:
        raise SimulationError(
            f"implausible leg length {leg:.3f} m (hip to ankle); is the skeleton in metres?"
        )
    r = {k: v * s for k, v in _RADIUS.items()}

    def local(b: str, x: F64) -> F64:
        return quat_rotate(quat_conj(G[idx[b]]), x - P[idx[b]])

    def capsule(b: str, a: F64, c: F64, radius: float) -> GeomSpec:
        la, lc = local(b, a), local(b, c)
        if np.linalg.norm(lc - la) < 1e-4:  # degenerate bone: a sphere
            return GeomSpec(b, "sphere", (radius,), pos=tuple(la))
        return GeomSpec(b, "capsule", (radius,), fromto=(*la, *lc))

    out: list[GeomSpec] = []
    # trunk: lateral capsules
    hip_l, hip_r = at("l_thigh"), at("r_thigh")
    hip_mid = 0.5 * (hip_l + hip_r)
    lat_p = _unit(hip_l - hip_r)
    up_p = at("waist") - hip_mid
    up_p = _unit(up_p - lat_p * float(lat_p @ up_p))
    half = max(0.5 * float(np.linalg.norm(hip_l - hip_r)) - 0.01 * s, 0.03 * s)
    c = hip_mid + up_p * 0.045 * s
    out.append(capsule("pelvis", c - lat_p * half, c + lat_p * half, r["pelvis"]))

    sh_l, sh_r = at("l_upper_arm"), at("r_upper_arm")
    lat_c = _unit(sh_l - sh_r)
    lat_w = _unit(lat_p + lat_c)
    c = 0.5 * (at("waist") + at("chest"))
    out.append(capsule("waist", c - lat_w * 0.06 * s, c + lat_w * 0.06 * s, r["waist"]))

    neck_base = at("head")  # the head body's anchor (neck joint, or head if no neck)
    c = at("chest") + 0.55 * (neck_base - at("chest"))
    half = max(0.5 * float(np.linalg.norm(sh_l - sh_r)) - 0.6 * r["chest"], 0.04 * s)
    out.append(capsule("chest", c - lat_c * half, c + lat_c * half, r["chest"]))

    # head (+ neck)
    head_j = parts.joint_of("head")
    head_p = ref.global_positions()[frame, head_j]
    ends = skel.layout.end_sites
    up_chest = _unit(neck_base - at("chest"))
    if np.linalg.norm(head_p - neck_base) > 1e-3:
        out.append(capsule("head", neck_base, head_p, r["neck"]))
        hdir = _unit(head_p - neck_base)
    else:
        hdir = up_chest
    grot_head = ref.forward_kinematics()[1][frame, head_j]
    end = np.asarray(ends.get(head_j, (0.0, 0.0, 0.0)), dtype=float)
    if np.linalg.norm(end) > 0.05 * s:
        centre = head_p + 0.5 * quat_rotate(grot_head, end)
    else:
        centre = head_p + hdir * 0.09 * s
    out.append(GeomSpec("head", "sphere", (r["head"],), pos=tuple(local("head", centre))))

    gpos_ref, grot_ref = ref.forward_kinematics()
    for side in "lr":
        # arms
        out.append(
            capsule(
                f"{side}_upper_arm", at(f"{side}_upper_arm"), at(f"{side}_forearm"), r["upper_arm"]
            )
        )
        out.append(
            capsule(f"{side}_forearm", at(f"{side}_forearm"), at(f"{side}_hand"), r["forearm"])
        )
        hand_j = int(anchors[idx[f"{side}_hand"]])
        hend = np.asarray(ends.get(hand_j, (0.0, 0.0, 0.0)), dtype=float)
        wrist = at(f"{side}_hand")
        if np.linalg.norm(hend) > 0.05 * s:
            hdir_w = _unit(quat_rotate(grot_ref[frame, hand_j], hend))
            length = min(0.6 * float(np.linalg.norm(hend)), 0.14 * s)
        else:  # straight continuation of the forearm
            hdir_w = _unit(wrist - at(f"{side}_forearm"))
            length = _HAND_LEN * s
        out.append(
            capsule(f"{side}_hand", wrist + hdir_w * 0.01 * s, wrist + hdir_w * length, r["hand"])
        )
        # legs
        out.append(capsule(f"{side}_thigh", at(f"{side}_thigh"), at(f"{side}_shin"), r["thigh"]))
        out.append(capsule(f"{side}_shin", at(f"{side}_shin"), at(f"{side}_foot"), r["shin"]))
        box, ball_x = _foot_box(
            skel,
            parts,
            anchors,
            ref,
            frame,
            side,
            s,
            G[idx[f"{side}_foot"]],
            gpos_ref,
            grot_ref,
        )
        out.append(box)
        out.append(_ball_patch(box, ball_x))
    return tuple(out)


def _ball_patch(box: GeomSpec, ball_x: float) -> GeomSpec:
    """The ball-of-foot contact patch: a small cube, aligned with the foot box, whose bottom
    face lies in the sole plane under the ball (``ball_x`` along the box's x axis from its
    centre), in the foot's local frame: flat on the floor like the box it stands in for."""
    hz, r = box.size[2], BALL_PATCH_HALF_SIZE
    local = np.array([ball_x, 0.0, -hz + r])
    pos = np.asarray(box.pos) + quat_rotate(np.asarray(box.quat), local)
    return GeomSpec(box.body, "box", (r, r, r), pos=tuple(pos), quat=box.quat, patch=True)


def _foot_box(
    skel: Skeleton,
    parts: BodyPartMap,
    anchors: NDArray[np.int64],
    ref: Motion,
    frame: int,
    side: str,
    s: float,
    g_foot: F64,
    gpos: F64,
    grot: F64,
) -> tuple[GeomSpec, float]:
    """The foot box in the foot's local frame, and the ball's (toe joint's) offset from the
    box centre along the box's x axis.

    The sole is placed from the clip: the ankle's lowest height over the reference motion is its
    height above the sole, and the ball (toe joint) sits its own lowest height above it; the
    box's roll comes from the frame where the ankle is lowest (most likely flat on the floor).
    """
    b = f"{side}_foot"
    fj = int(anchors[SIM_BODIES.index(b)])
    toe = parts.joints.get(f"{side}_toe")
    ankle_z = gpos[:, fj, 2]
    t_low = int(np.argmin(ankle_z))
    h_a = (
        float(np.clip(ankle_z.min(), 0.05 * s, 0.16 * s))
        if ref.num_frames > 1 or ankle_z.min() > 0.02
        else 0.08 * s
    )
    # ankle -> ball, in the foot's local frame (rigid: toes are folded at their reference pose)
    if toe is not None:
        f = quat_rotate(quat_conj(grot[frame, fj]), gpos[frame, toe] - gpos[frame, fj])
        h_b = (
            float(np.clip(gpos[:, toe, 2].min(), 0.0, h_a - 0.02 * s))
            if ref.num_frames > 1
            else 0.02 * s
        )
    else:
        end = np.asarray(skel.layout.end_sites.get(fj, (0.0, 0.0, 0.0)), dtype=float)
        if np.linalg.norm(end) > 0.05 * s:
            f = end
        else:  # forward of the pelvis, expressed in the foot frame
            fwd = np.cross(
                gpos[frame, parts.joint_of("l_thigh")] - gpos[frame, parts.joint_of("r_thigh")],
                [0.0, 0.0, 1.0],
            )
            f = quat_rotate(quat_conj(grot[frame, fj]), _unit(-fwd) * 0.13 * s)
        h_b = 0.02 * s
    # world up at the flattest frame, in foot-local coordinates
    u0 = quat_rotate(quat_conj(grot[t_low, fj]), np.array([0.0, 0.0, 1.0]))
    lateral = np.cross(f, u0)
    if np.linalg.norm(lateral) < 1e-6:
        lateral = _perp(f)
    lateral = _unit(lateral)
    fhat = _unit(f - lateral * float(lateral @ f))
    n = np.cross(lateral, fhat)
    if n @ u0 < 0:
        n = -n
    flen = float(np.linalg.norm(f))
    k = float(np.clip((h_a - h_b) / max(flen, 1e-6), 0.0, 0.8))
    up = np.sqrt(1.0 - k * k) * n - k * fhat  # sole normal: the ball is (h_a - h_b) below
    fwd = _unit(fhat - up * float(up @ fhat))
    lat = np.cross(up, fwd)
    x0 = -_FOOT["heel"] * s
    x1 = float(f @ fwd) + _FOOT["toe"] * s
    hz = _FOOT["half_height"] * s
    centre = fwd * 0.5 * (x0 + x1) + up * (-h_a + hz)
    quat = quat_from_matrix(np.stack([fwd, lat, up], axis=1))
    del g_foot
    box = GeomSpec(
        b,
        "box",
        (0.5 * (x1 - x0), _FOOT["half_width"] * s, hz),
        pos=tuple(centre),
        quat=tuple(quat),
    )
    return box, float(f @ fwd) - 0.5 * (x0 + x1)
