"""Hits in time order against an exact event-driven solver of hard discs in a box, written here.

The oracle imports nothing of airtable.physics: plain Python floats, the next
event the earliest of every pair's contact time and every puck's wall times,
everyone advanced to it, the hit resolved as a 1D collision along the line of
centres. In perfect kiss the engine must follow it to round-off over each
scene's first hits (before chaos amplifies round-off), for any dt up to 1/30 s,
wherever those hits are finitely many: an inelastic collapse (see ROUND_OFF)
is found by the oracle and left out.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from airtable.physics.table import AirTable

WIDTH_M, HEIGHT_M = 10.0, 8.7556


# Below restitution 1 discs can hit infinitely often in a finite time: inelastic collapse. A light
# disc squeezed between two others (or a wall and another) is hit by each ever more often at ever
# smaller speeds, and the motion converges to one in which none of them approach each other; but
# hits taken one by one reach that limit only in the limit. The oracle follows them to within
# round-off of it: a pair approaching slower than ROUND_OFF times the scene's top speed does not
# hit (a hit would change less than that; at round-off itself it would change nothing and come
# again at the same time, for ever), and discs less than POSITION_ROUND_OFF times the box's size
# apart touch (a pair that has just hit touches, but its distance holds the positions' round-off:
# with a gap of round-off and a sliding motion the quadratic sees a graze where touching discs that
# approach hit). A touching pair left approaching that slowly, or more than COLLAPSE_HITS hits in a
# run, is a collapse (`collapsed`): no finite run of hits comes near either (a pi setup at the
# scenes' widest mass ratio, 10^6, has 3141 hits; 400 random elastic runs at most 216).
ROUND_OFF = 1e-12
POSITION_ROUND_OFF = 1e-15
COLLAPSE_HITS = 20_000


class Oracle:
    """Discs in the box [0, width] x [0, height], moved from event to event (Rapaport's method)."""

    def __init__(self, pucks: list[list[float]], width: float, height: float, cr_puck: float, cr_wall: float):
        self.p = [list(p) for p in pucks]  # [x, y, vx, vy, r, m]
        self.width, self.height, self.cr_puck, self.cr_wall = width, height, cr_puck, cr_wall
        self.t = 0.0
        self.events = 0
        self.slowest = ROUND_OFF * max((math.hypot(p[2], p[3]) for p in pucks), default=0.0)  # m/s
        self.touch = POSITION_ROUND_OFF * max(width, height)  # m
        self.collapsed = False  # an inelastic collapse met (see ROUND_OFF)

    def _pair_time(self, a: list[float], b: list[float]) -> float:
        dx, dy, wx, wy = a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3]
        reach = a[4] + b[4]
        b_ = dx * wx + dy * wy
        if b_ >= 0.0:
            return math.inf
        dist = math.hypot(dx, dy)
        if dist - reach <= self.touch:  # touching or overlapping, and approaching: they hit now
            if -b_ / dist > self.slowest:
                return 0.0
            self.collapsed = True  # hits converged within round-off of their limit
            return math.inf
        aa = wx * wx + wy * wy
        c = dx * dx + dy * dy - reach * reach
        disc = b_ * b_ - aa * c
        if disc <= 0.0 or math.sqrt(disc) / reach <= self.slowest:  # (the approach speed at contact)
            return math.inf
        return (-b_ - math.sqrt(disc)) / aa

    def _wall_time(self, p: list[float]) -> tuple[float, int]:
        best, axis = math.inf, -1
        for k, size in ((0, self.width), (1, self.height)):
            v = p[2 + k]
            if v < 0.0:
                t = (p[4] - p[k]) / v
            elif v > 0.0:
                t = (size - p[4] - p[k]) / v
            else:
                continue
            if max(t, 0.0) < best:
                best, axis = max(t, 0.0), k
        return best, axis

    def _next(self):
        best = (math.inf, None, None)
        for i, a in enumerate(self.p):
            t, axis = self._wall_time(a)
            if t < best[0]:
                best = (t, i, -1 - axis)
            for j in range(i + 1, len(self.p)):
                t = self._pair_time(a, self.p[j])
                if t < best[0]:
                    best = (t, i, j)
        return best

    def _advance(self, dt: float) -> None:
        for p in self.p:
            p[0] += p[2] * dt
            p[1] += p[3] * dt
        self.t += dt

    def _resolve(self, i: int, j: int) -> None:
        a = self.p[i]
        if j < 0:
            a[2 - 1 - j] *= -self.cr_wall
            return
        b = self.p[j]
        dx, dy = a[0] - b[0], a[1] - b[1]
        d = math.hypot(dx, dy)
        nx, ny = dx / d, dy / d
        u1, u2 = a[2] * nx + a[3] * ny, b[2] * nx + b[3] * ny
        m1, m2 = a[5], b[5]
        # momentum kept, relative normal speed reversed times e
        w1 = (m1 * u1 + m2 * u2 - m2 * self.cr_puck * (u1 - u2)) / (m1 + m2)
        w2 = (m1 * u1 + m2 * u2 + m1 * self.cr_puck * (u1 - u2)) / (m1 + m2)
        a[2], a[3] = a[2] + (w1 - u1) * nx, a[3] + (w1 - u1) * ny
        b[2], b[3] = b[2] + (w2 - u2) * nx, b[3] + (w2 - u2) * ny

    def run_until(self, t_end: float) -> None:
        """Advance to time t_end, resolving every hit on the way; stop where it meets a collapse."""
        for _ in range(COLLAPSE_HITS):
            t, i, j = self._next()
            if self.collapsed:
                return
            if self.t + t > t_end:
                break
            self._advance(t)
            self._resolve(i, j)
            self.events += 1
        else:
            self.collapsed = True
            return
        self._advance(t_end - self.t)

    def time_of_event(self, n: int, t_max: float) -> float:
        """The time of the n-th hit from now (t_max if fewer come before it), on a copy."""
        copy = Oracle(self.p, self.width, self.height, self.cr_puck, self.cr_wall)
        for _ in range(n):
            t, i, j = copy._next()
            if copy.t + t > t_max:
                return t_max
            copy._advance(t)
            copy._resolve(i, j)
        return copy.t


