"""Rewind: the table's recent moments, bounded by bytes, and a view that can go back and forth through them (no pygame).

The app records the table after every frame in which it stepped
(`record`), as a physics.state.TableState: exact, so going back and running
on again gives the very same motion, at any restitution. Each state shares
with the one before it whatever did not change (masses, radii, springs,
colours, a still puck's position), so a moment costs about its positions and
velocities. The oldest moments go first once `budget_bytes` is reached: a
few pucks keep many minutes, ten thousand a few seconds, and no size ever
holds more than the budget. Measured (frames of 4 steps of 1/240 s, under
gravity): 10 pucks 2.5 kB a frame (30 s: 4.4 MB; 64 MB: about 7 minutes),
99 pucks 10.5 kB (30 s: 18.6 MB), 1000 pucks settling into a pile 122 kB
(8.8 s in 64 MB: the contact stage's warm start is most of it), 10000 pucks
about 330-480 kB (2 to 3.4 s).

While paused the view moves through the history (`back`, `forward`, by
frames or by seconds), restoring the table at each moment, so everything
that draws the table (the teacher's window, the students' snapshots) shows
that moment. `at` is where the view is; None means the newest moment, the
live table. `drop_future` makes the moment on view the newest: the app calls
it when the table runs on from the past.
"""

from __future__ import annotations

import bisect

from airtable.model.timeline import Timeline
from airtable.physics.state import TableState, capture, own_nbytes, restore, unchanged
from airtable.physics.table import AirTable

BUDGET_BYTES = 64 * 2**20  # 64 MB: the bound, whatever the number of pucks
# The list entries that hold a state, its cost and its time, beside the state itself.
ENTRY_OVERHEAD_BYTES = 3 * 8 + 2 * 32
# Simulated times are sums of steps: a second back from t = 2 s may be 0.9999999999 s.
TIME_SLACK_S = 1e-6


class History:
    """The table's latest states, at most `budget_bytes` of them, and the moment on view (`at`)."""

    def __init__(self, budget_bytes: int = BUDGET_BYTES) -> None:
        self.budget_bytes = int(budget_bytes)
        self.clear()

    def clear(self) -> None:
        self.states: list[TableState] = []
        self.costs: list[int] = []  # bytes each state adds beside the one before it
        self.times_s: list[float] = []
        self.nbytes = 0
        self.dropped = 0  # moments dropped to stay in budget since the last clear
        self.at: int | None = None

    def __len__(self) -> int:
        return len(self.states)

    @property
    def in_past(self) -> bool:
        """True while the view shows a moment older than the newest."""
        return self.at is not None

    @property
    def index(self) -> int:
        """The moment on view (the newest while live); -1 if nothing is kept."""
        return self.at if self.at is not None else len(self.states) - 1

    # ------------------------------------------------------------ keeping

    def record(self, table: AirTable) -> bool:
        """Keep the table as it is now as the newest moment; False if it had not changed (or while in the past)."""
        if self.at is not None:
            return False
        newest = self.states[-1] if self.states else None
        state = capture(table, like=newest)
        if newest is not None and unchanged(state, newest):
            return False
        cost = own_nbytes(state, newest) + ENTRY_OVERHEAD_BYTES
        self.states.append(state)
        self.costs.append(cost)
        self.times_s.append(state.time_s)
        self.nbytes += cost
        self._drop_oldest()
        return True

    def _drop_oldest(self) -> None:
        """Drop the oldest moments until the history fits its budget (all of them, if one moment is too big)."""
        drop = 0
        total = self.nbytes
        while drop < len(self.states) and total > self.budget_bytes:
            total -= self.costs[drop]
            drop += 1
            if drop < len(self.states):  # the new oldest shares with nobody now: it pays for all its parts
                full = own_nbytes(self.states[drop]) + ENTRY_OVERHEAD_BYTES
                total += full - self.costs[drop]
                self.costs[drop] = full
        if drop:
            del self.states[:drop], self.costs[:drop], self.times_s[:drop]
            self.nbytes = total
            self.dropped += drop

    def drop_future(self) -> int:
        """Forget the moments after the one on view, which becomes the newest; returns how many went."""
        if self.at is None:
            return 0
        keep = self.at + 1
        gone = len(self.states) - keep
        self.nbytes -= sum(self.costs[keep:])
        del self.states[keep:], self.costs[keep:], self.times_s[keep:]
        self.at = None
        return gone

    # ------------------------------------------------------------ moving the view

    def back(self, table: AirTable, frames: int = 1) -> bool:
        """Show the moment `frames` before the one on view; False if there is none older.

        Leaving the newest moment first keeps the table as it is (a change made
        while paused is part of the history, not lost)."""
        if self.at is None:
            self.record(table)
        return self._go(table, max(0, self.index - frames))

    def forward(self, table: AirTable, frames: int = 1) -> bool:
        """Show the moment `frames` after the one on view; False if the view is already the newest."""
        if self.at is None:
            return False
        return self._go(table, min(len(self.states) - 1, self.at + frames))

    def back_seconds(self, table: AirTable, seconds: float) -> bool:
        """Show the last moment at least `seconds` of simulated time before the one on view (or the oldest)."""
        if self.at is None:
            self.record(table)
        if not self.states:
            return False
        target = bisect.bisect_right(self.times_s, self.times_s[self.index] - seconds + TIME_SLACK_S) - 1
        return self._go(table, max(0, min(target, self.index - 1)))

    def forward_seconds(self, table: AirTable, seconds: float) -> bool:
        """Show the first moment at least `seconds` after the one on view (or the newest)."""
        if self.at is None:
            return False
        target = bisect.bisect_left(self.times_s, self.times_s[self.at] + seconds - TIME_SLACK_S)
        return self._go(table, min(len(self.states) - 1, max(target, self.at + 1)))

    def _go(self, table: AirTable, index: int) -> bool:
        if not self.states or index == self.index or index < 0:
            return False
        restore(table, self.states[index])
        self.at = None if index == len(self.states) - 1 else index
        return True

    # ------------------------------------------------------------ telling

    @property
    def span_s(self) -> float:
        """Simulated time from the oldest moment kept to the newest."""
        return self.times_s[-1] - self.times_s[0] if self.times_s else 0.0

    def timeline(self) -> Timeline | None:
        """Where the view is, for the timeline bar; None if nothing is kept."""
        if not self.states:
            return None
        return Timeline(self.times_s[0], self.times_s[-1], self.times_s[self.index], len(self.states), self.index)
