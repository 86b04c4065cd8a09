"""The demo menu: every demo in a list, picked with the arrow keys and Enter or by typing its key.

Keys like "t1" have no key of their own on the keyboard; the menu reaches them.
Typing narrows the choice: the first demo whose key starts with what was typed
is selected, and a key that nothing else extends (say "t2" beside "t10")
starts at once; so does "2" beside "2p", which the menu lists as Shift+2. No
pygame here: the app passes key names ("up", "return", "backspace") and typed
characters.
"""

from __future__ import annotations

from collections.abc import Sequence

from airtable.app.demo_loader import key_label

VISIBLE_ROWS = 14  # rows shown around the selection in a long list, unless the panel says how many fit


class DemoMenu:
    def __init__(self, items: Sequence[tuple[str, str]], current: str | None = None) -> None:
        """`items`: (demo key, title) in the order shown; `current` is selected first."""
        self.items = list(items)
        keys = [k for k, _ in self.items]
        self.selected = keys.index(current) if current in keys else 0
        self.typed = ""

    def press(self, name: str, text: str = "", shift: bool = False) -> str | None:
        """A key press: `name` as pygame.key.name gives it, `text` the character typed, `shift` held.

        Returns the demo key to start, or None while the choice goes on.
        """
        if not self.items:
            return None
        if name in ("up", "down", "page up", "page down"):
            step = {"up": -1, "down": 1, "page up": -VISIBLE_ROWS, "page down": VISIBLE_ROWS}[name]
            self.selected = min(max(self.selected + step, 0), len(self.items) - 1)
            self.typed = ""
            return None
        if name in ("return", "enter"):
            return self.items[self.selected][0]
        if text and not text.isascii() and len(name) == 1 and name.isascii():
            text = name  # a letter of another layout ("е"): demo keys are Latin, taken by where the key sits
        if shift and len(name) == 1 and name.isdigit():
            text = f"{name}p"  # Shift+1 is demo "1p", as on the table (a user test: the menu typed "!")
        if name == "backspace":
            self.typed = self.typed[:-1]
        elif text and text.isprintable() and not text.isspace():
            self.typed += text
        else:
            return None
        return self._match()

    def _starting(self) -> list[int]:
        """The rows whose demo key starts with what was typed."""
        return [i for i, (k, _) in enumerate(self.items) if k.lower().startswith(self.typed.lower())]

    def _match(self) -> str | None:
        keys = [k for k, _ in self.items]
        starting = self._starting()
        if not self.typed or not starting:
            return None
        self.selected = starting[0]
        typed = self.typed.lower()
        exact = [i for i in starting if keys[i].lower() == typed]
        # A key listed as Shift+N ("2p") is not reached by typing on after "2": it does not make "2" wait.
        longer = [i for i in starting if keys[i].lower() != typed and key_label(keys[i]) == keys[i]]
        if exact and not longer:
            return keys[exact[0]]
        return None

    def rows(self, visible: int = VISIBLE_ROWS, label=str) -> list[tuple[str, str]]:
        """The rows to show: all, or `visible` around the selection, the selected one marked;
        `label` turns a demo key into what a person presses ("1p" -> "Shift+1")."""
        first = min(max(self.selected - visible // 2, 0), max(len(self.items) - visible, 0))
        shown = []
        for i in range(first, min(first + visible, len(self.items))):
            key, title = self.items[i]
            mark = "> " if i == self.selected else "   "
            shown.append((f"{mark}{label(key)}", title))
        return shown

    def footer(self) -> str:
        typed = f"; typed so far: {self.typed}" if self.typed else ""
        if self.typed and not self._starting():
            typed = f"; no demo key starts with {self.typed} (Backspace)"  # a user test: no word that nothing matched
        return f"{self.selected + 1} of {len(self.items)}. Up / Down and Enter, or type a key; Esc or Tab closes{typed}"
