"""Hits in time order: every wall and pair hit of a step, resolved at the moment it happens.

After the Euler update each puck moves on a straight line through the step: at
time t (0 <= t <= dt) puck k is at o_k + v_k t, o_k being where its present path
had it at t = 0 (its "origin"). A hit is an event at the time two paths first
touch (collision.contact_time) or a path reaches a wall (collision.wall_time).
The events wait in a queue by time, as in Rapaport's event-driven method: the
earliest is resolved (the pucks where they touch, collided along the normal with
collision.collide_along, then on new paths from there), and only the hits of the
pucks it changed are predicted again; a prediction made before one of its
pucks changed is stale and dropped. So a puck's several hits, a hit just after
a wall bounce and a pair squeezed against a wall all happen in their order: in
perfect kiss the motion is that of hard discs, whatever the step.

Which pairs can meet: those the neighbour list holds while every path stays
near where the step ends (NeighbourList.pairs_while_moving); a puck given a
path longer than that is checked against every puck.

What is left to later stages: hits slower than a puck's rest speed, and pairs
that pressed on each other in the last step (the contact stage holds those).
Outside perfect kiss only fast pairs' hits are predicted (a puck of the pair
moving FAST_FRACTION of the smaller one's radius in a step: it could pass
through the small one, or knock it through a third) and, in two-step, those of
unlike pucks, of pucks touching them and those that make a puck fast
(Step.ours_after); the pair
stage sees the others overlapping. Of those, a hit the step's end would catch
overlapping and approaching is left to the pair stage too, which resolves it
the course's way (two-step: backed up t_p = overlap / normal speed along the
line of centres there; "off": velocities only), unless a puck of the pair
moves CHAIN_FRACTION of the smaller one's radius in a step: in two-step that hit is resolved
here, at dt - t_p along the line of centres at the step's end (the pair ends
where the two-step correction puts it), so the hits a shot starts down a row of
touching pucks come in order. A hit the end would catch too late (past the
closest approach) or not at all (through) is resolved here, at first contact.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from airtable.physics import broadphase, collapse, collision, either, vectors
from airtable.physics.collision import PairRecords
from airtable.physics.rest_speeds import RestSpeeds, still_held
from airtable.physics.walls import room_to_walls

if TYPE_CHECKING:
    from airtable.physics.context import StepContext
    from airtable.physics.storage import Storage

# A bound on the events of one step (the pi setup at 10^8:1 needs some hundreds).
MAX_EVENTS = 100_000
# Said once (table.notices) if a step ever reaches MAX_EVENTS.
CAPPED_NOTICE = (
    "A step had more hits than the engine resolves one by one; the rest of that step's hits"
    " were left to the overlap correction."
)
# Below restitution 1, a pair hits in one step at most as many times as it takes its restitution
# to cut an approach speed by REPEAT_DECAY (and at least REPEAT_MIN times); its further hits are
# left to the pair and contact stages: else pucks that collide inelastically in a cluster hit
# each other again and again at ever smaller speeds (inelastic collapse): 200000 events in one
# step of a 300-puck gas at restitution 0. At 0.9 that is 88 hits, at 0.5 14: a light puck squeezed
# between a wall and a heavy one may bounce a dozen times in a step, and each of those is real. (At
# 1e-3, 10 at 0.5: a light puck between a heavy one and two light ones, hit ten times in a step by one
# of them as the heavy one drove in, was stuck to them before its last two hits; 2 of 800 random
# scenes of the event oracle's left the exact motion so, none of 1500 at 1e-4.) The same for a puck
# and a wall below restitution 1 (the wall stage puts back what is left): a heavy puck pushing a
# light one into a wall of restitution 0 made 100000 events, 2 to 3 s, in one step.
REPEAT_MIN = 3
REPEAT_DECAY = 1e-4
# A puck that bounces this many times in a row between the two walls across one axis within a step, with
# nothing else changing its path, stops across them (RATTLE_NOTICE): it has less room across than
# 1/RATTLE_MAX of its path in a step. That is a puck that fits its table but for round-off (its radius
# half the height less 1e-16 m bounced 2 million times a step: a second a step), or one at some
# kilometres a second; its rattle is far too small to see. A light puck squeezed between a heavy one
# and a wall (the pi demo) hits the heavy one between its wall hits, and is never stopped.
RATTLE_MAX = 256
RATTLE_NOTICE = (
    "A puck with almost no room between two walls (it crossed that room hundreds of times in a step) was"
    " stopped across them; it still moves along them."
)


def repeat_max(cr: float) -> int:
    """How many times a pair of restitution cr (< 1) may hit in one step (see REPEAT_DECAY)."""
    if cr <= 0.0:
        return REPEAT_MIN
    return max(REPEAT_MIN, math.ceil(math.log(REPEAT_DECAY) / math.log(cr)))


# A stuck pair (Step.stick) approaching slower than this (m/s) is left alone: round-off of the last
# cluster solved, not a hit (solving it again would change nothing and queue it again, at once).
STUCK_SPEED_MPS = 1e-9
# A stuck pair's solves in one step stop after this many (a bound: each solve leaves its cluster at rest
# along its contacts, so a few suffice; what is left, if anything, the pair stage puts apart).
STUCK_SOLVES_MAX = 200
# In two-step, pair hits are predicted when some puck moves this share of the smallest radius
# in a step; below it nobody can pass through a puck, and the pair stage sees every hit.
FAST_FRACTION = 0.5
# In two-step, a hit the step's end would catch overlapping and approaching is the pair stage's
# (it resolves it the same way), unless a puck of the pair moves this share of its radius in a step:
# then the hits it starts down a row of touching pucks come here, in order, or the row's end swaps.
CHAIN_FRACTION = 1.0
# In two-step, a hit the step's end catches overlapping is the pair stage's if its pucks' masses are within
# this ratio: its correction moves each puck its mass share of it, and a puck much lighter than its partner
# moves nearly all of it, into its next neighbour (a light puck between heavy ones was pushed through one).
LIKE_MASSES = 2.0
# A push along n counts as into a wall (off_a_pinned) only where n leans into it by more than this (the cosine):
# two pucks side by side on the floor, one 1e-17 m lower by round-off, made a level hit a bounce off the floor.
INTO_WALL = 1e-9
# A puck whose path changed has its hits with up to this many partners predicted one by one in
# Python numbers (a few microseconds each), with more at once in numpy (some sixty calls whatever
# their number): the same lines either way (either.py), the same bits.
FEW_PARTNERS = 10


@dataclass
class Rules:
    """What the step asks of its hits: restitutions, what to predict, the rest speeds."""

    cr_puck: float
    cr_wall: float
    pairs: str  # the correction mode ("perfect-kiss", "two-step", "off"), or "none": no pair hits
    walls: bool  # wall hits at their time (wall_correction); else the wall stage puts pucks back
    accel_y_mps2: float = 0.0  # gravity's part of the step's velocity change (0 or -g)
    rest: RestSpeeds | None = None  # pair hits slower than their rest speed rest (rest_speeds.py)
    wall_rest: np.ndarray | None = None  # per puck (N,) or per puck and axis (N, 2), for walls
    held: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None  # pairs (i < j) resting: the contacts'


@dataclass
class Hits:
    """What the hits in time order did in one step: the pair hits as rows, the wall bounces."""

    # (i, j, n, xj at contact, overlap, reach, rj, xi, xj before, xi, xj after, vi, vj before, after):
    # the fields of Collisions.of_pairs (collision.PairRecords), one hit each, vectors complex
    rows: list = field(default_factory=list)
    walls: int = 0
    bounced: list = field(default_factory=list)  # the rows of the wall hits, one a hit
    capped: bool = False
    rattled: bool = False  # a puck was stopped between two walls (RATTLE_MAX)
    maybe_past: np.ndarray | None = None  # the rows that may still be past a wall (None: any)

    def records(self) -> PairRecords:
        """The pair hits' collision records: an exact hit where the pucks touched (overlap 0), a
        two-step one where the step's end caught them overlapping, and where it moved them."""
        return PairRecords(len(self.rows), rows=self.rows)


