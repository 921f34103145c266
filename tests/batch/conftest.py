"""Fixtures of the batch tests: a warm clip cache and sweep files written on the fly."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
FRONT_KICK = EXAMPLES / "front_kick.toml"


@pytest.fixture(scope="session")
def warm_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Build the clip cache and search index once, in the folder the repo-wide autouse fixture
    points REACTMOCAP_CACHE_DIR at, so worker processes load them instead of each building."""
    cache = tmp_path_factory.getbasetemp() / "clip-cache"
    old = os.environ.get("REACTMOCAP_CACHE_DIR")
    os.environ["REACTMOCAP_CACHE_DIR"] = str(cache)
    try:
        from reactmocap.response.pipeline import run_scenario
        from reactmocap.response.scenario import load_scenario

        run_scenario(load_scenario(FRONT_KICK))
    finally:
        if old is None:
            del os.environ["REACTMOCAP_CACHE_DIR"]
        else:
            os.environ["REACTMOCAP_CACHE_DIR"] = old
    return cache


@pytest.fixture
def write_sweep(tmp_path: Path) -> Callable[..., Path]:
    """write_sweep(axes_toml, base=FRONT_KICK, name="s", extra="") -> path of a sweep file."""

    def write(
        axes: str, *, base: Path | str = FRONT_KICK, name: str = "s", extra: str = ""
    ) -> Path:
        p = tmp_path / f"{name}.toml"
        p.write_text(f'base = "{base}"\n{extra}\n[axes]\n{axes}\n')
        return p

    return write
