"""Segment mass tables of the thesis's male and female bodies (seed ``001``, Wooten, chapter 3).

Source: Tables 3.1 (male) and 3.2 (female), "Dynamics parameters of the rigid body segments",
section 3.1 "Dynamic Simulations" (printed page 30), and Tables 3.3/3.4 (joint locations, same
section). The thesis computed each segment's mass and inertia from a convex polyhedron and the
Dempster & Gaughran [DG65] densities, in its model space: **Z up, X forward (the body faces +X),
+Y to the body's left**, metres, heels and balls of the feet at z = 0 (section 3.1). That frame is
right-handed and Z-up, so it *is* our world frame: no axis conversion is needed.

Reading of the OCR text (``/work/shared/seeds/001_*.txt``):

* Bilateral rows are printed once with a ``±`` before |y|; the OCR renders it as ``0:096``. We
  store |y| and a ``bilateral`` flag; the SD/FAST listing (Appendix A) has both sides.
* Table 3.2's column headers are garbled (``(g/cm ) (kg)`` / ``(x; y; z kgm )``): the units are
  the same as Table 3.1 (g/cm^3, kg, kg m^2, m). Its torso rows are labelled Upper/Mid/Lower
  *Chest* where Table 3.1 says *Torso*; they are the same SD/FAST bodies (CHEST1/2/3).
* Table 3.2's caption gives a total of 55.24 kg, but its rows (bilateral rows doubled) sum to
  53.32 kg and the Appendix A.2 listing to 53.30 kg. Table 3.1's rows sum to 97.87 kg against a
  caption of 97.84 kg. We take the row sum as the denominator of the fractions and keep the
  captions in :data:`CAPTION_TOTAL_MASS` for reference only.
* The printed values are rounded *or truncated* (e.g. male hand COM x 0.14388 -> 0.143, female
  head Iyy 0.0262514 -> 0.0262), so they agree with the listing to one unit in the last place.
* Table 3.4 prints the female Spine (L3) joint at x = 0.016; the listing chain gives -0.0160 (a
  lost minus sign, in the thesis or the OCR). Stored as printed.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

from reactmocap.errors import UnknownKeyError

__all__ = [
    "CAPTION_TOTAL_MASS",
    "MASS_FRACTIONS",
    "PART_DENSITY",
    "REFERENCE_PARTS",
    "SEGMENT_TO_PART",
    "SEXES",
    "THESIS_JOINT_TABLES",
    "THESIS_SEGMENT_TABLES",
    "Sex",
    "ThesisJoint",
    "ThesisSegment",
    "part_mass_fractions",
    "table_total_mass",
    "listing_body_part",
    "thesis_segments",
]

Sex = Literal["male", "female"]
SEXES: tuple[Sex, ...] = ("male", "female")

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class ThesisSegment:
    """One row of Table 3.1/3.2.

    ``mass`` is one side's mass for a ``bilateral`` row; ``inertia`` is the diagonal printed,
    about the COM in world axes (kg m^2); ``com`` is world space with y = |y|; ``listing`` names
    the SD/FAST bodies of Appendix A that the row describes.
    """

    name: str
    density: float  # g/cm^3
    mass: float
    inertia: Vec3
    com: Vec3
    bilateral: bool
    listing: tuple[str, ...]


@dataclass(frozen=True)
class ThesisJoint:
    """One row of Table 3.3/3.4: world location (y = |y|) and rotation axes in listing order."""

    name: str
    location: Vec3
    dofs: str
    bilateral: bool
    listing: tuple[str, ...]


def _s(name: str, rho: float, m: float, inertia: Vec3, com: Vec3, *listing: str) -> ThesisSegment:
    return ThesisSegment(name, rho, m, inertia, com, len(listing) == 2, listing)


# fmt: off
_MALE = (  # Table 3.1, section 3.1, p. 30
    _s("Head",        1.171,  7.11, (0.0492, 0.0597, 0.0298), (0.045, 0.000, 1.693), "HEAD"),
    _s("Sternum",     1.009,  2.20, (0.0051, 0.0123, 0.0089), (-0.011, 0.000, 1.469), "STERNUM"),
    _s("Upper Torso", 1.009,  8.78, (0.1036, 0.0494, 0.1401), (0.000, 0.000, 1.353), "CHEST1"),
    _s("Mid Torso",   1.009,  8.39, (0.0737, 0.0433, 0.0956), (0.010, 0.000, 1.245), "CHEST2"),
    _s("Lower Torso", 1.029,  6.16, (0.0443, 0.0271, 0.0608), (0.015, 0.000, 1.129), "CHEST3"),
    _s("Pelvis",      1.029, 10.73, (0.0862, 0.0711, 0.1095), (-0.007, 0.000, 1.002), "PELVIS"),
    _s("Upper Leg",   1.040, 10.46, (0.1535, 0.1637, 0.0443), (-0.008, 0.096, 0.763), "ULEGL", "ULEGR"),
    _s("Lower Leg",   1.079,  5.32, (0.0745, 0.0784, 0.0113), (-0.041, 0.096, 0.333), "LLEGL", "LLEGR"),
    _s("Foot",        1.066,  0.83, (0.0008, 0.0017, 0.0017), (-0.020, 0.097, 0.039), "FOOTL", "FOOTR"),
    _s("Metatarsal",  1.066,  0.28, (0.0002, 0.0002, 0.0003), (0.085, 0.103, 0.018), "TOEL", "TOER"),
    _s("Shoulder",    1.009,  4.09, (0.0144, 0.0204, 0.0204), (-0.009, 0.104, 1.464), "CHESTL", "CHESTR"),
    _s("Upper Arm",   1.068,  3.82, (0.0257, 0.0092, 0.0272), (0.005, 0.296, 1.467), "UARML", "UARMR"),
    _s("Lower Arm",   1.102,  1.78, (0.0130, 0.0029, 0.0148), (0.057, 0.591, 1.478), "LARML", "LARMR"),
    _s("Hand",        1.070,  0.67, (0.0012, 0.0007, 0.0013), (0.143, 0.832, 1.457), "HANDL", "HANDR"),
)
_FEMALE = (  # Table 3.2, section 3.1, p. 30 ("densities are the same as the male model")
    _s("Head",        1.171, 4.63, (0.0217, 0.0262, 0.0143), (-0.046, 0.000, 1.487), "HEAD"),
    _s("Sternum",     1.009, 1.20, (0.0025, 0.0054, 0.0033), (-0.046, 0.000, 1.270), "STERNUM"),
    _s("Upper Chest", 1.009, 4.28, (0.0236, 0.0158, 0.0337), (-0.023, 0.000, 1.159), "CHEST1"),
    _s("Mid Chest",   1.009, 2.62, (0.0103, 0.0064, 0.0135), (-0.014, 0.000, 1.071), "CHEST2"),
    _s("Lower Chest", 1.029, 2.10, (0.0083, 0.0043, 0.0112), (-0.010, 0.000, 0.991), "CHEST3"),
    _s("Pelvis",      1.029, 6.33, (0.0387, 0.0283, 0.0439), (-0.027, 0.000, 0.888), "PELVIS"),
    _s("Upper Leg",   1.040, 7.41, (0.1115, 0.1155, 0.0220), (-0.027, 0.082, 0.662), "ULEGL", "ULEGR"),
    _s("Lower Leg",   1.079, 2.00, (0.0150, 0.0152, 0.0021), (-0.039, 0.087, 0.263), "LLEGL", "LLEGR"),
    _s("Foot",        1.066, 0.51, (0.0004, 0.0007, 0.0006), (-0.015, 0.094, 0.036), "FOOTL", "FOOTR"),
    _s("Metatarsal",  1.066, 0.15, (0.0001, 0.0001, 0.0001), (0.073, 0.087, 0.014), "TOEL", "TOER"),
    _s("Shoulder",    1.009, 3.07, (0.0097, 0.0122, 0.0121), (-0.047, 0.086, 1.265), "CHESTL", "CHESTR"),
    _s("Upper Arm",   1.068, 1.83, (0.0122, 0.0022, 0.0124), (-0.052, 0.296, 1.265), "UARML", "UARMR"),
    _s("Lower Arm",   1.102, 0.78, (0.0027, 0.0007, 0.0030), (-0.005, 0.539, 1.235), "LARML", "LARMR"),
    _s("Hand",        1.070, 0.33, (0.0004, 0.0003, 0.0004), (0.055, 0.718, 1.193), "HANDL", "HANDR"),
)


def _j(name: str, loc: Vec3, dofs: str, *listing: str) -> ThesisJoint:
    return ThesisJoint(name, loc, dofs, len(listing) == 2, listing)


_MALE_JOINTS = (  # Table 3.3, section 3.1 (model height 1.84 m)
    _j("Neck (C2)",  (0.013, 0.000, 1.555), "XYZ", "NECKC2"),
    _j("Spine (T4)", (-0.012, 0.000, 1.400), "XYZ", "SPINET4"),
    _j("Spine (T7)", (-0.002, 0.000, 1.304), "XYZ", "SPINET7"),
    _j("Spine (L1)", (-0.001, 0.000, 1.180), "XYZ", "SPINEL1"),
    _j("Spine (L3)", (0.001, 0.000, 1.079), "XYZ", "SPINEL3"),
    _j("Hip",        (-0.019, 0.082, 0.937), "XYZ", "HIPL", "HIPR"),
    _j("Knee",       (-0.020, 0.096, 0.524), "Y", "KNEEL", "KNEER"),
    _j("Ankle",      (-0.054, 0.088, 0.084), "XY", "ANKLEL", "ANKLER"),
    _j("Metatarsal", (0.049, 0.110, 0.022), "Y", "MTL", "MTR"),
    _j("Clavicle",   (0.003, 0.035, 1.483), "XZ", "CLAVL", "CLAVR"),
    _j("Shoulder",   (-0.001, 0.182, 1.483), "XYZ", "SHLDL", "SHLDR"),
    _j("Elbow",      (0.016, 0.456, 1.475), "YZ", "ELBL", "ELBR"),
    _j("Wrist",      (0.119, 0.758, 1.474), "XY", "WRSTL", "WRSTR"),
)
_FEMALE_JOINTS = (  # Table 3.4, section 3.1 (model height 1.6 m)
    _j("Neck (C2)",  (-0.062, 0.000, 1.394), "XYZ", "NECKC2"),
    _j("Spine (T4)", (-0.035, 0.000, 1.201), "XYZ", "SPINET4"),
    _j("Spine (T7)", (-0.031, 0.000, 1.111), "XYZ", "SPINET7"),
    _j("Spine (L1)", (-0.022, 0.000, 1.027), "XYZ", "SPINEL1"),
    _j("Spine (L3)", (0.016, 0.000, 0.962), "XYZ", "SPINEL3"),  # sic: listing gives x = -0.016
    _j("Hip",        (-0.038, 0.077, 0.836), "XYZ", "HIPL", "HIPR"),
    _j("Knee",       (-0.027, 0.078, 0.401), "Y", "KNEEL", "KNEER"),
    _j("Ankle",      (-0.039, 0.088, 0.082), "XY", "ANKLEL", "ANKLER"),
    _j("Metatarsal", (0.043, 0.094, 0.015), "Y", "MTL", "MTR"),
    _j("Clavicle",   (-0.035, 0.023, 1.300), "XZ", "CLAVL", "CLAVR"),
    _j("Shoulder",   (-0.066, 0.171, 1.287), "XYZ", "SHLDL", "SHLDR"),
    _j("Elbow",      (-0.036, 0.450, 1.244), "YZ", "ELBL", "ELBR"),
    _j("Wrist",      (0.038, 0.666, 1.220), "XY", "WRSTL", "WRSTR"),
)
# fmt: on

THESIS_SEGMENT_TABLES: MappingProxyType[str, tuple[ThesisSegment, ...]] = MappingProxyType(
    {"male": _MALE, "female": _FEMALE}
)
THESIS_JOINT_TABLES: MappingProxyType[str, tuple[ThesisJoint, ...]] = MappingProxyType(
    {"male": _MALE_JOINTS, "female": _FEMALE_JOINTS}
)
#: totals printed in the captions of Tables 3.1/3.2 (the female one disagrees with its rows)
CAPTION_TOTAL_MASS: MappingProxyType[str, float] = MappingProxyType(
    {"male": 97.84, "female": 55.24}
)

#: canonical part kind of each thesis row (``l_``/``r_`` prefixed for bilateral rows). Why: the
#: character has two spine joints (waist, back). The thesis's Lower+Mid torso (L3 to T7) is the
#: abdomen; T7 up plus the shoulder girdle (clavicle bodies, folded into the chest like the
#: skeleton's Shoulder joints) is the thorax; the head body starts at C2, the neck rides on the
#: sternum body. With this split the male fractions (pelvis 11.0%, waist 14.9%, chest 19.6%) sit
#: close to Dempster's pelvis/abdomen/thorax (14.2/13.9/21.6% in Winter's table).
SEGMENT_TO_PART: MappingProxyType[str, str] = MappingProxyType(
    {
        "Head": "head",
        "Sternum": "chest",
        "Upper Torso": "chest",
        "Upper Chest": "chest",
        "Shoulder": "chest",
        "Mid Torso": "waist",
        "Mid Chest": "waist",
        "Lower Torso": "waist",
        "Lower Chest": "waist",
        "Pelvis": "pelvis",
        "Upper Leg": "thigh",
        "Lower Leg": "shin",
        "Foot": "foot",
        "Metatarsal": "foot",
        "Upper Arm": "upper_arm",
        "Lower Arm": "forearm",
        "Hand": "hand",
    }
)

#: the canonical parts the thesis bodies resolve to (a subset of ``bodyparts.BODY_PARTS``: the
#: neck is inside chest/head and the toes inside the feet)
_TRUNK_KINDS = ("pelvis", "waist", "chest", "head")
REFERENCE_PARTS: tuple[str, ...] = _TRUNK_KINDS + tuple(
    f"{s}_{p}"
    for s in ("l", "r")
    for p in ("upper_arm", "forearm", "hand", "thigh", "shin", "foot")
)


def thesis_segments(sex: str) -> tuple[ThesisSegment, ...]:
    """The rows of Table 3.1 (``"male"``) or 3.2 (``"female"``)."""
    try:
        return THESIS_SEGMENT_TABLES[sex]
    except KeyError:
        raise UnknownKeyError(f"unknown sex {sex!r}; valid keys: {list(SEXES)}") from None


def table_total_mass(sex: str) -> float:
    """Sum of the table's rows, bilateral rows counted twice (kg)."""
    return sum(s.mass * (2 if s.bilateral else 1) for s in thesis_segments(sex))


