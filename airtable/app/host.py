"""What a feature may use of the app (feature.py): the table, its clients, the window, the clock and a few verbs.

`App` is a `Host` by its shape alone and imports nothing of this module;
a feature names `Host` in its type hints instead of the app, so features
never import the app and the app's import of them makes no circle.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from airtable.app.aids_paint import AidsPainter
    from airtable.app.demo_loader import Demo, DemoError, DemoShelf
    from airtable.app.environment import Environment
    from airtable.app.overlays import Overlays
    from airtable.app.window import GameWindow
    from airtable.model.client import Client
    from airtable.physics.table import AirTable


class Host(Protocol):
    table: AirTable
    env: Environment
    window: GameWindow
    painter: AidsPainter  # places the labels of every aid, so they keep clear of each other
    overlays: Overlays
    clients: list[Client]  # index 0 is the local user
    local: Client
    server: object | None  # the GameServer, None without one (--no-server)
    shelf: DemoShelf
    demo_key: str  # the demo on the table
    error_key: str  # the demo whose start failed last
    variation: int
    build_error: DemoError | None
    goes_on: str | None  # after a failed start, the run that goes on on the table (None: it is empty)
    paused: bool
    clock_s: float  # time the app has run
    mouse_px: Sequence[float]

    @property
    def demos(self) -> dict[str, Demo]: ...
    @property
    def demo(self) -> Demo: ...
    @property
    def dt_s(self) -> float: ...

    def say(self, text: str, *, lasting: bool = False) -> None: ...
    def report(self, error: DemoError) -> None: ...
    def caption(self) -> str: ...
    def start_demo(self, key: str, variation: int = 0) -> None: ...
    def student_count(self) -> int: ...
    def physics_step(self) -> bool: ...
    def forget_after(self, t_s: float) -> None: ...
    def escape_features(self) -> bool: ...
    def quit_would_lose(self) -> list[str]: ...
    def stop(self) -> None: ...
