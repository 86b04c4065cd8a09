"""Stiff springs keep their slow modes: substeps instead of a damping implicit step (substeps.py).

Oracles by hand: a pair of masses m on a spring k rings at omega = sqrt(k / mu),
mu = m / 2; a lattice's slowest mode comes from its stiffness matrix, built
here from the geometry and solved with numpy's eigh, apart from the engine.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from airtable.physics import forces, substeps
from airtable.physics.table import AirTable

DT_S = 1 / 240
M_KG = 0.009
R_M = 0.1
N, L_M = 5, 0.4  # the lattice: N x N pucks, L_M apart, springs on edges and diagonals


def _puck(table: AirTable, pos) -> object:
    return table.add_puck(pos_m=pos, radius_m=R_M, density_kgpm2=M_KG / (math.pi * R_M * R_M))


def _lattice_springs() -> list[tuple[int, int, float]]:
    out = []
    for i in range(N):
        for j in range(N):
            for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
                if 0 <= i + di < N and 0 <= j + dj < N:
                    out.append((i * N + j, (i + di) * N + j + dj, L_M * math.hypot(di, dj)))
    return out


def _lattice_rest() -> np.ndarray:
    return np.array([(3.0 + L_M * i, 3.0 + L_M * j) for i in range(N) for j in range(N)])


def _slowest_mode(k: float) -> tuple[float, np.ndarray]:
    """(omega, unit mode shape (2 N^2,)) of the lattice's slowest vibration, from K = sum of k n n^T blocks."""
    x = _lattice_rest()
    stiffness = np.zeros((2 * N * N, 2 * N * N))
    for a, b, _ in _lattice_springs():
        n = (x[a] - x[b]) / np.linalg.norm(x[a] - x[b])
        block = k * np.outer(n, n)
        for p, q, sign in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            stiffness[2 * p : 2 * p + 2, 2 * q : 2 * q + 2] += sign * block
    w2, shapes = np.linalg.eigh(stiffness / M_KG)
    first = int(np.flatnonzero(w2 > 1e-6 * w2.max())[0])  # after the three rigid motions
    return math.sqrt(w2[first]), shapes[:, first]


def _k_for_slowest_period(steps: float) -> float:
    """The k (N/m) whose slowest lattice mode takes `steps` steps of DT_S a period (omega scales as sqrt(k))."""
    w1, _ = _slowest_mode(1.0)
    return (2 * math.pi / (steps * DT_S) / w1) ** 2


def _mode_amplitudes(k: float, periods: int) -> tuple[np.ndarray, AirTable]:
    """Ring the slowest mode (1 mm) with no dampers; return its amplitude sqrt(q^2 + (q'/omega)^2) at every step."""
    omega, shape = _slowest_mode(k)
    table = AirTable()
    rest = _lattice_rest()
    pucks = [_puck(table, tuple(p)) for p in rest]
    for a, b, length in _lattice_springs():
        table.add_spring(pucks[a], pucks[b], length_m=length, k_Npm=k, damper_Nspm=0.0)
    table.pos_m[:] = rest + 1e-3 * shape.reshape(-1, 2)
    out = []
    for _ in range(round(periods * 2 * math.pi / omega / DT_S)):
        table.step(DT_S)
        q, dq = float(np.dot((table.pos_m - rest).ravel(), shape)), float(np.dot(table.vel_mps.ravel(), shape))
        out.append(math.hypot(q, dq / omega))
    return np.array(out), table


def _busiest_load(k: float) -> float:
    """The busiest puck's sum of k dt^2 / m, in units of the explicit budget forces.EXPLICIT_STIFFNESS."""
    per_puck = np.zeros(N * N)
    for a, b, _ in _lattice_springs():
        per_puck[[a, b]] += k
    return float(per_puck.max()) * DT_S**2 / M_KG / forces.EXPLICIT_STIFFNESS


