"""No import cycle reaches the engine (dirac.analysis) or the code generator (dirac.codegen).

The graph is built from the source with :mod:`ast`, so imports inside functions and under
``TYPE_CHECKING`` count as edges: a lazy import that closes a circle is still a circle.
"""

from __future__ import annotations

import ast
from pathlib import Path

import dirac

PACKAGE = Path(dirac.__file__).parent
CHECKED = ("dirac.analysis", "dirac.codegen")


def module_names() -> dict[str, Path]:
    names = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        names[".".join(parts)] = path
    return names


def import_graph() -> dict[str, set[str]]:
    """Module -> the dirac modules it imports anywhere in its source."""
    modules = module_names()
    graph = {}
    for name, path in modules.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                edges.update(alias.name for alias in node.names if alias.name in modules)
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package[: len(package) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                edges.update(m for m in [source, *(f"{source}.{a.name}" for a in node.names)] if m in modules)
        graph[name] = edges - {name}
    return graph


def reaches(graph: dict[str, set[str]], start: str, goal: str) -> bool:
    seen, todo = set(), [start]
    while todo:
        current = todo.pop()
        for nxt in graph[current]:
            if nxt == goal:
                return True
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return False


def test_graph_sees_function_level_imports():
    graph = import_graph()
    assert "dirac.codegen" in graph["dirac.flows.mechanics"]  # imported inside from_lagrangian


def test_no_module_of_the_engine_or_the_code_generator_imports_itself_back():
    graph = import_graph()
    circles = [name for name in graph if name.startswith(CHECKED) and reaches(graph, name, name)]
    assert circles == []