def hits_in_order(table: Storage, ctx: StepContext) -> None:
    """Stage 3: resolve the step's wall and pair hits in the order they happen; set ctx.maybe_past to the
    rows that may still be past a wall (None: any)."""
    rules = Rules(
        table.cr_puck,
        table.cr_wall,
        pairs=table.puck_correction if table.puck_collisions else "none",
        walls=table.wall_correction,
        accel_y_mps2=-table.gravity_mps2 if table.gravity_on else 0.0,
        rest=ctx.rest,
        wall_rest=ctx.wall_rest,
        held=None if ctx.rest is None else table.contact_solver.held,
    )
    pucks = (table.pos_m, table.vel_mps, table.radius_m, table.mass_kg)
    hits = resolve_hits(*pucks, table.size_m, ctx.dt, rules, table.neighbour_list)
    table.wall_collision_count += hits.walls
    ctx.bounced = hits.bounced
    if hits.rows:
        ctx.records.append(hits.records())
        table.collision_count += len(hits.rows)
    if hits.capped:
        table.notices.say("capped", CAPPED_NOTICE)
    if hits.rattled:
        table.notices.say("rattled", RATTLE_NOTICE)
    ctx.maybe_past = hits.maybe_past


def resolve_hits(pos, vel, radius, mass, size_m, dt: float, rules: Rules, neighbours) -> Hits:
    """Resolve this step's hits in time order, in place (see the module docstring).

    pos: positions at the end of the step (x0 + v dt, done); vel: the step's
    velocities. neighbours: the table's NeighbourList.
    """
    step = _Step(pos, vel, radius, mass, size_m, dt, rules)
    if len(pos) == 0 or dt <= 0.0:
        return step.hits
    past = step.past_walls() if rules.walls else None
    for k in step.moving_faster_than_wall_rest(past) if past else ():
        step.predict_walls(k)
    if step.predicts_pairs():
        if step.unlike:
            step.find_unlike_contacts(neighbours)
        step.find_partners(neighbours)
        step.predict_pairs(*step.first_pairs())
    step.run()
    step.write_back()
    if past is not None:  # only those past a wall, or on a new path, may still be (resting, landed)
        rows = set(past).union(step.changed.nonzero()[0].tolist())  # a few (np.union1d: ten times the cost)
        step.hits.maybe_past = np.array(sorted(rows), dtype=np.intp)
    return step.hits


