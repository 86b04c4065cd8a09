"""The panels' text flow (panel_view.layout): rows into columns, then pages, on bodies of any size."""

from __future__ import annotations

import pygame
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.app import panel_view
from airtable.app.panel_view import ACCENT

WORDS = st.text(alphabet="abcdefghij", min_size=1, max_size=12)
TEXT = st.lists(WORDS, min_size=1, max_size=14).map(" ".join)
ROW = st.one_of(TEXT, st.tuples(WORDS, TEXT))
SIDE_KEYS = st.text(alphabet="klmnop", min_size=1, max_size=12)  # (the side sections' keys: told apart)
SIDE_ROW = st.one_of(TEXT, st.tuples(SIDE_KEYS, TEXT))
HEADINGS = ("Demos", "More")


@pytest.fixture(scope="module")
def font():
    pygame.font.init()
    return pygame.font.Font(None, 18)


@settings(max_examples=60, deadline=None)
@given(
    first=st.lists(ROW, min_size=1, max_size=25),
    side=st.lists(st.lists(SIDE_ROW, min_size=1, max_size=12), min_size=1, max_size=2),
    width=st.integers(200, 1400),
    lines=st.integers(4, 40),
)
def test_a_heading_never_ends_a_column_and_a_key_sits_beside_its_text(font, first, side, width, lines):
    """A user test: on help page 2 at 1280x720 the "Demos" heading was the last line of a column, the
    demos it headed at the top of the next."""
    sections = [("", first), *zip(HEADINGS, side, strict=False)]
    line_h = font.get_linesize()
    pages = panel_view.layout(font, sections, (width, lines * line_h))
    for pieces in pages:  # (placed in reading order: down a column, then the next column)
        for p, after in zip(pieces, pieces[1:]):
            if p.color == ACCENT and p.text in HEADINGS:
                assert (after.y, after.x >= p.x) == (p.y + line_h, True), f"heading {p.text!r} ends its column"
            elif p.color == ACCENT and p.text:  # a key: its description beside it, or under it if it is long
                assert after.x > p.x and after.y in (p.y, p.y + line_h, 0)
        assert not (pieces and pieces[-1].color == ACCENT and pieces[-1].text in HEADINGS)
    for pieces in pages[1:]:  # a page going on with a side section begins with its heading (the title is "Keys")
        side_keys = [k for k, p in enumerate(pieces) if p.color == ACCENT and p.text and set(p.text) <= set("klmnop")]
        if side_keys:
            before = pieces[: side_keys[0]]
            assert any(p.text in HEADINGS for p in before), "a page goes on with a section under the wrong heading"
