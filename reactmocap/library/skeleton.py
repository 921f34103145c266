"""Skeleton: joint names, parents and rest offsets (Z-up metres), plus the BVH layout it came
from so that writing reproduces the source file's channels, units and axes."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from reactmocap.errors import MotionError

__all__ = ["BVHLayout", "Skeleton", "mirror_name_pairs"]

ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")
POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")
VALID_CHANNELS = ROTATION_CHANNELS + POSITION_CHANNELS


@dataclass(frozen=True)
class BVHLayout:
    """How a skeleton was stored in its source file (used by the writer to round-trip).

    ``unit`` and ``up`` are the source file's; ``channels[j]`` lists joint j's channel names in
    file order. ``end_sites`` maps a joint index to its End Site offset (Z-up metres).
    """

    channels: tuple[tuple[str, ...], ...]
    unit: str = "m"
    up: Literal["y", "z"] = "z"
    end_sites: dict[int, tuple[float, float, float]] = field(default_factory=dict)

    def has_position(self, joint: int) -> bool:
        return any(c in POSITION_CHANNELS for c in self.channels[joint])


@dataclass(frozen=True, eq=False)
class Skeleton:
    """A joint hierarchy.

    Attributes:
        names: ``(J,)`` unique joint names.
        parents: ``(J,)`` int parent index, ``-1`` for the root; parents precede children.
        offsets: ``(J, 3)`` rest translation of each joint in its parent's frame, Z-up metres.
        layout: source BVH layout; a default 3-rotation-channel layout if not given.
    """

    names: tuple[str, ...]
    parents: NDArray[np.int64]
    offsets: NDArray[np.float64]
    layout: BVHLayout = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        names = tuple(str(n) for n in self.names)
        parents = np.asarray(self.parents, dtype=np.int64).reshape(-1)
        offsets = np.array(self.offsets, dtype=np.float64)
        n = len(names)
        if n == 0:
            raise MotionError("Skeleton needs at least one joint")
        if parents.shape != (n,):
            raise MotionError(f"parents must have shape ({n},), got {parents.shape}")
        if offsets.shape != (n, 3):
            raise MotionError(f"offsets must have shape ({n}, 3), got {offsets.shape}")
        if not np.all(np.isfinite(offsets)):
            raise MotionError("offsets contain NaN or inf")
        dup = sorted({x for x in names if names.count(x) > 1})
        if dup:
            raise MotionError(f"duplicate joint names: {dup}")
        if parents[0] != -1 or np.any(parents[1:] < 0) or np.any(parents[1:] >= np.arange(1, n)):
            raise MotionError("parents must be -1 for joint 0 and precede each child")
        layout = self.layout
        if layout is None:
            chans = (POSITION_CHANNELS + ("Zrotation", "Xrotation", "Yrotation"),) + (
                ("Zrotation", "Xrotation", "Yrotation"),
            ) * (n - 1)
            layout = BVHLayout(channels=chans)
        if len(layout.channels) != n:
            raise MotionError(f"layout has {len(layout.channels)} channel lists for {n} joints")
        offsets.setflags(write=False)
        parents.setflags(write=False)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "layout", layout)

    @property
    def num_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise MotionError(f"no joint named {name!r}; joints are {list(self.names)}") from None

    def children(self, joint: int) -> list[int]:
        return [int(i) for i in np.flatnonzero(self.parents == joint)]

    def chain(self, joint: int) -> list[int]:
        """Joint indices from the root down to ``joint`` inclusive."""
        out = [joint]
        while self.parents[out[-1]] >= 0:
            out.append(int(self.parents[out[-1]]))
        return out[::-1]

    def with_offsets(self, offsets: ArrayLike) -> Skeleton:
        return Skeleton(self.names, self.parents, np.asarray(offsets), self.layout)

    def same_structure(self, other: Skeleton) -> bool:
        return self.names == other.names and bool(np.array_equal(self.parents, other.parents))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Skeleton):
            return NotImplemented
        return self.same_structure(other) and bool(np.allclose(self.offsets, other.offsets))

    __hash__ = None  # type: ignore[assignment]

    def mirror_permutation(self) -> NDArray[np.int64]:
        """``perm[j]`` = index of joint j's left/right counterpart (itself if unpaired)."""
        perm = np.arange(self.num_joints)
        lookup = {n: i for i, n in enumerate(self.names)}
        for name, other in mirror_name_pairs(self.names).items():
            perm[lookup[name]] = lookup[other]
        return perm


# Side tokens, tried in order. Each pattern captures (prefix, side, suffix); swapping the side
# token gives the counterpart name. Case is kept ("Left" <-> "Right", "_L" <-> "_R", "l" <-> "r").
_SIDE_PATTERNS = [
    re.compile(r"^(.*?)(Left|LEFT|left)(.*)$"),
    re.compile(r"^(.*?)(Right|RIGHT|right)(.*)$"),
    re.compile(r"^(.*[_.\- ])([LlRr])$"),  # Hand_L, hand.l
    re.compile(r"^(.*[_.\- ])([LlRr])([_.\- ].*)$"),  # Hand_L_end
    re.compile(r"^()([LlRr])([_.\- ].+)$"),  # L_Hand
    re.compile(r"^(.*?:)?([lr])([a-z].*)$"),  # CMU lowercase: lfemur, mixamo ns kept
    re.compile(r"^()([LR])([A-Z].*)$"),  # LThigh
]
_SWAP = {
    "Left": "Right", "Right": "Left", "LEFT": "RIGHT", "RIGHT": "LEFT", "left": "right",
    "right": "left", "L": "R", "R": "L", "l": "r", "r": "l",
}  # fmt: skip


def mirror_name_pairs(names: tuple[str, ...] | list[str]) -> dict[str, str]:
    """Pair left/right joint names automatically. Only names whose counterpart exists pair up."""
    present = set(names)
    pairs: dict[str, str] = {}
    for name in names:
        for pat in _SIDE_PATTERNS:
            m = pat.match(name)
            if not m:
                continue
            groups = m.groups()
            prefix = groups[0] or ""
            side = groups[1]
            suffix = groups[2] if len(groups) > 2 else ""
            other = f"{prefix}{_SWAP[side]}{suffix}"
            if other in present and other != name:
                pairs[name] = other
                break
    # keep only symmetric pairs
    return {a: b for a, b in pairs.items() if pairs.get(b) == a}
