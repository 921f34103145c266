"""The package's public surface: every module says what it exports (``__all__``, each name
defined), and the package ships ``py.typed``."""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

import pytest

import reactmocap

#: modules without ``__all__`` on purpose: the entry point, and a file a benchmark writes
EXEMPT = {"reactmocap.__main__", "reactmocap.athletics.measured"}
MODULES = sorted(
    m.name
    for m in pkgutil.walk_packages(reactmocap.__path__, "reactmocap.")
    if not m.ispkg and m.name not in EXEMPT
)


@pytest.mark.parametrize("name", MODULES)
def test_every_module_declares_its_exports(name: str) -> None:
    # before: vault_control, vault_setup and vault_table1 had none
    module = importlib.import_module(name)
    exports = getattr(module, "__all__", None)
    assert exports is not None, f"{name} has no __all__"
    assert [n for n in exports if not hasattr(module, n)] == [], name


def test_the_package_is_typed() -> None:
    assert (Path(reactmocap.__file__).parent / "py.typed").is_file()
    assert "ReactMocapError" in reactmocap.__all__ and "OutputError" in reactmocap.__all__