@pytest.mark.parametrize(
    "beyond", [12.0, 100.0, 1000.0], ids=["12 steps a period", "100 times the explicit budget", "1000 times"]
)
def test_a_stiff_lattice_keeps_its_slowest_mode(beyond: float) -> None:
    # 12 steps a period is the lattice: its busiest puck holds 12 times the explicit budget, and a
    # backward-Euler step lost 74 % of the mode each period. At 100 times, the mode takes 4.2 steps a period.
    k = _k_for_slowest_period(12.0)
    k *= beyond / _busiest_load(k)
    assert _busiest_load(k) == pytest.approx(beyond)
    periods = 8
    amplitude, table = _mode_amplitudes(k, periods)
    per = len(amplitude) // periods
    first, last = amplitude[:per].mean(), amplitude[-per:].mean()
    loss_per_period = 1.0 - (last / first) ** (1.0 / (periods - 1))
    assert abs(loss_per_period) < 0.01
    assert table.notices == []  # nothing solved implicitly: nothing to confess


@pytest.mark.parametrize("steps", [4.0, 6.0, 12.0, 60.0])
def test_a_spring_pair_rings_at_its_own_period(steps: float) -> None:
    # Two 9 g pucks (mu = 4.5 g) on a spring with no damper, stretched 1 cm: period 2 pi sqrt(mu / k).
    # k for `steps` steps a period: 640 N/m at 4 steps (4 substeps), 18 N/m at 60 (none).
    mu = M_KG / 2
    k = mu * (2 * math.pi / (steps * DT_S)) ** 2
    table = AirTable()
    a, b = _puck(table, (4.0, 4.0)), _puck(table, (5.01, 4.0))
    table.add_spring(a, b, length_m=1.0, k_Npm=k, damper_Nspm=0.0)
    energy0 = table.spring_energy_J()
    stretch, energy = [], []
    for _ in range(round(40 * steps)):  # 40 periods
        table.step(DT_S)
        stretch.append(float(np.linalg.norm(a.pos_m - b.pos_m)) - 1.0)
        energy.append(table.kinetic_energy_J() + table.spring_energy_J())
    s = np.array(stretch)
    k_cross = np.flatnonzero((s[:-1] > 0) != (s[1:] > 0))
    t_cross = (k_cross + 1 + s[k_cross] / (s[k_cross] - s[k_cross + 1])) * DT_S  # linear between steps
    period = 2.0 * (t_cross[-1] - t_cross[0]) / (len(t_cross) - 1)
    assert period == pytest.approx(2 * math.pi * math.sqrt(mu / k), rel=0.015)
    # The energy the chart shows is the step's. Semi-implicit Euler's swings within a period, by up
    # to omega h / 2 (h the substep: omega h <= 0.5, so 25 %), and never drifts: its mean over the
    # first 8 periods and over the last 8 agree to 0.5 % (both a few % above the start, which is a
    # turning point of the swing).
    np.testing.assert_allclose(energy, energy0, rtol=0.25)
    window = round(8 * steps)
    first, last = np.mean(energy[:window]), np.mean(energy[-window:])
    assert last == pytest.approx(first, rel=0.005)
    assert first == pytest.approx(energy0, rel=0.05)
    assert table.notices == []


def test_the_substep_count_by_hand() -> None:
    # One spring k between two 9 g pucks: load = k dt^2 / (m SUBSTEP_STIFFNESS), n = ceil(sqrt(load)).
    a, b, mass = np.array([0]), np.array([1]), np.full(2, M_KG)
    for k, n in ((10.0, 1), (60.0, 1), (80.0, 2), (640.0, 4), (1e4, 13)):
        load = k * DT_S**2 / (M_KG * substeps.SUBSTEP_STIFFNESS)
        assert n == max(1, math.ceil(math.sqrt(load)))
        assert substeps.count(mass, a, b, np.array([k]), DT_S) == n
    # Beyond MAX_SUBSTEPS none: the implicit step takes it, and says so.
    assert substeps.count(mass, a, b, np.array([1e6]), DT_S) == 1


