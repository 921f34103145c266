"""Motion search: the paper's window distance ``D`` and a KD-tree index over library windows with
exact re-ranking and local refinement (Zordan et al. 2005, section 3).

Typical use::

    from reactmocap.search import MotionIndex, SearchWeights, WindowConfig

    index = MotionIndex.build(library.clips, SearchWeights(), WindowConfig(fps=30), mirror=True)
    best = index.query(trajectory, start_frame=0)
    found = library.clips[best.clip].transformed(best.yaw, best.translation)  # overlays the query
"""

from reactmocap.search.build import build_index, library_fingerprint
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
from reactmocap.search.index import MotionIndex
from reactmocap.search.query import QueryCache, brute_force, prepare_query, search_window
from reactmocap.search.types import Breakdown, QueryStats, SearchResult

__all__ = [
    "BREAKDOWN_TERMS",
    "FEATURE_SETS",
    "Breakdown",
    "FeatureSet",
    "FrameFeatures",
    "MotionIndex",
    "QueryCache",
    "QueryStats",
    "QueryWindow",
    "SearchResult",
    "SearchWeights",
    "WindowConfig",
    "brute_force",
    "build_index",
    "calibrate",
    "frame_features",
    "get_feature_set",
    "library_fingerprint",
    "prepare_query",
    "search_window",
]
