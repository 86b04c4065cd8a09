"""Held seats: a student who drops keeps their number and colour for a while.

When a student's connection ends without a goodbye (the Wi-Fi dropped, the lid was closed, the
server timed them out), their seat is held for HOLD_S: a newcomer gets the lowest number that is
neither taken nor held, nor a name a held seat's student had (a newcomer "Ann" is "Ann 2" while
Ann is away), and the student who comes back with the seat's token (identity.py) gets their own
number, name and colour again. A seat is given up by a goodbye or the teacher's removal,
and when its hold runs out. Owned by the server's network thread.
"""

from __future__ import annotations

from collections.abc import Container

HOLD_S = 150.0  # at least two minutes, as the classroom expects after a drop
MAX_HELD = 10_000  # bound on what is remembered, whatever the churn


class HeldSeats:
    """Seat numbers held for students who dropped, until a time (time.monotonic seconds)."""

    def __init__(self, hold_s: float = HOLD_S) -> None:
        self.hold_s = float(hold_s)
        self._until: dict[int, float] = {}
        self._names: dict[int, str] = {}  # the name each held seat's student had (as shown, without the label)

    def hold(self, number: int, now: float, name: str = "") -> None:
        """Keep seat `number` (and `name`, its student's) for its student until now + hold_s."""
        if len(self._until) >= MAX_HELD:
            self._forget_old(now)
            if len(self._until) >= MAX_HELD:
                self.give_back(min(self._until, key=self._until.__getitem__))
        self._until[number] = now + self.hold_s
        self._names[number] = name

    def give_back(self, number: int) -> None:
        """The seat is its student's again (or given up): no longer held."""
        self._until.pop(number, None)
        self._names.pop(number, None)

    def away(self, now: float) -> list[tuple[int, str, float]]:
        """(seat number, name, seconds since the drop) of each seat held now, lowest first."""
        self._forget_old(now)
        return [(n, self._names.get(n, ""), now - (self._until[n] - self.hold_s)) for n in sorted(self._until)]

    def is_held(self, number: int, now: float) -> bool:
        until = self._until.get(number)
        return until is not None and now < until

    def held(self, now: float) -> list[int]:
        """The numbers held now, lowest first."""
        self._forget_old(now)
        return sorted(self._until)

    def free_number(self, taken: Container[int], now: float) -> int:
        """The lowest seat number that is neither `taken` nor held (so numbers get reused)."""
        self._forget_old(now)
        number = 1
        while number in taken or number in self._until:
            number += 1
        return number

    def _forget_old(self, now: float) -> None:
        for number in [n for n, until in self._until.items() if now >= until]:
            self.give_back(number)
