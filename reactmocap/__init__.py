"""reactmocap: motion-capture characters that react physically to impacts."""

from reactmocap.errors import (
    BodyPartMappingError,
    BVHParseError,
    ConfigError,
    LibraryError,
    MotionError,
    ReactMocapError,
    SearchError,
    SimulationError,
    UnknownKeyError,
)
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton

__version__ = "0.1.0"

__all__ = [
    "BVHParseError",
    "BodyPartMappingError",
    "ConfigError",
    "LibraryError",
    "Motion",
    "MotionError",
    "ReactMocapError",
    "SearchError",
    "SimulationError",
    "Skeleton",
    "UnknownKeyError",
    "__version__",
]
