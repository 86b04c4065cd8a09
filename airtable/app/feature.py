"""What a feature of the teacher's app is: one object that owns its state, its keys, its update and its drawing.

The app keeps its features in one list and the frame calls each hook on every
feature in turn (as arcade's SectionManager routes to its sections); a hook a
feature does not need stays a no-op. A feature reaches the app only through the
narrow `Host` of host.py, so no feature imports the app, and none imports
another that imports it back.

The frame calls, in this order: `handle_event` for each event (a feature that
takes one stops it there), `before_physics`, `after_step` after every physics
step, `after_physics`, then `status_parts` and `hud_lines` for the text, and
`draw` in `draw_order`. `on_demo_start` runs when a demo (re)starts and
`forget_after` when the table runs on from a moment in the past; `on_escape` when Esc finds no
overlay open (a prediction round under way ends before the app asks to quit).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    import pygame

    from airtable.app.host import Host
    from airtable.app.overlays import Overlays
    from airtable.physics.table import AirTable

# A key is a pygame key, or (modifier mask, key) for a key pressed with Ctrl or Shift.
Key = int | tuple[int, int]


@dataclass(frozen=True)
class Binding:
    """One row of the key table: its label and help text, and what each of its keys does.

    An action is a function of the binding's owner (a method of the feature, unbound).
    A row with no actions only documents a key handled elsewhere (the mouse, the demo
    keys); a row with no help adds its keys to the row of the same label that another
    owner documents (F2-F5 share F1's row)."""

    label: str
    help: str = ""
    actions: Mapping[Key, Callable[[Any], None]] = field(default_factory=dict)
    held: bool = False  # acts every frame while held, not on the press


class Feature:
    """A part of the teacher's app; every hook is a no-op until a feature overrides it."""

    bindings: ClassVar[tuple[Binding, ...]] = ()  # its rows of the key table (controls.py orders them)
    draw_order: ClassVar[int] = 0  # lower draws first (arcade's Section.draw_order)

    def __init__(self, host: Host) -> None:
        self.host = host

    @property
    def overlays(self) -> Overlays:
        """The app's one overlay stack: a feature's OverlayFlag lives there."""
        return self.host.overlays

    def handle_event(self, event: pygame.event.Event) -> bool:
        """An event, before the key table and the mouse see it; True if the feature took it."""
        return False

    def on_demo_start(self, table: AirTable) -> None:
        """A demo (re)started on `table` (already built)."""

    def before_physics(self) -> None:
        """Every frame, after input, before the frame's physics steps (paused or not)."""

    def after_step(self, table: AirTable) -> None:
        """After each physics step."""

    def after_physics(self) -> None:
        """Every frame, after the frame's physics steps."""

    def forget_after(self, t_s: float) -> None:
        """The table runs on from `t_s`, a moment in the past: what came later did not happen."""

    def on_escape(self) -> bool:
        """Esc with no overlay open: end what the feature has under way (a prediction round) before
        the app asks to quit; True if it ended something."""
        return False

    def status_parts(self, for_students: bool) -> list[str]:
        """Its parts of the status line; `for_students`: without the teacher's keys."""
        return []

    def hud_lines(self) -> list[str]:
        """Its heads-up lines under the title."""
        return []

    def draw(self) -> None:
        """Draw onto the host's window, over the table."""
