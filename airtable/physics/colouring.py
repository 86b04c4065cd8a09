"""Rounds of contacts in which no puck appears twice, kept from step to step.

The contact stage (contacts.py) solves its contacts round by round: within a
round no puck appears twice, so a round is one numpy operation and still the
exact sequential result. Splitting the contacts into rounds is colouring the
graph whose nodes are the contacts and whose edges join contacts sharing a
puck; a round is a colour.

While a pile settles its contacts change a little every step (a few made, a
few broken, among two thousand). Colouring them all afresh each step cost as
much as solving them, so, as Box2D v3 keeps a contact's colour for as long as
the contact lasts, each contact keeps its round while it lasts (`keep`), and
only the new ones are fitted in (`fit`): each takes the first round where
neither of its pucks is taken yet. That is the greedy colouring, which needs
about 7 to 9 rounds in a hexagonal pile (a puck there has at most 6
neighbours), where choosing rounds by random priorities took 15.

A contact may also be given a band (a height in the pile): it then goes
after every contact of a lower band it shares a puck with, so that one sweep
over the rounds passes support from the floor up the pile (contacts.py).

Walls and sleeping pucks never move in the contact stage, so they may appear
in a round any number of times: the colouring sees them all as one body,
`sink`, that is never taken.
"""

from __future__ import annotations

import numpy as np

# Knuth's multiplicative hash: odd, so it maps 0 .. 2^32 - 1 onto themselves one to one.
_GOLDEN = np.uint64(0x9E3779B1)
_LOW_32 = np.uint64((1 << 32) - 1)


def priorities(contacts: np.ndarray, band: np.ndarray | None = None) -> np.ndarray:
    """A distinct priority for each of these contacts (indices; uint64, lowest first): by band, then
    scrambled, so that a row of contacts in key order does not take one round each."""
    prio = (contacts.astype(np.uint64) * _GOLDEN) & _LOW_32
    return prio if band is None else prio | (band.take(contacts).astype(np.uint64) << np.uint64(32))


def keep(rounds: np.ndarray, a: np.ndarray, b: np.ndarray, sink: int) -> np.ndarray:
    """The rounds still valid: -1 for a contact sharing a body other than `sink` with an earlier
    contact of its round (a sleeper woke: it is a body again). rounds: -1 for new contacts."""
    bodies = sink + 1
    row = (rounds + 1) * bodies  # row 0: the new contacts
    size = (int(rounds.max(initial=-1)) + 2) * bodies
    uses = np.bincount(np.concatenate([row + a, row + b]), minlength=size).reshape(-1, bodies)
    uses[0] = uses[:, sink] = 0
    if uses.max() <= 1:
        return rounds  # the common case, and cheap to tell: no body twice in a round
    old = np.flatnonzero(rounds >= 0)
    codes = np.concatenate([a.take(old), b.take(old)])
    real = np.flatnonzero(codes != sink)
    contact = np.concatenate([old, old]).take(real)
    codes = rounds.take(contact).astype(np.int64) * bodies + codes.take(real)
    order = np.argsort(codes, kind="stable")
    codes = codes.take(order)
    twice = np.flatnonzero(codes[1:] == codes[:-1])
    out = rounds.copy()
    out[contact.take(order).take(twice + 1)] = -1
    return out


def keep_order(rounds: np.ndarray, a: np.ndarray, b: np.ndarray, sink: int, band: np.ndarray, only=None) -> np.ndarray:
    """The rounds still in band order: -1 for a kept contact not after every round where one of its
    bodies has a contact of a lower band (its pucks moved to other bands since it was fitted in).

    only: a mask of the bodies to look at (sink's False), or None: all. The caller
    knows the order can be broken only at these (where contacts came or changed band).
    """
    old = np.flatnonzero(rounds >= 0)
    body = np.concatenate([a.take(old), b.take(old)])
    real = np.flatnonzero(body != sink) if only is None else np.flatnonzero(only.take(body))
    contact = np.concatenate([old, old]).take(real)
    body, level, r = body.take(real), band.take(contact).astype(np.int64), rounds.take(contact)
    order = np.argsort(body * (int(band.max()) + 1) + level)  # by body, then band
    body, level, r, contact = body.take(order), level.take(order), r.take(order), contact.take(order)
    # The latest round so far among each body's contacts by band (offset by body: none carries over).
    width = int(rounds.max()) + 2
    latest = np.maximum.accumulate(body * width + r)
    place = np.arange(len(body))
    starts = np.ones(len(body), dtype=bool)
    starts[1:] = (body[1:] != body[:-1]) | (level[1:] != level[:-1])
    first = np.maximum.accumulate(np.where(starts, place, 0))  # where each (body, band) group begins
    before = (first - 1).clip(0)
    lower = np.where((first > 0) & (body.take(before) == body), latest.take(before) - body * width, -1)
    late = contact.take(np.flatnonzero(lower >= r))
    if len(late) == 0:
        return rounds
    out = rounds.copy()
    out[late] = -1
    return out