# Round-off. The engine holds every coordinate to some ulps: it rounds each position once a step
# (x + v dt: the same increment rounds the same way step after step) and places each hit on positions
# it takes back from the step's end; the oracle rounds once an event. Where the motion is chaotic those
# ulps grow, in any solver: an error e across the line of centres of a touching pair turns the normal
# by e / reach, and the pair's velocities with it (in one scene 4.5e-15 m at the second hit, with 0.15 m
# of reach at 100 m/s, is 1.2e-7 m nine hits later). The oracle measures that growth on itself:
# ROUND_OFF_RUNS runs from starts with every coordinate (x, y, vx, vy) moved by one ulp, up or down at
# random (from the scene's seed), each stopped at every step's end as the engine is; the spread is the
# farthest any of them ends from the unmoved run. (Not the start scaled by 1 + 1e-15: that moves two
# discs apart by 1e-15 times their distance, 1e-16 m for a touching pair, a tenth of one rounding of
# their coordinates; it failed four scenes where the engine parts from the exact motion by round-off at
# the first hits, as the oracle does: a few ulps, in exact arithmetic.) Over 3000 random scenes the engine
# ended at most 6 spreads from the oracle.
ROUND_OFF_RUNS = 5


def round_off_spread(pucks, steps: int, dt: float, cr_puck, cr_wall, seed: int, want) -> np.ndarray | None:
    """How far the oracle's end after `steps` steps of dt moves under round-off (see ROUND_OFF_RUNS),
    per column (x, y: m; vx, vy: m/s) of `want`, its unmoved end; None if a run meets a collapse."""
    rng = np.random.default_rng((seed, 1))
    spread = np.zeros(4)
    for _ in range(ROUND_OFF_RUNS):
        signs = rng.choice((-1.0, 1.0), size=(len(pucks), 4))
        start = [[c + sign * math.ulp(c) for c, sign in zip(p[:4], row)] + p[4:] for p, row in zip(pucks, signs)]
        oracle = Oracle(start, WIDTH_M, HEIGHT_M, cr_puck, cr_wall)
        for k in range(1, steps + 1):
            oracle.run_until(k * dt)
            if oracle.collapsed:
                return None
        spread = np.maximum(spread, np.abs(np.array([p[:4] for p in oracle.p]) - want).max(axis=0))
    return spread


