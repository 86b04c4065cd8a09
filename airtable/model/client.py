"""Client: one user at the table (the local mouse or a network player).

A client holds its latest input: cursor position in world metres, which mouse
button is down (0 none, 1-3 the three cursor strings). When a
button goes down over a puck the client grabs it; until the button is released,
`cursor_pulls` turns it into a Pull (the string's spring and drag) that the game
loop hands to every `AirTable.step`. No pygame and no sockets here.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from airtable.physics.forces import Pull

LOCAL_COLOR = (0, 255, 0)  # the teacher's own cursor; players get other colours

# Cursor strings by mouse button: (spring k in N/m, drag c in N s/m).
# F = k (cursor - puck) - c v_puck.
CURSOR_STRINGS: dict[int, tuple[float, float]] = {
    1: (60.0, 2.0),  # medium
    2: (2.0, 0.2),  # soft
    3: (1000.0, 20.0),  # stiff
}


@dataclass(eq=False)
class Client:
    """One user's input state and the puck they hold (compared by identity)."""

    name: str = "local"
    color: tuple[int, int, int] = LOCAL_COLOR
    cursor_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    button: int = 0
    held: object = None  # airtable.physics.bodies.Puck or None
    active: bool = True

    def set_input(self, table, cursor_m, button: int, grab_within_m: float = 0.0) -> None:
        """Take new input; grab the puck under the cursor when a button goes down (or the nearest one,
        if its edge is within `grab_within_m`: table.puck_at)."""
        self.cursor_m = np.asarray(cursor_m, dtype=float).reshape(2).copy()
        if button not in (0, *CURSOR_STRINGS):
            raise ValueError(f"mouse button must be 0-3, not {button!r}")
        pressed = button != 0 and self.button == 0
        self.button = button
        if button == 0:
            self.held = None
        elif pressed:
            self.held = table.puck_at(self.cursor_m, grab_within_m)
        if self.held is not None and not self.held.alive:
            self.held = None

    def release(self) -> None:
        """Let go of the puck (button up); used when a network client leaves."""
        self.button = 0
        self.held = None


def cursor_pulls(clients: Iterable[Client]) -> list[Pull]:
    """The cursor string of every client holding a puck, as forces for the next step."""
    pulls = []
    for client in clients:
        puck = client.held
        if puck is None or not puck.alive or client.button not in CURSOR_STRINGS:
            continue
        k, c = CURSOR_STRINGS[client.button]
        anchor = (float(client.cursor_m[0]), float(client.cursor_m[1]))
        pulls.append(Pull(row=puck.index, anchor_m=anchor, k_Npm=k, drag_Nspm=c))
    return pulls