def fit(rounds: np.ndarray, a: np.ndarray, b: np.ndarray, sink: int, band=None) -> np.ndarray:
    """Rounds for every contact: the kept ones (rounds >= 0) stay, the new ones (-1) are fitted in.

    The new contacts are taken one by one by `priorities` (lowest first); each takes the first
    round free at both its bodies and after every round where one of them has a contact of a
    lower `band` (None: all in one band). Empty rounds are dropped. (Taken in passes, each of the
    contacts first at both their bodies, all at once, gives the same rounds: a contact sees the
    same contacts before it. In a heap of pucks dropped on one spot, every puck touching every
    other, those passes cost the number of pucks times the contacts; this costs the contacts.)
    """
    new = np.flatnonzero(rounds < 0)
    if len(new) == 0:
        return _dense(rounds)
    band = np.zeros(len(rounds), dtype=np.int16) if band is None else band
    rounds = rounds.copy()
    new = new.take(np.argsort(priorities(new, band)))  # (distinct priorities: no ties)
    used, lower = _taken(rounds, a, b, sink, band, new)
    for k, x, y, level in zip(new.tolist(), a.take(new).tolist(), b.take(new).tolist(), band.take(new).tolist()):
        after = 0  # the first round after every round of a contact of a lower band at x or y
        for marks in (lower.get(x), lower.get(y)):
            for other, last in (marks or {}).items():
                if other < level and last >= after:
                    after = last + 1
        busy = used.get(x, 0) | used.get(y, 0) | ((1 << after) - 1)
        r = (~busy & (busy + 1)).bit_length() - 1  # the lowest round not busy
        rounds[k] = r
        _take(used, lower, sink, x, r, level)
        _take(used, lower, sink, y, r, level)
    return _dense(rounds)


def _taken(rounds, a, b, sink: int, band, new: np.ndarray) -> tuple[dict, dict]:
    """For the bodies of the `new` contacts (the others are not asked about) but the sink: each
    one's rounds taken by its kept contacts, as bits of a number, and the latest of them per band."""
    asked = np.zeros(sink + 1, dtype=bool)
    asked[a.take(new)] = asked[b.take(new)] = True
    asked[sink] = False
    old = np.flatnonzero((asked.take(a) | asked.take(b)) & (rounds >= 0))
    used: dict[int, int] = {}
    lower: dict[int, dict[int, int]] = {}
    bodies = np.concatenate([a.take(old), b.take(old)]).tolist()
    for body, r, level in zip(bodies, rounds.take(old).tolist() * 2, band.take(old).tolist() * 2, strict=True):
        _take(used, lower, sink, body, r, level)
    return used, lower


def _take(used: dict, lower: dict, sink: int, body: int, r: int, level: int) -> None:
    """Round r is taken at `body` by a contact of band `level` (the sink is never taken)."""
    if body != sink:
        used[body] = used.get(body, 0) | (1 << r)
        marks = lower.setdefault(body, {})
        marks[level] = max(marks.get(level, -1), r)


def _dense(rounds: np.ndarray) -> np.ndarray:
    """The rounds renumbered without the empty ones, in the same order."""
    used = np.bincount(rounds)
    if len(rounds) == 0 or used.all():
        return rounds
    return (np.cumsum(used > 0) - 1).take(rounds)
