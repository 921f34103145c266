"""reactmocap: motion-capture characters that react physically to impacts."""

from reactmocap.errors import (
    BodyPartMappingError,
    BVHParseError,
    ConfigError,
    LibraryError,
    MotionError,
    OutputError,
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
    "OutputError",
    "ReactMocapError",
    "SearchError",
    "SimulationError",
    "Skeleton",
    "UnknownKeyError",
    "__version__",
]