@settings(max_examples=25, deadline=None, derandomize=True)  # physics within tolerances: the same scenes every run
@given(
    k=st.floats(1.0, 1e9),
    dt=st.sampled_from([1 / 1000, 1 / 240, 1 / 60, 1 / 30]),
    damper=st.sampled_from([0.0, 2.0]),
)
def test_any_stiffness_steps_to_finite_numbers_and_says_what_it_does(k: float, dt: float, damper: float) -> None:
    table = AirTable()
    a, b, c = _puck(table, (4.0, 4.0)), _puck(table, (4.45, 4.0)), _puck(table, (4.2, 4.4))
    for p, q in ((a, b), (b, c), (c, a)):
        table.add_spring(p, q, length_m=0.5, k_Npm=k, damper_Nspm=damper)
    c.vel_mps = (2.0, -1.0)
    for _ in range(30):
        table.step(dt)
    assert np.isfinite(table.pos_m).all() and np.isfinite(table.vel_mps).all()
    assert math.isfinite(table.spring_energy_J())
    per_puck_load = 2 * k * dt * dt / (M_KG * substeps.SUBSTEP_STIFFNESS)
    implicit = [s for s in table.notices if "implicitly" in s]
    if per_puck_load > substeps.MAX_SUBSTEPS**2 and 2 * k * dt * dt / M_KG > forces.EXPLICIT_STIFFNESS:
        assert len(implicit) == 1  # beyond what substeps take: said, once
    else:
        assert implicit == []  # substeps (or none needed): the spring rings at its own period


# ---------------------------------------------------------------- pieces: a step where many pucks are fast


@pytest.mark.parametrize(
    "moves, fast_ones, mode, want",
    [
        # A puck at speed v moves v dt / (FAST_FRACTION r) "fast lengths" in a step: in n pieces it is fast
        # where that is at least n. 100 pucks may have FEW_FAST = 10 fast in a piece.
        (2.5, 100, "two-step", 3),  # all move 2.5: fast in 1 and 2 pieces, in 3 none
        (2.5, 100, "off", 3),
        (2.5, 100, "perfect-kiss", 1),  # every hit found in order anyway
        (2.5, 100, "none", 1),  # collisions off (step.py): no hits to find
        (2.5, 10, "two-step", 1),  # ten fast ones: the hit stage takes them
        (2.5, 11, "two-step", 3),
        (0.99, 100, "two-step", 1),  # none fast
        (1.01, 100, "two-step", 2),  # just over one fast length: fast in one piece, not in two
        (1000.0, 100, "two-step", substeps.MAX_PIECES),
    ],
)
def test_a_step_is_cut_into_the_fewest_pieces_in_which_few_pucks_are_fast(moves, fast_ones, mode, want) -> None:
    r, dt = 0.1, 1 / 240
    speed = moves * substeps.FAST_FRACTION * r / dt
    vel = np.zeros((100, 2))
    vel[:fast_ones] = (0.6 * speed, 0.8 * speed)  # (a 3-4-5 triangle: the speed exactly)
    vel[fast_ones:] = (0.01, 0.0)
    assert substeps.pieces(vel, np.full(100, r), dt, mode) == want


