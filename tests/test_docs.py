"""The README a newcomer reads: short, complete (every option, every demo), and every link,
picture and `python -m` command in it and in docs/ leads somewhere real."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

from airtable import cli, client_cli
from airtable.app.demo_loader import key_label

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PAGES = [README, *sorted((ROOT / "docs").glob("*.md"))]
README_MAX_BYTES = 12 * 1024  # what a newcomer reads in one sitting; the rest belongs in docs/


def _text(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def _options(main, capsys) -> set[str]:
    with pytest.raises(SystemExit):
        main(["--help"])
    return set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", capsys.readouterr().out)) - {"--help"}


def test_the_readme_is_short():
    assert len(README.read_bytes()) <= README_MAX_BYTES, "README.md is too long: move detail to docs/"


@pytest.mark.parametrize("main", [cli.main, client_cli.main], ids=["python -m airtable", "airtable-client"])
def test_the_readme_names_every_option_of_both_commands(main, capsys):
    options = _options(main, capsys)
    assert len(options) >= 5
    missing = sorted(o for o in options if f"`{o}" not in _text(README) and f" {o} " not in _text(README))
    assert not missing, f"README.md does not document {missing}"


def test_the_readme_demo_table_has_a_row_for_every_demo(demos):
    rows = [line for line in _text(README).splitlines() if line.startswith("| ")]
    keys = {row.split("|")[1].strip().split(" (")[0] for row in rows}
    for key, demo in demos.items():
        assert key_label(key) in keys, f"README's demo table lacks {key_label(key)} ({demo.title})"
        assert any(demo.title in row for row in rows), demo.title


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_link_and_picture_leads_to_a_file_and_heading_that_exist(page):
    for target in re.findall(r"\]\(([^)\s]+)\)", _text(page)):
        if "://" in target:
            continue
        file_part, _, anchor = target.partition("#")
        linked = (page.parent / file_part).resolve() if file_part else page
        assert linked.is_file(), f"{page.name} links to {target}, which does not exist"
        if anchor:
            headings = re.findall(r"^#+ (.+)$", _text(linked), flags=re.MULTILINE)
            assert anchor in {_slug(h) for h in headings}, f"{page.name}: no heading for #{anchor} in {linked.name}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_python_m_command_names_a_module_that_exists(page):
    for module in set(re.findall(r"python -m ([\w.]+)", _text(page))):
        assert importlib.util.find_spec(module) is not None, f"{page.name}: python -m {module} does not exist"


def test_the_pictures_tool_draws_a_picture_of_the_app_at_its_time(tmp_path):
    import pygame

    from tools import doc_pictures

    assert doc_pictures.main(["--out", str(tmp_path), "help.png"]) == 0
    image = pygame.image.load(str(tmp_path / "help.png"))
    assert image.get_size() == doc_pictures.SIZE_PX
    assert len(set(pygame.surfarray.array2d(image).ravel().tolist())) > 20  # drawn, not one flat colour
    for name in doc_pictures.PICTURES:  # every picture the docs show is one the tool makes
        assert (ROOT / "docs" / name).is_file()
