"""The key table of the teacher's app: the rows every owner binds, in the help's order, and the dispatch.

App-level keys first, demo keys second: each feature (and the app itself) lists
its rows in `bindings` (feature.py); `KeyTable` gathers them into the one key
table that drives both the dispatch and the F1 help screen (and README's
table, tools/keytable.py), in the order of `HELP_ORDER`. A key that the table
does not take, typed as a digit or a letter, picks a demo (`demo_key_for`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import replace

import pygame

from airtable.app.feature import Binding, Key

# A key held with one of these and bound to nothing with it does nothing (not what it does alone).
CHORD_MODS = pygame.KMOD_CTRL | pygame.KMOD_ALT | pygame.KMOD_GUI
# The modifier keys themselves (pressed alone, they start a chord).
MODIFIER_KEYS = frozenset(
    getattr(pygame, f"K_{side}{name}") for side in "LR" for name in ("SHIFT", "CTRL", "ALT", "META", "SUPER")
)

# SDL names a letter key after the keyboard layout: on a Russian one the G key is "п" (the key
# code is the letter's code point), which no binding names. Such keys are read by where they sit
# on the keyboard instead: the scancodes of A to Z (USB usage ids 4 to 29, in pygame's events).
LETTER_SCANCODES = range(4, 30)


def by_position(event: pygame.event.Event) -> pygame.event.Event:
    """A key event for a letter of another alphabet, as the Latin letter on the same key (g for "п" on a
    Russian layout); any other event as it is. The text typed (event.unicode) stays the layout's."""
    if event.type not in (pygame.KEYDOWN, pygame.KEYUP) or event.key < 0x80 or event.key & (1 << 30):
        return event  # ASCII, or a key named by its place already (F1, arrows: SDL's scancode mask)
    scancode = getattr(event, "scancode", 0)
    if scancode not in LETTER_SCANCODES:
        return event
    return pygame.event.Event(event.type, {**event.dict, "key": pygame.K_a + scancode - LETTER_SCANCODES[0]})


# The help screen's rows, top to bottom: the order a teacher meets the keys in, not the owners'.
HELP_ORDER = (
    "1-9, 0",
    "Shift+1/2/3",
    "Tab",
    "Left / Right",
    "PageUp / PageDown",
    "Space",
    ", / .",
    "f",
    "g",
    "p",
    "z",
    "h / n (hold)",
    "mouse wheel",
    "Ctrl + mouse drag",
    "q",
    "mouse buttons 1 / 2 / 3",
    "e",
    "s",
    "r",
    "a",
    "v",
    "c",
    "m / b",
    "i (hold)",
    "l",
    "u / w",
    "Shift+g",
    "- / =, [ / ]",
    "d / t / k",
    "x / Ctrl+S",
    "F6",
    "F1",
    "F11",
    "F12",
    "Esc",
)

# Number row and keypad digits, in the order 1..9, 0.
DIGIT_KEYS = (*(getattr(pygame, f"K_{d}") for d in "1234567890"),)
KEYPAD_KEYS = (*(getattr(pygame, f"K_KP_{d}") for d in "1234567890"),)


def help_rows(bindings: Iterable[Binding]) -> tuple[Binding, ...]:
    """The rows in HELP_ORDER, a row without help merged into the documented row of its label.

    Raises ValueError for a label HELP_ORDER does not place, or a place nobody documents."""
    rows: dict[str, Binding] = {}
    extra: list[Binding] = []
    for b in bindings:
        if b.label not in HELP_ORDER:
            raise ValueError(f"key table: place {b.label!r} in controls.HELP_ORDER")
        if not b.help:
            extra.append(b)
        elif b.label in rows:
            raise ValueError(f"key table: two rows documented as {b.label!r}")
        else:
            rows[b.label] = b
    for b in extra:
        if b.label not in rows:
            raise ValueError(f"key table: nobody documents the row {b.label!r}")
        rows[b.label] = replace(rows[b.label], actions={**rows[b.label].actions, **b.actions})
    missing = [label for label in HELP_ORDER if label not in rows]
    if missing:
        raise ValueError(f"key table: no row for {missing}")
    return tuple(rows[label] for label in HELP_ORDER)


def demo_key_for(event: pygame.event.Event) -> str | None:
    """The demo key a KEYDOWN names: a digit of the number row or keypad, with Shift adding "p"."""
    digits = DIGIT_KEYS if event.key in DIGIT_KEYS else KEYPAD_KEYS if event.key in KEYPAD_KEYS else None
    if digits is None:
        return None
    key = "1234567890"[digits.index(event.key)]
    return key + "p" if event.mod & pygame.KMOD_SHIFT else key


class KeyTable:
    """The owners' bindings as one dispatch: `press` and `run_held` (the help's rows are `help_rows`)."""

    def __init__(self, owners: Sequence[object]) -> None:
        """`owners`: objects with `bindings` (the features and the app); each action is called with its owner.
        A key bound twice raises ValueError (the second would silently win)."""
        self._press: dict[int, Callable[[], None]] = {}
        self._modified: dict[tuple[int, int], Callable[[], None]] = {}
        self._held: dict[int, Callable[[], None]] = {}
        for owner in owners:
            for b in owner.bindings:
                for key, action in b.actions.items():
                    table = self._table(key, b.held)
                    if key in table:
                        raise ValueError(f"key table: {b.label!r} binds a key bound already")
                    table[key] = _bound(action, owner)

    def _table(self, key: Key, held: bool) -> dict:
        if isinstance(key, tuple):
            return self._modified
        return self._held if held else self._press

    def press(self, event: pygame.event.Event) -> bool:
        """A KEYDOWN: run its action (a key with Ctrl or Shift first, as Ctrl+S); False if it has none."""
        mod = getattr(event, "mod", 0)
        action = next((a for (mask, key), a in self._modified.items() if key == event.key and mod & mask), None)
        if action is None and mod & CHORD_MODS:
            return event.key not in MODIFIER_KEYS  # Ctrl+W is not w (it lowered the wall restitution): nothing
        action = action or self._press.get(event.key)
        if action is None:
            return False
        action()
        return True

    def run_held(self, keys_down: Iterable[int]) -> None:
        """Every frame: the actions of the keys held down (zoom, inspect)."""
        for key in list(keys_down):
            action = self._held.get(key)
            if action is not None:
                action()


def _bound(action: Callable[[object], None], owner: object) -> Callable[[], None]:
    return lambda: action(owner)
