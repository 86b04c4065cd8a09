"""Text panels over the table (help, notes, errors), laid out to fit the window.

Rows flow top to bottom into as many columns as the panel's width holds at a
readable line length; what does not fit on one page goes on the next, so
nothing is ever cut, whatever the window size or the number of demos.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pygame

ACCENT = (255, 220, 120)
TEXT_COLOR = (230, 230, 230)
DIM_TEXT = (150, 150, 150)
PANEL_COLOR = (10, 10, 30, 255)  # opaque: nothing shows through the text
COLUMN_EMS = 20  # a column is at least this many font sizes wide (about 50 characters)

Row = tuple[str, str] | str


def panel_surface(size_px: tuple[int, int]) -> pygame.Surface:
    """A transparent surface of `size_px` for a panel; 0 wide or tall where a window too small for the
    panel leaves it less (a window shrunk to a strip must not end the lesson)."""
    return pygame.Surface((max(0, int(size_px[0])), max(0, int(size_px[1]))), pygame.SRCALPHA)


def shorten(font: pygame.font.Font, text: str, width: int) -> str:
    """`text`, cut and ended with "..." if it is wider than `width` pixels."""
    if font.size(text)[0] <= width:
        return text
    while text and font.size(text + "...")[0] > width:
        text = text[:-1]
    return text + "..." if text else ""


def wrap(font: pygame.font.Font, text: str, width: int) -> list[str]:
    """Split text into lines that fit `width` pixels (a word longer than that is broken across lines)."""
    lines: list[str] = []
    current = ""
    for long_word in text.split():
        # A word wider than the line (a file's path) is broken into pieces that fit, not left to run out.
        *pieces, word = _break_word(font, long_word, width)
        if pieces:
            lines.extend([current, *pieces] if current else pieces)
            current = ""
        trial = f"{current} {word}".strip()
        if current and font.size(trial)[0] > width:
            lines.append(current)
            current = word
        else:
            current = trial
    if current:
        lines.append(current)
    return lines


# A word broken across lines is broken after the last of these that fits, if any: a name or a path
# then reads in whole parts ("Александр-" / "Константин", not "Александр-Кон" / "стантин": a user test).
BREAKS_AFTER = "-/\\_."


def _break_word(font: pygame.font.Font, word: str, width: int) -> list[str]:
    """`word` in pieces no wider than `width` pixels (at least one character each), broken after a
    hyphen, slash, backslash, underscore or dot where one fits (BREAKS_AFTER)."""
    pieces = []
    while font.size(word)[0] > width and len(word) > 1:
        n = 1
        while n < len(word) - 1 and font.size(word[: n + 1])[0] <= width:
            n += 1
        after = max(word.rfind(c, 0, n) for c in BREAKS_AFTER) + 1  # (0: none in the part that fits)
        n = after if after > n // 2 else n  # (not one early on: that line would be left nearly empty)
        pieces.append(word[:n])
        word = word[n:]
    return [*pieces, word]


@dataclass(frozen=True)
class Piece:
    """One line of text placed in the panel: its top-left corner and colour."""

    x: int
    y: int
    text: str
    color: tuple[int, int, int]


def _blocks(font, sections: Sequence[tuple[str, Sequence[Row]]], col_w: int) -> tuple[list[list[tuple]], list[str]]:
    """Each row as a block of (x offset, text, colour) lines that must stay together; and for each block
    the heading of its section ("" for none), to begin a page with when the section goes on there."""
    blocks, headings = [], []
    for heading, rows in sections:
        first = len(blocks)
        keys = [r[0] for r in rows if isinstance(r, tuple)]
        gap = font.get_height()
        key_w = min(max((font.size(k)[0] for k in keys), default=0), col_w // 3) + gap
        for row in rows:
            if isinstance(row, tuple):
                key, text = row
                lines = [(key_w, line, TEXT_COLOR) for line in wrap(font, text, col_w - key_w) or [""]]
                if font.size(key)[0] + gap > key_w:  # a long key gets a line of its own
                    blocks.append([(0, key, ACCENT), *lines])
                else:  # the key shares the first line's y: marked so the flow does not count it
                    blocks.append([(-1, key, ACCENT), *lines])
            else:
                blocks.append([(0, line, TEXT_COLOR) for line in wrap(font, row, col_w) or [""]])
        if heading:  # a blank line, then the heading (the blank is dropped at a column's top), kept with
            # its first row: alone at the foot of a column it headed nothing (help page 2 at 1280x720)
            head = [(0, "", ACCENT), (0, heading, ACCENT)] if first else [(0, heading, ACCENT)]
            blocks[first:first] = [head + (blocks.pop(first) if len(blocks) > first else [])]
        headings += [heading] * (len(blocks) - first)
    return blocks, headings


def layout(
    font: pygame.font.Font,
    sections: Sequence[tuple[str, Sequence[Row]]],
    size_px: tuple[int, int],
) -> list[list[Piece]]:
    """Pages of placed lines filling a body of `size_px`: columns first, then pages."""
    width, height = size_px
    gap = font.get_height()
    n_cols = max(1, min(3, (width + gap) // (COLUMN_EMS * font.get_height() + gap)))
    col_w = (width - gap * (n_cols - 1)) // n_cols
    line_h = font.get_linesize()
    rows_per_col = max(1, height // line_h)
    blocks, headings = _blocks(font, sections, col_w)
    pages: list[list[Piece]] = [[]]
    col, used = 0, 0

    def next_column(heading: str) -> None:
        """On to the next column; on a new page, the section's heading first (the page's title is the first's)."""
        nonlocal col, used
        col, used = col + 1, 0
        if col == n_cols:
            pages.append([])
            col = 0
            if heading:
                pages[-1].append(Piece(0, 0, heading, ACCENT))
                used = 1

    for block, heading in zip(blocks, headings, strict=True):
        lines = sum(1 for x, _, _ in block if x >= 0)
        if used and used + lines > rows_per_col:  # the block goes whole to the next column
            next_column("" if any(text == heading for _, text, _ in block[:2]) else heading)
        if used == 0 and block[0][1] == "":  # no blank line at the top of a column
            block = block[1:]
        beside = None  # a key that goes beside the next line (its description's first)
        for x, text, color in block:
            if x < 0:
                beside = (text, color)
                continue
            if used >= rows_per_col:  # a block taller than a column goes on in the next one
                next_column(heading)
            x0 = col * (col_w + gap)
            if beside is not None:
                pages[-1].append(Piece(x0, used * line_h, *beside))
                beside = None
            pages[-1].append(Piece(x0 + x, used * line_h, text, color))
            used += 1
    return pages


