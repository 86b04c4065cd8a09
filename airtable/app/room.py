"""The teacher runs the room: the roster of students, removing one, hands off,
the floor passed around, and an anonymous projector (no pygame here).

The rules that decide whose cursor acts live on the server (`GameServer.hands_off`,
`GameServer.floor`, `GameServer.may_act`), applied where students' inputs
reach the game loop. This module keeps the teacher's side: what the keys do,
the roster panel's selection, and the words the projector and the students
see. Students learn of hands off and the floor from the status line that
every snapshot carries: its part `HANDS_OFF` puts a banner on their windows
(`student_banner`), and `floor: C3 Ann` says whose turn it is.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from airtable.app.overlays import OverlayFlag, Overlays
from airtable.model.scene import Scene

if TYPE_CHECKING:
    from airtable.app.app import App
    from airtable.model.seats import Seat

HANDS_OFF = "HANDS OFF"  # a status part: every student's window shows HANDS_OFF_BANNER
HANDS_OFF_BANNER = "hands off: the teacher is explaining"
FLOOR_PREFIX = "floor: "
IDLE_FLAG_S = 60.0  # no input change for this long: "idle" in the roster
REMOVE_CONFIRM_S = 4.0  # the second Delete within this time removes the student
REMOVED_SENTENCE = "the teacher removed you from the table"


def student_banner(scene: Scene, me: str = "") -> str | None:
    """The line across a student's window that the teacher's status line asks for, if any."""
    return HANDS_OFF_BANNER if HANDS_OFF in scene.status_parts else None


def seat_flags(seat: Seat) -> str:
    """The roster's warnings for one seat: idle long, cursor far off, or both (a squatter)."""
    idle = seat.idle_s >= IDLE_FLAG_S
    if idle and seat.far_off:
        return f"squatting? idle {seat.idle_s:.0f} s, cursor far off the table"
    if idle:
        return f"idle {seat.idle_s:.0f} s"
    return "cursor far off the table" if seat.far_off else ""


def anonymous_label(name: str) -> str:
    """ "C3 Ann" -> "C3": the player's id alone."""
    return name.split(" ", 1)[0]


@dataclass
class Room:
    """The teacher's side of running the room."""

    show_roster = OverlayFlag("roster")  # not a field: the flag lives in `overlays`
    overlays: Overlays = field(default_factory=Overlays)
    selected: int = 0  # row of the roster panel
    anonymous: bool = False  # names hidden on the projector (colours stay)
    remove_armed: tuple[int, float] | None = None  # (player number, clock_s until which Delete removes)
    row_boxes: list[tuple[int, object]] = field(default_factory=list)  # (number, pygame.Rect) drawn last frame
    panel_box: object = None  # the roster panel's pygame.Rect as last drawn

    def label(self, name: str) -> str:
        """A player's name as the projector shows it."""
        return anonymous_label(name) if self.anonymous else name

    def projected(self, scene: Scene) -> Scene:
        """The scene as the teacher's window draws it: students' names hidden when anonymous."""
        if not self.anonymous or not scene.cursors:
            return scene
        cursors = tuple(dataclasses.replace(c, name=anonymous_label(c.name)) for c in scene.cursors)
        return dataclasses.replace(scene, cursors=cursors)


# ---------------------------------------------------------------- what the app shows


def _seats(app: App) -> list[Seat]:
    return app.server.roster() if app.server is not None else []


def status_parts(app: App) -> list[str]:
    """Hands off and the floor, for the status line every window shows."""
    server = app.server
    if server is None:
        return []
    parts = [HANDS_OFF] if server.hands_off else []
    if server.floor is not None:
        seat = next((s for s in _seats(app) if s.number == server.floor), None)
        if seat is None:  # the student with the floor left
            server.floor = None
            app.say("the student with the floor left: everyone's cursor acts again")
        else:
            parts.append(FLOOR_PREFIX + app.room.label(seat.name))
    return parts


def hud_lines(app: App) -> list[str]:
    """The player count, always there while the server is on."""
    server = app.server
    if server is None:
        return []
    n = server.player_count
    return [f"{n} student{'' if n == 1 else 's'} (F2: roster)"]


# ---------------------------------------------------------------- keys


def _need_server(app: App) -> bool:
    if app.server is None:
        app.say("no students: the table runs without its server (--no-server)")
        return False
    return True


def toggle_roster(app: App) -> None:
    if _need_server(app):
        app.room.show_roster = not app.room.show_roster
        app.room.remove_armed = None


def toggle_hands_off(app: App) -> None:
    if _need_server(app):
        app.server.hands_off = not app.server.hands_off
        app.say("hands off: students' cursors let go" if app.server.hands_off else "students' cursors act again")


def next_floor(app: App) -> None:
    """The floor to the next student in seat order; after the last, back to everyone."""
    if not _need_server(app):
        return
    numbers = [s.number for s in _seats(app)]
    current = app.server.floor
    later = [n for n in numbers if current is None or n > current]
    app.server.floor = later[0] if later else None
    if app.server.floor is None:
        app.say("the floor is back to everyone" if numbers else "no students to give the floor to")


def toggle_anonymous(app: App) -> None:
    app.room.anonymous = not app.room.anonymous
    app.say("names hidden on the projector" if app.room.anonymous else "names shown on the projector")


def move_selection(app: App, step: int) -> None:
    n = len(_seats(app))
    app.room.selected = min(max(0, app.room.selected + step), max(0, n - 1))
    app.room.remove_armed = None


def selected_seat(app: App) -> Seat | None:
    seats = _seats(app)
    if not seats:
        return None
    app.room.selected = min(app.room.selected, len(seats) - 1)
    return seats[app.room.selected]


def remove_selected(app: App) -> None:
    """Delete: arm the removal of the selected student; Delete again within a few seconds removes them."""
    seat = selected_seat(app)
    if seat is None:
        return
    room = app.room
    name = room.label(seat.name)
    if room.remove_armed is not None and room.remove_armed[0] == seat.number and app.clock_s < room.remove_armed[1]:
        room.remove_armed = None
        if app.server.remove(seat.number):
            app.say(f"removed {name}")
        return
    room.remove_armed = (seat.number, app.clock_s + REMOVE_CONFIRM_S)
    app.say(f"press Delete again to remove {name}")


def click(app: App, pos: tuple[int, int]) -> bool:
    """A click on the roster panel selects the row under it; True if the panel took the click."""
    room = app.room
    for number, rect in room.row_boxes:
        if rect.collidepoint(pos):
            numbers = [s.number for s in _seats(app)]
            if number in numbers:
                room.selected = numbers.index(number)
                room.remove_armed = None
            return True
    return room.panel_box is not None and room.panel_box.collidepoint(pos)
