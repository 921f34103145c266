"""Motion search: weighted window features, the paper's window distance ``D`` and a KD-tree index
with exact re-ranking and local refinement (Zordan et al. 2005, section 3).

Typical use::

    from reactmocap.search import MotionIndex, SearchWeights, WindowConfig

    index = MotionIndex.build(library.clips, SearchWeights(), WindowConfig(fps=30), mirror=True)
    best = index.query(trajectory, start_frame=0)
    found = library.clips[best.clip].transformed(best.yaw, best.translation)  # overlays the query
"""

from reactmocap.search.config import SearchWeights, WindowConfig
from reactmocap.search.distance import BREAKDOWN_TERMS, QueryWindow
from reactmocap.search.features import (
    FEATURE_SETS,
    FeatureSet,
    FrameFeatures,
    calibrate,
    frame_features,
    get_feature_set,
)
from reactmocap.search.index import (
    Breakdown,
    MotionIndex,
    SearchResult,
    brute_force,
    library_fingerprint,
)

__all__ = [
    "BREAKDOWN_TERMS",
    "FEATURE_SETS",
    "Breakdown",
    "FeatureSet",
    "FrameFeatures",
    "MotionIndex",
    "QueryWindow",
    "SearchResult",
    "SearchWeights",
    "WindowConfig",
    "brute_force",
    "calibrate",
    "frame_features",
    "get_feature_set",
    "library_fingerprint",
]
