"""The one exception hierarchy of reactmocap: everything raised on purpose derives from
:class:`ReactMocapError`, so callers can catch a single type and the CLI can print a located
message instead of a traceback."""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "BVHParseError",
    "BodyPartMappingError",
    "ConfigError",
    "LibraryError",
    "MotionError",
    "OutputError",
    "ReactMocapError",
    "SearchError",
    "SimulationError",
    "UnknownKeyError",
]


class ReactMocapError(Exception):
    """Root of every error reactmocap raises deliberately."""


class MotionError(ReactMocapError, ValueError):
    """A Skeleton or Motion was built from arrays of the wrong shape, type or content."""


class BVHParseError(ReactMocapError):
    """A BVH file could not be read. Carries the file, the 1-based line and what was expected."""

    def __init__(
        self,
        message: str,
        *,
        file: str | Path | None = None,
        line: int | None = None,
        expected: str | None = None,
    ) -> None:
        self.file = str(file) if file is not None else None
        self.line = line
        self.expected = expected
        self.reason = message
        where = self.file or "<bvh>"
        if line is not None:
            where += f":{line}"
        text = f"{where}: {message}"
        if expected:
            text += f" (expected {expected})"
        super().__init__(text)


class BodyPartMappingError(ReactMocapError):
    """A skeleton's joints could not be mapped onto the canonical body parts."""


class LibraryError(ReactMocapError):
    """A clip library could not be loaded (missing folder, no clips, bad file in strict mode)."""


class ConfigError(ReactMocapError, ValueError):
    """A configuration or scenario file has a bad field. The message names the field."""


class UnknownKeyError(ReactMocapError, KeyError):
    """A registry lookup used a key that is not registered. The message lists the valid keys."""

    def __str__(self) -> str:  # KeyError would repr() the message
        return str(self.args[0]) if self.args else ""


class OutputError(ReactMocapError, OSError):
    """An output file could not be written (read-only folder, a file where a folder should be,
    disk full). Names the path and why. An ``OSError`` too, for callers that tolerate one."""


class SearchError(ReactMocapError):
    """A motion search could not be built, loaded or answered."""


class SimulationError(ReactMocapError):
    """A physics simulation went unstable or was configured wrongly."""