class _Step:
    """One step's event queue and the pucks' present paths (origins and velocities, complex x + iy)."""

    def __init__(self, pos, vel, radius, mass, size_m, dt: float, rules: Rules) -> None:
        self.zpos, self.zvel = vectors.as_complex(pos), vectors.as_complex(vel)
        self.radius, self.mass, self.dt, self.rules = radius, mass, dt, rules
        self.width, self.height = float(size_m[0]), float(size_m[1])
        self.queue: list[tuple] = []
        self.seq = 0  # breaks ties between events at one time: the earlier predicted first
        self.t_now = 0.0
        self.changed = np.zeros(len(pos), dtype=bool)  # the pucks whose path changed ...
        self.zorigin = np.zeros(len(pos), dtype=complex)  # ... and their new origins
        self.version: dict[int, int] = {}  # per puck: how many times its path changed
        self.hit_pairs: dict[tuple[int, int], int] = {}  # how many times each pair (i < j) hit
        self.stuck: dict[int, set[int]] = {}  # per puck: those it sticks to for the rest of the step (stick)
        self.solves: dict[tuple[int, int], int] = {}  # how many times each stuck pair (i < j) was solved
        self.first_speed: dict[tuple[int, int], float] = {}  # each pair's approach speed at its first hit
        self.hit_walls: dict[tuple[int, int], int] = {}  # how many times each puck hit a wall across each axis
        # Per (puck, axis): (its path's version after its last wall hit across that axis, the wall's side,
        # how many hits in a row between the two walls there, nothing else in between) (RATTLE_MAX)
        self.rattles: dict[tuple[int, int], tuple[int, bool, int]] = {}
        self.pinned: dict[int, complex] = {}  # pucks resting on a wall for the rest of the step: its normal
        self.hits = Hits()
        self.partners = None  # the pairs that may meet, per puck (see find_partners)
        self.only_fast: np.ndarray | None = None  # the pucks whose partners were found, if not all
        self.speed_sq = vectors.squared_abs(self.zvel)  # each puck's speed squared on its first path
        speed = math.sqrt(float(self.speed_sq.max())) if len(vel) else 0.0
        self.travel = speed * dt  # the farthest any puck moves this step on its first path (m)
        self.r_min = float(radius.min()) if len(radius) else 0.0
        # In two-step with masses unlike (LIKE_MASSES), slow hits may be this stage's too (ours_after).
        self.unlike = rules.pairs == "two-step" and len(mass) > 0 and _unlike(float(mass.min()), float(mass.max()))
        self.in_unlike_contact: np.ndarray | None = None  # per puck (find_unlike_contacts)
        # The pairs found hold every pair that can meet while each path stays within `covered`
        # of its puck's step end; `reach_out` is the farthest any present path strays.
        self.covered = self.reach_out = 2.0 * self.travel
        self.extra: dict[int, set[int]] = {}  # partners found for paths that stray farther
        self.offset: dict[int, complex] = {}  # added to a velocity at the end (bounce_under_gravity)

    # ------------------------------------------------------------ paths

    def at(self, k, t: float):
        """Where puck k is at time t of the step on its present path (a row: complex; rows: at_rows)."""
        if isinstance(k, np.ndarray):
            return self.at_rows(k, t)
        if not self.changed.item(k):
            return self.zpos.item(k) + self.zvel.item(k) * (t - self.dt)
        return self.zorigin.item(k) + self.zvel.item(k) * t

    def at_rows(self, rows: np.ndarray, t: float) -> np.ndarray:
        """Where the pucks `rows` are at time t of the step on their present paths (`at`, for many)."""
        out = self.zpos.take(rows) + self.zvel.take(rows) * (t - self.dt)
        moved = self.changed.take(rows)
        if moved.any():
            k = rows[moved]
            out[moved] = self.zorigin.take(k) + self.zvel.take(k) * t
        return out

    def set_path(self, k: int, x: complex, v: complex) -> None:
        """Puck k is at x at t_now and goes on at v: a new origin, and its old predictions stale."""
        self.zvel[k] = v
        self.zorigin[k] = x - v * self.t_now
        self.changed[k] = True
        self.version[k] = self.version.get(k, 0) + 1
        if self.partners is None:
            return
        # The step's end of its first path (zpos, written back only at the end) and how far
        # the new path strays from it: beyond what the pairs were found for, look at everyone.
        # With the partners of the fast pucks only (find_partners), a puck made fast looks too.
        end = self.zpos.item(k)
        stray = max(abs(x - end), abs(x + v * (self.dt - self.t_now) - end))
        newly_fast = self.only_fast is not None and not self.only_fast[k] and self.fast_for_any(k)
        if stray > self.covered or newly_fast:
            if newly_fast:
                self.only_fast[k] = True  # (its partners are then all found: once is enough)
            self.reach_out = max(self.reach_out, stray)
            self.add_everyone_near(k, end, stray)

    def add_everyone_near(self, k: int, end: complex, stray: float) -> None:
        """Puck k's path strays `stray` from its step end: its partners from every puck."""
        near = broadphase.rows_near(self.zpos, self.radius, end, self.radius.item(k), stray + self.reach_out)
        for other in near.tolist():
            if other != k:
                self.extra.setdefault(k, set()).add(other)
                self.extra.setdefault(other, set()).add(k)

    def partners_of(self, k: int) -> list[int]:
        """The pucks k may meet this step, in increasing order: hits at one time are resolved in the
        order they were predicted, so that order must not depend on how the pairs were found."""
        out = self.partners.of(k)
        more = self.extra.get(k)
        return out if not more else sorted(set(out) | more)

    def write_back(self) -> None:
        """The pucks whose path changed end the step where their present path has them."""
        for k in self.changed.nonzero()[0].tolist():
            self.zpos[k] = self.zorigin.item(k) + self.zvel.item(k) * self.dt
        for k, dv in self.offset.items():
            self.zvel[k] += dv

    # ------------------------------------------------------------ predicting

    def past_walls(self) -> list[int]:
        """The rows the step ends past a wall: each hit a wall during it (or was there already)."""
        room = room_to_walls(vectors.as_rows(self.zpos), self.radius, (self.width, self.height))
        return (room < 0.0).nonzero()[0].tolist()

    def predicts_pairs(self) -> bool:
        """Whether any pair hit is this stage's: in perfect kiss every one; in the other modes only
        those of fast pucks (a gas whose pucks all move under FAST_FRACTION of their radius has none)
        and, in two-step among unlike masses, those of ours_after."""
        if self.rules.pairs == "perfect-kiss":
            return True
        if self.rules.pairs == "none":
            return False
        if self.unlike:
            return True  # (the hits of unlike pucks the step's end catches are ours: ours_after)
        if self.travel < 0.999 * FAST_FRACTION * self.r_min:
            return False  # the fastest puck is not fast for the smallest one (a gas): no need to look at each
        return bool(self.fast_rows().any())

    def fast_rows(self) -> np.ndarray:
        """Which pucks move FAST_FRACTION of the smallest radius in the step on their first paths: those
        that may be in a fast pair (fast)."""
        return _moves(self.speed_sq, self.r_min, self.dt, FAST_FRACTION)

    def fast_for_any(self, k: int) -> bool:
        """Whether puck k moves FAST_FRACTION of the smallest radius in a step on its present path."""
        return _moves(vectors.squared_abs(self.zvel.item(k)), self.r_min, self.dt, FAST_FRACTION)

    def fast(self, a, b, fraction: float = FAST_FRACTION):
        """Whether a puck of the pair (a, b) (rows, or arrays of rows) moves `fraction` of the smaller
        one's radius in a step on its present path: a big puck's slow push can send a small one
        through its next neighbour as surely as a fast small puck can pass through one."""
        speed_sq = either.maximum(
            vectors.squared_abs(either.take(self.zvel, a)), vectors.squared_abs(either.take(self.zvel, b))
        )
        return _moves(
            speed_sq, either.minimum(either.take(self.radius, a), either.take(self.radius, b)), self.dt, fraction
        )

    def ours_after(self, a, b):
        """Whether the step's end catches the pair (a, b) overlapping and approaching (two-step's case)
        and its hit is yet this stage's, to come in its order (rows, or arrays of rows): the pair
        stage's correction moves each puck its mass share of it, so a puck much lighter than its partner
        (LIKE_MASSES) is moved nearly all of it, into its next neighbour (and light pucks in a cluster
        with an unlike pair, squeezed between heavy ones, were moved back and forth between this stage
        and that one: find_unlike_contacts); and a hit that leaves a puck moving FAST_FRACTION of the
        smallest radius a step may send it through its next neighbour."""
        va, vb = either.take(self.zvel, a), either.take(self.zvel, b)
        end = self.at(a, self.dt) - self.at(b, self.dt)
        caught, _, _ = _caught_overlapping(end, va - vb, either.take(self.radius, a) + either.take(self.radius, b))
        if not either.count(caught):
            return caught  # (most pairs a puck's new path is checked against)
        ma, mb = either.take(self.mass, a), either.take(self.mass, b)
        n = end / either.where(caught, vectors.length(end), 1.0)
        new_a, new_b = collision.collide_along(n, va, vb, ma, mb, self.rules.cr_puck)
        speed_sq = either.maximum(vectors.squared_abs(new_a), vectors.squared_abs(new_b))
        unlike = _unlike(ma, mb)
        if self.in_unlike_contact is not None:  # (a like pair squeezed between heavy pucks: the squeeze is ours)
            unlike = unlike | either.take(self.in_unlike_contact, a) | either.take(self.in_unlike_contact, b)
        return caught & (unlike | _moves(speed_sq, self.r_min, self.dt, FAST_FRACTION))

    def find_partners(self, neighbours) -> None:
        """The pairs that may meet during the step, on any path within 2 travels of the step's ends."""
        pos = vectors.as_rows(self.zpos)
        found = neighbours.pairs_while_moving(pos, self.radius, 2.0 * self.travel)
        if found is not None:
            self.partners = neighbours.partners()
        elif self.rules.pairs != "perfect-kiss":  # only fast pucks' hits (and ours_after's): their partners
            self.only_fast = self.fast_rows()
            if self.in_unlike_contact is not None:
                self.only_fast |= self.in_unlike_contact
            i, j = broadphase.pairs_near(pos, self.radius, self.only_fast.nonzero()[0], 4.0 * self.travel)
            self.partners = broadphase.Partners(i, j, len(pos))
        else:  # paths longer than the list's skin: the pairs within reach of them now
            margin = 4.0 * self.travel
            i, j = broadphase.find_candidate_pairs(pos, self.radius, margin_m=margin, closer=True)
            near = broadphase.squared_distances(pos, i, j) < (self.radius.take(i) + self.radius.take(j) + margin) ** 2
            i, j = i.take(near.nonzero()[0]), j.take(near.nonzero()[0])
            self.partners = broadphase.Partners(i, j, len(pos))

    def find_unlike_contacts(self, neighbours) -> None:
        """Mark the pucks of every cluster of touching (or overlapping) pucks at the step's end that holds a
        pair of unlike masses (LIKE_MASSES): their hits may be ours though slow (ours_after). (Light pucks
        squeezed between heavy ones: the heavy pairs' hits here and the light ones' in the pair stage
        undid each other every step.)"""
        pos = vectors.as_rows(self.zpos)
        i, j, reach = neighbours.pairs(pos, self.radius)  # (the list the pair stage reads next)
        k = broadphase.touching(pos, i, j, reach).nonzero()[0]
        i, j = i.take(k), j.take(k)
        unlike = _unlike(self.mass.take(i), self.mass.take(j)).nonzero()[0]
        cluster = broadphase.clusters(len(pos), i, j)
        self.in_unlike_contact = np.isin(cluster, cluster.take(i.take(unlike)))

    def first_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """The pairs that on their first paths may touch during the step, approaching faster than they rest."""
        i, j = self.partners.i, self.partners.j
        d, w = self.zpos.take(i) - self.zpos.take(j), self.zvel.take(i) - self.zvel.take(j)
        ww, dw = vectors.squared_abs(w), vectors.dot(d, w)
        # Approaching at the start (dw at t = 0 < 0: on a straight line never later if not then),
        # and coming within reach: the closest point of the relative path over the step.
        s = np.minimum(np.maximum(dw / np.where(ww > 0.0, ww, 1.0), 0.0), self.dt)  # time back from the end
        reach = self.radius.take(i) + self.radius.take(j)
        close = (dw - ww * self.dt < 0.0) & (vectors.squared_abs(d - w * s) < reach * reach)
        if self.rules.rest is not None and close.any():  # (ww: at least the approach along their line, squared)
            k = close.nonzero()[0]  # (few: the rest speeds of these only; their line at t = 0, as predict_pairs)
            close[k] = ww.take(k) > self.rules.rest.pairs(i.take(k), j.take(k), d.take(k) - w.take(k) * self.dt) ** 2
        if self.rules.pairs != "perfect-kiss":  # only fast pairs: the others are seen overlapping
            speed_sq = np.maximum(self.speed_sq.take(i), self.speed_sq.take(j))
            fast = _moves(speed_sq, np.minimum(self.radius.take(i), self.radius.take(j)), self.dt, FAST_FRACTION)
            slow = (close & ~fast).nonzero()[0] if self.rules.pairs == "two-step" else ()
            if len(slow):  # (some of them ours too: ours_after)
                fast[slow] = self.ours_after(i.take(slow), j.take(slow))
            close &= fast
        k = close.nonzero()[0]
        if self.rules.held is not None and len(k):  # (ww: at least their approach)
            held = still_held(self.rules.held(i.take(k), j.take(k)), np.sqrt(ww.take(k)))
            k = k.take((~held).nonzero()[0])
        i, j = i.take(k), j.take(k)
        by_pair = np.lexsort((j, i))  # in order of (i, j), however the pairs were found (partners_of)
        return i.take(by_pair), j.take(by_pair)

    def predict_pairs(self, a, b) -> None:
        """Queue the next hit of each pair (a[k], b[k]) on their present paths, if it comes within the
        step, in the pairs' order: numpy arrays of rows (a step's first pairs, or a puck's many partners,
        at once), or one pair (a and b ints) in Python numbers, by the same lines (either.py)."""
        rules, ours = self.rules, False
        if isinstance(a, np.ndarray) and len(a) == 0:
            return
        if rules.pairs != "perfect-kiss":  # the pair stage sees the others overlapping, if they hit
            fast = self.fast(a, b)
            if rules.pairs == "two-step":
                ours = self.ours_after(a, b)  # (hits the pair stage would see that are ours all the same)
                fast = fast | ours
            if not either.count(fast):
                return  # no hit of theirs is this stage's: none is worked out
        t, speed = self.next_hit(a, b, ours)
        ok = t <= self.dt  # (inf where they never meet)
        if rules.pairs != "perfect-kiss":
            ok &= fast
        if rules.rest is not None:  # slower: a resting contact, the contact stage's
            ok &= speed > rules.rest.pairs(a, b, self.at(a, self.t_now) - self.at(b, self.t_now))
        if rules.held is not None and either.count(ok):  # pressed on each other in the last step: resting
            ok &= ~still_held(_held(rules.held, a, b), speed)
        if not isinstance(ok, np.ndarray):  # one pair
            if ok:
                self.push_pair(t, a, b, speed)
            return
        for k in ok.nonzero()[0].tolist():
            self.push_pair(t.item(k), a.item(k), b.item(k), speed.item(k))

    def push_pair(self, t: float, a: int, b: int, speed: float) -> None:
        """Queue a hit of the pair (a, b) at t, approaching at `speed`; not a stuck pair's slower than
        STUCK_SPEED_MPS (the round-off its last solve left)."""
        if speed <= STUCK_SPEED_MPS and b in self.stuck.get(a, ()):
            return
        self.push(t, a, b)

    def next_hit(self, a, b, ours=False):
        """(t, u) for the pairs (a, b) on their present paths: when they next hit (s into the step; inf if
        never) and how fast they then approach along the normal (m/s); arrays, or one pair (predict_pairs).

        A hit the step's end would catch overlapping and approaching is the pair stage's (never, here),
        except in two-step where a puck of the pair moves CHAIN_FRACTION of its radius in a step, or
        the hit is otherwise ours (`ours`: ours_after): then it comes t_p before the end (the course's
        case; see the module docstring).
        """
        t_now, dt, mode = self.t_now, self.dt, self.rules.pairs
        d, w = self.at(a, t_now) - self.at(b, t_now), either.take(self.zvel, a) - either.take(self.zvel, b)
        reach = either.take(self.radius, a) + either.take(self.radius, b)
        t, speed = collision.contact_time(d, w, reach)
        t = t_now + either.where(t > 0.0, t, 0.0)  # overlapping and approaching (by round-off): they hit now
        if mode == "perfect-kiss":
            return t, speed
        caught, t_p, u = _caught_overlapping(d + w * (dt - t_now), w, reach)
        if mode == "two-step":  # a puck over its radius a step may start a chain: its hits in order here
            chain = self.fast(a, b, CHAIN_FRACTION)
            here = caught & (chain | (ours & _in_time(dt - t_p, t_now, dt)))
            t, speed = either.where(here, either.maximum(dt - t_p, t_now), t), either.where(here, u, speed)
            caught = either.where(chain | ours, False, caught)
        return either.where(caught, math.inf, t), speed

    def predict_walls(self, k: int) -> None:
        """Queue puck k's next wall hit on its present path, if it comes within the step."""
        x, v, r = self.at(k, self.t_now), self.zvel.item(k), self.radius.item(k)
        for axis, (xa, va, size) in enumerate(((x.real, v.real, self.width), (x.imag, v.imag, self.height))):
            if collision.wedged(r, size):
                continue  # no hit, ever (walls.stop_wedged)
            t = collision.wall_time(xa, va, r, size - r)
            if t is None or self.t_now + t > self.dt or not abs(va) > self._wall_rest(k, axis):
                continue
            if self.rules.cr_wall < 1.0 and self.hit_walls.get((k, axis), 0) >= repeat_max(self.rules.cr_wall):
                continue  # (see REPEAT_DECAY: a puck squeezed against the wall by another)
            self.push(self.t_now + t, k, -1 - axis)

    def moving_faster_than_wall_rest(self, rows: list[int]) -> list[int]:
        """Those of `rows` that move faster than their wall rest speed along an axis: no other can have
        a wall hit queued (predict_walls), as a pile's pucks resting on the floor cannot, some forty a step."""
        rest = self.rules.wall_rest
        if rest is None:
            return rows
        v = self.zvel.take(rows)
        rest = rest.take(rows, axis=0)
        x_rest, y_rest = (rest, rest) if rest.ndim == 1 else (rest[:, 0], rest[:, 1])
        fast = (np.abs(v.real) > x_rest) | (np.abs(v.imag) > y_rest)
        return np.array(rows).take(fast.nonzero()[0]).tolist()

    def _wall_rest(self, k: int, axis: int) -> float:
        """Puck k's rest speed towards the walls across `axis`. Held on a wall in the last step, it rests
        there whatever its speed, unless a hit in this step drove it in: then it bounces (a puck dropped on
        one sliding along the floor stuck to it, half the energy gone, where the lower one was held)."""
        rest = self.rules.wall_rest
        if rest is None:
            return 0.0
        speed = rest.item(k) if rest.ndim == 1 else rest.item(k, axis)
        if speed == math.inf and self.changed.item(k) and self.rules.rest is not None:
            return self.rules.rest.walls.item(k, axis)
        return speed

    def predict(self, k: int) -> None:
        """Every next hit of puck k (its path just changed)."""
        if self.rules.walls:
            self.predict_walls(k)
        if self.partners is not None:
            others = self.partners_of(k)
            if len(others) > FEW_PARTNERS:  # at once in numpy (a fast puck in a crowd)
                self.predict_pairs(np.full(len(others), k), np.array(others, dtype=np.intp))
                return
            for other in others:  # one by one in Python numbers
                self.predict_pairs(k, other)

    def push(self, t: float, a: int, b: int) -> None:
        """Queue a hit of a with b (b < 0: the wall across axis -1 - b), as their paths are now."""
        versions = (self.version.get(a, 0), self.version.get(b, 0) if b >= 0 else 0)
        self.seq += 1
        heapq.heappush(self.queue, (t, self.seq, a, b, versions))

    # ------------------------------------------------------------ resolving

    def run(self) -> None:
        """Resolve the queued hits, earliest first, predicting again for the pucks each changes."""
        events = 0
        while self.queue:
            t, _, a, b, versions = heapq.heappop(self.queue)
            if versions != (self.version.get(a, 0), self.version.get(b, 0) if b >= 0 else 0):
                continue  # one of them changed path since: no longer its next hit
            events += 1
            if events > MAX_EVENTS:
                self.hits.capped = True
                return
            self.t_now = t
            if b < 0:
                self.bounce(a, -1 - b)
                self.predict(a)
            else:
                for k in self.collide(a, b):  # the pucks whose paths it changed
                    self.predict(k)

    def bounce(self, k: int, axis: int) -> None:
        """Puck k reaches the wall across `axis` now: its normal velocity reverses times cr_wall."""
        x, v = self.at(k, self.t_now), self.zvel.item(k)
        e, a = self.rules.cr_wall, self.rules.accel_y_mps2
        self.hits.walls += 1
        self.hits.bounced.append(k)
        self.hit_walls[k, axis] = hits = self.hit_walls.get((k, axis), 0) + 1
        if e < 1.0 and hits >= repeat_max(e):  # its last hit here: it rests on the wall (off_a_pinned)
            self.pinned[k] = self.wall_normal(x, axis)
            e = 0.0
        if self.rattle(k, axis, v) >= RATTLE_MAX:  # it stops across them, where it is
            self.hits.rattled = True
            e = 0.0
        if axis == 0:
            self.set_path(k, x, complex(collision.bounce(v.real, e), v.imag))
        elif a == 0.0:
            self.set_path(k, x, complex(v.real, collision.bounce(v.imag, e)))
        else:
            vy, offset = self.bounce_under_gravity(v.imag, a, e)
            self.set_path(k, x, complex(v.real, vy))
            self.offset[k] = complex(0.0, offset)

    def rattle(self, k: int, axis: int, v: complex) -> int:
        """How many times in a row puck k, coming at v, has hit the two walls across `axis` by turns, this hit
        included, with no other change of its path in between (RATTLE_MAX)."""
        high = (v.real > 0.0) if axis == 0 else (v.imag > 0.0)  # (which wall: the way it goes, not where it is)
        version, side, count = self.rattles.get((k, axis), (-1, high, 0))
        count = count + 1 if version == self.version.get(k, 0) and side != high else 1
        self.rattles[k, axis] = (self.version.get(k, 0) + 1, high, count)  # (set_path comes next: + 1)
        return count

    def wall_normal(self, x: complex, axis: int) -> complex:
        """The normal into the table of the wall across `axis` nearer to x (collision.WALL_NORMALS)."""
        at, size = (x.real, self.width) if axis == 0 else (x.imag, self.height)
        return collision.WALL_NORMALS[axis if at < 0.5 * size else axis + 2]

    def bounce_under_gravity(self, vy: float, a: float, e: float) -> tuple[float, float]:
        """(velocity along y of the path to the step's end, what to add to it at the end) after a
        floor or ceiling hit now, under a pull a (m/s^2) along y, at restitution e; vy: the step's velocity.

        Semi-implicit Euler samples a parabola exactly: over a step whose end velocity is vy,
        the puck is at y0 + (vy - a dt / 2) s + a s^2 / 2 at time s, and vy is that parabola's
        velocity half a step before the end. So the hit is resolved on the parabola: the speed
        there at contact reverses times e, a new parabola leaves the wall, and the step ends
        on it with its velocity half a step back, as if the step had run continuously: bounce
        heights fall by e^2. (A straight path is kept for the rest of the step's hits.)
        """
        s, left = self.t_now, self.dt - self.t_now
        leave = collision.bounce(vy - a * (0.5 * self.dt - s), e)  # off the speed at contact
        end = leave + a * (0.5 * self.dt - s)  # the new parabola's velocity half a step before the end
        if left <= 0.0 and leave * vy < 0.0:
            return leave, end - leave  # a hit at the very end
        path = leave + 0.5 * a * left  # to where the new parabola is at the step's end
        if path * vy >= 0.0 or left <= 0.0:
            return 0.0, 0.0  # it would be back at the wall within the step: it lands there
        return path, end - path

    def collide(self, a: int, b: int) -> tuple[int, ...]:
        """a and b hit now: they collide along the normal (collision.collide_along); returns the
        pucks whose paths changed.

        The normal is the line of centres now; in two-step, for a pair the end of
        the step would catch overlapping and approaching, the line of centres there.
        Below restitution 1, a pair's repeat_max-th hit in a step and any after it are `capped`.
        """
        capped = self.capped(a, b)
        if capped is not None:
            return capped
        xa, xb = self.at(a, self.t_now), self.at(b, self.t_now)
        va, vb = self.zvel.item(a), self.zvel.item(b)
        rb = self.radius.item(b)
        n, overlap, seen, reach = xa - xb, 0.0, (xa, xb), self.radius.item(a) + rb  # the record: where, how deep
        if self.rules.pairs == "two-step":
            left = self.dt - self.t_now
            end = n + (va - vb) * left
            caught, t_p, _ = _caught_overlapping(end, va - vb, reach)
            if caught and (_in_time(self.dt - t_p, self.t_now, self.dt) or self.fast(a, b, CHAIN_FRACTION)):
                n, overlap, seen = end, reach - abs(end), (xa + va * left, xb + vb * left)
        n /= abs(n)
        pinned = self.off_a_pinned(a, b, n, va, vb, xb)
        if pinned:
            new_a, new_b, xb = pinned
        elif pinned := self.off_a_pinned(b, a, -n, vb, va, xa):
            new_b, new_a, xa = pinned
        else:
            new_a, new_b = collision.collide_along(n, va, vb, self.mass.item(a), self.mass.item(b), self.rules.cr_puck)
        if new_a == va and new_b == vb:
            return ()  # nothing changed (round-off): predicting the same hit again would never end
        self.set_path(a, xa, new_a)
        self.set_path(b, xb, new_b)
        after = (self.at(a, self.dt), self.at(b, self.dt)) if overlap else seen
        self.hits.rows.append((a, b, n, seen[1], overlap, reach, rb, *seen, *after, va, vb, new_a, new_b))
        key = _key(a, b)
        self.hit_pairs[key] = self.hit_pairs.get(key, 0) + 1
        if key not in self.first_speed:  # (a pair in the pi setup hits thousands of times a step)
            self.first_speed[key] = -vectors.dot(va - vb, n)
        return a, b

    def capped(self, a: int, b: int) -> tuple[int, ...] | None:
        """Below restitution 1, what a pair's hit does once the pair has hit repeat_max times in the step: the
        pucks whose paths it changed; None: it is an ordinary hit. Approaching REPEAT_DECAY as fast as at
        its first hit or slower, as the cap expects (a cluster's collapse), nothing: the pair stage parts
        what is left. Faster (a squeeze: a heavy puck keeps pushing a light one), the pair sticks (stick).
        A pair with a puck resting on a wall (pinned) or stuck counts as inelastic as the wall: an elastic
        puck between a heavy one and a puck pinned in a corner was hit 50000 times at one moment."""
        key, cr = _key(a, b), self.rules.cr_puck
        if a in self.pinned or b in self.pinned or a in self.stuck or b in self.stuck:
            cr = min(cr, self.rules.cr_wall)
        stuck = b in self.stuck.get(a, ())
        if cr >= 1.0 or not (stuck or self.hit_pairs.get(key, 0) + 1 >= repeat_max(cr)):
            return None
        if not stuck:
            x, w = self.at(a, self.t_now) - self.at(b, self.t_now), self.zvel.item(a) - self.zvel.item(b)
            if -vectors.dot(w, x) / abs(x) <= REPEAT_DECAY * self.first_speed.get(key, math.inf):
                return ()
        self.solves[key] = solves = self.solves.get(key, 0) + 1
        return self.stick(a, b) if solves <= STUCK_SOLVES_MAX else ()

    def stick(self, a: int, b: int) -> tuple[int, ...]:
        """The pair (a, b) sticks for the rest of the step: it, every stuck pair touching it and the walls
        its pucks touch collide at once, perfectly inelastically (collapse.py); returns the pucks whose
        paths changed (none if nothing approached faster than round-off). (A light puck stuck to a heavy
        one and bouncing off an elastic wall between them hit each several thousand times a step.)"""
        self.stuck.setdefault(a, set()).add(b)
        self.stuck.setdefault(b, set()).add(a)
        bodies, pairs = self.stuck_cluster(a, b)
        x = {k: self.at(k, self.t_now) for k in bodies}
        v = {k: self.zvel.item(k) for k in bodies}
        walls = [(k, normal) for k in bodies for normal in self.walls_touched(k, x[k])]
        ends = pairs + [(k, -1) for k, _ in walls]
        n = np.array([(x[p] - x[q]) / abs(x[p] - x[q]) for p, q in pairs] + [normal for _, normal in walls])
        vn = np.array([vectors.dot(v[p] - (v[q] if q >= 0 else 0.0), n_k) for (p, q), n_k in zip(ends, n)])
        if not (vn < -STUCK_SPEED_MPS).any():
            return ()
        at = {k: i for i, k in enumerate(bodies)}
        p_a, p_b = np.array([at[p] for p, _ in ends]), np.array([at[q] if q >= 0 else -1 for _, q in ends])
        push = collapse.impulses(n, vn, p_a, p_b, 1.0 / self.mass.take(bodies)) * n
        new = dict(v)
        for (p, q), dv in zip(ends, push.tolist()):
            new[p] += dv / self.mass.item(p)
            if q >= 0:
                new[q] -= dv / self.mass.item(q)
        for (p, q), dv, n_k in zip(ends, push.tolist(), n.tolist()):
            if dv and q >= 0:
                reach, rq = self.radius.item(p) + self.radius.item(q), self.radius.item(q)
                self.hits.rows.append(
                    (p, q, n_k, x[q], 0.0, reach, rq, x[p], x[q], x[p], x[q], v[p], v[q], new[p], new[q])
                )
                self.hit_pairs[_key(p, q)] = self.hit_pairs.get(_key(p, q), 0) + 1
        changed = tuple(k for k in bodies if new[k] != v[k])
        for k in changed:
            self.set_path(k, x[k], new[k])
        return changed

    def walls_touched(self, k: int, x: complex) -> list[complex]:
        """The normals into the table of the walls puck k at x touches now (within round-off), and of the
        wall it is pinned to (bounce)."""
        r = self.radius.item(k)
        rooms = collision.wall_rooms(x.real, x.imag, r, (self.width, self.height))
        out = [normal for room, normal in zip(rooms, collision.WALL_NORMALS, strict=True) if room <= r * 1e-9]
        pinned = self.pinned.get(k)
        return out if pinned is None or pinned in out else [*out, pinned]

    def stuck_cluster(self, a: int, b: int) -> tuple[list[int], list[tuple[int, int]]]:
        """(the pucks, the pairs i < j) of the stuck pairs touching now that (a, b) reaches through others."""
        bodies, pairs, todo = [a, b], [_key(a, b)], [a, b]
        while todo:  # (each puck once: bounded by the table)
            p = todo.pop()
            for q in sorted(self.stuck.get(p, ())):
                if _key(p, q) in pairs or not self.touching(p, q):
                    continue
                pairs.append(_key(p, q))
                if q not in bodies:
                    bodies.append(q)
                    todo.append(q)
        return bodies, pairs

    def touching(self, p: int, q: int) -> bool:
        """Whether pucks p and q touch now (within round-off of their reach)."""
        reach = self.radius.item(p) + self.radius.item(q)
        return abs(self.at(p, self.t_now) - self.at(q, self.t_now)) <= reach * (1.0 + 1e-9)

    def off_a_pinned(self, a: int, b: int, n: complex, va: complex, vb: complex, xb: complex) -> tuple:
        """(va, vb, xb) after b, now at xb, hits puck a, which rests on a wall (pinned: its hits there reached
        repeat_max; or held there by the contacts) and which b pushes into it along n (from b to a): b
        bounces off the wall through a, its speed along n reversed times cr_wall, a stays. () if a is not
        so pinned.

        The exact run has infinitely many ever faster hits of a between b and the wall; at cr_wall 0
        their limit is this one (b stops). Colliding a and b as a pair let b pass through a once a
        could no longer hit the wall. A puck the contacts hold on the wall moves into it on its path
        here (by this step's gravity, say), where the contacts will put it back: b, which met it there,
        is moved out of where it rests as a bounce there would have left it (a 50 kg puck landing at
        dt 1/30 on a 4 kg one on the floor ended 5.6 mm deep in it)."""
        wall, held = self.pinned.get(a), False
        if wall is None:
            wall, held = self.held_on_wall(a, b, n), True
        towards = vectors.dot(vb, n)
        if wall is None or vectors.dot(n, wall) >= -INTO_WALL or not towards > 0.0:
            return ()  # (b does not push a into the wall: a, sliding along it into b, hits it as any puck)
        e = self.rules.cr_wall
        if held:
            overlap = self.radius.item(a) + self.radius.item(b) - abs(xb - self.on_wall(a, wall))
            if overlap > 0.0:
                xb -= (1.0 + e) * overlap * n
        return va, vb - (1.0 + e) * towards * n, xb

    def on_wall(self, k: int, wall: complex) -> complex:
        """Where puck k rests on the wall whose normal into the table is `wall`, beside where it is now."""
        x, r = self.at(k, self.t_now), self.radius.item(k)
        if wall.real:
            return complex(r if wall.real > 0.0 else self.width - r, x.imag)
        return complex(x.real, r if wall.imag > 0.0 else self.height - r)

    def held_on_wall(self, a: int, b: int, n: complex) -> complex | None:
        """The normal of a wall puck a rests on (the contacts held it there in the last step: its wall rest
        speed is infinite) that b, much heavier (LIKE_MASSES), pushes it into along n; else None. Such a
        puck is pinned there too (off_a_pinned): its bounce off the wall is never predicted, so colliding
        it as a pair drove it past the wall, and putting it back drove it into b (a 50 kg puck landing on
        a 4 kg one on the floor sank 3.5 cm into it, at dt 1/30 and 1/60)."""
        rest = self.rules.wall_rest
        if rest is None or rest.ndim != 2 or not self.mass.item(b) > LIKE_MASSES * self.mass.item(a):
            return None
        x = self.at(a, self.t_now)
        for axis in (0, 1):
            if rest.item(a, axis) == math.inf and vectors.dot(n, normal := self.wall_normal(x, axis)) < -INTO_WALL:
                return normal
        return None


