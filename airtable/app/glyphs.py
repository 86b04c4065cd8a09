"""Which characters the window's font can draw.

The app draws names with pygame's default font, which has no Hebrew, Chinese or
emoji: such a name would show as boxes on the projector. The entry point works
out once, on the main thread, which characters the font has (`NameCheck`); the
server's network thread then only looks them up, and refuses a name it cannot
draw with a sentence.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Iterable

import pygame

# The font's scripts all lie below this (Latin, Greek, Cyrillic, punctuation, arrows).
LAST_CHECKED = 0x2FFF


def drawable_characters(last: int = LAST_CHECKED, among: Iterable[str] | None = None) -> frozenset[str]:
    """Every character up to `last` (of `among`, if given) that pygame's default font has a glyph for:
    those that do not draw as the box of a missing glyph (the same as a private-use character)."""
    pygame.font.init()
    font = pygame.font.Font(None, 12)

    def pixels(ch: str) -> tuple:
        try:
            s = font.render(ch, False, (255, 255, 255))
        except pygame.error:  # a glyph of zero width (a combining mark): nothing to show on its own
            return None
        return s.get_size(), pygame.image.tobytes(s, "RGBA")

    missing = pixels(chr(0x10FFFD))
    chars = map(chr, range(0x20, last + 1)) if among is None else (c for c in set(among) if ord(c) <= last)
    return frozenset(ch for ch in chars if ch.isprintable() and pixels(ch) != missing)


def _plain(ch: str) -> str:
    """The letter without its accents ("e" for "ễ")."""
    return unicodedata.normalize("NFD", ch)[0]


def name_refusal(name: str) -> str | None:
    """What NameCheck says of `name` on this computer, looking up only its own letters (quick: the
    student's command asks before it joins, and draws names in the same default font)."""
    return NameCheck(drawable_characters(among={*name, *map(_plain, name)}))(name)


class NameCheck:
    """Refuses names the teacher's screen cannot draw; safe to call from any thread."""

    def __init__(self, drawable: frozenset[str]) -> None:
        self.drawable = drawable

    def __call__(self, name: str) -> str | None:
        """A sentence refusing `name`, or None if every character of it can be drawn."""
        ch = next((c for c in name if self._lacks(c)), None)
        if ch is None:
            return None
        sub = self._instead(ch)
        instead = f"write {sub!r} for it" if sub else "leave it out"
        # The whole name as it could be written, so the student need not work it out letter by letter.
        kept = " ".join("".join(self._instead(c) for c in name).split())
        if any(c.isalnum() for c in kept):
            instead = f'{instead}, as in "{kept}"'
        else:
            instead = "pick a name in Latin, Greek or Cyrillic letters"
        return f"the name has {ch!r} (U+{ord(ch):04X}), which the teacher's screen's font cannot draw; {instead}"

    def _lacks(self, ch: str) -> bool:
        return not ch.isspace() and ch not in self.drawable

    def _instead(self, ch: str) -> str:
        """`ch` if it can be drawn, else its letter without accents if that can, else nothing."""
        if not self._lacks(ch):
            return ch
        plain = _plain(ch)
        return plain if not self._lacks(plain) else ""