def random_scene(seed: int, n: int) -> list[list[float]]:
    """n discs in the box, none overlapping: radii over two decades (1 cm to 1 m), masses over six
    (1 g to 1 t), speeds up to 200 m/s in any direction."""
    rng = np.random.default_rng(seed)
    pucks: list[list[float]] = []
    for _ in range(n):
        r = 10.0 ** rng.uniform(-2.0, 0.0)
        for _attempt in range(400):
            x, y = rng.uniform(r, WIDTH_M - r), rng.uniform(r, HEIGHT_M - r)
            if all(math.hypot(x - p[0], y - p[1]) > r + p[4] + 1e-6 for p in pucks):
                break
            if _attempt % 50 == 49:
                r *= 0.5
        else:
            continue
        speed, angle = 10.0 ** rng.uniform(-1.0, math.log10(200.0)), rng.uniform(0.0, 2.0 * math.pi)
        mass = 10.0 ** rng.uniform(-3.0, 3.0)
        pucks.append([x, y, speed * math.cos(angle), speed * math.sin(angle), r, mass])
    return pucks


def table_of(pucks, cr_puck: float, cr_wall: float, width=WIDTH_M, height=HEIGHT_M) -> AirTable:
    table = AirTable(width, height)
    table.puck_correction = "perfect-kiss"
    table.cr_puck, table.cr_wall = cr_puck, cr_wall
    for x, y, vx, vy, r, m in pucks:
        table.add_puck((x, y), r, m / (math.pi * r * r), (vx, vy))
    return table


dts = st.sampled_from([1 / 1000, 1 / 240, 1 / 120, 1 / 60, 1 / 30]) | st.floats(1 / 1000, 1 / 30)
restitutions = st.sampled_from([1.0, 1.0, 0.9, 0.5])


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), dts, restitutions, restitutions)
@example(seed=15, n=12, dt=1 / 32, cr_puck=1.0, cr_wall=1.0)  # 29 hits in a step: chaos (the tolerance)
@example(seed=46, n=20, dt=1 / 32, cr_puck=0.9, cr_wall=1.0)  # a pair hits 4+ times in a step (repeat_max)
@example(seed=1980032180, n=19, dt=1 / 30, cr_puck=0.5, cr_wall=0.5)  # issue 24: a collapse, left out (ROUND_OFF)
@example(seed=4089532836, n=13, dt=1 / 240, cr_puck=1.0, cr_wall=1.0)  # round-off at the first hits, grown ...
@example(seed=4044363540, n=17, dt=1 / 240, cr_puck=1.0, cr_wall=0.9)  # ... past 1e-9 m (round_off_spread)
@example(seed=3250422163, n=11, dt=0.013400020908274319, cr_puck=1.0, cr_wall=0.5)  # 1.2e-7 m
@example(seed=2016456835, n=27, dt=1 / 1000, cr_puck=1.0, cr_wall=0.5)  # 203 steps, each rounding every position
@example(seed=30, n=29, dt=1 / 30, cr_puck=0.5, cr_wall=1.0)  # a pair's 10 hits in a step, all real (repeat_max)
@example(seed=2023680856, n=27, dt=1 / 30, cr_puck=0.9, cr_wall=0.5)  # a puck's 11 hits on a wall, all real
@example(seed=1680487804, n=13, dt=1 / 120, cr_puck=0.5, cr_wall=1.0)
def test_perfect_kiss_follows_the_exact_hard_disc_motion(seed: int, n: int, dt: float, cr_puck, cr_wall) -> None:
    pucks = random_scene(seed, n)
    oracle = Oracle(pucks, WIDTH_M, HEIGHT_M, cr_puck, cr_wall)
    speed = max(math.hypot(p[2], p[3]) for p in pucks)
    # The first 12 hits, or 0.5 s; then the whole steps within that. (A gram at 100 m/s glancing
    # off a tonne turns round-off into metres within a few dozen hits, in any solver.)
    horizon = oracle.time_of_event(12, 0.5)
    steps = max(1, int(horizon / dt))
    oracle.run_until(steps * dt)
    # The claim is for runs of finitely many hits: the engine follows a pair for events.repeat_max hits
    # in a step (a collapse can take millions: a step has a frame's time), then the overlap stage.
    assume(not oracle.collapsed)
    want = np.array([p[:4] for p in oracle.p])
    # A step can hold more hits than the horizon (29 at 200 m/s and masses 5 decades apart in one step
    # of 1/32 s), and small fast discs turn an ulp into 1e-7 m within a dozen hits: the oracle itself
    # then moves further than 1e-9 m when its start moves by round-off. The engine must agree with it
    # 1e-9 m, or 100 times as well as the oracle agrees with itself under round-off (round_off_spread).
    chaos = round_off_spread(pucks, steps, dt, cr_puck, cr_wall, seed, want)
    assume(chaos is not None)
    table = table_of(pucks, cr_puck, cr_wall)
    for _ in range(steps):
        table.step(dt)
    atol = max(1e-9, 100.0 * float(chaos[:2].max()))
    np.testing.assert_allclose(table.pos_m, want[:, :2], rtol=0.0, atol=atol)
    np.testing.assert_allclose(
        table.vel_mps, want[:, 2:], rtol=0.0, atol=max(1e-9 * max(speed, 1.0), 100.0 * float(chaos[2:].max()))
    )


