"""Who may come in: per-address limits, the password brake and a quiet log.

Used by the server's network thread only. One computer (one address) may
hold only a few handshakes and a few seats at once, so one student cannot
fill the table. Connections from this computer itself (loopback) are the
teacher's own and are not limited unless `limit_loopback` is set. A class
behind one router shares one address: the teacher lets it in with
--per-address N, or with a password (whoever gives it is not limited per
address); the refusal says so to the student, the log and the projector.

Wrong passwords from an address earn a growing wait before the next guess
is even checked, then a lockout; the log gets one line per address, not one
per guess.
"""

from __future__ import annotations

import ipaddress
import logging
import time
from collections import Counter
from dataclasses import dataclass

HANDSHAKES_PER_ADDRESS = 4
PLAYERS_PER_ADDRESS = 3
FIRST_PASSWORD_WAIT_S = 1.0  # after the second wrong password in a row; doubles with each one (a typo costs nothing)
LOCKOUT_AFTER = 5  # wrong passwords in a row before the lockout
LOCKOUT_S = 60.0
SUMMARY_EVERY_S = 30.0
# How the teacher lets a whole class in from one address (a school's router, NAT).
ALLOW_A_CLASS = "start the table with --per-address 40, or with a --password (then the limit does not apply)"


def is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host.split("%")[0]).is_loopback
    except ValueError:
        return False


# The teacher's notice counts refused students by name up to this many per address.
MAX_NAMES_COUNTED = 1000


@dataclass
class _Guesses:
    wrong: int = 0
    next_try: float = 0.0  # no guess is checked before this time
    refused: int = 0  # guesses refused unchecked since the last log line


class Gate:
    """Per-address counts of handshakes and players, and wrong-password history."""

    def __init__(
        self,
        handshakes_per_address: int = HANDSHAKES_PER_ADDRESS,
        players_per_address: int = PLAYERS_PER_ADDRESS,
        limit_loopback: bool = False,
        password_wait_s: float = FIRST_PASSWORD_WAIT_S,
    ) -> None:
        self.password_wait_s = password_wait_s
        self.handshakes_per_address = handshakes_per_address
        self.players_per_address = players_per_address
        self.limit_loopback = limit_loopback
        self.handshakes: Counter[str] = Counter()
        self.players: Counter[str] = Counter()
        # The names refused a seat per address, for the teacher's notice: a refused window asks again every
        # few seconds, and each try counted as a student made three students read as 33 (a user test).
        self.turned_away: dict[str, set[str]] = {}
        self._guesses: dict[str, _Guesses] = {}
        self._open = 0

    def _limited(self, host: str) -> bool:
        return self.limit_loopback or not is_loopback(host)

    def handshake_refusal(self, host: str) -> str | None:
        """Why a new connection from `host` is refused, or None."""
        if self._limited(host) and self.handshakes[host] >= self.handshakes_per_address:
            return (
                f"your computer already has {self.handshakes[host]} connections joining at once; "
                "wait for them to finish and try again"
            )
        return None

    def seat_refusal(self, host: str, password_given: bool = False, name: str | None = None) -> str | None:
        """Why `host` may not take one more seat, or None.

        `password_given`: the student gave the table's password, which is the teacher's own
        door, so a class behind one router (one address to the server) may come in. `name`: the
        student's (None: none given), to count students, not tries."""
        if password_given or not self._limited(host) or self.players[host] < self.players_per_address:
            return None
        names = self.turned_away.setdefault(host, set())
        if len(names) < MAX_NAMES_COUNTED:  # (bounded: a flood of made-up names cannot grow it)
            names.add(name or "")
        return (
            f"{self.players[host]} windows from your address ({host}) play already, the most one address may "
            f"(a class behind one router counts as one computer); ask the teacher to {ALLOW_A_CLASS}"
        )

    def teacher_notice(self) -> str | None:
        """One line for the projector and the log while students are turned away per address, else None."""
        if not self.turned_away:
            return None
        host, names = max(self.turned_away.items(), key=lambda item: len(item[1]))
        # Nameless windows cannot be told apart (nor counted): then "students", no number.
        who = "students" if "" in names else f"{len(names)} student{'' if len(names) == 1 else 's'}"
        # Short enough for one line of a 4:3 projector's top band.
        return f"start with --per-address 40: {who} at {host} could not join (a class behind one router?)"

    @property
    def handshakes_open(self) -> int:
        """Handshakes under way, from every address."""
        return self._open

    def crowding(self, host: str) -> str | None:
        """When every handshake slot is taken: the address that should give one up for `host`, or None.

        The address holding the most handshakes, if it holds more than `host` would once let in:
        so one computer with many addresses cannot keep a newcomer out, and a newcomer's own
        handshake cannot be pushed out by an address that holds as few (see GameServer._admit)."""
        if not self.handshakes:
            return None
        crowded, most = self.handshakes.most_common(1)[0]
        return crowded if most > self.handshakes[host] + 1 else None

    def handshake_started(self, host: str) -> None:
        self.handshakes[host] += 1
        self._open += 1

    def handshake_ended(self, host: str, seated: bool) -> None:
        """A handshake finished: welcomed into a seat (`seated`) or dropped."""
        _down(self.handshakes, host)
        self._open -= 1
        if seated:
            self.players[host] += 1

    def seat_freed(self, host: str) -> None:
        _down(self.players, host)

    # ------------------------------------------------------------ passwords

    def password_wait(self, host: str, now: float) -> float:
        """Seconds before a password from `host` is checked again (0: check it now)."""
        guesses = self._guesses.get(host)
        if guesses is None or now >= guesses.next_try:
            return 0.0
        guesses.refused += 1
        return guesses.next_try - now

    def wrong_password(self, host: str, now: float, log: logging.Logger) -> None:
        guesses = self._guesses.setdefault(host, _Guesses())
        guesses.wrong += 1
        if guesses.wrong >= LOCKOUT_AFTER:
            guesses.next_try = now + LOCKOUT_S
            if guesses.wrong == LOCKOUT_AFTER:
                log.warning("%s gave %d wrong passwords: locked out for %g s", host, guesses.wrong, LOCKOUT_S)
        elif guesses.wrong > 1:
            guesses.next_try = now + self.password_wait_s * 2 ** (guesses.wrong - 2)
        else:  # the first costs no wait, and is remembered for LOCKOUT_S (forget_old_guesses) like the others
            guesses.next_try = now
            log.info("wrong password from %s", host)

    def right_password(self, host: str) -> None:
        self._guesses.pop(host, None)

    def forget_old_guesses(self, now: float, log: logging.Logger) -> None:
        """Drop addresses whose wait is long over; log what was refused meanwhile."""
        for host, guesses in list(self._guesses.items()):
            if guesses.refused and now >= guesses.next_try:
                log.info("%s tried to join %d more times while it had to wait", host, guesses.refused)
                guesses.refused = 0
            if now > guesses.next_try + LOCKOUT_S:
                del self._guesses[host]