def listing_body_part(sex: str, body: str) -> str:
    """Canonical part of an Appendix A body (``"ULEGL"`` -> ``"l_thigh"``, ``"CHESTR"`` ->
    ``"chest"``)."""
    for seg in thesis_segments(sex):
        if body in seg.listing:
            kind = SEGMENT_TO_PART[seg.name]
            if kind in _TRUNK_KINDS:
                return kind
            return ("l_" if body.endswith("L") else "r_") + kind
    raise UnknownKeyError(f"unknown listing body {body!r}; valid keys: {_listing_names(sex)}")


def _listing_names(sex: str) -> list[str]:
    return [b for seg in thesis_segments(sex) for b in seg.listing]


def part_mass_fractions(sex: str) -> dict[str, float]:
    """Fraction of total mass in each of :data:`REFERENCE_PARTS` (sums to 1). A bilateral row
    counts once per side; its mass is the side the table prints."""
    total = table_total_mass(sex)
    out = dict.fromkeys(REFERENCE_PARTS, 0.0)
    for seg in thesis_segments(sex):
        for body in seg.listing:
            out[listing_body_part(sex, body)] += seg.mass / total
    return out


def _part_density() -> dict[str, float]:
    # mass / volume over the rows of a part, so a part made of rows with different densities
    # (waist: 1.009 and 1.029) gets the density that reproduces the rows' total mass.
    mass: dict[str, float] = {}
    vol: dict[str, float] = {}
    for seg in _MALE:
        kind = SEGMENT_TO_PART[seg.name]
        mass[kind] = mass.get(kind, 0.0) + seg.mass
        vol[kind] = vol.get(kind, 0.0) + seg.mass / (seg.density * 1000.0)
    return {k: round(mass[k] / vol[k], 1) for k in mass}


#: segment density per canonical part kind (kg/m^3), from the Dempster & Gaughran values the
#: thesis prints (identical for both sexes)
PART_DENSITY: MappingProxyType[str, float] = MappingProxyType(_part_density())


def _mean_fractions() -> dict[str, float]:
    tables = [part_mass_fractions(s) for s in SEXES]
    out = {p: sum(t[p] for t in tables) / len(tables) for p in REFERENCE_PARTS}
    total = sum(out.values())
    return {p: v / total for p, v in out.items()}


#: the one mass-fraction table: fraction of total body mass in each canonical body part, the
#: mean of the thesis's male and female tables (sums to 1)
MASS_FRACTIONS: MappingProxyType[str, float] = MappingProxyType(_mean_fractions())
