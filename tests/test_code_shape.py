"""The code stays readable: short functions, no tangles, and each room keeps its rule.

Students read this code to learn how an engine is built, so every function in
airtable/, bench/ and tools/ fits on a screen (at most 60 lines) and ruff's mccabe check (`make
lint`, max-complexity 12) keeps branching in check. Physics and protocol code
never import pygame or sockets.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "airtable"
MAX_FUNCTION_LINES = 60
# The package, and the benchmarks and tools beside it (in the repository, not in the wheel).
OUTSIDE = ("bench", "tools")
ROOMS = sorted({p.parent for top in (PACKAGE, *(ROOT / name for name in OUTSIDE)) for p in top.rglob("*.py")})


def _functions(path: Path):
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


@pytest.mark.parametrize("room", ROOMS, ids=lambda p: str(p.relative_to(PACKAGE.parent)))
def test_no_function_over_60_lines(room: Path) -> None:
    long = [
        f"{path.relative_to(PACKAGE.parent)}:{fn.lineno} {fn.name} ({fn.end_lineno - fn.lineno + 1} lines)"
        for path in sorted(room.glob("*.py"))
        for fn in _functions(path)
        if fn.end_lineno - fn.lineno + 1 > MAX_FUNCTION_LINES
    ]
    assert not long, "functions longer than 60 lines:\n" + "\n".join(long)


def test_the_package_never_imports_the_benchmarks_or_tools() -> None:
    # They are not in the wheel: an import of them would break every installed copy.
    for path in sorted(PACKAGE.rglob("*.py")):
        assert not _imports(path) & set(OUTSIDE), path


def test_physics_imports_no_pygame_and_no_sockets() -> None:
    for path in sorted((PACKAGE / "physics").glob("*.py")):
        assert not _imports(path) & {"pygame", "socket", "selectors"}, path


def test_protocol_imports_no_pygame_and_no_sockets() -> None:
    for name in ("protocol.py",):
        assert not _imports(PACKAGE / "net" / name) & {"pygame", "socket", "selectors"}, name
