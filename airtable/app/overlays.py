"""What lies over the table, in one stack: Esc closes what the teacher opened last.

Every feature that shows something over the table (help, notes, the demo
menu, an error, a notice, the roster, the chart, the values and momenta
panels, the quit question) opens and closes it here, by name, so Esc, the
layout and idling all know the same set. Panels (the boxes in the middle of
the window) are drawn over the side overlays (chart, values, momenta), so
the top one is the newest panel if one is open, else the newest side overlay.

A feature keeps its flag as an `OverlayFlag`: `app.aids.show_chart = True` opens
"chart" on its owner's `overlays` stack (the app's), and reading the flag asks the stack.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

# Drawn in the middle of the window, one at a time, over everything else.
PANELS = frozenset({"quit", "menu", "error", "notice", "help", "notes", "roster"})
# Drawn beside the table (or in its corners); several may show at once.
SIDE = frozenset({"chart", "values", "momenta"})
NAMES = PANELS | SIDE


class Overlays:
    """The open overlays by name, oldest first."""

    def __init__(self) -> None:
        self._open: list[str] = []

    def open(self, name: str) -> None:
        """Show `name`, on top of the others (an open one moves to the top)."""
        if name not in NAMES:
            raise ValueError(f"no overlay called {name!r}")
        self.close(name)
        self._open.append(name)

    def close(self, name: str) -> bool:
        """Hide `name`; False if it was not open."""
        if name in self._open:
            self._open.remove(name)
            return True
        return False

    def set(self, name: str, shown: bool) -> None:
        """Open or close `name`; one already open keeps its place."""
        if not shown:
            self.close(name)
        elif name not in self._open:
            self.open(name)

    def shown(self, name: str) -> bool:
        return name in self._open

    def top(self) -> str | None:
        """What Esc closes: the newest panel, else the newest side overlay, else None."""
        panels = [n for n in self._open if n in PANELS]
        if panels:
            return panels[-1]
        return self._open[-1] if self._open else None

    def panel(self) -> str | None:
        """The panel drawn in the middle of the window, if any."""
        top = self.top()
        return top if top in PANELS else None

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._open))

    def __len__(self) -> int:
        return len(self._open)


class OverlayFlag:
    """A bool attribute that lives in the owner's `overlays` stack under `name`."""

    def __init__(self, name: str) -> None:
        if name not in NAMES:
            raise ValueError(f"no overlay called {name!r}")
        self.name = name

    def __get__(self, owner, kind=None):
        if owner is None:
            return self
        return owner.overlays.shown(self.name)

    def __set__(self, owner, shown: bool) -> None:
        owner.overlays.set(self.name, bool(shown))


class OverlayValue:
    """An attribute whose value is shown over the table while it is set (a menu, an error, a notice's
    lines): setting a value opens overlay `name` on the owner's `overlays`, setting None or an empty
    one closes it; reading gives the value while the overlay is open, else `empty`."""

    def __init__(self, name: str, empty=None) -> None:
        if name not in NAMES:
            raise ValueError(f"no overlay called {name!r}")
        self.name, self.empty = name, empty

    def __set_name__(self, owner, attribute: str) -> None:
        self.slot = f"_{attribute}"

    def __get__(self, owner, kind=None):
        if owner is None:
            return self
        shown = owner.overlays.shown(self.name)
        return getattr(owner, self.slot, self.empty) if shown else self.empty

    def __set__(self, owner, value) -> None:
        setattr(owner, self.slot, value)
        owner.overlays.set(self.name, bool(value))


# An Esc this soon after the last one is part of a run of them, each closing the next thing: at 0.3 s, Escs half
# a second apart closed five overlays, asked, and quit the lesson (a user test). Reading the question takes longer.
ESC_PAUSE_S = 1.0


class EscapeBurst:
    """Esc pressed again and again to clear the screen must not answer the quit question it
    opens: an Esc counts as that answer only after a pause (ESC_PAUSE_S since the last one)."""

    def __init__(self) -> None:
        self._last_s = -math.inf

    def deliberate(self, now_s: float) -> bool:
        """Note an Esc at `now_s`; whether it came after a pause."""
        paused = now_s - self._last_s >= ESC_PAUSE_S
        self._last_s = now_s
        return paused
