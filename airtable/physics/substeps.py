"""Substeps: springs stiffer than a step can follow are integrated in shorter steps.

Semi-implicit Euler (v += F/m h, then x += v h) keeps a spring's energy with
no drift and no damping, and its period, as long as the step h resolves the
spring's vibration. A backward-Euler (implicit) step is stable at any
stiffness but damps every mode it takes, the slow ones too: a 5 x 5 lattice
whose slowest mode took 12 steps lost 74 % of it each period. So a step
whose springs are too stiff for it is cut into n substeps of h = dt / n,
each the whole force-and-integrate stage, with n the least that brings
every puck's springs within SUBSTEP_STIFFNESS (sum of k h^2 / m): then
omega h <= 0.5 for a pair, and it rings at its own period to 1 %.

While pucks with such springs press on each other (a jelly tangled by a yank,
pucks that springs squeeze together), the substeps are pieces of the whole
step instead (`for_contacts`): each piece finds and holds its contacts. With
the contacts held once after n substeps of the springs, a step's positions
had come a path its end velocity does not tell, and the contact stage's
velocity change and overlap push, worked out for one plain step, did work
against the springs every step: a yanked jelly went from 150 to 1000 J in 5 s
and pucks squeezed by springs without dampers gained up to 27 times their
energy. Pieces cost the whole loop each (a jelly piece about 1 ms), so a jelly
that only rests on a wall keeps the cheaper substeps (in 48 yanks of the
three jellies, some left on the floor, none gained energy). A puck coming
at a wall faster than LANDING_MPS within the step cuts it into pieces too:
resolved once after the substeps, a stiff jelly's landing read 15 % more
energy than it started with.

Springs that would need more than MAX_SUBSTEPS get none: the step takes
what is beyond its explicit budget implicitly, as before (forces.py,
implicit.py), stable for any k but damped, and the table says so once.
(Substeps with an implicit part left in them rang on: a stiff jelly landing
threw single pucks at 2.5 times its speed.)

A step is also cut into pieces, each a whole step of dt / n, where in two-step or
"off" more than a few pucks move FAST_FRACTION of their radius (events.py) in it:
a gas stirred hot by a cursor string. The hit stage resolves each fast puck's hits
one by one in Python (some 40 microseconds a puck), while a piece of the step costs
what a step of the crowd in numpy costs: in a 2000-puck gas eight times as hot as
it starts, 21.6 ms a step whole against 4.0 ms in three pieces. `pieces` gives the
fewest in which at most FAST_SHARE of the pucks (and no fewer than FEW_FAST) are
fast. In perfect kiss every hit is found in order whatever the step: no pieces.
"""

from __future__ import annotations

import math

import numpy as np

from airtable.physics import broadphase, collision, vectors
from airtable.physics.events import FAST_FRACTION

# Per puck, the sum of k h^2 / m each substep may take explicitly: a pair of equal
# pucks then has omega h = sqrt(2 k h^2 / m) <= 0.5, and semi-implicit Euler's
# period, 2 pi / omega times (omega h / 2) / asin(omega h / 2), is within 1.1 %.
SUBSTEP_STIFFNESS = 0.125
# At most this many substeps a step: a 5 x 5 lattice 100 times beyond the explicit limit needs 20, a chain
# 1000 times beyond it 64 (at 32 its slowest mode, 1.3 steps a period at dt 1/30, kept an eighth of its
# swing a period in the implicit step). A substep costs 50-80 us on a small table: 64 of them 3-5 ms.
MAX_SUBSTEPS = 64


def count(mass: np.ndarray, a: np.ndarray, b: np.ndarray, k: np.ndarray, dt_s: float) -> int:
    """How many substeps a step of dt_s needs for springs k (N/m) joining pucks a and b (mass in kg)."""
    if len(k) == 0:
        return 1
    per_puck = np.bincount(a, k, len(mass)) + np.bincount(b, k, len(mass))
    load = float((per_puck / mass).max()) * dt_s * dt_s / SUBSTEP_STIFFNESS
    if not 1.0 < load <= MAX_SUBSTEPS * MAX_SUBSTEPS:  # also NaN and inf: no substeps
        return 1
    return math.ceil(math.sqrt(load) * (1.0 - 1e-12))


# A puck on springs meeting a wall faster than this (m/s) lands (a jelly dropped): the step is cut into
# pieces for it, where a resting one keeps the substeps. Resting contacts press slower (resting.py's 0.2).
LANDING_MPS = 0.5


def for_contacts(table, dt_s: float) -> int:
    """Into how many pieces a step of dt_s is cut for its springs' substeps (see the module docstring):
    `count`'s substeps if pucks on springs may meet (MEETING_PIECES times as many where their springs bend their
    paths), the contact stage held a pair last step or a puck is landing on a wall, else 1."""
    if table.n_springs == 0:
        return 1
    n = count(table.mass_kg, *table.spring_ends, table.spring_k_Npm, dt_s)
    if n == 1:
        return 1
    meeting, accel = _meeting(table, dt_s)
    if len(meeting) == 0:
        return n if table.contact_solver.held_pairs() or _hits_a_wall(table, dt_s) else 1
    bend = accel.take(meeting) * (0.5 * (dt_s / n) ** 2)  # how far a substep's springs bend their paths
    if (bend > BEND_SHARE * table.radius_m.take(meeting)).any():
        return min(MAX_SUBSTEPS, MEETING_PIECES * n)
    return n


