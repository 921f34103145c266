"""Fixtures for the search tests: the synthetic clips (built in code, 60 fps) and, where present,
the shared real clips (../shared/mocap beside the repository)."""

from __future__ import annotations

from pathlib import Path

import pytest

from reactmocap.library.motion import Motion
from reactmocap.search import MotionIndex, SearchWeights, WindowConfig

SHARED_MOCAP = Path(__file__).resolve().parents[2].parent / "shared" / "mocap"


@pytest.fixture(scope="session")
def synth_clips() -> dict[str, Motion]:
    from reactmocap.library.synth import synthetic_clips

    return synthetic_clips(60.0)


@pytest.fixture(scope="session")
def synth_index(synth_clips: dict[str, Motion]) -> MotionIndex:
    """Synthetic clips + mirrors, default settings (30 Hz index, 0.3 s windows)."""
    return MotionIndex.build(synth_clips, SearchWeights(), WindowConfig(), mirror=True)


@pytest.fixture(scope="session")
def real_clips() -> dict[str, Motion]:
    d = SHARED_MOCAP / "bandai-namco-1"
    if not d.is_dir():
        pytest.skip(f"real mocap not found at {d} (../shared/mocap is only beside the repo in CI)")
    try:
        from reactmocap.library.clip_library import load_library
    except ModuleNotFoundError as exc:  # the BVH reader is built in another issue
        pytest.skip(f"BVH loader not available yet ({exc})")
    return dict(load_library(d, cache=False).clips)
