"""The wheel students install holds the product only: the package, its demos and assets,
never the benchmarks or the load tools (bench/, tools/), which stay in the repository.

The wheel's contents come from pyproject's explicit package list (no package finding), so
the list and the folders it maps to say what ships. (`make wheel` then `unzip -l` shows the
same; building needs setuptools' build environment, which a test must not download.)
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _setuptools_config() -> dict:
    tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11")
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]


def _folder(package: str, package_dir: dict[str, str]) -> Path:
    """The folder setuptools takes `package` from: its own mapping, else its parent's, else its dotted path."""
    parts = package.split(".")
    for cut in range(len(parts), 0, -1):
        mapped = package_dir.get(".".join(parts[:cut]))
        if mapped is not None:
            return ROOT / mapped / Path(*parts[cut:])
    return ROOT / Path(*parts)


def test_the_wheel_ships_the_package_with_its_demos_and_assets_and_no_bench_or_tools():
    config = _setuptools_config()
    packages, package_dir = config["packages"], config.get("package-dir", {})
    assert all(p == "airtable" or p.startswith("airtable.") for p in packages), packages
    folders = {p: _folder(p, package_dir) for p in packages}
    assert folders["airtable.demos"] == ROOT / "demos"
    assert folders["airtable.assets"] == ROOT / "assets"
    for package, folder in folders.items():
        assert folder.is_dir(), package
        assert folder.relative_to(ROOT).parts[0] not in ("bench", "tools", "tests"), package
    # Every folder of the package with Python files in it ships (nothing of the app left out).
    code = {p.parent for p in (ROOT / "airtable").rglob("*.py") if "__pycache__" not in p.parts}
    assert code <= set(folders.values())
    assert (ROOT / "demos" / "demo_0p_gas.py").is_file()  # the benchmark's gas is a demo: it ships