def body_rect(size_px: tuple[int, int], font, title_font, small_font) -> pygame.Rect:
    """Where the text goes inside a panel of `size_px`: under the title, above the page note."""
    pad = font.get_height()
    top = pad // 2 + title_font.get_linesize() + pad // 3
    return pygame.Rect(pad, top, size_px[0] - 2 * pad, size_px[1] - top - small_font.get_linesize() - pad // 2)


def next_page(shown: bool, page: int, pages: int) -> tuple[bool, int]:
    """(shown, page) after the key that turns a text's pages: a text not shown opens at its first page,
    one shown goes to its next page, and after its last it closes (back at the first)."""
    if not shown:
        return True, 0
    following = page + 1
    return (True, following) if following < pages else (False, 0)


def page_note(page: int, pages: int, page_key: str | None) -> str:
    """The note under page `page` (from 0) of `pages`: which key turns them (None: none does, as in the menu,
    which scrolls, or an error, which Esc hides)."""
    if page_key is None:
        then = "a larger window shows the rest"
    else:
        then = f"press {page_key} for the next" if page + 1 < pages else f"{page_key} again closes it"
    return f"page {page + 1} of {pages}: {then}"


def render_panel(
    size_px: tuple[int, int],
    title: str,
    sections: Sequence[tuple[str, Sequence[Row]]],
    *,
    font: pygame.font.Font,
    title_font: pygame.font.Font,
    small_font: pygame.font.Font,
    page: int = 0,
    page_key: str | None = None,
    fit: bool = False,
) -> tuple[pygame.Surface, int]:
    """An opaque panel of `size_px` with `title` and the page `page` of its text, and the page count;
    `page_key` turns the pages (the note under a text of several says so; None: no key does). With `fit`, a text that
    fits on one page gets a panel only as tall as it needs (the lecture notes: the table shows below)."""
    pad = font.get_height()
    if title_font.size(title)[0] > size_px[0] - 2 * pad:  # a long title in the body's type
        title_font = font
    body = body_rect(size_px, font, title_font, small_font)
    pages = layout(font, sections, body.size)
    if fit and len(pages) == 1 and pages[0]:
        used = max(piece.y for piece in pages[0]) + font.get_linesize()
        size_px = (size_px[0], min(size_px[1], body.y + used + pad // 2))
    panel = panel_surface(size_px)
    panel.fill(PANEL_COLOR)
    pygame.draw.rect(panel, ACCENT, panel.get_rect(), max(1, pad // 10))
    panel.blit(title_font.render(shorten(title_font, title, size_px[0] - 2 * pad), True, ACCENT), (pad, pad // 2))
    page %= len(pages)
    for piece in pages[page]:
        panel.blit(font.render(piece.text, True, piece.color), (body.x + piece.x, body.y + piece.y))
    if len(pages) > 1:
        text = shorten(small_font, page_note(page, len(pages), page_key), size_px[0] - 2 * pad)  # (cut, not clipped)
        note = small_font.render(text, True, DIM_TEXT)
        panel.blit(note, note.get_rect(bottomright=(size_px[0] - pad, size_px[1] - pad // 4)))
    return panel, len(pages)