def _down(counter: Counter[str], host: str) -> None:
    counter[host] -= 1
    if counter[host] <= 0:
        del counter[host]


class QuietLog:
    """Logs the first line of a kind at once, then one summary every SUMMARY_EVERY_S,
    so a flood of refusals cannot flood the teacher's log."""

    def __init__(self, log: logging.Logger) -> None:
        self.log = log
        self._seen: set[str] = set()  # the kinds logged this period
        self._held: Counter[str] = Counter()  # lines held back this period, by kind
        self._named: Counter[str] = Counter()  # kinds logged this period, by budget
        self._levels: dict[str, int] = {}
        self._since = time.monotonic()

    def note(
        self, kind: str, line: str, *args, level: int = logging.WARNING, budget: tuple[str, int] = ("", 0)
    ) -> None:
        """Log `line` if it is the first of `kind` this period, else count it for the summary.

        `budget` (group, most): kinds that share a group (the joins from one address, each student a
        kind) log at most `most` first lines a period; more kinds count toward the group's summary."""
        group, most = budget
        if kind not in self._seen and group and self._named[group] >= most:
            kind = group  # a flood of kinds (a script joining under ever new names): counted, never named
        elif kind not in self._seen:
            self.log.log(level, line, *args)
            self._seen.add(kind)
            self._named[group] += 1
            self._levels[kind] = level
            return
        self._levels.setdefault(kind, level)
        self._held[kind] += 1

    def flush(self, now: float) -> None:
        if now - self._since < SUMMARY_EVERY_S:
            return
        for kind, count in self._held.items():
            self.log.log(self._levels[kind], "%d more in %.0f s: %s", count, now - self._since, kind)
        self._seen.clear()
        self._held.clear()
        self._named.clear()
        self._levels.clear()
        self._since = now
