"""The thesis's male and female bodies as MuJoCo models, straight from its SD/FAST listings.

Source: seed ``001`` (Wooten), Appendix A.1 "SD-Fast Input File for Male Model" and A.2 "... for
Female Model" (53 DOF each). Each listing body is transcribed below as a Python literal.

SD/FAST conventions, as the listings use them:

* ``mass`` (kg) and ``inertia`` (kg m^2) about the body's centre of mass, in the body frame. Three
  numbers are the diagonal; the female CHEST1 has a full matrix (see OCR note there).
* ``bodyToJoint``: vector from the body's COM to its inboard joint; ``inbToJoint``: from the
  inboard (parent) body's COM to the same joint. Both are in body frames, which in the reference
  configuration (all joint angles zero) are aligned with the model space, so
  ``joint = com(parent) + inbToJoint = com(body) + bodyToJoint``.
* Joint types: the root PELVIS is a free body; ``gimbal`` = 3 rotations about the listed pins in
  order; ``ball`` = 3-DOF ball (no pins); ``ujoint`` = 2 rotations about the two pins (first pin
  first); ``pin`` = 1 hinge.
* ``# original center of mass`` comments give every COM in model space; we store them and the test
  checks that chaining ``inbToJoint - bodyToJoint`` from the pelvis reproduces them.

Coordinates: the thesis model space is Z up, X forward (the body faces +X), +Y the body's left,
metres, heels and balls of the feet at z = 0 (section 3.1). That is already our right-handed Z-up
world, so the conversion to Z-up is the identity: vectors are used as printed.

MuJoCo layout: each body's frame sits at its inboard joint (the pelvis's at its COM), aligned with
the world in the reference pose; ``ipos = -bodyToJoint``; ``pos = inbToJoint - parent's
bodyToJoint``. Inertias are explicit, so the geoms carry no mass. ``gimbal`` maps to a MuJoCo ball
joint by default (same 3 DOF, no Euler singularity, what the PD servo expects); ``gimbal="hinges"``
gives three hinges about the listed pins instead. ``ujoint`` and ``pin`` map to one hinge per pin.

Geometry (collision only): each segment is the solid box with the segment's own mass and inertia
(half-extents ``sqrt(1.5 (I_b + I_c - I_a) / m)``), on its principal axes at its COM; the foot and
toe boxes are stretched down to z = 0 so the soles start on the ground as the thesis says. The
geoms collide with world geoms only (contype 1, conaffinity 0): the thesis modelled only the
feet's and hands' contact with the ground.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import UnknownKeyError
from reactmocap.library.anthropometry import SEXES, listing_body_part

__all__ = [
    "ListingBody",
    "inertia_matrix",
    "reference_body_model",
    "reference_body_spec",
    "reference_listing",
    "reference_part_masses",
    "reference_segment_masses",
    "reference_total_mass",
]

Vec3 = tuple[float, float, float]
JointType = Literal["free", "gimbal", "ball", "ujoint", "pin"]


@dataclass(frozen=True)
class ListingBody:
    """One ``body =`` block of an SD/FAST listing. ``pins`` are axis letters in listing order."""

    name: str
    parent: str | None
    joint: str | None
    jtype: JointType
    mass: float
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3]  # diagonal, or full symmetric 3x3 rows
    body_to_joint: Vec3
    inb_to_joint: Vec3
    pins: str
    com: Vec3  # "# original center of mass" comment, model space


_O: Vec3 = (0.0, 0.0, 0.0)


def _b(
    name: str,
    parent: str | None,
    joint: str | None,
    jtype: JointType,
    pins: str,
    mass: float,
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3],
    b2j: Vec3,
    i2j: Vec3,
    com: Vec3,
) -> ListingBody:
    return ListingBody(name, parent, joint, jtype, mass, inertia, b2j, i2j, pins, com)


# fmt: off
# Appendix A.1 ("creature man"), in listing order.
_MALE: tuple[ListingBody, ...] = (
    _b("PELVIS", None, None, "free", "", 10.73192768, (0.08625900, 0.07114769, 0.10951932),
       _O, _O, (-0.006808, 0.000377, 1.001726)),
    _b("CHEST3", "PELVIS", "SPINEL3", "gimbal", "xyz", 6.16425603,
       (0.04426617, 0.02708728, 0.06084866), (-0.01437270, 0.00016502, -0.04986785),
       (0.00760776, -0.00037653, 0.07717409), (0.015173, -0.000165, 1.128768)),
    _b("ULEGR", "PELVIS", "HIPR", "gimbal", "yxz", 10.46012762,
       (0.15355185, 0.16367185, 0.04429564), (-0.01112982, 0.01363505, 0.17363924),
       (-0.01239224, -0.08237653, -0.06462591), (-0.008070, -0.095635, 0.763461)),
    _b("ULEGL", "PELVIS", "HIPL", "gimbal", "yxz", 10.47768003,
       (0.15406018, 0.16421820, 0.04440836), (-0.01108264, -0.01365917, 0.17341847),
       (-0.01239224, 0.08162347, -0.06462591), (-0.008117, 0.095659, 0.763682)),
    _b("LLEGR", "ULEGR", "KNEER", "pin", "y", 5.32342559,
       (0.07455836, 0.07841995, 0.01133475), (0.02146139, -0.00046737, 0.19117168),
       (-0.01192982, -0.00036495, -0.23906076), (-0.041461, -0.095533, 0.333228)),
    _b("LLEGL", "ULEGL", "KNEEL", "pin", "y", 5.32382113,
       (0.07456326, 0.07842407, 0.01133626), (0.02145587, 0.00042748, 0.19113195),
       (-0.01188264, 0.00034083, -0.23928153), (-0.041456, 0.095573, 0.333268)),
    _b("FOOTR", "LLEGR", "ANKLER", "ujoint", "xy", 0.82704597,
       (0.00079011, 0.00169920, 0.00170150), (-0.03407298, 0.00929370, 0.04439173),
       (-0.01303861, 0.00723263, -0.24962832), (-0.020427, -0.097594, 0.039208)),
    _b("FOOTL", "LLEGL", "ANKLEL", "ujoint", "xy", 0.82708382,
       (0.00079017, 0.00169904, 0.00170133), (-0.03407336, -0.00934602, 0.04440053),
       (-0.01304413, -0.00727252, -0.24966805), (-0.020427, 0.097646, 0.039199)),
    _b("TOER", "FOOTR", "MTR", "pin", "y", 0.27931170,
       (0.00019601, 0.00021530, 0.00032521), (-0.03513905, -0.00723206, 0.00374546),
       (0.07012702, -0.01250630, -0.01700827), (0.084839, -0.102868, 0.018455)),
    _b("TOEL", "FOOTL", "MTL", "pin", "y", 0.27936107,
       (0.00019611, 0.00021532, 0.00032534), (-0.03513646, 0.00717282, 0.00374795),
       (0.07012664, 0.01245398, -0.01699947), (0.084836, 0.102927, 0.018452)),
    # OCR: this block's inbToJoint values and the pins' last components were pushed below the
    # block; read back as inbToJoint = (-0.01637270, 0.00016502, 0.05143215), pins x, y, z. The
    # chain check reproduces the block's COM comment and Table 3.3's L1 joint with them.
    _b("CHEST2", "CHEST3", "SPINEL1", "gimbal", "xyz", 8.38627372,
       (0.07367761, 0.04328265, 0.09559950), (-0.01167600, -0.00009735, -0.06524239),
       (-0.01637270, 0.00016502, 0.05143215), (0.010476, 0.000097, 1.245442)),
    _b("CHEST1", "CHEST2", "SPINET7", "gimbal", "xyz", 8.77688230,
       (0.10357844, 0.04943749, 0.14010687), (-0.00156584, -0.00006612, -0.04937830),
       (-0.01247600, -0.00009735, 0.05855761), (-0.000434, 0.000066, 1.353378)),
    _b("STERNUM", "CHEST1", "SPINET4", "gimbal", "xyz", 2.19711680,
       (0.00510826, 0.01233765, 0.00897859), (-0.00110665, 0.00020018, -0.06970092),
       (-0.01196584, -0.00006612, 0.04582170), (-0.011293, -0.000200, 1.468901)),
    _b("CHESTR", "STERNUM", "CLAVR", "ujoint", "xz", 4.08793607,
       (0.01437074, 0.02037179, 0.02048838), (0.01161879, 0.06885024, 0.01912323),
       (0.01379335, -0.03519982, 0.01439908), (-0.009119, -0.104250, 1.464177)),
    _b("CHESTL", "STERNUM", "CLAVL", "ujoint", "xz", 4.08715518,
       (0.01440587, 0.02039169, 0.02046155), (0.01162093, -0.06887917, 0.01909569),
       (0.01379335, 0.03560018, 0.01439908), (-0.009121, 0.104279, 1.464204)),
    _b("UARMR", "CHESTR", "SHLDR", "ball", "", 3.82365595,
       (0.02567638, 0.00921546, 0.02716907), (-0.00576475, 0.11420892, 0.01641385),
       (0.00861879, -0.07724976, 0.01902323), (0.005265, -0.295709, 1.466786)),
    _b("UARML", "CHESTL", "SHLDL", "ball", "", 3.82079247,
       (0.02565624, 0.00919585, 0.02714534), (-0.00574953, -0.11419286, 0.01639848),
       (0.00862093, 0.07722083, 0.01899569), (0.005250, 0.295693, 1.466802)),
    _b("LARMR", "UARMR", "ELBR", "ujoint", "yz", 1.77960435,
       (0.01303935, 0.00294703, 0.01485761), (-0.04084986, 0.13475268, -0.00377603),
       (0.01123525, -0.16039108, 0.00781385), (0.057350, -0.590853, 1.478376)),
    _b("LARML", "UARML", "ELBL", "ujoint", "yz", 1.75104662,
       (0.01253812, 0.00287798, 0.01431001), (-0.04134162, -0.13637649, -0.00378509),
       (0.01125047, 0.16040714, 0.00779848), (0.057842, 0.592476, 1.478385)),
    _b("HANDR", "LARMR", "WRSTR", "ujoint", "xy", 0.66527452,
       (0.00118359, 0.00067766, 0.00128598), (-0.02477955, 0.07408025, 0.01696596),
       (0.06175014, -0.16684732, -0.00407603), (0.143880, -0.831780, 1.457334)),
    _b("HANDL", "LARML", "WRSTL", "ujoint", "xy", 0.66455597,
       (0.00120281, 0.00069644, 0.00128522), (-0.02478783, -0.07404980, 0.01702640),
       (0.06125838, 0.16522351, -0.00408509), (0.143888, 0.831750, 1.457274)),
    _b("HEAD", "STERNUM", "NECKC2", "gimbal", "xyz", 7.10606697,
       (0.04919430, 0.05971314, 0.02982596), (-0.03142963, 0.00003337, -0.13849000),
       (0.02459335, 0.00020018, 0.08589908), (0.044730, -0.000033, 1.693290)),
)

# Appendix A.2 ("creature woman"), in listing order.
_FEMALE: tuple[ListingBody, ...] = (
    _b("PELVIS", None, None, "free", "", 6.32919497, (0.03868504, 0.02831247, 0.04393691),
       _O, _O, (-0.027413, 0.000268, 0.887866)),
    _b("CHEST3", "PELVIS", "SPINEL3", "gimbal", "xyz", 2.10200160,
       (0.00834432, 0.00433670, 0.01115681), (-0.00557687, -0.00010479, -0.02941049),
       (0.01141261, -0.00026837, 0.07413422), (-0.010423, 0.000105, 0.991410)),
    _b("ULEGR", "PELVIS", "HIPR", "gimbal", "yxz", 7.41113444,
       (0.11154523, 0.11546858, 0.02203643), (-0.01116249, 0.00485824, 0.17370996),
       (-0.01058739, -0.07726837, -0.05186578), (-0.026838, -0.081858, 0.662290)),
    _b("ULEGL", "PELVIS", "HIPL", "gimbal", "yxz", 7.38199049,
       (0.11072447, 0.11463433, 0.02190973), (-0.01116803, -0.00492935, 0.17430041),
       (-0.01058739, 0.07673163, -0.05186578), (-0.026832, 0.081929, 0.661700)),
    _b("LLEGR", "ULEGR", "KNEER", "pin", "y", 1.99922397,
       (0.01500744, 0.01518789, 0.00206030), (0.01198529, 0.00954947, 0.13838679),
       (-0.00016249, 0.00385824, -0.26129004), (-0.038985, -0.087549, 0.262613)),
    _b("LLEGL", "ULEGL", "KNEEL", "pin", "y", 1.99896813,
       (0.01500421, 0.01518365, 0.00205986), (0.01199311, -0.00953830, 0.13838563),
       (-0.00016803, -0.00392935, -0.26069959), (-0.038993, 0.087538, 0.262614)),
    _b("FOOTR", "LLEGR", "ANKLER", "ujoint", "xy", 0.51208883,
       (0.00039442, 0.00073929, 0.00065925), (-0.02420792, 0.00579759, 0.04573842),
       (-0.00001471, -0.00045053, -0.18061321), (-0.014792, -0.093798, 0.036262)),
    _b("FOOTL", "LLEGL", "ANKLEL", "ujoint", "xy", 0.51200006,
       (0.00039428, 0.00073911, 0.00065909), (-0.02420616, -0.00580036, 0.04573784),
       (-0.00000689, 0.00046170, -0.18061437), (-0.014794, 0.093800, 0.036262)),
    _b("TOER", "FOOTR", "MTR", "pin", "y", 0.15297542,
       (0.00007656, 0.00007881, 0.00012469), (-0.02982516, -0.00725216, 0.00148575),
       (0.05779208, -0.00020241, -0.02126158), (0.072825, -0.086748, 0.013514)),
    _b("TOEL", "FOOTL", "MTL", "pin", "y", 0.15297222,
       (0.00007660, 0.00007881, 0.00012474), (-0.02982516, 0.00724545, 0.00149124),
       (0.05779384, 0.00019964, -0.02126216), (0.072825, 0.086755, 0.013509)),
    _b("CHEST2", "CHEST3", "SPINEL1", "gimbal", "xyz", 2.62236597,
       (0.01026760, 0.00640238, 0.01355024), (-0.00845506, -0.00011161, -0.04408629),
       (-0.01157687, -0.00010479, 0.03558951), (-0.013545, 0.000112, 1.071086)),
    # OCR: the only full inertia matrix, printed "0.02356694 0.00003799 0.00026791 ? 0.01582748
    # -0.00001199 ? ? 0.03369183": the upper triangle row by row, with "?" for the lower-triangle
    # entries (lost in the OCR, or SD/FAST's "?"). Read as the symmetric matrix below; its
    # diagonal matches Table 3.2's Upper Chest (0.0236 0.0158 0.0337).
    _b("CHEST1", "CHEST2", "SPINET7", "gimbal", "xyz", 4.27710072,
       ((0.02356694, 0.00003799, 0.00026791),
        (0.00003799, 0.01582748, -0.00001199),
        (0.00026791, -0.00001199, 0.03369183)),
       (-0.00815706, -0.00034165, -0.04777056), (-0.01745506, -0.00011161, 0.03991371),
       (-0.022843, 0.000342, 1.158771)),
    _b("STERNUM", "CHEST1", "SPINET4", "gimbal", "xyz", 1.20288477,
       (0.00255317, 0.00544391, 0.00331153), (0.01147995, 0.00002965, -0.06913993),
       (-0.01215706, -0.00034165, 0.04222944), (-0.046480, -0.000030, 1.270140)),
    _b("CHESTR", "STERNUM", "CLAVR", "ujoint", "xz", 3.07161686,
       (0.00974820, 0.01216337, 0.01205795), (0.01172404, 0.06311748, 0.03513842),
       (0.01147995, -0.02297035, 0.02986007), (-0.046724, -0.086117, 1.264862)),
    _b("CHESTL", "STERNUM", "CLAVL", "ujoint", "xz", 3.07182394,
       (0.00975929, 0.01213742, 0.01213174), (0.01184086, -0.06322476, 0.03483491),
       (0.01147995, 0.02302965, 0.02986007), (-0.046841, 0.086225, 1.265165)),
    _b("UARMR", "CHESTR", "SHLDR", "ball", "", 1.82684296,
       (0.01220178, 0.00219215, 0.01243861), (-0.01443781, 0.12472698, 0.02174872),
       (-0.01927596, -0.08488252, 0.02213842), (-0.051562, -0.295727, 1.265251)),
    _b("UARML", "CHESTL", "SHLDL", "ball", "", 1.85585454,
       (0.01239712, 0.00225052, 0.01262077), (-0.01409531, -0.12370283, 0.02222437),
       (-0.01915914, 0.08477524, 0.02183491), (-0.051905, 0.294703, 1.264776)),
    _b("LARMR", "UARMR", "ELBR", "ujoint", "yz", 0.74929802,
       (0.00270968, 0.00074898, 0.00301057), (-0.03083470, 0.08893459, 0.00864379),
       (0.01556219, -0.15427302, -0.02125128), (-0.005165, -0.538935, 1.235356)),
    _b("LARML", "UARML", "ELBL", "ujoint", "yz", 0.78526077,
       (0.00300027, 0.00082843, 0.00333567), (-0.03228567, -0.09163420, 0.00960664),
       (0.01590469, 0.15529717, -0.02077563), (-0.003714, 0.541634, 1.234393)),
    _b("HANDR", "LARMR", "WRSTR", "ujoint", "xy", 0.33399683,
       (0.00041227, 0.00026027, 0.00040049), (-0.01693224, 0.05186523, 0.02697691),
       (0.04316530, -0.12706541, -0.01535621), (0.054932, -0.717865, 1.193023)),
    _b("HANDL", "LARML", "WRSTL", "ujoint", "xy", 0.31935170,
       (0.00036701, 0.00024317, 0.00035605), (-0.01774276, -0.05393011, 0.02778205),
       (0.04171433, 0.12436580, -0.01439336), (0.055743, 0.719930, 1.192218)),
    _b("HEAD", "STERNUM", "NECKC2", "gimbal", "xyz", 4.63528342,
       (0.02167552, 0.02625140, 0.01435155), (-0.01565287, -0.00002632, -0.09308243),
       (-0.01552005, 0.00002965, 0.12356007), (-0.046347, 0.000026, 1.486782)),
)
# fmt: on

_LISTINGS: dict[str, tuple[ListingBody, ...]] = {"male": _MALE, "female": _FEMALE}
_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_SOLE_BODIES = ("FOOT", "TOE")  # name prefixes of the bodies whose boxes reach down to z = 0


def reference_listing(sex: str) -> tuple[ListingBody, ...]:
    """The transcribed SD/FAST listing of Appendix A.1 (``"male"``) or A.2 (``"female"``)."""
    try:
        return _LISTINGS[sex]
    except KeyError:
        raise UnknownKeyError(f"unknown sex {sex!r}; valid keys: {list(SEXES)}") from None


def inertia_matrix(body: ListingBody) -> NDArray[np.float64]:
    """The body's 3x3 inertia about its COM (kg m^2)."""
    arr = np.asarray(body.inertia, dtype=np.float64)
    return np.diag(arr) if arr.ndim == 1 else arr


