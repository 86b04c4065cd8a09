"""The package rules of DESIGN.md 1, read from the code (issue 22, item 6).

physics imports nothing of the rest; model imports only physics; net imports model
and physics, never a window; the app (the teacher's window) and the student's window
import what they need, but the app never the network or the student's window; no
two modules import each other. The layering is about what runs, so imports made
only for type hints (under `if TYPE_CHECKING:`) do not count there; a circle
counts even through them, since two modules that name each other are one
tangle to read (the features name a narrow `Host`, never the app).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "airtable"
# What each package may import of airtable (itself always).
ALLOWED = {
    "physics": set(),
    "model": {"physics"},
    "net": {"model", "physics"},
    "app": {"model", "physics"},
    "student": {"app", "model", "net", "physics"},
}
NO_PYGAME = ("physics", "model", "net")


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _type_only(tree: ast.Module) -> set[int]:
    """Line numbers of imports under `if TYPE_CHECKING:`."""
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            lines.update(n.lineno for n in ast.walk(node) if isinstance(n, (ast.Import, ast.ImportFrom)))
    return lines


def run_time_imports(path: Path, type_hints: bool = False) -> set[str]:
    """The modules (dotted names, as written) that `path` imports when it runs; with `type_hints`,
    those it imports only for type hints too."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skip = set() if type_hints else _type_only(tree)
    found = set()
    for node in ast.walk(tree):
        if getattr(node, "lineno", None) in skip:
            continue
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{a.name}" for a in node.names)
    return found


MODULES = {module_name(p): p for p in PACKAGE.rglob("*.py")}


def import_graph(type_hints: bool) -> dict[str, set[str]]:
    return {n: {m for m in run_time_imports(p, type_hints) if m in MODULES and m != n} for n, p in MODULES.items()}


GRAPH = import_graph(type_hints=False)
EVERY_IMPORT = import_graph(type_hints=True)


def package_of(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] in ALLOWED) else None


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_each_package_imports_only_what_it_may(package):
    wrong = []
    for module, imported in GRAPH.items():
        if package_of(module) != package:
            continue
        for other in imported:
            theirs = package_of(other)
            if theirs is None and other != "airtable":  # a top-level module: only the commands may
                if not module.endswith(".command"):
                    wrong.append(f"{module} -> {other}")
            elif theirs not in (package, None) and theirs not in ALLOWED[package]:
                wrong.append(f"{module} -> {other}")
    assert not wrong, "imports against DESIGN.md 1:\n" + "\n".join(sorted(wrong))


@pytest.mark.parametrize("package", NO_PYGAME)
def test_no_pygame_and_no_drawing_below_the_windows(package):
    for path in sorted((PACKAGE / package).glob("*.py")):
        assert "pygame" not in {m.split(".")[0] for m in run_time_imports(path)}, path


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The circles a depth-first walk of `graph` meets, each as its modules in order."""
    state: dict[str, int] = {}  # 1: on the path being walked, 2: done
    found = []

    def walk(module: str, path: list[str]) -> None:
        state[module] = 1
        for other in sorted(graph[module]):
            if state.get(other) == 1:
                found.append(path[path.index(other) :])
            elif other not in state:
                walk(other, [*path, other])
        state[module] = 2

    for module in sorted(graph):
        if module not in state:
            walk(module, [module])
    return found


def test_no_two_modules_import_each_other():
    """Nor any longer circle: the run-time import graph has no cycle at all."""
    found = [" -> ".join([*c, c[0]]) for c in circles(GRAPH)]
    assert not found, "import circles:\n" + "\n".join(found)


def test_no_circle_even_through_type_hints():
    """No two modules name each other, not even for type hints."""
    found = [" -> ".join([*c, c[0]]) for c in circles(EVERY_IMPORT)]
    assert not found, "import circles (type hints included):\n" + "\n".join(found)


def test_the_rules_see_the_packages():
    """The test reads real code: every package has modules and the graph has edges between them."""
    for package in ALLOWED:
        assert any(package_of(m) == package for m in MODULES), package
    assert any(package_of(o) == "model" for imported in GRAPH.values() for o in imported)