def test_a_gas_stirred_hot_keeps_its_energy_and_order_when_its_steps_are_cut_into_pieces() -> None:
    # 200 pucks at 10 times the gas demo's speed: steps in pieces, every hit elastic.
    from airtable.demos.demo_0p_gas import gas_scene

    table = gas_scene(200, speed_mps=10.0, seed=3)
    assert substeps.pieces(table.vel_mps, table.radius_m, 1 / 30, table.puck_correction) > 1
    energy = table.kinetic_energy_J()
    seen = 0
    for _ in range(60):
        table.step(1 / 30)
        seen += len(table.last_collisions)
    assert table.kinetic_energy_J() == pytest.approx(energy, rel=1e-12)
    assert seen == table.collision_count > 0  # each piece's collisions are the step's
    i, j = np.triu_indices(table.n_pucks, k=1)
    d = np.hypot(*(table.pos_m[i] - table.pos_m[j]).T)
    # Two-step leaves an overlap where pucks move near half their radius a step, each piece's share
    # here (the demo gas at 3 m/s and dt 1/60 keeps 35 mm whole), far from a centre inside another puck.
    assert (d - table.radius_m[i] - table.radius_m[j]).min() > -0.1 * 0.75
    assert (table.pos_m >= table.radius_m[:, None] - 1e-9).all()
    assert (table.pos_m <= table.size_m - table.radius_m[:, None] + 1e-9).all()


def _squeezed(table: AirTable, n: int, k: float, shrink: list[float], vel: list[tuple[float, float]]) -> None:
    """n pucks on a ring, springs between them shorter than their distance: the springs press them together."""
    rows = []
    for i in range(n):
        angle = 2 * math.pi * i / n
        pos = (5.0 + 0.35 * math.cos(angle), 4.0 + 0.35 * math.sin(angle))
        rows.append(table.add_puck(pos_m=pos, radius_m=0.12, density_kgpm2=0.3, vel_mps=vel[i]))
    s = 0
    for i in range(n):
        for j in range(i + 1, n):
            if shrink[s] < 1.0:  # (a shrink of 1 or more: no spring here)
                length = float(np.hypot(*(table.pos_m[i] - table.pos_m[j]))) * shrink[s]
                table.add_spring(rows[i], rows[j], length_m=length, k_Npm=k, damper_Nspm=0.0)
            s += 1


@settings(max_examples=6, deadline=None, derandomize=True)  # physics within tolerances: the same scenes every run
@given(
    n=st.integers(3, 6),
    k=st.floats(150.0, 800.0),  # 2 to 6 substeps at dt 1/240 for these 14 g pucks
    shrink=st.lists(st.floats(0.2, 1.5), min_size=21, max_size=21),
    vel=st.lists(st.tuples(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0)), min_size=7, max_size=7),
    cr=st.sampled_from([0.0, 0.7, 1.0]),
    gravity=st.booleans(),
)
def test_pucks_springs_squeeze_together_never_gain_energy(n, k, shrink, vel, cr, gravity) -> None:
    """Springs with no dampers pressing pucks into each other: nothing drives them, so their energy
    (kinetic, springs', gravity's) cannot grow; contacts and collisions below restitution 1 only take.
    Held once after the springs' substeps, the contacts pumped up to 27 times the energy in 2 s.
    Semi-implicit Euler's energy, read at each step's end, swings step to step by tens of per cent
    with the stiff springs: compared here as means over the first 0.1 s and the last 0.5 s of 1.5 s."""
    table = AirTable()
    table.gravity_on, table.cr_puck, table.cr_wall = gravity, cr, cr
    _squeezed(table, n, k, shrink, vel)
    if table.n_springs == 0 or substeps.count(table.mass_kg, *table.spring_ends, table.spring_k_Npm, DT_S) == 1:
        return  # (no spring, or soft enough for one step: not the case asked about)
    energy = []
    for _ in range(360):
        table.step(DT_S)
        energy.append(table.kinetic_energy_J() + table.spring_energy_J() + table.gravity_energy_J())
    assert np.all(np.isfinite(table.pos_m))
    assert np.mean(energy[-120:]) <= 1.05 * np.mean(energy[:24])