# Where pucks on springs may meet and a substep's springs bend their paths by more than BEND_SHARE of their radius
# (a h^2 / 2), each substep is cut into MEETING_PIECES pieces: a piece's hits are found on straight paths. Two 14 g
# pucks pulled together by a 4700 N/m spring, in pieces of a substep (bent 18 mm, 15 % of their radius), met where
# their paths did not, each hit doing tens of joules of work for or against the spring: 40 times their energy in
# 2 s (by hand: none); in four, at most 1.05 times. (Pieces as many as the pull at the moment asked, 25 to 29, lost
# the energy's bound: 9 times; a step's length that changes with it is no longer one step of one scheme.) The
# jellies, whose springs bend a substep's paths less, keep their substeps.
BEND_SHARE = 0.02
MEETING_PIECES = 4


def _meeting(table, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(the pucks on springs that may reach another puck within the step, by their speed and what their
    springs pull now (a pull's dt^2 travel, twice over: the pull grows as the spring stretches), and those they
    may reach; each puck's acceleration by its springs at the most (m/s^2)). Substeps would carry them there and
    through, unseen: two 14 g pucks pulled together by a 3000 N/m spring flew through each other at 150 m/s."""
    if not table.puck_collisions:
        return np.empty(0, dtype=np.intp), np.empty(0)
    pos, a, b = table.pos_m, *table.spring_ends
    pull = table.spring_k_Npm * np.abs(table.spring_stretch_m())
    n = len(pos)
    accel = (np.bincount(a, pull, n) + np.bincount(b, pull, n)) / table.mass_kg  # (pulls may cancel: at the most)
    travel = vectors.lengths(table.vel_mps) * dt_s + accel * dt_s**2
    sprung = np.unique(np.concatenate((a, b)))
    i, j = broadphase.pairs_near(pos, table.radius_m, sprung, 2.0 * float(travel.take(sprung).max()))
    gap = vectors.lengths(pos[i] - pos[j]) - table.radius_m[i] - table.radius_m[j]
    meet = np.flatnonzero(gap < travel[i] + travel[j])
    return np.concatenate([i.take(meet), j.take(meet)]), accel


def _hits_a_wall(table, dt_s: float) -> bool:
    """Whether a puck coming at a wall faster than LANDING_MPS may reach it within the step."""
    for room, away in collision.each_wall(table.pos_m, table.vel_mps, table.radius_m, table.size_m):
        if ((-away > LANDING_MPS) & (room < -away * dt_s)).any():
            return True
    return False


# A step is cut into pieces when more of its pucks than this share of them (and than FEW_FAST) are fast.
FAST_SHARE = 0.005
FEW_FAST = 10
# At most this many pieces a step: a table of pucks at hundreds of metres a second is left to the hit stage.
MAX_PIECES = 8


def pieces(vel: np.ndarray, radius: np.ndarray, dt_s: float, mode: str) -> int:
    """Into how many pieces of dt_s / n a step of pucks at velocities `vel` (N, 2; m/s) and radii `radius`
    (m) is cut (see the module docstring): the fewest in which at most FAST_SHARE of them, or FEW_FAST,
    move FAST_FRACTION of their radius; 1 in perfect kiss, and up to MAX_PIECES."""
    allowed = max(FEW_FAST, int(FAST_SHARE * len(radius)))
    if mode not in ("two-step", "off") or len(radius) <= allowed or not dt_s > 0.0:
        return 1  # (a step of 0 moves nothing: nothing is fast)
    with np.errstate(over="ignore"):  # (a runaway speed: inf, taken as fast; integrate.py slows it)
        speed_sq = vectors.squared_lengths(vel)
    limit = FAST_FRACTION * float(radius.min()) / dt_s
    if not float(speed_sq.max()) > limit * limit:  # the fastest is not fast for the smallest: the usual case
        return 1
    # In n pieces a puck is fast where it moves FAST_FRACTION of its radius n times in the whole step.
    times_sq = speed_sq / (radius * radius) * (dt_s / FAST_FRACTION) ** 2
    if np.count_nonzero(times_sq >= 1.0) <= allowed:  # a few fast ones: the hit stage's
        return 1
    at = len(times_sq) - 1 - allowed
    most = math.sqrt(float(np.partition(times_sq, at)[at]))  # the (allowed + 1)th most
    if not most >= 1.0:  # (also NaN)
        return 1
    return MAX_PIECES if most >= MAX_PIECES else math.floor(most) + 1  # (inf: MAX_PIECES)