def test_the_oracle_by_hand() -> None:
    # Two equal discs head on at 1 m/s each, 1 m apart edge to edge: they touch at 0.5 s and swap
    # velocities; at 1 s each is back where it started, moving outwards.
    oracle = Oracle([[3.0, 4.0, 1.0, 0.0, 0.5, 1.0], [5.0, 4.0, -1.0, 0.0, 0.5, 1.0]], 10.0, 8.0, 1.0, 1.0)
    oracle.run_until(1.0)
    assert oracle.events == 1
    assert oracle.p[0][:3] == pytest.approx([3.0, 4.0, -1.0], abs=1e-15)
    assert oracle.p[1][:3] == pytest.approx([5.0, 4.0, 1.0], abs=1e-15)
    # A disc at 2 m/s, 1 m from the right wall edge to edge, e = 0.5: there at 0.5 s, then 1 m/s back.
    oracle = Oracle([[8.5, 4.0, 2.0, 0.0, 0.5, 1.0]], 10.0, 8.0, 1.0, 0.5)
    oracle.run_until(1.5)
    assert oracle.p[0][:3] == pytest.approx([8.5, 4.0, -1.0], abs=1e-15)


def test_the_oracle_follows_an_inelastic_collapse_to_its_limit_and_says_so() -> None:
    # By hand, in 1D: a 1 kg disc between two 100 kg ones, the left coming at 1 m/s, restitution 0.5.
    # The light one is hit by each in turn, ever more often at ever smaller speeds; in the limit no
    # pair approaches: the three move together at 100 / 201 m/s (momentum), within a finite time.
    oracle = Oracle(
        [[3.0, 4.0, 1.0, 0.0, 0.5, 100.0], [4.1, 4.0, 0.0, 0.0, 0.5, 1.0], [5.3, 4.0, 0.0, 0.0, 0.5, 100.0]],
        20.0,
        8.0,
        0.5,
        1.0,
    )
    oracle.run_until(1.0)
    assert oracle.collapsed and oracle.t < 1.0
    assert [p[2] for p in oracle.p] == pytest.approx([100.0 / 201.0] * 3, abs=1e-9)
    # Issue 24's scene: a 21 g disc between a 315 kg and a 0.5 kg one at 0.5, 1 ms before the end
    # of the first step of 1/30 s, after 400 hits.
    oracle = Oracle(random_scene(1980032180, 19), WIDTH_M, HEIGHT_M, 0.5, 0.5)
    oracle.run_until(1 / 30)
    assert oracle.collapsed and 300 < oracle.events < 1000
    # The same discs at restitution 1: finitely many hits, none of them a collapse.
    oracle = Oracle(random_scene(1980032180, 19), WIDTH_M, HEIGHT_M, 1.0, 1.0)
    oracle.run_until(1 / 30)
    assert not oracle.collapsed and oracle.events < 30 and oracle.t == 1 / 30