def test_forces_set_from_outside_act_through_every_piece_of_a_step() -> None:
    """A step in pieces (a stiff spring pressing two pucks together) gives a far puck pushed by a
    force set on it F dt / m, as a step in one piece does."""
    table = AirTable()
    a = table.add_puck(pos_m=(4.88, 4.0), radius_m=0.12, density_kgpm2=0.3)
    b = table.add_puck(pos_m=(5.12, 4.0), radius_m=0.12, density_kgpm2=0.3)  # touching
    table.add_spring(a, b, length_m=0.2, k_Npm=3000.0, damper_Nspm=0.0)  # shorter: it presses them together
    free = table.add_puck(pos_m=(1.0, 1.0), radius_m=0.1, density_kgpm2=0.3)
    for _ in range(5):
        table.step(DT_S)  # (the pair touches: its contacts are held)
    assert table.contact_solver.held_pairs()
    assert substeps.for_contacts(table, DT_S) > 1
    row = table.n_pucks - 1
    table.force_N[row] = (0.3, -0.2)
    table.step(DT_S)
    assert table.vel_mps[row] == pytest.approx(np.array([0.3, -0.2]) * DT_S / table.mass_kg[row], rel=1e-12)
    assert free is not None


@settings(max_examples=12, deadline=None, derandomize=True)
@given(
    k=st.floats(100.0, 5000.0),
    apart=st.floats(0.3, 1.5),
    length=st.floats(0.0, 0.2),
    mode=st.sampled_from(["perfect-kiss", "two-step"]),
)
@example(k=4694.0, apart=0.3, length=0.0, mode="perfect-kiss")
def test_pucks_a_stiff_spring_pulls_together_never_pass_through_each_other(k, apart, length, mode) -> None:
    """Two 14 g pucks (r 0.12 m) set `apart`, joined by a spring shorter than their reach: it pulls them
    into each other at up to 150 m/s. They bounce off each other, elastic; by hand, their order never
    changes. Taken in substeps, the springs carried them through each other, or the energy ran away (40,
    150 and 535 times its start in 2 s). By hand the energy stays at the start, bouncing for ever. In pieces
    of a substep, the springs bent the pucks' paths in a piece by up to 15 % of their radius, and the hits,
    found on straight paths, did work for or against them: 20 times the start in 0.5 s at k 4694 N/m, 0.3 m
    apart (a wide run's). Cut four times finer (substeps.MEETING_PIECES), 40 random pairs over 2 s read at
    most 1.3 times the start but one, 4.1 times (36 of them over 1.2 times before, up to 6.2): a leftover."""
    table = AirTable()
    table.puck_correction = mode
    a = table.add_puck(pos_m=(5.0 - apart / 2, 4.0), radius_m=0.12, density_kgpm2=0.3)
    b = table.add_puck(pos_m=(5.0 + apart / 2, 4.0), radius_m=0.12, density_kgpm2=0.3)
    table.add_spring(a, b, length_m=length, k_Npm=k, damper_Nspm=0.0)
    start = table.kinetic_energy_J() + table.spring_energy_J()
    for _ in range(120):
        table.step(DT_S)
        assert b.pos_m[0] - a.pos_m[0] > 0.24 - 1e-3
        assert table.kinetic_energy_J() + table.spring_energy_J() < 5.0 * start


@pytest.mark.parametrize("variation", [0, 1, 2])
def test_a_dropped_jelly_never_reads_more_energy_than_it_started_with(demos, variation) -> None:
    """The jelly demo (springs in 2, 4, 9 substeps) thrown up and landing: gravity, dampers and bounces at
    restitution 0.7 only take. The stiff one's landing read 15 % more than its start for a few steps when
    its wall hits were resolved once after the springs' substeps; it lands now in pieces of the step."""
    table = AirTable()
    demos["6p"].build(table, variation)

    def energy() -> float:
        return table.kinetic_energy_J() + table.spring_energy_J() + table.gravity_energy_J()

    start, most = energy(), 0.0
    for _ in range(480):  # 2 s: up, the landing, the first bounces
        table.step(DT_S)
        most = max(most, energy())
    assert most <= start * (1.0 + 1e-3)
