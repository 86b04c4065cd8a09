"""The key table gathered from the features: every key bound once, every row placed in the help."""

from __future__ import annotations

import pygame
import pytest

from airtable.app.app import BINDINGS, App
from airtable.app.controls import HELP_ORDER, KeyTable, by_position, help_rows
from airtable.app.feature import Binding, Feature


def test_the_help_lists_every_key_the_features_bind(demos):
    app = App(demos, headless=True)
    bound = {key for owner in (app, *app.features) for b in owner.bindings for key in b.actions}
    listed = {key for row in BINDINGS for key in row.actions}
    assert bound == listed
    assert [row.label for row in BINDINGS] == list(HELP_ORDER)


def test_a_row_without_help_joins_the_documented_row_of_its_label():
    """The room's F2-F5 share F1's row, so the help fits one page."""
    f1 = next(row for row in BINDINGS if row.label == "F1")
    assert f1.help.startswith("this help screen") and {pygame.K_F1, pygame.K_F5} <= set(f1.actions)
    with pytest.raises(ValueError, match="nobody documents"):
        help_rows([Binding("F1", actions={pygame.K_F2: lambda feature: None})])


def test_a_row_the_help_does_not_place_is_refused():
    with pytest.raises(ValueError, match="HELP_ORDER"):
        help_rows([Binding("F7", "nothing yet")])


def test_a_key_bound_twice_is_refused():
    class Twice(Feature):
        bindings = (Binding("f", "again", {pygame.K_f: lambda feature: None}),)

    with pytest.raises(ValueError, match="bound already"):
        KeyTable([Twice(None), Twice(None)])


def _key(kind: int, key: int, scancode: int, text: str = "") -> pygame.event.Event:
    return pygame.event.Event(kind, key=key, scancode=scancode, mod=0, unicode=text)


def test_a_russian_layout_keeps_the_letter_keys(demos):
    """A user test: with `setxkbmap ru` the G key (SDL's key code: "п", its code point) and the C key did
    nothing. Letters of any layout act as the Latin letter on the same key (scancodes of A to Z: 4 to 29)."""
    app = App(demos, headless=True)
    gravity = app.table.gravity_on
    g_key = 4 + ord("g") - ord("a")  # the scancode of the G key
    app.handle_event(_key(pygame.KEYDOWN, ord("п"), g_key, "п"))
    app.handle_event(_key(pygame.KEYUP, ord("п"), g_key))
    assert app.table.gravity_on is not gravity
    assert not app.keys_down  # released as it was pressed
    # Named keys and Latin letters are left as they are; the text typed stays the layout's.
    f1 = _key(pygame.KEYDOWN, pygame.K_F1, 58)
    assert by_position(f1) is f1
    latin = by_position(_key(pygame.KEYDOWN, pygame.K_q, 4 + ord("q") - ord("a"), "q"))
    assert latin.key == pygame.K_q
    assert by_position(_key(pygame.KEYDOWN, ord("с"), 6, "с")).unicode == "с"  # the C key: "с" typed
    assert by_position(_key(pygame.KEYDOWN, ord("с"), 6, "с")).key == pygame.K_c


def test_ctrl_or_alt_with_a_key_bound_alone_does_nothing_and_ctrl_q_asks_to_quit(demos):
    """A user test: Ctrl+W lowered the wall restitution, Ctrl+Q reset the view, Ctrl+Alt+S saved a demo
    twice over: a chord is not the key alone. Ctrl+Q and Ctrl+W quit as desktop programs do, asking first."""
    app = App(demos, demo_key="5", headless=True)
    cr_wall, demo = app.table.cr_wall, app.demo_key
    for mod in (pygame.KMOD_LCTRL, pygame.KMOD_LALT, pygame.KMOD_LCTRL | pygame.KMOD_LSHIFT):
        for key in (pygame.K_e, pygame.K_g, pygame.K_1):
            app.handle_event(pygame.event.Event(pygame.KEYDOWN, key=key, scancode=0, mod=mod, unicode=""))
    assert app.table.cr_wall == cr_wall and app.demo_key == demo and app.running
    for _ in range(150):  # a recording to lose: quitting asks
        app.frame(1 / 60)
    app.handle_event(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_q, scancode=0, mod=pygame.KMOD_LCTRL, unicode=""))
    assert app.panels.panel() == "quit" and app.running
    app.handle_event(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_w, scancode=0, mod=pygame.KMOD_LCTRL, unicode=""))
    assert not app.running  # asked, and asked again: it quits
