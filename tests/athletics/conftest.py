"""Fixtures for the athletics tests: a synthetic clip as a mocap body (no files needed)."""

from __future__ import annotations

import pytest

from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips


@pytest.fixture(scope="session")
def guard() -> Motion:
    return synthetic_clips(30.0)["guard"]
