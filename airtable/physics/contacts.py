"""Resting contact: pucks that press on each other or on a wall, solved together.

A collision is an event: two pucks meet fast, bounce, and part (pairs.py).
A resting contact is a state: a puck in a pile presses on its neighbours and
on the floor step after step, approaching them each step only by what the
step's forces added (g dt under gravity). Bouncing those contacts one at a
time never lets support travel up a stack, so they get a stage of their own,
after the collisions, in which walls and puck pairs take part together.

Which contacts: pairs and puck-wall contacts that touch or nearly touch
(gap under a margin: MARGIN_M plus as far as the stage may move a puck,
and HOLD_M more for last step's contacts) and approach slower than the
rest speed over the restitution, and pairs that pressed on each other in
the last step, whatever their speed (up to HELD_MPS). Pairs that approach
faster are collisions (they keep the course's model: the hit stage's, or the
next step's; at restitution 0 no contact is: see rest_speeds.py), but they
take part too, so that the stage never drives them into each other: where it
stops one puck of such a pair, the other must not run into it. Each contact k
has a normal n (from body b to body a; a wall is a body that never moves) and
asks:

* velocity: the relative normal velocity vn after the stage is at least
  its least speed (0 for pucks already touching: no bounce; for a pair still
  a gap s apart, -s / dt: it may close the gap, not more: _least_speeds);
* position: a separate pseudo-velocity (a "split impulse") pushes out a
  fraction POSITION_FRACTION of the overlap beyond SLOP_M per step (into a
  wall, all beyond WALL_LEFT_M). It moves positions only and never enters the
  velocities, so correcting overlap feeds no energy into the motion.

Both are solved by sequential impulses (Erin Catto's; Box2D and Chipmunk
solve contacts this way): each contact's impulse is accumulated over the
iterations and clamped at zero (contacts push, never pull); a contact's
impulse from the last step is applied first ("warm starting"), so a pile at
rest starts from the answer. The contacts are coloured into rounds in which
no puck appears twice, so each round is one numpy operation and still the
exact sequential result; a contact keeps its round while it lasts, and new
ones are fitted in (colouring.py), as Box2D v3 keeps a contact's colour. The
iterations after the first are sped up as conjugate gradients speed up plain
ones (_iterate), and a small group of contacts gets as many as ITERATION_WORK
pays for: a stack landing settles within its step.

Up to EXACT_MAX contacts the problem is instead solved exactly (collapse.py);
beyond, where the iterations leave a contact off its bound, their answer is
carried to the end by conjugate gradients that keep every impulse a push
(proportioning.py): a slab of hundreds of pucks landing, whose chains of
contacts the iterations pass a push along only a link or so at a time.

Order of the step: positions have already moved with the velocities when
this stage runs, so a velocity change dv also moves the puck by dv dt: the
stage gives the same result as solving contacts before the position update.

Where the contacts are: where the step began (pos - vel dt), as Box2D finds
its speculative contacts before it moves the bodies. Their normals and gaps
are then the ones the velocities act across; taken where the free motion
ends, a pair landing fast is found deep inside each other, with a normal
turned by as much: solved along it, a restitution-0 pile sank millimetres
into itself (30 mm at dt 1/60), and pushing that overlap out again raised
pucks and the pile's energy. A puck an earlier stage bounced did not begin
its present path anywhere real: its contacts are taken where the step ends,
at the gap it had if it approached.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from airtable.physics import collapse, collision, colouring, proportioning, vectors
from airtable.physics.rest_speeds import still_held

# Iterations over all contacts per step (Box2D and pymunk use about ten);
# the loop stops early once an iteration changes no velocity by CONVERGED_MPS.
ITERATIONS = 10
# A step may spend about this many contact-iterations before it stops unconverged,
# and at most MAX_ITERATIONS: a group of contacts too many to solve exactly (a heap of a hundred
# pucks) gets as many iterations as its chains need (a 101-puck heap's 310 contacts, dropped at dt
# 1/60: at 25 iterations its pucks sank 4.5 mm into each other, at 70 1.3 mm), and a pile of 2200
# contacts or more its ITERATIONS (an 800-puck pile settling has 1000 to 2300 awake ones: more
# iterations there cost more than they show).
ITERATION_WORK = 22_000
MAX_ITERATIONS = 200
# A step whose iterations would still let a contact close more than DEEPEST_M (m) past its bound
# iterates on, while it does, up to DEEP_WORK contact-iterations (and MAX_ITERATIONS): a slab of
# 300 pucks thrown down at 3 m/s (1634 contacts, dt 1/60) sank 12 mm into itself in the step it
# landed with its planned 13 iterations, 0.5 mm with 122. An 800-puck pile dropped iterates 70 %
# more while it lands (0.5-1 s), and 0.6 % more while it settles (1.5-2 s: 0.07 mm off, mostly).
DEEPEST_M = 2.5e-4
DEEP_WORK = 200_000
# ... looking how deep every this many iterations (a look costs about a fifth of an iteration).
DEEP_CHECKS = 5
# Up to this many contacts (a stack, a slab, a heap of fifty pucks) are solved exactly, at once
# (collapse.solve: the complementarity problem by active sets), not by sequential impulses, whose
# chains converge as slowly as the masses along them differ: a stack with masses 1 to 1e5 upward,
# dropped at restitution 0, crushed its bottom pucks into each other and jumped up (a user test);
# a 29-puck heap's small puck, wedged on the floor between two bigger ones at 2 m/s, still sank 4 mm
# into them after 135 iterations over its 59 contacts, and an 80-puck heap 5.6 mm after 50 over its
# 160; a 10 x 10 slab of masses three decades apart, thrown down (190 contacts), sank 23 mm and its
# pucks leapt up at 1.8 m/s, in 54 ms a step. Up to here the exact solve costs what the iterations
# do, or less (that slab: 3 ms a step, landing dead; heaps of 75 to 100 pucks, 180 to 330 contacts:
# 4 to 18 ms a step against 7 to 24). Beyond 160 contacts it takes only block pivoting's TRIES
# (collapse.solve, safe=False: its LU solves grow as the cube of the contacts, and the safe pivoting's
# hundred of them cost 0.2 to 0.7 s on a few hundred dependent contacts, as where a pile falls asleep
# around its last awake pucks); heaps settle so in 98 to 100 % of their steps. If the pivoting does
# not settle, the step takes the iterations.
EXACT_MAX = 400
SAFE_MAX = 160
# ... and beyond, up to EXACT_MAX, where the masses of the pucks these contacts touch differ more than this many
# times: there the iterations, which the step falls back to, converge as slowly as the masses differ (random
# square slabs of 100-200 pucks, masses over three or six decades, thrown down: 3 of 24 sank 6-228 mm and threw
# pucks up at up to 57 m/s; with the safe pivoting, all land dead, their worst step 44 ms).
SAFE_MASS_RATIO = 100.0
# After the exact solve did not settle, this many steps go straight to the iterations: the same
# contacts do not settle the next step either (where an 800-puck pile falls asleep around its last
# awake pucks, 41 of 43 exact solves in a second did not, at 50 to 180 ms each).
EXACT_PAUSE = 60
# Where the iterations (more than EXACT_MAX contacts, or the exact solve paused) leave a contact off
# its bound by more than POLISH_MPS (m/s), or the last step was solved to the end, their answer is
# polished, up to POLISH_MAX contacts (a 20 x 20 slab landing has 1500: left to them, it sank 0.2-0.4 mm into
# itself, and pushing that out raised its energy and tipped it over within 0.3 s); up to LEAP_MAX, only where
# they leave a contact off by LEAP_MPS (a puck leaping or sinking: a slab landing) or one sinking DEEPEST_M (an
# 800-puck pile settling has 2100 to 2300 contacts, which they leave up to 0.16 m/s off, and polishing those
# doubled its step), or off by POLISH_MPS where a landing kept them going past their plan (_planned_iterations;
# unless paused: a 22 x 24 slab landing, 2020 contacts 1.5 cm/s off, had its columns left 0.12 mm apart in height,
# and tipped over within 0.2 s, a puck thrown up at 92 mm/s). A polish is, in turn:
# QUICK_STEPS of proportioning.solve from their answer or the last step's (a slab at rest settles in one or
# two: block pivoting first cost 0.1 to 0.6 s a step on a 20 x 20 slab at rest, 780 contacts); block pivoting
# from the contacts they have pushing, where it costs little (EXACT_MAX) or the masses differ (SAFE_MASS_RATIO,
# up to PIVOT_MAX: there proportioning converges as slowly as they differ, and on a slab of rows of 1 g and
# 1000 kg its answers, near but not exact, led the next step's iterations to diverge); then proportioning to
# POLISH_TOL_MPS in at most POLISH_STEPS steps and POLISH_WORK contact-steps, or LEAP_WORK where they leap or
# the last step was solved to the end (a square slab of 25 x 25 pucks landing took 500 to 1700 steps, three
# steps running, then one a step). Where that does not settle, its answer if it leaves the contacts nearer
# their bounds than theirs; if it does not, the iterations go on, and the polish pauses (EXACT_PAUSE) but for
# leaps. Square slabs of 200 to 340 pucks thrown down (600 to 1100 contacts as they land: each puck's diagonal
# neighbours are within the margin) threw top pucks up at up to 2.8 m/s from the iterations' answer; 22 x 22
# and 25 x 25 ones (1800 to 2400 contacts) at 0.3 to 1.6 m/s, sinking 3 to 8 mm: polished, they land dead.
POLISH_MPS = 1e-4
POLISH_TOL_MPS = 1e-6
NEAR_MPS = 1e-5
POLISH_MAX = 2000
PIVOT_MAX = 1000
POLISH_STEPS = 2000
QUICK_STEPS = 60
POLISH_WORK = 300_000
LEAP_MPS = 0.3
LEAP_MAX = 4000
LEAP_WORK = 4_000_000
CONVERGED_MPS = 1e-7
# ... and where their answer gains kinetic energy, more than this share of what the pucks came with
# (_gains_energy: the answer never does; a hexagonal slab of masses three decades apart, collapsing at dt 1/240,
# gained 4e-5 of its whole energy in a step from the iterations, the polish paused).
GAIN_SHARE = 1e-9
# ... and where it sinks a contact further, to overlap deeper than this (m) at the step's end: its pseudo-velocities
# do not converge either (a hexagonal slab of masses three decades apart, collapsing, sank 2.4 mm into itself over
# the polish's pause; polishing every step instead took 8 times as long).
LEFT_DEEP_M = 5e-4
# The first iteration's rounds go bottom-up by horizontal bands this many
# radii high (a contact after its pucks' contacts of lower bands): support from
# the floor then travels up a pile within one iteration. The later iterations
# only refine that answer and take the fewer rounds of a colouring in no order
# (9 against about 19 on an 800-puck pile settling, each round costing numpy's fixed
# price). Bands of one contact each would be exact Gauss-Seidel from the bottom
# but need a round per contact of the tallest stack; random order alone is as
# cheap as these bands, and a 300-puck pile then keeps 3x the jitter.
BAND_RADII = 8.0
# Each step its contacts change, the band rounds are checked for order (a contact after its pucks'
# contacts of lower bands: pucks move between bands) and the ones out of order fitted in again, up
# to this many times (each refitted contact may put one above it out of order; the rest wait).
BAND_PASSES = 3
# Contacts are the pairs closer than their reach plus this (m), plus as far
# as this stage may move a puck in the step: a contact left out here is one
# the stage can push a puck into (it is speculative: a gap may close, not more).
MARGIN_M = 1e-3
# A pair that was a contact in the last step stays one until it is this much (m) further apart than
# the margin. The margin follows the fastest puck on the table and swings between 5 and 19 mm from
# step to step in an 800-puck pile settling: without this the pairs at its edge came and went, a
# third of the steps' new rounds and layouts for nothing (such a contact has a gap: all it can do
# is keep the pair from closing more than that gap within the step).
HOLD_M = 0.02
# Overlap left alone (m), so contacts stay touching from step to step.
SLOP_M = 2e-5
# Share of the overlap beyond the slop pushed out per step.
POSITION_FRACTION = 0.4
# ... but into a wall, all beyond this (m): the wall stage after this one (walls.again) puts the puck back on the
# wall anyway, and pushed out here the pucks resting on it move with it instead of it into them (a light puck struck
# down onto a heavy one on the floor drove it 1.7 mm into the floor, and the wall stage then 1 mm into the light
# one). (Not all: a settling pile's floor contacts, pushed out at once, made its steps twice as long.)
WALL_LEFT_M = 5e-4
MAX_PUSH_MPS = 0.5
WALL_NORMALS = np.array(collision.WALL_NORMALS)  # (an array: taken per contact)


def margin_m(vel: np.ndarray, dt: float) -> float:
    """How far apart (m) a pair or a puck and a wall may be where the step began and still be a contact:
    MARGIN_M, plus as far as this stage may move two pucks towards each other in the step."""
    return MARGIN_M + (2.0 * float(np.abs(vel).max()) + MAX_PUSH_MPS) * dt


@dataclass
class _Contacts:
    """The contacts of one step: body a, body b (the row count for a wall), normal n from b to a."""

    a: np.ndarray
    b: np.ndarray
    n: np.ndarray  # complex unit normals
    gap: np.ndarray  # m, negative: overlap
    least: np.ndarray  # m/s: the least relative normal velocity after the stage (_least_speeds)
    left: np.ndarray  # m: the most overlap the stage leaves in a step (inf: pairs; WALL_LEFT_M: walls)
    collides: np.ndarray  # bool: a collision (approaching faster than it rests), not a resting contact
    keys: np.ndarray  # one integer per contact, the same from step to step


_FIELDS = tuple(_Contacts.__dataclass_fields__)


def _pair_contacts(pos, vel, radius, size_m, ci, cj, reach, rest, held, margin, dt: float, kept=None) -> _Contacts:
    """The candidate pairs that touch (within margin) and approach slower than their rest speed;
    and those of `kept` (last step's contacts) within HOLD_M more. Pairs that pass each other are
    taken where they pass (_passing)."""
    d = vectors.take(pos, ci) - vectors.take(pos, cj)
    lim = reach + margin
    squared = vectors.squared_lengths(d)
    near = squared < lim * lim
    if kept is not None:
        hold = lim + HOLD_M
        maybe = np.flatnonzero((squared < hold * hold) & ~near)
        near[maybe] = kept(ci.take(maybe), cj.take(maybe))
    near = np.flatnonzero(near)
    if len(near) == 0:  # (most steps of a few pucks: none of the work below)
        return _no_contacts()
    i, j = ci.take(near), cj.take(near)
    d, w, reach = vectors.take(d, near), vectors.take(vel, i) - vectors.take(vel, j), reach.take(near)
    n, dist = vectors.unit_vectors(d, i + j)
    gap = dist - reach
    k, n_near, gap_near = _passing(d, gap, reach, dt, _Paths(pos, vel, radius, size_m, i, j))
    if len(k):  # (a pair that pressed in the last step is a resting contact: where the step began)
        free = np.flatnonzero(~held(i.take(k), j.take(k)))
        n[k.take(free)], gap[k.take(free)] = vectors.take(n_near, free), gap_near.take(free)
    vn = vectors.dot_rows(w, n)
    fast = np.flatnonzero(vn < -rest.pairs(i, j, vectors.as_complex(np.ascontiguousarray(n))))
    collides = np.zeros(len(i), dtype=bool)
    collides[fast] = ~still_held(held(i.take(fast), j.take(fast)), -vn.take(fast))  # (few, even in a pile)
    nc = vectors.as_complex(n)
    keys = i.astype(np.int64) * (len(pos) + 4) + j
    return _Contacts(i, j, nc, gap, np.zeros(len(i)), np.full(len(i), np.inf), collides, keys)


class _Paths:
    """The straight paths through the step of the pairs (i, j), from `pos` at `vel`, up to the first wall each meets:
    less what would take a puck into a wall it is on where the step begins (a puck resting on the floor: its step's
    fall)."""

    def __init__(self, pos, vel, radius, size_m, i: np.ndarray, j: np.ndarray) -> None:
        self.pos, self.radius, self.size_m, self.i, self.j = pos, radius, size_m, i, j
        self.vel_i, self.vel_j = self._along_walls(vel, i), self._along_walls(vel, j)
        self.w = self.vel_i - self.vel_j

    def _along_walls(self, vel, rows: np.ndarray) -> np.ndarray:
        x, v, r = vectors.take(self.pos, rows), vectors.take(vel, rows).copy(), self.radius.take(rows)[:, None]
        v[((x - r <= SLOP_M) & (v < 0.0)) | ((self.size_m - r - x <= SLOP_M) & (v > 0.0))] = 0.0
        return v

    def at_a_wall(self, k: np.ndarray) -> np.ndarray:
        """When either puck of each pair k first reaches a wall on its path (s; inf: never): there it stops."""
        t = np.full(len(k), np.inf)
        for rows, v in ((self.i.take(k), self.vel_i), (self.j.take(k), self.vel_j)):
            x, vk, r = vectors.take(self.pos, rows), vectors.take(v, k), self.radius.take(rows)[:, None]
            room = np.where(vk < 0.0, x - r, self.size_m - r - x)
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.minimum(t, np.where(vk != 0.0, np.maximum(room, 0.0) / np.abs(vk), np.inf).min(axis=1))
        return t


def _passing(d: np.ndarray, gap: np.ndarray, reach: np.ndarray, dt: float, paths: _Paths):
    """(k, n, gap) of the pairs d apart (rows, from b to a) where the step begins, `gap` apart, whose straight
    paths (_Paths) pass each other in the step without touching: their rows k, and the normal and gap at their
    closest approach.

    A contact asks n . w >= -gap / dt (it may close its gap, not more), which keeps a pair apart along straight
    paths for any normal n with n . d >= reach (then n . (d + w t) >= reach up to t = dt). The normal where the
    step begins asks the most: a puck falling past another 1 mm away at 6 m/s, dt 1/60, was pushed sideways at
    0.57 m/s though they never touch. Along the normal at their closest approach they ask nothing (n . w = 0
    there) unless something else drives them together. Pairs within SLOP_M touch: theirs stay where the step
    began (a slab of rows of 1 g and 1000 kg, its neighbours 1e-16 m apart, exploded with them turned). A path ends
    at the first wall it meets, where the puck stops (a puck falling past one sliding on the floor was taken where
    its path, run on through the floor, passed closest: the normal pointed up, and lifted the other at 0.44 m/s).
    """
    w = paths.w
    k = np.flatnonzero((gap > SLOP_M) & (vectors.dot_rows(d, w) < 0.0))  # apart and closing: closest ahead
    dk, wk = vectors.take(d, k), vectors.take(w, k)
    t = np.minimum(collision.closest_time_in_step(dk, wk, dt), paths.at_a_wall(k))
    closest, apart = vectors.unit_vectors(dk + wk * t[:, None])
    passing = np.flatnonzero(apart > reach.take(k))
    k, closest = k.take(passing), vectors.take(closest, passing)
    return k, closest, vectors.dot_rows(vectors.take(d, k), closest) - reach.take(k)


def _wall_contacts(pos, vel, radius, size_m, rest, margin) -> _Contacts:
    """The pucks within margin of a wall, moving into it slower than their rest speed (rest: (N, 2), per axis).
    Wall by wall (left, bottom, right, top: WALL_NORMALS'), each wall's pucks in row order."""
    room = np.stack(collision.wall_rooms(pos[:, 0], pos[:, 1], radius, size_m))  # (4, N)
    near = room < margin
    if not near.any():  # (most steps of a few pucks: none of the work below)
        return _no_contacts()
    vx, vy = vel[:, 0], vel[:, 1]
    away = np.stack((vx, vy, -vx, -vy))
    across = np.tile(rest.T, (2, 1))  # (4, N): each wall's axis, x, y, x, y
    fits = np.tile(~collision.wedged(radius, np.asarray(size_m)[:, None]), (2, 1))  # (wedged: neither wall holds it)
    w, a = np.nonzero(near & (away >= -across) & fits)
    count = len(pos)
    keys = a.astype(np.int64) * (count + 4) + count + w
    b = np.full(len(a), count)
    walls = (WALL_NORMALS.take(w), room[w, a], np.zeros(len(a)), np.full(len(a), WALL_LEFT_M), np.zeros(len(a), bool))
    return _Contacts(a, b, *walls, keys)


def _no_contacts() -> _Contacts:
    """No contact: each field empty, of its type."""
    none = np.empty(0, dtype=np.intp)
    return _Contacts(none, none, np.empty(0, dtype=complex), *([np.empty(0)] * 3), np.empty(0, dtype=bool), none)


def _may_rest(i: np.ndarray, j: np.ndarray, asleep: np.ndarray | None, pressed: np.ndarray | None):
    """Which of the pairs (i, j) may be contacts (indices; None: all of them): not both asleep (to the
    awake a sleeper is immovable, and sleepers rest as they are), and one pressed by the forces
    (RestSpeeds.pressed: of two pucks nothing presses, a touch is a collision). A puck and a wall: i = j."""
    keep = None if asleep is None else ~(asleep.take(i) & asleep.take(j))
    if pressed is not None:
        some = pressed.take(i) | pressed.take(j)
        keep = some if keep is None else keep & some
    return None if keep is None else np.flatnonzero(keep)


class _Round(NamedTuple):
    """One round's contacts: views into its _Layout's buffers; targets and impulses as (m, 2) [velocity, position].
    (A tuple: quicker to make and to unpack in each sweep than an object's fields to look up.)"""

    fab: np.ndarray  # (2, m, 2) flat indices of body a's velocity and pseudo-velocity (2 a, 2 a + 1), then b's
    knc: np.ndarray  # (m, 2) complex conjugate normals times the effective mass k = 1 / (wa + wb)
    nab: np.ndarray  # (2, m, 2) complex: the velocity change of body a per unit impulse, and minus body b's
    kt: np.ndarray  # (m, 2) k times the target: least relative normal velocity, and pseudo-velocity
    change: np.ndarray  # (m, 2) minus the last iteration's change of impulse
    impulse: np.ndarray  # (m, 2) accumulated, >= 0


class ContactSolver:
    """The contact stage, with the impulses it keeps from step to step for warm starting."""

    def __init__(self) -> None:
        self._keys = np.empty(0, dtype=np.int64)  # sorted
        self._impulses = np.empty((0, 2))
        self._resting = np.empty(0, dtype=bool)  # (by _keys) which contacts were resting ones, not collisions
        self._rows = -1
        # Each contact's round (colouring.py), by _keys: bottom-up by bands for the first
        # iteration, and in no order (fewer rounds) for the later ones.
        self._band_rounds = np.empty(0, dtype=np.intp)
        self._free_rounds = np.empty(0, dtype=np.intp)
        self._key_order = np.empty(0, dtype=np.intp)  # this step's contacts in key order
        self._layouts: _Colouring | None = None  # the last step's contacts, rounds and their layouts
        self._wall_rest: tuple | None = None  # (rest, _impulses, answer) of the last wall_rest
        self._held_walls: tuple | None = None  # (_impulses, rows, axes) of the pucks pressed on a wall
        self.count = 0  # contacts in the last step
        self.iterations = 0  # iterations the last step needed
        self._paused = 0  # steps left that skip the exact solve (EXACT_PAUSE)
        self._polish_paused = 0  # steps left that skip the polish (EXACT_PAUSE)
        self._exact = False  # whether the last step's contacts were solved to the end (exactly, or polished)

    def held(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Which pairs (i, j) pressed on each other in the last step (a resting contact's non-zero impulse).

        Such a pair is a resting contact whatever its approach speed (up to HELD_MPS): a pile
        whose contacts have not quite converged must not start to bounce.
        """
        found, kept = self._last_step(i, j)
        if len(self._keys) == 0:
            return kept
        return kept & self._resting.take(found) & (self._impulses[found, 0] > 0.0)

    def kept(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Which pairs (i, j) were contacts in the last step."""
        return self._last_step(i, j)[1]

    def _last_step(self, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(where each pair (i, j) is or would be among the last step's contacts, whether it is one)."""
        return self._find(i.astype(np.int64) * (self._rows + 4) + j)

    def _find(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(where each contact of `keys` is or would be among the last step's contacts, whether it is one)."""
        if len(self._keys) == 0 or len(keys) == 0:
            return np.zeros(len(keys), dtype=np.intp), np.zeros(len(keys), dtype=bool)
        found = np.searchsorted(self._keys, keys).clip(0, len(self._keys) - 1)
        return found, self._keys.take(found) == keys

    def piled(self, n: int) -> np.ndarray | None:
        """(n,) which pucks were in a contact with another puck in the last step (None: none were, or the
        rows changed): pucks in a pile, pressed every way by their neighbours (rest_speeds.py)."""
        if self._rows != n:
            return None
        i, j = self._puck_pairs()
        if len(i) == 0:
            return None
        out = np.zeros(n, dtype=bool)
        out[i] = out[j] = True
        return out

    def pressing(self) -> bool:
        """Whether any contact of the last step pressed (a non-zero impulse, which the next step starts from)."""
        return bool(self._impulses.any())

    def held_pairs(self) -> bool:
        """Whether the last step held two pucks against each other (not only pucks on walls)."""
        return len(self._puck_pairs()[0]) > 0

    def _puck_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """The last step's resting contacts of two pucks, (i, j), from their keys (a wall's has j >= the row count)."""
        i, j = np.divmod(self._keys, self._rows + 4)
        pairs = np.flatnonzero((j < self._rows) & self._resting)
        return i.take(pairs), j.take(pairs)

    def wall_rest(self, rest: np.ndarray) -> np.ndarray:
        """The (N, 2) rest speeds `rest` towards the walls across x and y, made infinite where the puck
        pressed on a wall across that axis in the last step (it rests there whatever its speed)."""
        if self._wall_rest is not None and self._wall_rest[0] is rest and self._wall_rest[1] is self._impulses:
            return self._wall_rest[2]  # asked again within the step (walls, then contacts): the same answer
        out = rest.copy()
        self._wall_rest = (rest, self._impulses, out)
        if len(self._keys) == 0 or self._rows != len(rest):
            return out
        if self._held_walls is not None and self._held_walls[0] is self._impulses:
            out[self._held_walls[1], self._held_walls[2]] = np.inf  # (found by _keep, without a division)
            return out
        row, other = np.divmod(self._keys, self._rows + 4)
        held = np.flatnonzero((other >= self._rows) & (self._impulses[:, 0] > 0.0))
        out[row.take(held), (other.take(held) - self._rows) % 2] = np.inf
        return out

    def forget(self) -> None:
        """Drop the kept impulses (pucks were added, removed or moved by hand)."""
        self.__init__()

    def solve(
        self, pos, vel, radius, mass, size_m, candidates, rest, dt, asleep=None, began=None, margin=None,
    ) -> bool:  # fmt: skip
        """Solve the resting contacts in place; return whether there were any.

        candidates: (i, j, reach) pairs that may touch; rest: the step's rest
        speeds (rest_speeds.RestSpeeds): contacts approaching slower are resting; asleep:
        which pucks sleep (sleep.py), or None: to the awake pucks a sleeper is
        immovable, and its contacts with the walls and with other sleepers are
        left out. began: the positions when the step began (None: unknown, every contact
        is taken where the step ends). margin: how far apart a contact may be (m; None: margin_m).
        """
        if len(pos) != self._rows:
            self.forget()
            self._rows = len(pos)
        c, start = self._contacts(pos, vel, radius, size_m, candidates, rest, dt, asleep, began, margin)
        self.count = len(c.a)
        if self.count == 0:
            self._keys, self._impulses = np.empty(0, dtype=np.int64), np.empty((0, 2))
            self._resting = np.empty(0, dtype=bool)
            self._band_rounds = self._free_rounds = np.empty(0, dtype=np.intp)
            return False
        self._y, self._r_mean = start[:, 1], float(radius.mean())  # for the bands
        inv = np.append(1.0 / mass, 0.0)  # the walls never move, nor do sleepers
        if asleep is not None:
            inv[:-1][asleep] = 0.0
        w = np.zeros((len(pos) + 1, 2), dtype=complex)  # velocities and pseudo-velocities; the last row: walls
        w[:-1, 0] = vectors.as_complex(np.ascontiguousarray(vel))
        v0 = w[:-1, 0].copy()
        was_exact, self._exact = self._exact, False
        impulses = self._try_exactly(c, inv, w, dt)
        if impulses is None:  # (many contacts, or those the exact solve did not settle)
            impulses = self._iterate_then_polish(c, inv, w, dt, mass, asleep, was_exact)
        self._keep(c, impulses)
        moved = (w[:-1, 0] - v0 + w[:-1, 1]) * dt
        pos += np.column_stack([moved.real, moved.imag])
        vel[:, 0], vel[:, 1] = w[:-1, 0].real, w[:-1, 0].imag
        return True

    def _contacts(self, pos, vel, radius, size_m, candidates, rest, dt, asleep, began, margin) -> tuple:
        """(_Contacts: the step's contacts, with their least speeds; where each puck's step is taken to begin)."""
        ci, cj, reach = candidates
        may = _may_rest(ci, cj, asleep, rest.pressed)  # (not self.kept: that is last step's contacts)
        if may is not None:
            ci, cj, reach = ci.take(may), cj.take(may), reach.take(may)
        margin = margin_m(vel, dt) if margin is None else margin
        # The contacts where the step began, for the pucks still on the path they began it on
        # (see "Where the contacts are" above); `moved` is what the others' positions hold already.
        moved = vel.copy()
        if began is not None:
            off, size = np.abs(pos - vel * dt - began), np.abs(began)  # (columns: a max along rows of 2 is slow)
            plain = np.maximum(off[:, 0], off[:, 1]) <= 1e-9 * (1.0 + np.maximum(size[:, 0], size[:, 1]))
            moved[plain] = 0.0
        start = pos - (vel - moved) * dt
        pc = _pair_contacts(start, vel, radius, size_m, ci, cj, reach, rest, self.held, margin, dt, self.kept)
        wc = _wall_contacts(start, vel, radius, size_m, self.wall_rest(rest.walls), margin)
        may = _may_rest(wc.a, wc.a, asleep, rest.pressed)
        if may is not None:
            wc = _Contacts(*(getattr(wc, f).take(may) for f in _FIELDS))
        c = _Contacts(*(np.concatenate([getattr(pc, f), getattr(wc, f)]) for f in _FIELDS))
        parting = 0.0
        if began is None or not plain.all():  # where they were at the start if they approached
            zm = np.append(vectors.as_complex(np.ascontiguousarray(moved)), 0.0)
            parting = (c.n.conjugate() * (zm.take(c.a) - zm.take(c.b))).real
            c.gap = c.gap - np.minimum(parting, 0.0) * dt
        c.least = _least_speeds(c, parting, dt)
        return c, start

    def _iterate_then_polish(self, c: _Contacts, inv, w: np.ndarray, dt: float, mass, asleep, was_exact: bool):
        """Sequential impulses in coloured rounds, warm-started, on `w` in place; then polished (see POLISH_MPS)
        where the last step was solved to the end or their answer leaves a contact off its bound by more than
        POLISH_MPS (up to POLISH_MAX contacts), and wherever it leaves a puck leaping or sinking (LEAP_MPS, up to
        LEAP_MAX). Returns the impulses (m, 2). Where no polish follows they iterate on while a contact would
        sink too deep (DEEPEST_M); where one does not settle, the next EXACT_PAUSE steps polish only leaps."""
        if self._polish_paused:
            self._polish_paused -= 1
        start = w.copy() if self.count <= LEAP_MAX else None
        first, later = self._gather(c, inv, dt, asleep)
        w[:-1, 0] += _warm_push(c, mass, self._warm, asleep)  # warm start: last step's velocity impulses first
        too_deep = lambda: _sinks(c, w, dt) > DEEPEST_M  # noqa: E731
        sure = not self._polish_paused and self.count <= POLISH_MAX  # (a polish follows whatever they leave off)
        self.iterations, layout = _iterate(w, first, later, (lambda: False) if sure else too_deep)
        impulses = layout.impulses()
        if start is None:
            return impulses
        off = _off_bound(c, w, _targets(c, dt), impulses)
        leaping = off > LEAP_MPS or too_deep() or _gains_energy(mass, start, w) or _sinking(c, inv, w, dt)
        # (a landing: the iterations went on past their plan to keep contacts from sinking; see POLISH_MAX)
        landing = not self._polish_paused and self.iterations > _planned_iterations(self.count) and off > POLISH_MPS
        leaping = leaping or landing
        if not (leaping or (not self._polish_paused and was_exact) or (sure and off > POLISH_MPS)):
            return impulses
        work = POLISH_WORK if sure and not (leaping or was_exact) else LEAP_WORK
        polished = self._polished(c, inv, w, start, dt, impulses, work, off)
        if polished is None or not self._exact:
            self._polish_paused = EXACT_PAUSE
        if polished is not None:
            return polished
        more, layout = _iterate(w, layout, layout, too_deep)  # (from where they stopped)
        self.iterations += more
        return layout.impulses()

    def _polished(self, c: _Contacts, inv, w: np.ndarray, start: np.ndarray, dt: float, impulses, work: int, off):
        """The iterations' impulses carried to the answer, in place: by a few steps of proportioning from them or
        the last step's (a pile at rest barely changes), else by block pivoting from the contacts they have
        pushing (where it costs little, or the masses differ: see SAFE_MASS_RATIO; unless paused), else by up to
        `work` contact-steps of proportioning; where that does not settle, its answer if it leaves the contacts
        nearer their bounds than theirs do (`off`: then self._exact is False). None (`w` untouched) if none is."""
        apart = _masses_apart(inv.take(np.append(c.a, c.b)))
        polished = None if apart else self._polish(c, inv, w, start, dt, impulses, QUICK_STEPS)
        pivots = self.count <= (PIVOT_MAX if apart else EXACT_MAX)
        if polished is None and pivots and not self._paused:
            polished = self._solve_exactly(c, inv, start, dt, impulses > 0.0)
            if polished is not None:
                w[:] = start
        if polished is None:
            polished = self._polish(c, inv, w, start, dt, impulses, POLISH_STEPS, work, off, stall=not apart)
        return polished

    def _polish(
        self, c: _Contacts, inv, w, start, dt: float, impulses, most: int, work=POLISH_WORK, better_than=None,
        stall=True,
    ):  # fmt: skip
        """The iterations' impulses carried to the answer by proportioning.solve, from `start` (the velocities
        before them) or the last step's (_nearest), column by column, in place: the velocities' in at most
        `most` steps and `work` contact-steps, the pseudo-velocities' in POLISH_WORK (unsettled, the iterations'
        are kept). None (`w` untouched) if the velocities' does not settle, unless `better_than` is given: then
        if it comes within NEAR_MPS of their bounds as applied, or nearer than `better_than` (self._exact False).
        stall: whether it may stop where it comes no nearer (proportioning.solve: not where the masses differ).
        """
        response = proportioning.Response(c.n, c.a, c.b, inv)
        target = _targets(c, dt)
        q = np.column_stack([_normal_speeds(c, start, col) for col in (0, 1)]) - target
        out, polished, exact = impulses.copy(), start.copy(), True
        for col, budget in ((0, work), (1, POLISH_WORK)):
            begin = _nearest(response, q[:, col], impulses[:, col], self._warm if col == 0 else None)
            steps = min(most, budget // len(c.a))
            p, settled = proportioning.solve(response, q[:, col], begin, POLISH_TOL_MPS, steps, stall)
            if better_than is None and not settled and col == 0:
                return None
            if settled or col == 0:  # (the velocities' may be near enough unsettled: checked below)
                out[:, col] = p
            _push_column(c, inv, polished, out[:, col], col)
            # Checked as applied, to NEAR_MPS: impulses out of all scale, pushing against each other along dependent
            # contacts (a jam), leave round-off in the velocities (a puck jumped 50 mm in a step of a pile falling
            # asleep, its pseudo-velocities' problem having no answer).
            off = _off_bound(c, polished, target, out, col) if settled or col == 0 else 0.0
            if not off <= NEAR_MPS:  # (NaN: not)
                if col == 1 or better_than is None or not off < better_than:
                    return None
                exact = False
        w[:] = polished
        self._exact = exact
        return out

    def _try_exactly(self, c: _Contacts, inv: np.ndarray, w: np.ndarray, dt: float) -> np.ndarray | None:
        """_solve_exactly, unless the contacts are too many (EXACT_MAX) or one did not settle lately (EXACT_PAUSE)."""
        if self._paused:
            self._paused -= 1
            return None
        if self.count > EXACT_MAX:
            return None
        return self._solve_exactly(c, inv, w, dt)

    def _solve_exactly(self, c: _Contacts, inv: np.ndarray, w: np.ndarray, dt: float, pushed=None) -> np.ndarray | None:
        """A few contacts (EXACT_MAX) solved at once, exactly (collapse.solve), velocities and
        pseudo-velocities in `w` in place; returns their impulses (m, 2), contact by contact, or
        None (`w` untouched, and the next EXACT_PAUSE steps iterate) if the solve did not settle.
        pushed: (m, 2) where to start (None: the contacts that pushed in the last step)."""
        m, rows = len(c.a), self._rows
        bodies, local = np.unique(np.concatenate([c.a, c.b]), return_inverse=True)  # (the bodies these touch)
        a, b = local[:m], np.where(c.b == rows, -1, local[m:])  # (collapse's wall: -1)
        target = _targets(c, dt)
        vn = _normal_speeds(c, w)
        inv_bodies = inv.take(bodies)
        response = collapse.response(c.n, a, b, inv_bodies)  # (one matrix for both problems)
        pushed = self._pushed(c.keys) if pushed is None else pushed  # (a pile's pushing set changes little)
        safe = m <= SAFE_MAX or (m <= EXACT_MAX and _masses_apart(inv_bodies))
        velocity = collapse.solve(response, vn - target[:, 0], pushed[:, 0], safe)  # vn after: at least the bound
        position = None if velocity is None else collapse.solve(response, -target[:, 1], pushed[:, 1], safe)
        if position is None:
            self._paused = EXACT_PAUSE  # (the same contacts would not settle the next step either)
            return None
        impulses = columns(velocity, position)
        pushed_w = w.copy()
        _push(c, inv, pushed_w, impulses)
        # Checked as applied, as the polish is: on contacts that depend on each other, among sleepers (immovable), an
        # answer of impulses out of all scale (1e6 N s on 10 g pucks) settled by its own measure and moved a puck
        # 124 mm in a step by its pseudo-velocities, 0.013 m/s off their bounds as applied.
        if not max(_off_bound(c, pushed_w, target, impulses, col) for col in (0, 1)) <= NEAR_MPS:
            self._paused = EXACT_PAUSE
            return None
        w[:] = pushed_w
        self._key_order = np.argsort(c.keys)
        self._layouts = None  # (the rounds start afresh when the contacts are many again)
        self._band_rounds = self._free_rounds = np.empty(0, dtype=np.intp)
        self.iterations, self._exact = 1, True
        return impulses

    def _pushed(self, keys: np.ndarray) -> np.ndarray:
        """(m, 2) which of the contacts `keys` pushed in the last step, in velocity and in position."""
        found, kept = self._find(keys)
        if not kept.any():
            return np.zeros((len(keys), 2), dtype=bool)
        return kept[:, None] & (self._impulses.take(found, axis=0) > 0.0)

    def _gather(self, c: _Contacts, inv, dt: float, asleep=None) -> tuple[_Layout, _Layout]:
        """This step's targets, inverse masses (inv, with the walls' 0 last) and warm-start impulses,
        filled into the layouts of the rounds of the first iteration and of the later ones."""
        target = _targets(c, dt)
        impulse = np.zeros((len(c.keys), 2))  # pseudo-velocities start from nothing each step
        self._warm = impulse[:, 0]
        cached = self._layouts
        if cached is not None and cached.same(c.keys, asleep, self, lambda: self._bands(c, cached.key_order)):
            # The very contacts of the last step, in the same order, the same pucks asleep, the same bands: the
            # same rounds.
            self._key_order = cached.key_order
            impulse[cached.key_order, 0] = self._impulses[:, 0]
        else:
            self._key_order = korder = np.argsort(c.keys)
            last = np.full(len(korder), -1)  # each contact's place in the last step's, by key order
            if len(self._keys):
                keys = c.keys.take(korder)
                found = np.searchsorted(self._keys, keys).clip(0, len(self._keys) - 1)
                hit = np.flatnonzero(self._keys.take(found) == keys)
                last[hit] = found.take(hit)
            kept = np.flatnonzero(last >= 0)
            impulse[korder.take(kept), 0] = self._impulses[last.take(kept), 0]
            self._layouts = cached = self._colour(c, last, korder, asleep)
        first, later = cached.first, cached.later
        wa, wb = inv.take(c.a), inv.take(c.b)
        # Each per-contact number twice, for the velocity and the pseudo-velocity: (m, 2), so
        # that nothing is broadcast in the rounds (an (m, 1) column costs twice as much).
        nab = np.concatenate([c.n * wa, -(c.n * wb)])
        k = 1.0 / (wa + wb)
        knc = c.n.conjugate() * k
        values = (columns(knc, knc), columns(nab, nab), target * columns(k, k), wa + wb, impulse)
        return first.fill(*values), later.fill(*values)

    def _colour(self, c: _Contacts, last: np.ndarray, korder: np.ndarray, asleep=None) -> _Colouring:
        """The rounds of this step's contacts (in key order; last: each one's place in the last
        step's, -1 if new): the kept contacts keep theirs, the new ones are fitted in
        (colouring.py); and their layouts, laid out again only if they changed."""
        rows = self._rows
        # Walls and sleepers never move here: to the colouring they are one body, `rows`, never taken.
        a, b = c.a.take(korder), c.b.take(korder)
        if asleep is not None:
            a, b = np.where(asleep.take(a), rows, a), np.where(np.append(asleep, True).take(b), rows, b)
        kept, at = last >= 0, last.clip(0)
        band = self._bands(c, korder)
        dirty = self._dirty(a, b, kept, at, band, asleep)
        rounds, ordered = [], False
        for before, level in ((self._band_rounds, band), (self._free_rounds, None)):
            r = colouring.keep(np.where(kept, before.take(at), -1) if len(before) else np.full(len(a), -1), a, b, rows)
            if level is not None:
                _mark(dirty, a, b, r < 0, rows)  # new and refitted contacts: the order may break at their bodies
            r = colouring.fit(r, a, b, rows, level)
            for _ in range(BAND_PASSES if level is not None else 0):  # refitted ones may leave others out of order
                again = colouring.keep_order(r, a, b, rows, level, dirty)
                if again is r:
                    ordered = True
                    break
                _mark(dirty, a, b, again < 0, rows)
                r = colouring.fit(again, a, b, rows, level)
            rounds.append(r)
        cached = self._layouts
        asleep = None if asleep is None else asleep.copy()
        if cached is not None and np.array_equal(cached.keys, c.keys) and cached.has(*rounds):
            self._band_rounds, self._free_rounds = cached.band, cached.free  # the kept arrays, as `same` asks
            kept_layouts = (cached.band, cached.free, cached.first, cached.later)
            return _Colouring(c.keys, asleep, korder, *kept_layouts, band, ordered)
        self._band_rounds, self._free_rounds = rounds
        # In (round, key) order: rounds are few, so a stable sort of them as 16-bit numbers is a quick radix sort.
        first, later = (
            _Layout(korder.take(np.argsort(r.astype(np.int16), kind="stable")), np.bincount(r), c.a, c.b)
            for r in rounds
        )
        return _Colouring(c.keys, asleep, korder, *rounds, first, later, band, ordered)

    def _dirty(self, a, b, kept, at, band, asleep) -> np.ndarray | None:
        """The bodies where the band order of the kept rounds may be broken (a mask, the walls' row
        False), or None: anywhere. The last colouring left its rounds in order (else None), so
        only where a kept contact changed band or a sleeper woke; the new contacts are added later.

        The same answer as looking everywhere, so a restored state (no last colouring) gives the same rounds.
        """
        cached = self._layouts
        if cached is None or not cached.ordered or cached.band is not self._band_rounds or band is None:
            return None
        dirty = np.zeros(self._rows + 1, dtype=bool)
        _mark(dirty, a, b, kept & (band != cached.levels.take(at)), self._rows)
        if cached.asleep is not None:  # the woken: their contacts were the walls' row's, never looked at
            dirty[:-1] |= cached.asleep if asleep is None else cached.asleep & ~asleep
        return dirty

    def _bands(self, c: _Contacts, korder: np.ndarray) -> np.ndarray | None:
        """Each contact's band (key order): its height above the lowest, in BAND_RADII radii."""
        if BAND_RADII <= 0:
            return None
        y = self._y.take(c.a.take(korder))
        return np.minimum((y - y.min()) / (BAND_RADII * self._r_mean), 30_000).astype(np.int16)

    def _keep(self, c: _Contacts, impulses: np.ndarray) -> None:
        """Keep this step's impulses ((m, 2), contact by contact) by contact key, for the next step's warm start,
        and which were resting contacts (a collision that pushed, lest the stage drive it harder, did not press: it
        still collides in the next step; nor are its pucks in a pile, pressed every way, for it: RestSpeeds.piled)."""
        order = self._key_order
        self._keys, self._impulses = c.keys.take(order), impulses.take(order, axis=0)
        self._resting = ~c.collides.take(order)
        # The pucks pressed on a wall, and the wall's axis (normal 1 or -1: x; 1j or -1j: y), for wall_rest.
        walls = np.flatnonzero(c.b == self._rows)
        held = walls.take(np.flatnonzero(impulses[walls, 0] > 0.0))  # (a wall contact never collides)
        self._held_walls = (self._impulses, c.a.take(held), (c.n.take(held).imag != 0.0).astype(np.intp))

    # What the solver keeps from step to step: its impulses by contact (the warm start), and each
    # contact's rounds (they depend on the contacts it had before, so they change results). The
    # solver replaces these arrays each step and never changes them in place, so a save keeps references.
    KEPT = (
        *("_keys", "_impulses", "_resting", "_rows", "_band_rounds", "_free_rounds", "count", "iterations"),
        *("_paused", "_exact", "_polish_paused"),
    )
    # Worked out afresh in each solve (the layouts from the kept rounds, the same in the same order):
    # they change no result, so a save need not keep them.
    NOT_KEPT = frozenset({"_y", "_r_mean", "_warm", "_key_order", "_layouts", "_wall_rest", "_held_walls"})

    def save(self, like: tuple | None = None) -> tuple:
        """The KEPT values (references), for state.py; `like`'s parts where they are the same objects."""
        unknown = set(vars(self)) - set(self.KEPT) - self.NOT_KEPT
        if unknown:
            raise TypeError(f"the contact solver keeps {sorted(unknown)}: ContactSolver.save must learn to save it")
        kept = [getattr(self, k) for k in self.KEPT]
        if like is None:
            return tuple(kept)
        same = [_same_part(a, b) for a, b in zip(kept, like, strict=True)]
        if all(same):
            return like
        return tuple(old if s else new for new, old, s in zip(kept, like, same, strict=True))

    def restore(self, saved: tuple) -> None:
        """Back to a save: the same impulses and rounds."""
        for name, value in zip(self.KEPT, saved, strict=True):
            setattr(self, name, value)

    def retry(self, saved: tuple) -> None:
        """Back to a save to solve the same step again (resting.hold, with more pairs), keeping the pauses the
        try began: what did not settle is not tried again within the step (demo 4 struck at restitution 0: an
        exact solve of 120 contacts that did not settle, 80 ms, was tried again with each wider margin)."""
        paused, polish_paused = self._paused, self._polish_paused
        self.restore(saved)
        self._paused, self._polish_paused = max(self._paused, paused), max(self._polish_paused, polish_paused)


def _same_part(a, b) -> bool:
    """Arrays and tuples of arrays are the same only if they are the same objects; plain values if equal."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return a is b
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(x is y for x, y in zip(a, b, strict=True))
    return a == b


def _mark(dirty: np.ndarray | None, a: np.ndarray, b: np.ndarray, which: np.ndarray, sink: int) -> None:
    """Mark the bodies of the contacts `which` (a mask) in `dirty` (if any), never the sink."""
    if dirty is not None:
        k = np.flatnonzero(which)
        dirty[a.take(k)] = dirty[b.take(k)] = True
        dirty[sink] = False


@dataclass
class _Colouring:
    """A step's contacts (keys in their order, the sleepers), their rounds and their layouts."""

    keys: np.ndarray
    asleep: np.ndarray | None
    key_order: np.ndarray
    band: np.ndarray
    free: np.ndarray
    first: _Layout
    later: _Layout
    levels: np.ndarray | None  # each contact's band (key order) when coloured
    ordered: bool  # whether `band` was then in band order everywhere

    def same(self, keys: np.ndarray, asleep: np.ndarray | None, solver: ContactSolver, bands) -> bool:
        """Whether these contacts are those of the solver's last step, with the same rounds and sleepers, and
        their rounds in the order of their bands now (bands(): each one's band, key order): colouring them again
        would give the same rounds, as it does after a restore (which keeps the rounds, not this colouring)."""
        if self.band is not solver._band_rounds or self.free is not solver._free_rounds:
            return False  # a restored state: its rounds may be other ones
        if len(solver._keys) != len(keys) or not np.array_equal(self.keys, keys):
            return False
        if not ((asleep is None and self.asleep is None) or (
            asleep is not None and self.asleep is not None and np.array_equal(asleep, self.asleep)
        )):  # fmt: skip
            return False
        return self.levels is None or (self.ordered and np.array_equal(self.levels, bands()))

    def has(self, band: np.ndarray, free: np.ndarray) -> bool:
        """Whether these are the rounds laid out."""
        return np.array_equal(self.band, band) and np.array_equal(self.free, free)


class _Layout:
    """One colouring's rounds laid out once: index arrays, buffers, and each round's views into them.

    Built when the colouring changes (in a pile at rest, seldom); each step
    then refills the buffers in place, and the rounds, whose arrays are views
    of them, are ready. That saves making a dozen arrays and a `_Round` per
    round at every step.
    """

    def __init__(self, order: np.ndarray, lengths: np.ndarray, a: np.ndarray, b: np.ndarray) -> None:
        """order: the contacts round by round; lengths: how many in each round (none empty)."""
        self.order = order
        m = len(order)
        self.lengths = lengths
        ends = np.cumsum(lengths)
        self.starts = ends - lengths
        bounds = list(zip(self.starts.tolist(), ends.tolist(), strict=True))
        # Body a's rows of a round, then body b's, side by side: one gather and one write per round.
        # Rows of [everything about body a; everything about body b], contact by contact: the place
        # p of a round starting at s and ending at e has its a row at p + s and its b row at p + e.
        place = np.arange(m)
        at_a, at_b = place + np.repeat(self.starts, lengths), place + np.repeat(ends, lengths)
        self.ab_rows = np.empty(2 * m, dtype=np.intp)
        self.ab_rows[at_a], self.ab_rows[at_b] = order, m + order
        ab = 2 * np.concatenate([a, b]).take(self.ab_rows)
        fab = columns(ab, ab + 1)  # the flat indices of each body's velocity and pseudo-velocity
        self.knc, self.nab = np.empty((m, 2), dtype=complex), np.empty((2 * m, 2), dtype=complex)
        self.kt, self.impulse = np.empty((m, 2)), np.empty((m, 2))
        # Every round's last change of impulse, to find the largest once per iteration, and per
        # contact its round's largest wa + wb, which turns a change of impulse into one of speed.
        # (m, 2), both columns alike: an (m, 1) array broadcast against (m, 2) costs twice as much.
        self.changes, self.w_max = np.zeros((m, 2)), np.empty((m, 2))
        self.rounds = [
            _Round(fab[2 * s : 2 * e].reshape(2, e - s, 2), self.knc[s:e], self.nab[2 * s : 2 * e].reshape(2, e - s, 2),
                   self.kt[s:e], self.changes[s:e], self.impulse[s:e])
            for s, e in bounds
        ]  # fmt: skip
        # For the few impulses an extrapolation cuts at zero (push): for each impulse (contact by
        # contact, velocity then position), its places in fab and nab for body a and for body b.
        # (Built by the first push: the first iteration's layout never pushes.)
        self.fab = fab.reshape(-1)
        self._at, self._entries = (at_a, at_b), None

    def converged(self, gg: tuple[float, float] | None = None) -> bool:
        """Whether the last iteration changed no speed by CONVERGED_MPS (a change of impulse times w_max).

        The largest change of impulse times the least w_max bounds that from
        below, and in a pile it is far above: one cheap reduction then answers.
        Given gg, each column's sum of squared changes, their root mean square
        bounds the largest from below too, with no reduction at all.
        """
        if gg is not None and math.sqrt(max(gg) / len(self.changes)) * self.w_min >= 2.0 * CONVERGED_MPS:
            return False  # (twice: room for the roundings of the sums and the root)
        largest = float(np.abs(self.changes).max())
        if largest * self.w_min >= CONVERGED_MPS:
            return False
        return float((np.abs(self.changes) * self.w_max).max()) < CONVERGED_MPS

    def impulses(self) -> np.ndarray:
        """(contacts, 2) the rounds' impulses so far, contact by contact."""
        out = np.empty((len(self.order), 2))
        out[self.order] = self.impulse
        return out

    def push(self, w: np.ndarray, direction: np.ndarray, image: np.ndarray) -> None:
        """Move the impulses (this layout's order) by `direction`, but to no less than 0, and the
        velocities `w` to match; image: the velocity change that `direction` alone makes.

        Only the few impulses cut at zero need a look of their own: the image is
        kept up by the caller from the sweeps' own changes, whole arrays at once.
        """
        self.impulse += direction
        w += image
        impulse = self.impulse.reshape(-1)
        cut = np.flatnonzero(impulse < 0.0)
        if len(cut):  # these moved by less than direction: take back the part below zero
            at = self._impulse_entries().take(cut, axis=0)  # (cut, 2): body a's and body b's
            np.subtract.at(w.reshape(-1), self.fab.take(at), self.nab.reshape(-1).take(at) * impulse.take(cut)[:, None])
            impulse[cut] = 0.0

    def _impulse_entries(self) -> np.ndarray:
        """(2 m, 2) for each impulse (contact by contact, velocity then position), its places in
        fab and nab (seen as flat) for body a and for body b."""
        if self._entries is None:
            at_a, at_b = self._at
            parts = np.tile(np.arange(2), len(at_a))
            self._entries = columns(np.repeat(2 * at_a, 2) + parts, np.repeat(2 * at_b, 2) + parts)
        return self._entries

    def fill(self, knc, nab, kt, w_sum, impulse) -> _Layout:
        """This step's values (contact by contact; nab: body a's rows, then body b's) into the rounds."""
        order = self.order
        np.take(knc, order, axis=0, out=self.knc, mode="clip")  # "clip": no bounds check, no buffering
        np.take(nab, self.ab_rows, axis=0, out=self.nab, mode="clip")
        np.take(kt, order, axis=0, out=self.kt, mode="clip")
        w_round = np.maximum.reduceat(w_sum.take(order), self.starts)
        self.w_max[:, 0] = self.w_max[:, 1] = np.repeat(w_round, self.lengths)
        self.w_min = float(w_round.min())
        np.take(impulse, order, axis=0, out=self.impulse, mode="clip")
        return self


def _targets(c: _Contacts, dt: float) -> np.ndarray:
    """(m, 2) each contact's least relative normal velocity after the stage, and its pseudo-velocity:
    the least speed (_least_speeds, in c.least), and the pseudo-velocity that pushes out a share of its overlap
    (POSITION_FRACTION; into a wall, all beyond WALL_LEFT_M)."""
    return columns(
        c.least,
        np.minimum(np.maximum(POSITION_FRACTION * (-c.gap - SLOP_M), -c.gap - c.left) / dt, MAX_PUSH_MPS).clip(0.0),
    )


def _least_speeds(c: _Contacts, parting, dt: float) -> np.ndarray:
    """Each contact's least relative normal velocity after the stage (m/s): it may close its gap (where the step
    began) within the step, not more; so may a collision (the stage stopped one puck of a pair approaching fast
    and the other ran 13 mm into it; and the hit stage leaves a pair that meets slower than it rests: 0.3996 m/s
    at their first contact, against 0.4, and 0.4002 where the step began, it ran 1.3 mm into the other).

    parting: how fast the motion already in the positions parts the pair (an earlier stage bounced a puck: the
    stage moves it by its change of velocity times dt, so slowing that parting moves the pair closer as much), less
    the overlap the stage leaves alone (SLOP_M: the normal of a pair of a bounced puck and one on its path is
    taken between where they are at different times, and a bounced puck's fall of g dt, which the floor then stops,
    showed along it as a parting 5 um/s faster than theirs: a row of 1 kg pucks struck at 3 m/s gained 7e-6 m/s)."""
    return -np.maximum(c.gap, 0.0) / dt + np.maximum(parting - SLOP_M / dt, 0.0)


def columns(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """(m, 2) the two columns: written column by column, several times quicker in numpy than
    broadcasting or repeating along an axis of 2."""
    out = np.empty((len(first), 2), dtype=np.result_type(first, second))
    out[:, 0], out[:, 1] = first, second
    return out


def _warm_push(c: _Contacts, mass: np.ndarray, impulse: np.ndarray, asleep=None) -> np.ndarray:
    """The velocity change (complex, per puck) from every contact's warm-start impulse at once:
    a sum, so the order of the contacts does not matter. Sleepers do not move."""
    rows = len(mass)
    push = impulse * c.n
    a = push / mass.take(c.a)
    b = push / np.append(mass, 1.0).take(c.b)  # the walls' row (b = rows) is dropped below
    if asleep is not None:
        a[asleep.take(c.a)] = 0.0
        b[np.append(asleep, False).take(c.b)] = 0.0
    out = np.bincount(c.a, a.real, rows) - np.bincount(c.b, b.real, rows + 1)[:rows]
    return out + 1j * (np.bincount(c.a, a.imag, rows) - np.bincount(c.b, b.imag, rows + 1)[:rows])


def _normal_speeds(c: _Contacts, w: np.ndarray, col: int = 0) -> np.ndarray:
    """Each contact's relative normal velocity (m/s, negative: approaching) by the velocities `w` (w[:, col]:
    0 the velocities, 1 the pseudo-velocities)."""
    return (c.n.conjugate() * (w.take(c.a, axis=0)[:, col] - w.take(c.b, axis=0)[:, col])).real


def _masses_apart(inv: np.ndarray) -> bool:
    """Whether the masses of the bodies (their 1 / mass: `inv`; 0, a wall or a sleeper, left out) differ more
    than SAFE_MASS_RATIO times."""
    moving = inv[inv > 0.0]
    return len(moving) > 0 and moving.max() > SAFE_MASS_RATIO * moving.min()


def _push(c: _Contacts, inv: np.ndarray, w: np.ndarray, impulses: np.ndarray) -> None:
    """Apply the contacts' impulses (m, 2) to the velocities and pseudo-velocities `w`, in place."""
    for col in (0, 1):
        _push_column(c, inv, w, impulses[:, col], col)


def _push_column(c: _Contacts, inv: np.ndarray, w: np.ndarray, impulses: np.ndarray, col: int) -> None:
    """Apply one column of the contacts' impulses to that column of `w` (0: velocities, 1: pseudo-), in place."""
    push = impulses * c.n
    np.add.at(w[:, col], c.a, push * inv.take(c.a))
    np.add.at(w[:, col], c.b, -push * inv.take(c.b))  # (the walls' row: inv 0)


def _gains_energy(mass: np.ndarray, before: np.ndarray, after: np.ndarray) -> bool:
    """Whether the velocities `after` (column 0 of w) hold more kinetic energy than `before`, beyond GAIN_SHARE of it.

    The answer never does: the contacts' bounds hold for the pucks at rest (no bound asks a pair to part), so the
    answer, the velocities nearest `before` (in kinetic energy) that keep them, is no farther from rest than
    `before` is (a projection onto a convex set that holds rest). An answer that gains is the iterations' alone."""
    gain = mass * (np.abs(after[:-1, 0]) ** 2 - np.abs(before[:-1, 0]) ** 2)
    return float(gain.sum()) > GAIN_SHARE * float(np.dot(mass, np.abs(before[:-1, 0]) ** 2))


def _sinking(c: _Contacts, inv: np.ndarray, w: np.ndarray, dt: float) -> bool:
    """Whether the velocities `w`, on masses apart (SAFE_MASS_RATIO: there the iterations converge slowly), leave a
    contact sinking deeper than LEFT_DEEP_M (in a pile of like masses, settling, the iterations leave some 0.5 to
    2 mm for a step, as pymunk's do: polishing those made its steps four times as long)."""
    return _masses_apart(inv.take(np.append(c.a, c.b))) and _left_deep(c, w, dt) > LEFT_DEEP_M


def _left_deep(c: _Contacts, w: np.ndarray, dt: float) -> float:
    """How deep (m) the velocities and pseudo-velocities `w` leave the deepest contact that they sink further
    (a deeper overlap being pushed out, at MAX_PUSH_MPS at the most, is not looked at), at the step's end; 0 if none."""
    closing = _normal_speeds(c, w, 0) + _normal_speeds(c, w, 1)
    return float(-(c.gap + closing * dt).min(where=closing < 0.0, initial=0.0))


def _sinks(c: _Contacts, w: np.ndarray, dt: float) -> float:
    """How far (m) the velocities `w` would close the worst contact past its bound in dt (past its gap;
    for a pair touching or overlapping, past where it is: _least_speeds)."""
    return float(((c.least - _normal_speeds(c, w)) * dt).max())


def _nearest(response: proportioning.Response, q: np.ndarray, *candidates: np.ndarray | None) -> np.ndarray:
    """Of the candidate impulses and none at all, the nearest the answer by proportioning.objective, to
    start from: the iterations' answer mostly; where they diverged (masses decades apart, warm-started from a
    landing solved to the end: a user test's slab of rows of 1 g and 1000 kg), the last step's, or none."""
    best, least = np.zeros_like(q), 0.0
    for p in candidates:
        if p is not None and (f := proportioning.objective(response, q, p)) < least:
            best, least = p, f
    return best


def _off_bound(c: _Contacts, w: np.ndarray, target: np.ndarray, impulses: np.ndarray, col: int = 0) -> float:
    """How far (m/s) the velocities `w` (col 0; 1: the pseudo-velocities) leave the worst contact off its
    bound (target: _targets): approaching past it, or, where the contact pushes (impulses), parting faster
    than it (an impulse too big: a puck thrown up). NaN if any is."""
    off = _normal_speeds(c, w, col) - target[:, col]
    return max(float(-off.min()), float(off.max(where=impulses[:, col] > 0.0, initial=0.0)))


def _planned_iterations(m: int) -> int:
    """How many iterations a step of m contacts plans (ITERATION_WORK); beyond, they go on only while a contact
    would sink too deep (DEEPEST_M)."""
    return max(ITERATIONS, min(MAX_ITERATIONS, ITERATION_WORK // m))


def _iterate(w: np.ndarray, first: _Layout, later: _Layout, too_deep) -> tuple[int, _Layout]:
    """Sequential impulses, round by round, until converged or ITERATIONS; return the iterations used
    and the layout whose rounds hold the impulses. too_deep() says whether the velocities so far
    would still sink a contact too deep: then the iterations go on (DEEPEST_M).

    The first iteration goes bottom-up (`first`), so support from the floor
    travels up a pile; the later ones refine it and take the fewer rounds of
    `later`, which get the impulses so far. Those are sped up as conjugate
    gradients speed up plain iterations (Silcowitz, Niebe and Erleben's
    nonsmooth nonlinear conjugate gradients, 2009): each sweep's change of
    the impulses is a gradient, and a share of the last direction is added
    to it. Plain sweeps pass a push along a chain of contacts (a stack
    landing) one link at a time and back; these carry it on, and the chain
    settles within its step instead of leaving impulses half done.
    """
    flat = w.reshape(-1)
    _sweep(flat, first)
    if first.converged():
        return 1, first
    np.take(first.impulses(), later.order, axis=0, out=later.impulse, mode="clip")
    direction = image = None  # the direction, and the velocity change it makes (kept up as it changes)
    last_gg = (0.0, 0.0)
    m = len(later.order)
    iterations = _planned_iterations(m)
    most = max(iterations, min(MAX_ITERATIONS, DEEP_WORK // m))
    for it in range(2, most + 1):
        before = w.copy()
        _sweep(flat, later)
        gradient = later.changes  # the sweep's impulses before it, less after it (each contact changes once)
        # Per column (velocity, position): numpy broadcasts a pair along rows of two several times slower.
        gg = (float(gradient[:, 0] @ gradient[:, 0]), float(gradient[:, 1] @ gradient[:, 1]))
        if it == most or later.converged(gg):
            return it, later  # (the last word is a sweep's, never an extrapolation)
        if it >= iterations and (it - iterations) % DEEP_CHECKS == 0 and not too_deep():
            return it, later
        swept = w - before  # what the sweep did to the velocities: the image of -gradient
        if direction is None:
            direction, image = -gradient, swept
        else:
            for col in (0, 1):
                beta = gg[col] / max(last_gg[col], 1e-300) if gg[col] <= last_gg[col] else 0.0  # a rise: start again
                direction[:, col] *= beta
                image[:, col] *= beta
            later.push(w, direction, image)
            direction -= gradient
            image += swept
        last_gg = gg
    return most, later  # (only with fewer than two iterations)


def _sweep(flat: np.ndarray, layout: _Layout) -> None:
    """One iteration of sequential impulses over the layout's rounds, in place.

    Velocities as one row of numbers (1-D fancy indexing is several times
    cheaper than 2-D). No body appears twice in a round, so each writes back
    what it read plus its change; the walls' row takes many writes, all the
    same (wb = 0). A contact's impulse changes by k (target - vn), but stays
    at least 0: by max(k (target - vn), -impulse), here taken as minus the
    least of k vn - k target and the impulse (the fewest numpy calls). A
    contact is in one round, so its impulse is read once a sweep: all of them
    change at the end, in one call instead of one a round.
    """
    for fab, knc, nab, kt, change, impulse in layout.rounds:
        v = flat.take(fab)  # (2, m, 2): body a's rows, then body b's
        np.minimum((knc * (v[0] - v[1])).real - kt, impulse, out=change)
        v -= change * nab
        flat[fab] = v
    layout.impulse -= layout.changes