# ---------------------------------------------------------------- the pi setup


def pi_count(mass_ratio: float, x_light: float, gap: float, r_light: float, r_heavy: float, dt: float) -> int:
    """Hits (pair and wall) of a still light puck between the left wall and a heavy one coming at
    1 m/s; asserts at every step that neither passes the other nor the wall."""
    table = AirTable(40.0, 6.0)
    table.puck_correction = "perfect-kiss"
    light = table.add_puck((x_light, 3.0), r_light, 1.0 / (math.pi * r_light**2))
    x_heavy = x_light + r_light + r_heavy + gap
    heavy = table.add_puck((x_heavy, 3.0), r_heavy, mass_ratio / (math.pi * r_heavy**2), (-1.0, 0.0))
    # The masses exactly 1 and mass_ratio: a density times pi r^2 can round the ratio 1 to 1 + 2e-16, for which
    # the exact count is 4 (the light puck leaves the heavy one at 4e-16 m/s towards the wall), not 3.
    light.mass_kg, heavy.mass_kg = 1.0, mass_ratio
    for _ in range(round(20.0 / dt)):
        table.step(dt)
        assert light.pos_m[0] >= r_light - 1e-9
        assert heavy.pos_m[0] - light.pos_m[0] >= r_light + r_heavy - 1e-9
        v1, v2 = float(light.vel_mps[0]), float(heavy.vel_mps[0])
        if -1e-12 <= v1 <= v2:  # both leave, the light one no faster: no more hits (round-off may leave -1e-17)
            return table.collision_count + table.wall_collision_count
    raise AssertionError("the pucks never parted")


@settings(max_examples=20, deadline=None, derandomize=True)
@given(
    st.integers(0, 3),
    st.floats(0.0, 1.0),
    st.floats(0.0, 2.0),
    st.floats(0.02, 0.5),
    st.floats(0.02, 0.5) | st.just(0.0),
    dts,
)
@example(n=0, x_frac=0.0, gap=0.0, r_light=0.4403422620412529, r_heavy=0.5, dt=1 / 1000)  # masses 1 and 1 + 2e-16
def test_pi_counts_for_any_geometry(n: int, x_frac: float, gap: float, r_light: float, r_heavy: float, dt) -> None:
    # 3, 31, 314, 3141: the digits of pi (Galperin), wherever the pucks stand and whatever their radii.
    r_heavy = r_heavy or r_light  # equal radii often
    count = pi_count(100.0**n, r_light + x_frac, gap, r_light, r_heavy, dt)
    assert count == [3, 31, 314, 3141][n]


@pytest.mark.parametrize("n", [2, 3])
def test_pi_at_equal_radii_near_the_wall(n: int) -> None:
    # The case: equal radii a little nearer the wall, dt 1/240; it passed through before.
    assert pi_count(100.0**n, 0.15, 0.05, 0.1, 0.1, 1 / 240) == [3, 31, 314, 3141][n]


def test_a_light_puck_squeezed_between_two_heavy_ones_never_passes_through() -> None:
    table = AirTable(20.0, 6.0)
    table.puck_correction = "perfect-kiss"
    heavy = 1e4 / (math.pi * 0.1**2)
    left = table.add_puck((5.0, 3.0), 0.1, heavy, (1.0, 0.0))
    light = table.add_puck((5.5, 3.0), 0.1, 1.0 / (math.pi * 0.1**2))
    right = table.add_puck((6.0, 3.0), 0.1, heavy, (-1.0, 0.0))
    energy = table.kinetic_energy_J()
    for _ in range(400):  # 1.7 s: they meet within 0.35 s, part, and reach no wall
        table.step(1 / 240)
        x = [left.pos_m[0], light.pos_m[0], right.pos_m[0]]
        assert x[1] - x[0] >= 0.2 - 1e-9 and x[2] - x[1] >= 0.2 - 1e-9
    assert table.kinetic_energy_J() == pytest.approx(energy, rel=1e-9)
    assert left.vel_mps[0] < 0.0 < right.vel_mps[0]  # the heavy ones turned back


