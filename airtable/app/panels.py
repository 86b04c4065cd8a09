"""The panels in the middle of the teacher's window (`Panels`): help, notes, the demo menu, a demo's
error, a notice, and the quit question, with their keys.

What is open lives in the one overlay stack (overlays.py); this feature opens
and closes its panels there and draws the one on top. Esc closes what is on
top (any overlay: the roster, the chart, the lesson panels too), then a
prediction round under way; with nothing left it asks, and Esc again while
asked quits, once the burst of Escs that got there has paused.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import pygame

from airtable.app import panel_view
from airtable.app.controls import MODIFIER_KEYS
from airtable.app.demo_loader import has_own_key, key_label, key_order
from airtable.app.feature import Binding, Feature
from airtable.app.menu import DemoMenu
from airtable.app.overlays import EscapeBurst, OverlayFlag, OverlayValue

if TYPE_CHECKING:
    from airtable.app.host import Host

# Keys that only close a "press any key" notice; any other key closes it and does its work too, as it says
# (a user test: the first key, 3 for demo 3, was lost; the next one: g turned gravity on unannounced).
GO_ON_KEYS = frozenset((pygame.K_SPACE, pygame.K_RETURN, pygame.K_KP_ENTER))
GO_ON = "Space or Enter goes on; any other key goes on and does its work (3: demo 3)."
QUIT_CONFIRM_S = 4.0  # the quit question waits this long for a second Esc (or window close)
ERROR_TITLES = {
    "load": "Demo {key} could not be loaded",
    "build": "Demo {key} could not be built",
    "event": "Demo {key}: a timed event failed",
}


class Panels(Feature):
    """The panels' state (`app.panels`): which help page, the menu, the notice, the quit question."""

    show_help = OverlayFlag("help")
    show_notes = OverlayFlag("notes")
    menu = OverlayValue("menu")  # a DemoMenu while the menu is open
    notice = OverlayValue("notice", empty=[])  # lines of a "press any key" notice
    draw_order = 4  # over the aids and the round; the roster (room.py) is a panel too

    def __init__(self, host: Host, key_rows: Sequence[Binding]) -> None:
        super().__init__(host)
        self.key_rows = key_rows  # the help's rows: the app's whole key table
        self.help_page, self.help_pages = 0, 1
        self.notes_page, self.notes_pages = 0, 1  # (notes too long for the window go on pages too)
        self.quit_armed_until = -1.0  # clock_s until which a second Esc quits
        self._escapes = EscapeBurst()

    def panel(self) -> str | None:
        """Which panel is in the middle of the window now, if any (the quit question lapses)."""
        if self.overlays.shown("quit") and self.host.clock_s >= self.quit_armed_until:
            self.overlays.close("quit")
        return self.overlays.panel()

    def close_panel(self) -> bool:
        """Close what is on top (a panel, else the chart, values or momenta); False if nothing was open."""
        self.panel()  # a lapsed quit question first
        closing = self.overlays.top()
        if closing in ("help", "notes"):
            setattr(self, f"{closing}_page", 0)
        return closing is not None and self.overlays.close(closing)

    def handle_event(self, event: pygame.event.Event) -> bool:
        """The window's close button; and a key, while a panel that waits for one is open."""
        if event.type == pygame.QUIT:
            self.close_window()
            return True
        return event.type == pygame.KEYDOWN and self._take_key(event)

    def _take_key(self, event: pygame.event.Event) -> bool:
        """A panel that waits for a key takes it first; True if it did."""
        panel = self.panel()
        if event.key == pygame.K_ESCAPE or panel not in ("quit", "menu", "notice"):
            return False
        if event.key in MODIFIER_KEYS:
            return True  # Shift or Ctrl alone answers nothing: it starts a key
        if panel == "quit" and event.key == pygame.K_x:
            self.close_panel()
            return False  # the question says "x exports it": x stays, and exports
        if panel == "quit" and getattr(event, "mod", 0) & pygame.KMOD_CTRL and event.key in (pygame.K_q, pygame.K_w):
            return False  # Ctrl+Q again, as Esc again: it quits
        if panel == "menu" and event.key == pygame.K_F1:
            return False  # help over the menu (Esc closes it, and the menu is still there)
        if panel == "menu" and event.key == pygame.K_TAB:
            self.menu = None
        elif panel == "menu":
            shift = bool(getattr(event, "mod", 0) & pygame.KMOD_SHIFT)
            picked = self.menu.press(pygame.key.name(event.key), getattr(event, "unicode", ""), shift)
            if picked is not None:
                self.menu = None
                self.host.start_demo(picked)
        else:
            self.close_panel()  # "press any key to go on"; any key but Esc keeps the table running
            # The notice is news, not a question: a teacher's first key (3 for demo 3) also does its work.
            return panel != "notice" or event.key in GO_ON_KEYS
        return True

    # ------------------------------------------------------------ quitting

    def escape(self) -> None:
        """Esc: close what is on top; with nothing open, ask; Esc again while asked quits, once
        the Escs that closed things and asked have paused (EscapeBurst)."""
        deliberate = self._escapes.deliberate(self.host.clock_s)
        if self.panel() == "quit":
            if deliberate:
                self.quit_now()
            else:
                self.ask_to_quit()  # still asking, for as long again
        elif not self.close_panel() and not self.host.escape_features():
            self.ask_to_quit()

    def close_window(self) -> None:
        """The window's close button: quit, asking first while leaving would drop students or
        lose recording; closing again (or Esc) while asked quits."""
        if self.panel() == "quit" or not self.host.quit_would_lose():
            self.quit_now()
        else:
            self.ask_to_quit()

    def quit_now(self) -> None:
        """Quit after this frame, which is drawn without the question (--screenshot saves it)."""
        self.overlays.close("quit")
        self.host.stop()

    def ask_to_quit(self) -> None:
        self.quit_armed_until = self.host.clock_s + QUIT_CONFIRM_S
        self.overlays.open("quit")

    # ------------------------------------------------------------ keys

    def open_menu(self) -> None:
        host = self.host
        for error in host.shelf.refresh():
            host.report(error)
            host.say(str(error), lasting=True)  # (it was on the terminal only, and the demo left the menu)
        # A demo whose file now fails stays in the menu, marked: picking it shows why (its key does too).
        items = [(key, demo.title) for key, demo in host.demos.items()]
        items += [(key, f"{error.path.name}: does not load") for key, error in host.shelf.broken_keys().items()]
        self.menu = DemoMenu(sorted(items, key=lambda item: key_order(item[0])), current=host.demo_key)

    def toggle_notes(self) -> None:
        """L: the demo's lecture notes; again for their next page, if they have more than one; then closed."""
        self._turn_page("notes")

    def toggle_help(self) -> None:
        """F1: help; again for its next page, if it has more than one; then closed."""
        self._turn_page("help")

    def _turn_page(self, panel: str) -> None:
        """Open `panel` ("help" or "notes") at its first page, or show its next page, or close it after its last."""
        page = f"{panel}_page"
        shown, at = panel_view.next_page(getattr(self, f"show_{panel}"), getattr(self, page), getattr(self, f"{page}s"))
        setattr(self, f"show_{panel}", shown)
        setattr(self, page, at)

    # ------------------------------------------------------------ drawing

    def draw(self) -> None:
        panel, w, host = self.panel(), self.host.window, self.host
        if panel == "quit":
            # The question closes by itself: it says when (a user test: it vanished, unexplained, as it was read).
            left = max(1, math.ceil(self.quit_armed_until - host.clock_s))
            again = f"Esc (or Ctrl+Q) again within {left} s to quit; any other key to stay."
            w.draw_question("Quit?", [*host.quit_would_lose(), again])
        elif panel == "menu":
            rows = self.menu.rows(visible=w.panel_rows() - 2, label=key_label)  # the footer under them
            w.draw_panel("Demos", [*rows, self.menu.footer()])
        elif panel == "error":
            w.draw_panel(*self._error_text())
        elif panel == "notice":
            w.draw_panel("Some demo files could not be loaded", [*self.notice, GO_ON])
        elif panel == "help":
            rows = [(key_label(k) if has_own_key(k) else f"Tab, {k}", d.title) for k, d in host.demos.items()]
            keys = [(b.label, b.help) for b in self.key_rows]
            self.help_pages = w.draw_panel(
                "Keys", keys, side_title="Demos", side_rows=rows, page=self.help_page, page_key="F1"
            )
        elif panel == "notes":
            notes = [host.demo.notes or "(no notes)"]
            self.notes_pages = w.draw_panel(
                host.demo.label(host.variation), notes, large=True, page=self.notes_page, page_key="L"
            )

    def _error_text(self) -> tuple[str, list[str]]:
        """The demo error panel's title and lines: what failed, and how to try again."""
        key = self.host.error_key if self.host.build_error.stage != "event" else self.host.demo_key
        title = ERROR_TITLES[self.host.build_error.stage].format(key=key_label(key))
        again = f"press {key_label(key)} again" if has_own_key(key) else "pick it in Tab's menu"
        lines = [str(self.host.build_error), f"Fix the file, then {again}. Esc hides this."]
        if self.host.build_error.stage != "event":  # (a timed event's demo is the one on the table)
            # The heading says it too, but a narrow window cuts it (a user test at 640x480).
            goes_on = self.host.goes_on
            lines.append(f"On the table: {goes_on} goes on." if goes_on else "The table is empty.")
        return title, lines

    bindings = (
        Binding("Tab", "demo menu: every demo; arrows and Enter, or type its key", {pygame.K_TAB: open_menu}),
        Binding("l", "lecture notes for this demo (again: next page)", {pygame.K_l: toggle_notes}),
        Binding("F1", "this help screen (again: next page); F2-F5: the room", {pygame.K_F1: toggle_help}),
        Binding(
            "Esc",
            "close what is open (the newest first); else asks: Esc again quits. Ctrl+Q / Ctrl+W: quit "
            "(asking first if students or an unexported recording would be lost)",
            {
                pygame.K_ESCAPE: escape,
                (pygame.KMOD_CTRL, pygame.K_q): close_window,
                (pygame.KMOD_CTRL, pygame.K_w): close_window,
            },
        ),
    )
