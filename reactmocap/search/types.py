"""What a search returns (:class:`SearchResult`, :class:`Breakdown`, :class:`QueryStats`) and the
constants the index modules share: format version, mirrored-clip suffix, query defaults."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.search.distance import BREAKDOWN_TERMS

__all__ = [
    "CHUNK",
    "COARSE_FRAMES",
    "DEFAULT_EXACT",
    "DEFAULT_K",
    "DEFAULT_REFINE",
    "F32",
    "F64",
    "FORMAT_VERSION",
    "I64",
    "MIRROR_SUFFIX",
    "PCA_SAMPLE",
    "Breakdown",
    "QueryStats",
    "SearchResult",
]

#: version of the saved index; bumped whenever the stored features or embedding change
#: 2: centre of mass from the one mass-fraction table; 3: the feet's contacts in the embedding;
#: 4: each refinement interval's radius and bound
FORMAT_VERSION = 4
MIRROR_SUFFIX = "_mirror"
#: windows embedded (or localised) per batch: bounds the temporary arrays
CHUNK = 4096
#: frames per window in the coarse pre-ranking of KD candidates
COARSE_FRAMES = 10
#: KD candidates, exactly re-ranked candidates, candidates whose interval is refined
DEFAULT_K = 48
DEFAULT_EXACT = 6
DEFAULT_REFINE = 3
#: windows sampled to fit the PCA
PCA_SAMPLE = 8_000

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


@dataclass(frozen=True)
class Breakdown:
    """``D`` split by body group and term; the six values sum to ``D``."""

    trunk_position: float
    trunk_orientation: float
    limbs_position: float
    limbs_orientation: float
    support_position: float
    support_orientation: float
    support_part: str

    @classmethod
    def from_row(cls, row: F64, support_part: str) -> Breakdown:
        """From one row of :data:`BREAKDOWN_TERMS` values."""
        v = [float(x) for x in row]
        return cls(v[0], v[1], v[2], v[3], v[4], v[5], support_part=support_part)

    @property
    def total(self) -> float:
        return float(sum(getattr(self, t) for t in BREAKDOWN_TERMS))

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {t: float(getattr(self, t)) for t in BREAKDOWN_TERMS}
        d["support_part"] = self.support_part
        return d


@dataclass(frozen=True)
class SearchResult:
    """One matching library window.

    ``frame`` is the start frame in the clip's own frame rate, ``index_frame`` at the index rate,
    ``time`` in seconds. ``yaw`` (radians) and ``translation`` (x, y metres) map the library clip
    onto the query: ``clip_motion.transformed(yaw, translation)`` overlays the query window.
    """

    clip: str
    frame: int
    index_frame: int
    time: float
    distance: float
    yaw: float
    translation: tuple[float, float]
    breakdown: Breakdown
    rank: int = 0

    @property
    def yaw_deg(self) -> float:
        return float(np.degrees(self.yaw))

    def to_dict(self) -> dict[str, Any]:
        return {
            "rank": self.rank,
            "clip": self.clip,
            "frame": self.frame,
            "index_frame": self.index_frame,
            "time": self.time,
            "distance": self.distance,
            "yaw": self.yaw,
            "yaw_deg": self.yaw_deg,
            "translation": list(self.translation),
            "breakdown": self.breakdown.to_dict(),
        }


@dataclass(frozen=True)
class QueryStats:
    """What one search did (for reports and benchmarks); returned with its results."""

    candidates: int = 0  # KD-tree candidates
    refined_windows: int = 0  # windows of the refinement intervals (beyond the candidates)
    exact_windows: int = 0  # windows whose exact D was computed
    seconds: float = 0.0