# ---------------------------------------------------------------- conservation and reversal


def _angular_momentum(table: AirTable) -> float:
    x, v = table.pos_m, table.vel_mps
    return float(np.sum(table.mass_kg * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])))


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.integers(0, 2**32 - 1), st.integers(2, 30), dts)
def test_a_free_cluster_keeps_momentum_angular_momentum_and_energy(seed: int, n: int, dt: float) -> None:
    # A cluster in the middle of a huge table, all elastic: no wall is reached within the run.
    rng = np.random.default_rng(seed)
    pucks = random_scene(seed, n)
    for p in pucks:
        p[2], p[3] = rng.uniform(-5.0, 5.0, 2)  # slower, so that it stays clear of the walls
        p[0] += 1000.0
        p[1] += 1000.0
    table = table_of(pucks, 1.0, 1.0, width=2010.0, height=2010.0)
    m, v = table.mass_kg, table.vel_mps
    scale_p = float(np.sum(m * np.hypot(v[:, 0], v[:, 1])))
    scale_l = float(np.sum(m * np.hypot(*table.pos_m.T) * np.hypot(v[:, 0], v[:, 1])))
    p0, l0, e0 = table.momentum_Ns().copy(), _angular_momentum(table), table.kinetic_energy_J()
    for _ in range(max(1, int(0.5 / dt))):
        table.step(dt)
    np.testing.assert_allclose(table.momentum_Ns(), p0, rtol=0.0, atol=1e-12 * scale_p)
    assert abs(_angular_momentum(table) - l0) <= 1e-12 * scale_l
    assert table.kinetic_energy_J() == pytest.approx(e0, rel=1e-12)


def test_a_gas_run_forward_flipped_and_run_back_returns() -> None:
    # 196 pucks (a 14 x 14 grid), perfect kiss, walls: 3 s forward, every velocity negated, 3 s back.
    rng = np.random.default_rng(5)
    table = AirTable(7.0, 7.0)
    table.puck_correction = "perfect-kiss"
    g = (np.arange(14) + 0.5) * 0.5
    for x in g:
        for y in g:
            angle = rng.uniform(0.0, 2.0 * math.pi)
            table.add_puck((x + rng.uniform(-0.05, 0.05), y), 0.15, 1.0, (math.cos(angle), math.sin(angle)))
    start = table.pos_m.copy()
    for _ in range(360):
        table.step(1 / 120)
    assert table.collision_count > 1000
    table.vel_mps[:] *= -1.0
    for _ in range(360):
        table.step(1 / 120)
    assert np.abs(table.pos_m - start).max() < 1e-6


# ---------------------------------------------------------------- two-step and walls


@pytest.mark.parametrize("dt", [1 / 240, 1 / 60])
def test_two_step_never_lets_a_fast_shot_through_a_still_puck(dt: float) -> None:
    for k in range(40):
        table = AirTable()
        table.puck_correction = "two-step"
        offset = (k / 40.0) * 50.0 * dt  # where in the step the hit falls
        target = table.add_puck((5.0, 4.0), 0.05)
        shot = table.add_puck((2.0 - offset, 4.0 + 0.002 * (k % 5)), 0.05, vel_mps=(50.0, 0.0))  # near head on
        for _ in range(round(0.1 / dt)):
            table.step(dt)
        assert table.collision_count >= 1, k
        assert shot.pos_m[0] < target.pos_m[0], k  # never through


def test_two_step_keeps_the_order_of_a_row_of_touching_pucks() -> None:
    table = AirTable()
    table.puck_correction = "two-step"
    r = 0.05
    row = [table.add_puck((5.0 + 2 * r * k, 4.0), r) for k in range(10)]
    shooter = table.add_puck((4.0, 4.0), r, vel_mps=(20.0, 0.0))
    for _ in range(30):
        table.step(1 / 60)
        x = [shooter.pos_m[0]] + [p.pos_m[0] for p in row]
        assert all(b - a > 2 * r - 1e-6 for a, b in zip(x, x[1:])), x


