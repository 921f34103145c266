"""Shared fixtures for the physics tests: synthetic clips (no files needed)."""

from __future__ import annotations

from functools import lru_cache

import pytest

from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips


@lru_cache(maxsize=1)
def _clips() -> dict[str, Motion]:
    return synthetic_clips(30.0)


@pytest.fixture(scope="session")
def guard() -> Motion:
    return _clips()["guard"]


@pytest.fixture(scope="session")
def step_forward() -> Motion:
    return _clips()["step_forward"]


@pytest.fixture(scope="session")
def punch() -> Motion:
    return _clips()["punch"]