def _equivalent_box(mass: float, inertia: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """(half-extents, wxyz quat of the principal axes) of the uniform box with this inertia."""
    evals, evecs = np.linalg.eigh(inertia)
    # eigh sorts by size: reorder so principal axis i is the one nearest world axis i, sign +
    order = np.argsort(np.argmax(np.abs(evecs), axis=0))
    evals, evecs = evals[order], evecs[:, order]
    evecs *= np.sign(np.diag(evecs))
    a, b, c = evals
    half = np.sqrt(np.maximum(1.5 * np.array([b + c - a, a + c - b, a + b - c]) / mass, 1e-6))
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, evecs.reshape(-1))
    return half, quat


def reference_body_spec(
    sex: str,
    *,
    floor: bool = True,
    gimbal: Literal["ball", "hinges"] = "ball",
    timestep: float = 0.0005,
) -> mujoco.MjSpec:
    """MuJoCo spec of the thesis's ``"male"`` or ``"female"`` body in its reference pose.

    Bodies and joints keep the listing's names (``ULEGR``, ``HIPR``); hinges of a multi-pin joint
    are named ``{joint}_{axis}`` (``ANKLER_x``). ``floor`` adds a z = 0 plane (friction 1.0).
    """
    listing = reference_listing(sex)
    if gimbal not in ("ball", "hinges"):
        raise UnknownKeyError(f"unknown gimbal mapping {gimbal!r}; valid keys: ['ball', 'hinges']")
    spec = mujoco.MjSpec()
    spec.modelname = f"thesis_{sex}"
    spec.option.timestep = timestep
    spec.option.gravity = [0.0, 0.0, -9.80665]  # the listings' gravity
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    if floor:
        spec.worldbody.add_geom(
            name="floor",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=[5.0, 5.0, 0.1],
            friction=[1.0, 0.005, 0.0001],
        )

    by_name = {b.name: b for b in listing}
    made: dict[str, mujoco.MjsBody] = {}
    for body in listing:
        com = np.asarray(body.com)
        if body.parent is None:
            mj = spec.worldbody.add_body(name=body.name, pos=com)
            mj.add_freejoint(name=f"{body.name}_root")
        else:
            parent = by_name[body.parent]
            pos = np.subtract(body.inb_to_joint, parent.body_to_joint)
            mj = made[body.parent].add_body(name=body.name, pos=pos)
            _add_joint(mj, body, gimbal)
        made[body.name] = mj
        inertia = inertia_matrix(body)
        mj.mass = body.mass
        mj.ipos = -np.asarray(body.body_to_joint)
        mj.fullinertia = [*np.diag(inertia), inertia[0, 1], inertia[0, 2], inertia[1, 2]]
        mj.explicitinertial = True
        half, quat = _equivalent_box(body.mass, inertia)
        centre = np.array(mj.ipos, dtype=np.float64)
        if body.name.startswith(_SOLE_BODIES):
            # stretch the box down to the ground (model z = 0), keep its top face
            top = com[2] + half[2]
            half[2] = top / 2.0
            centre[2] += top / 2.0 - com[2]
        mj.add_geom(
            name=f"{body.name}_geom",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=half,
            pos=centre,
            quat=quat,
            contype=1,
            conaffinity=0,
            mass=0.0,
        )
    return spec


