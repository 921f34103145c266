"""The search package's module graph: the index container does not depend on the builder, the
query engine or the store, and no module-level import cycle exists."""

from __future__ import annotations

import ast
from pathlib import Path

import reactmocap.search

PACKAGE = Path(reactmocap.search.__file__).parent


def _module_imports(path: Path) -> set[str]:
    """Search modules imported at module level (function bodies and TYPE_CHECKING excluded)."""
    out = set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        out |= {n.split(".")[2] for n in names if n.startswith("reactmocap.search.")}
    return out


def test_index_does_not_import_build_query_or_store() -> None:
    assert not _module_imports(PACKAGE / "index.py") & {"build", "query", "store"}


def test_no_import_cycles() -> None:
    graph = {p.stem: _module_imports(p) for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    done: set[str] = set()

    def visit(node: str, path: tuple[str, ...]) -> None:
        assert node not in path, f"import cycle: {' -> '.join((*path, node))}"
        if node in done:
            return
        for nxt in graph.get(node, ()):
            visit(nxt, (*path, node))
        done.add(node)

    for mod in graph:
        visit(mod, ())
