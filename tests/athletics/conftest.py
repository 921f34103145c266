"""Fixtures for the athletics tests: a synthetic clip as a mocap body (no files needed), and
the benchmark scripts loaded as modules."""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest

from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips


@pytest.fixture(scope="session")
def guard() -> Motion:
    return synthetic_clips(30.0)["guard"]


@pytest.fixture(scope="session")
def load_bench() -> Callable[[str], ModuleType]:
    """``load_bench("bench_athletics")``: ``benchmarks/bench_athletics.py`` as a module (the
    scripts are not a package)."""

    def load(name: str) -> ModuleType:
        path = Path(__file__).resolve().parents[2] / "benchmarks" / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load