def _key(a: int, b: int) -> tuple[int, int]:
    """One key per pair, whichever puck is named first."""
    return (a, b) if a < b else (b, a)


def _moves(speed_sq, radius, dt: float, fraction: float):
    """Whether a puck of speed sqrt(speed_sq) and that radius moves `fraction` of its radius in a step
    (numpy arrays, or one puck in Python numbers: the same bits)."""
    lim = fraction * radius / dt
    return speed_sq > lim * lim


def _held(held: Callable[[np.ndarray, np.ndarray], np.ndarray], a, b):
    """Whether the contacts hold each pair (a, b) (Rules.held, which takes pairs i < j): arrays of rows,
    or one pair (then a bool)."""
    if isinstance(a, np.ndarray):
        return held(np.minimum(a, b), np.maximum(a, b))
    return bool(held(np.array([min(a, b)]), np.array([max(a, b)])).item(0))


def _unlike(m1, m2):
    """Whether masses m1 and m2 differ by over LIKE_MASSES times (numbers, or arrays of them)."""
    return either.maximum(m1, m2) > LIKE_MASSES * either.minimum(m1, m2)


def _in_time(t, t_now, dt: float):
    """Whether a two-step hit placed at t (t_p before the step's end) comes after now: one that would come
    earlier (an overlap deeper than the pair's approach since now explains) is resolved now along the line
    of centres now, as a first contact, unless it is a chain's. Placed now along the line of centres at the
    end, a light puck caged by heavy ones was hit thousands of times at one moment, each hit undoing the last.
    (Within round-off of dt: a hit placed at t is resolved when t_now is t.)"""
    return t >= t_now - 1e-9 * dt


def _caught_overlapping(d, w, reach):
    """(caught, t_p, u) for a pair d = x1 - x2 apart at the step's end, approaching at w = v1 - v2 there:
    whether the step ends with the pair overlapping and approaching (two-step's case), its penetration
    time t_p = overlap / u and u, the approach speed along the line of centres. One pair (complex d
    and w: caught a bool) or many (numpy arrays; t_p and u are 0 where not caught)."""
    dist = vectors.length(d)
    if isinstance(dist, float):
        u = -vectors.dot(d, w) / dist if dist > 0.0 else 0.0
        caught = dist < reach and u > 0.0
        return caught, ((reach - dist) / u if caught else 0.0), (u if caught else 0.0)
    u = -vectors.dot(d, w) / np.where(dist > 0.0, dist, 1.0)
    caught = (dist < reach) & (dist > 0.0) & (u > 0.0)
    return caught, np.where(caught, (reach - dist) / np.where(caught, u, 1.0), 0.0), np.where(caught, u, 0.0)
