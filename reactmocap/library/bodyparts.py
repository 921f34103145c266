"""Map any skeleton's joints onto the canonical body parts the physics character needs (on a
skeleton with a single spine joint, the waist and the chest share it).

Each part is named by the joint that *rotates* that segment (``l_thigh`` is the hip joint, whose
bone runs to the knee). Name rules cover the ``_L/_R`` style of the Bandai Namco clips,
CMU/Mixamo ``Left*/Right*`` (with any ``namespace:`` prefix such as ``mixamorig:``) and the
lower-case ``lfemur`` style of ASF-derived files. A TOML file can override them::

    [parts]            # explicit joint for a part
    chest = "Spine2"
    [aliases]          # extra base names for a part kind, tried first
    thigh = ["hipjoint2"]
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import BodyPartMappingError, ConfigError
from reactmocap.io import read_toml
from reactmocap.library.skeleton import Skeleton

__all__ = [
    "BODY_PARTS",
    "LIMB_PARTS",
    "OPTIONAL_PARTS",
    "TRUNK_PARTS",
    "BodyPartMap",
    "load_rules",
    "map_body_parts",
    "parts_for",
]

TRUNK_PARTS = ("pelvis", "waist", "chest", "neck", "head")
_SIDED = ("upper_arm", "forearm", "hand", "thigh", "shin", "foot", "toe")
LIMB_PARTS = tuple(f"{s}_{p}" for s in ("l", "r") for p in _SIDED)
BODY_PARTS = TRUNK_PARTS + LIMB_PARTS
#: parts whose absence is tolerated (the segment is folded into its parent)
OPTIONAL_PARTS = frozenset({"neck", "l_toe", "r_toe"})

# Base names (lower case, separators removed) for each part kind, in priority order.
_BASE_NAMES: dict[str, tuple[str, ...]] = {
    "pelvis": ("hips", "pelvis", "hip", "root"),
    "waist": ("waist", "abdomen", "spine", "lowerback", "spine0", "spine1", "torso"),
    "chest": ("chest", "upperchest", "thorax", "spine2", "spine1", "spine3", "upperback"),
    "neck": ("neck", "neck1", "lowerneck"),
    "head": ("head",),
    "upper_arm": ("upperarm", "arm", "humerus", "uparm"),
    "forearm": ("forearm", "lowerarm", "elbow", "radius", "lowarm"),
    "hand": ("hand", "wrist"),
    "thigh": ("upleg", "upperleg", "thigh", "femur", "hip", "upperthigh"),
    "shin": ("leg", "lowerleg", "shin", "knee", "calf", "tibia", "lowleg"),
    "foot": ("foot", "ankle"),
    "toe": ("toebase", "toe", "toes", "ball", "toe0"),
}
_ALL_BASES = {b for names in _BASE_NAMES.values() for b in names} | {
    "shoulder",
    "clavicle",
    "collar",
    "hipjoint",
}


def _normalize(name: str) -> str:
    name = name.rsplit(":", 1)[-1]  # "mixamorig:LeftArm" -> "LeftArm"
    return name.lower()


_SIDE_RULES = [
    re.compile(r"^(left|right)[_.\- ]?(.+)$"),
    re.compile(r"^(.+?)[_.\- ]?(left|right)$"),
    re.compile(r"^(.+)[_.\- ]([lr])$"),
    re.compile(r"^([lr])[_.\- ](.+)$"),
    re.compile(r"^([lr])(.+)$"),  # lfemur / LThigh: only if the rest is a known base
]


def _split(name: str) -> tuple[str | None, str]:
    """(side 'l'|'r'|None, base) of a joint name."""
    n = _normalize(name)
    for rule in _SIDE_RULES:
        m = rule.match(n)
        if not m:
            continue
        a, b = m.groups()
        side, base = (a, b) if a in ("left", "right", "l", "r") else (b, a)
        base = re.sub(r"[_.\- ]", "", base)
        if rule is _SIDE_RULES[-1] and base not in _ALL_BASES:
            continue
        return side[0], base
    return None, re.sub(r"[_.\- ]", "", n)


@dataclass(frozen=True)
class BodyPartMap:
    """Canonical part -> joint index on ``skeleton``. Missing optional parts are absent."""

    skeleton: Skeleton
    joints: Mapping[str, int]

    def joint_of(self, part: str) -> int:
        if part not in BODY_PARTS:
            raise BodyPartMappingError(f"unknown body part {part!r}; parts are {list(BODY_PARTS)}")
        if part not in self.joints:
            raise BodyPartMappingError(f"part {part!r} is not mapped on this skeleton")
        return self.joints[part]

    def name_of(self, part: str) -> str:
        return self.skeleton.names[self.joint_of(part)]

    def indices(self, parts: tuple[str, ...] | list[str]) -> NDArray[np.int64]:
        return np.array([self.joint_of(p) for p in parts], dtype=np.int64)

    @property
    def parts(self) -> tuple[str, ...]:
        return tuple(p for p in BODY_PARTS if p in self.joints)

    def mirrored(self) -> BodyPartMap:
        """Map with left/right parts swapped (for a mirrored motion whose joints kept names)."""
        swap = {p: ("r_" + p[2:] if p.startswith("l_") else "l_" + p[2:]) for p in LIMB_PARTS}
        return BodyPartMap(self.skeleton, {swap.get(p, p): j for p, j in self.joints.items()})


def load_rules(path: str | Path) -> dict[str, object]:
    """A body-part rules TOML (``[parts]``, ``[aliases]``), checked; errors name the file."""
    return _load_overrides(Path(path))


def parts_for(
    skeleton: Skeleton, rules: str | Path | Mapping[str, object] | None = None
) -> BodyPartMap:
    """:func:`map_body_parts` with ``rules`` where they fit the skeleton (it has every joint
    their ``[parts]`` name), by the name rules alone otherwise: one rules file serves a library
    that mixes skeletons."""
    over = _load_overrides(rules)
    named = dict(over.get("parts", {}) or {})  # type: ignore[call-overload]
    fits = all(j in skeleton.names for j in named.values())
    return map_body_parts(skeleton, over if fits else None)


def _load_overrides(rules: str | Path | Mapping[str, object] | None) -> dict[str, object]:
    if rules is None:
        return {}
    if isinstance(rules, Mapping):
        return _checked(dict(rules), "")
    path = Path(rules)
    data = read_toml(path, "body-part rules")
    unknown = set(data) - {"parts", "aliases"}
    if unknown:
        raise ConfigError(
            f"{path}: unknown sections {sorted(unknown)}; expected [parts], [aliases]"
        )
    return _checked(data, f"{path}: ")


def _checked(rules: dict[str, object], where: str) -> dict[str, object]:
    """``rules`` if its ``[parts]`` map known parts to joint names and its ``[aliases]`` known
    kinds to lists of names; a ConfigError naming the field otherwise (``where``: the file)."""
    parts, aliases = rules.get("parts") or {}, rules.get("aliases") or {}
    for section, table in (("parts", parts), ("aliases", aliases)):
        if not isinstance(table, Mapping):
            raise ConfigError(f"{where}[{section}] must be a table, got {table!r}")
    checks = (
        ("parts", parts, BODY_PARTS, "part", "a joint name", lambda v: isinstance(v, str)),
        ("aliases", aliases, _BASE_NAMES, "kind", "a list of names",
         lambda v: isinstance(v, list) and all(isinstance(n, str) for n in v)),
    )  # fmt: skip
    for section, table, valid, what, expected, ok in checks:
        for key, value in table.items():  # type: ignore[attr-defined]
            if key not in valid:
                raise ConfigError(
                    f"{where}[{section}] has unknown {what} {key!r}; {what}s are {list(valid)}"
                )
            if not ok(value):
                raise ConfigError(f"{where}[{section}].{key}: expected {expected}, got {value!r}")
    return rules


def map_body_parts(
    skeleton: Skeleton, rules: str | Path | Mapping[str, object] | None = None
) -> BodyPartMap:
    """Map ``skeleton`` onto :data:`BODY_PARTS`.

    Raises:
        BodyPartMappingError: naming the unmapped required parts and the available joints.
    """
    over = _load_overrides(rules)
    explicit = dict(over.get("parts", {}) or {})  # type: ignore[call-overload]
    aliases: dict[str, list[str]] = dict(over.get("aliases", {}) or {})  # type: ignore[call-overload]

    split = [_split(n) for n in skeleton.names]
    out: dict[str, int] = {}
    for part, joint_name in explicit.items():
        if joint_name not in skeleton.names:
            raise BodyPartMappingError(
                f"[parts] {part} = {joint_name!r}: no such joint; joints are {list(skeleton.names)}"
            )
        out[part] = skeleton.names.index(joint_name)

    def find(kind: str, side: str | None, taken: set[int]) -> int | None:
        bases = [b.lower() for b in aliases.get(kind, [])] + list(_BASE_NAMES[kind])
        for base in bases:
            for j, (s, b) in enumerate(split):
                if s == side and b == base and j not in taken:
                    return j
        return None

    used = set(out.values())
    for side in ("l", "r"):
        for kind in _SIDED:
            part = f"{side}_{kind}"
            if part not in out:
                j = find(kind, side, used)
                if j is not None:
                    out[part] = j
                    used.add(j)
    for kind in ("pelvis", "head", "neck"):
        if kind not in out:
            j = find(kind, None, used)
            if j is not None:
                out[kind] = j
                used.add(j)
    _map_spine(skeleton, out, find, used)

    missing = [p for p in BODY_PARTS if p not in out and p not in OPTIONAL_PARTS]
    if missing:
        raise BodyPartMappingError(
            f"cannot map body parts {missing}; available joints: {list(skeleton.names)}. "
            "Add a [parts] table to a body-part rules TOML to map them explicitly."
        )
    return BodyPartMap(skeleton, out)


def _map_spine(
    skeleton: Skeleton,
    out: dict[str, int],
    find: Callable[[str, str | None, set[int]], int | None],
    used: set[int],
) -> None:
    """Chest: by name, else the deepest common ancestor of the two upper arms. Waist: a spine
    joint strictly between pelvis and chest (by name first, else the first one on the path)."""
    if "chest" not in out:
        j = find("chest", None, used)
        arms = [out.get("l_upper_arm"), out.get("r_upper_arm")]
        if arms[0] is not None and arms[1] is not None:
            a, b = skeleton.chain(arms[0]), skeleton.chain(arms[1])
            common = [x for x, y in zip(a, b) if x == y]
            lca = common[-1]
            if j is None or j not in skeleton.chain(lca):
                j = lca
        if j is not None:
            out["chest"] = j
            used.add(j)
    if "waist" not in out and "pelvis" in out and "chest" in out:
        path = skeleton.chain(out["chest"])
        if out["pelvis"] in path:
            between = path[path.index(out["pelvis"]) + 1 : -1]
            if between:
                named = find("waist", None, used)
                out["waist"] = named if named in between else between[0]
            elif out["chest"] != out["pelvis"]:
                out["waist"] = out["chest"]  # one spine joint: waist and chest share it
