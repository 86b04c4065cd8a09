"""Which characters the window's font can draw.

The app draws names with pygame's default font, which has no Hebrew, Chinese or
emoji: such a name would show as boxes on the projector. The entry point works
out once, on the main thread, which characters the font has (`NameCheck`); the
server's network thread then only looks them up, and refuses a name it cannot
draw with a sentence.
"""

from __future__ import annotations

import unicodedata

import pygame

# The font's scripts all lie below this (Latin, Greek, Cyrillic, punctuation, arrows).
LAST_CHECKED = 0x2FFF


def drawable_characters(last: int = LAST_CHECKED) -> frozenset[str]:
    """Every character up to `last` that pygame's default font has a glyph for: those that
    do not draw as the box of a missing glyph (the same as a private-use character)."""
    pygame.font.init()
    font = pygame.font.Font(None, 12)

    def pixels(ch: str) -> tuple:
        try:
            s = font.render(ch, False, (255, 255, 255))
        except pygame.error:  # a glyph of zero width (a combining mark): nothing to show on its own
            return None
        return s.get_size(), pygame.image.tobytes(s, "RGBA")

    missing = pixels(chr(0x10FFFD))
    return frozenset(ch for ch in map(chr, range(0x20, last + 1)) if ch.isprintable() and pixels(ch) != missing)


class NameCheck:
    """Refuses names the teacher's screen cannot draw; safe to call from any thread."""

    def __init__(self, drawable: frozenset[str]) -> None:
        self.drawable = drawable

    def __call__(self, name: str) -> str | None:
        """A sentence refusing `name`, or None if every character of it can be drawn."""
        ch = next((c for c in name if not c.isspace() and c not in self.drawable), None)
        if ch is None:
            return None
        base = unicodedata.normalize("NFD", ch)[0]  # the letter without its accents ("e" for "ễ")
        instead = f"write {base!r} for it" if base != ch and base in self.drawable else "pick other letters or digits"
        return f"the name has {ch!r} (U+{ord(ch):04X}), which the teacher's screen's font cannot draw; {instead}"