def _add_joint(mj: mujoco.MjsBody, body: ListingBody, gimbal: str) -> None:
    if body.jtype == "ball" or (body.jtype == "gimbal" and gimbal == "ball"):
        mj.add_joint(name=body.joint, type=mujoco.mjtJoint.mjJNT_BALL)
        return
    for axis in body.pins:  # successive hinges in one body compose in listing order
        name = body.joint if len(body.pins) == 1 else f"{body.joint}_{axis}"
        mj.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=_AXES[axis])


def reference_body_model(sex: str, **kwargs: object) -> mujoco.MjModel:
    """Compiled :func:`reference_body_spec` (same keyword arguments)."""
    return reference_body_spec(sex, **kwargs).compile()  # type: ignore[arg-type]


def reference_segment_masses(sex: str) -> dict[str, float]:
    """Listing body name -> mass (kg), exactly as printed in Appendix A."""
    return {b.name: b.mass for b in reference_listing(sex)}


def reference_total_mass(sex: str) -> float:
    """Sum of the listing's body masses (kg): 97.84 male, 53.30 female."""
    return float(sum(reference_segment_masses(sex).values()))


def reference_part_masses(sex: str) -> dict[str, float]:
    """Canonical body part (``anthropometry.REFERENCE_PARTS``) -> mass (kg) of the listing."""
    out: dict[str, float] = {}
    for body in reference_listing(sex):
        part = listing_body_part(sex, body.name)
        out[part] = out.get(part, 0.0) + body.mass
    return out