def test_two_step_keeps_order_when_a_big_slow_puck_knocks_a_small_one_into_a_third() -> None:
    # A user test's case (from a random row): a 1 m puck moving 40 % of its radius a step hits a 3 cm
    # puck touching a 2 cm one. Slow for the big puck, the hit went to the pair stage, whose
    # correction moved the small puck 8.5 cm: through its neighbour. By hand (elastic, one line):
    # big 30 kg at v -> v (30 - 28) / 58; small 28 kg -> 60 v / 58, then it hits the 0.15 kg one:
    # small -> (60 v / 58) (28 - 0.15) / 28.15, the last -> (60 v / 58) 56 / 28.15.
    dt, v = 1 / 120, 0.4 * 1.0 * 120  # 48 m/s: 0.4 m a step
    table = AirTable(40.0, 6.0)
    table.puck_correction = "two-step"
    big = table.add_puck((4.0, 3.0), 1.0, 30.0 / math.pi, (v, 0.0))
    small = table.add_puck((5.5, 3.0), 0.03, 28.0 / (math.pi * 0.03**2))
    last = table.add_puck((5.55, 3.0), 0.02, 0.15 / (math.pi * 0.02**2))
    for _ in range(20):
        table.step(dt)
        x = [big.pos_m[0], small.pos_m[0], last.pos_m[0]]
        assert x[1] - x[0] > 1.03 - 1e-6 and x[2] - x[1] > 0.05 - 1e-6, x
    u = 60.0 * v / 58.0
    expected = [v * 2.0 / 58.0, u * 27.85 / 28.15, u * 56.0 / 28.15]
    np.testing.assert_allclose([big.vel_mps[0], small.vel_mps[0], last.vel_mps[0]], expected, rtol=1e-9)


def test_two_step_keeps_the_course_ratio() -> None:
    # Head on at restitution 1: the correction parts the pair by as much as it overlapped
    # (overlap / separation 1.0000); at e = 0.5 by half of it.
    for e in (1.0, 0.5):
        table = AirTable()
        table.puck_correction = "two-step"
        table.cr_puck = e
        table.add_puck((4.0, 4.0), 0.25, vel_mps=(1.0, 0.0))
        table.add_puck((4.505, 4.0), 0.25)  # overlaps 5 mm after one step of 1/100 s
        table.step(1 / 100)
        c = table.last_collisions
        assert len(c) == 1
        assert c.overlap_m[0] == pytest.approx(0.005, rel=1e-9)
        assert c.separation_m[0] == pytest.approx(e * 0.005, rel=1e-9)


def bounce_heights(e: float, drop_m: float = 0.5, dt: float = 1 / 240, count: int = 5) -> list[float]:
    table = AirTable()
    table.gravity_on, table.sleeping, table.cr_wall = True, False, e
    r = 0.1
    puck = table.add_puck(pos_m=(5.0, r + drop_m), radius_m=r)
    tops, rising, top = [], False, 0.0
    for _ in range(round(10.0 / dt)):
        table.step(dt)
        if rising:
            top = max(top, float(puck.pos_m[1]) - r)
            if puck.vel_mps[1] <= 0.0:
                tops.append(top)
                if len(tops) == count:
                    break
        rising, top = puck.vel_mps[1] > 0.0, (top if rising else 0.0)
    return tops


@pytest.mark.parametrize("e", [0.7, 0.5])
def test_wall_bounces_fall_by_e_squared(e: float) -> None:
    # A ball dropped 0.5 m at restitution e: each bounce reaches e^2 times the height before.
    heights = [0.5] + bounce_heights(e, count=4 if e == 0.7 else 3)
    ratios = [b / a for a, b in zip(heights, heights[1:])]
    assert len(ratios) >= 3
    for ratio in ratios:
        assert ratio == pytest.approx(e * e, rel=0.02)
        assert ratio < e * e * 1.02  # never gaining
