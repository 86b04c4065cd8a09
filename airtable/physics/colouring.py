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
_NONE = np.iinfo(np.uint64).max


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

    The new contacts are taken in passes: in each, those first by `priorities` (lowest first)
    among the remaining new contacts of both their bodies, which share no body, each take the
    first round free at both their bodies and after every round where one of them has a
    contact of a lower `band` (None: all in one band). Empty rounds are dropped.
    """
    new = np.flatnonzero(rounds < 0)
    if len(new) == 0:
        return _dense(rounds)
    band = np.zeros(len(rounds), dtype=np.int16) if band is None else band
    rounds = rounds.copy()
    taken = _taken(rounds, a, b, sink, band, new)
    while len(new):
        pick = _first_by_priority(new, a, b, sink, priorities(new, band))
        k = new.take(np.flatnonzero(pick))
        taken, r = _first_free(taken, a.take(k), b.take(k), band.take(k))
        rounds[k] = r
        taken[a.take(k), r] = taken[b.take(k), r] = band.take(k) + 1
        taken[sink] = 0
        new = new.take(np.flatnonzero(~pick))
    return _dense(rounds)


def _taken(rounds, a, b, sink: int, band, new: np.ndarray) -> np.ndarray:
    """(bodies, rounds + room) the band + 1 of each body's contact in each round (0: free), for
    the bodies of the `new` contacts (the others are not asked about)."""
    asked = np.zeros(sink + 1, dtype=bool)
    asked[a.take(new)] = asked[b.take(new)] = True
    asked[sink] = False
    old = np.flatnonzero((asked.take(a) | asked.take(b)) & (rounds >= 0))
    width = int(rounds.max()) + 9  # room for 8 more rounds, and more if they fill (_first_free)
    taken = np.zeros((sink + 1, width), dtype=np.int16)
    r, mark = rounds.take(old), band.take(old) + 1
    flat = taken.reshape(-1)  # a view: one-dimensional indices are cheaper than pairs of them
    flat[a.take(old) * width + r] = mark
    flat[b.take(old) * width + r] = mark
    taken[sink] = 0
    return taken


def _first_by_priority(new, a, b, sink: int, p) -> np.ndarray:
    """Which of the `new` contacts come first by their priorities p among the new contacts of both their bodies."""
    ra, rb = a.take(new), b.take(new)
    best = np.full(sink + 1, _NONE, dtype=np.uint64)
    np.minimum.at(best, ra, p)
    np.minimum.at(best, rb, p)
    best[sink] = 0  # the sink is never taken: a contact on it is first there
    return ((best.take(ra) == p) | (ra == sink)) & ((best.take(rb) == p) | (rb == sink))


def _first_free(taken, a, b, band) -> tuple[np.ndarray, np.ndarray]:
    """For contacts sharing no body: the first round free at both bodies and after their bodies'
    rounds of a lower band (widening `taken` if some have none); return taken and the rounds."""
    ta, tb = taken.take(a, axis=0), taken.take(b, axis=0)
    level = band[:, None]
    lower = ((ta > 0) & (ta <= level)) | ((tb > 0) & (tb <= level))
    width = taken.shape[1]
    after = np.where(lower.any(axis=1), width - np.argmax(lower[:, ::-1], axis=1), 0)
    free = (ta == 0) & (tb == 0) & (np.arange(width) >= after[:, None])
    if not free.any(axis=1).all():  # no room left in some row: twice as many rounds, and again
        wider = np.hstack([taken, np.zeros_like(taken)])
        return _first_free(wider, a, b, band)
    return taken, np.argmax(free, axis=1)


def _dense(rounds: np.ndarray) -> np.ndarray:
    """The rounds renumbered without the empty ones, in the same order."""
    used = np.bincount(rounds)
    if len(rounds) == 0 or used.all():
        return rounds
    return (np.cumsum(used > 0) - 1).take(rounds)
