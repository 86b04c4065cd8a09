"""Springs at any stiffness: static sag by hand, the implicit step by hand, bodies that ring down, honesty."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from airtable.physics import forces, substeps
from airtable.physics.forces import GRAVITY_MPS2, Pull
from airtable.physics.table import AirTable
from bench import hard as bench_hard

DT_S = 1 / 240


def _light_puck(table: AirTable, pos_m, mass_kg: float, r: float = 0.05):
    return table.add_puck(pos_m=pos_m, radius_m=r, density_kgpm2=mass_kg / (math.pi * r * r))


def test_explicit_fractions_by_hand_and_a_puck_with_no_spring_warns_nothing() -> None:
    """Pucks 0-1 on a spring of k 1e6, c 0; puck 2 on none (its budget over nothing overflowed:
    a RuntimeWarning on the teacher's console). m 1 kg, dt 1 ms: a puck's budget is
    EXPLICIT_STIFFNESS m / dt^2 = 5e5 N/m, so the spring is taken half explicitly."""
    mass = np.array([1.0, 1.0, 1e6])
    a, b = np.array([0]), np.array([1])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        frac_k, frac_c = forces.explicit_fractions(mass, a, b, np.array([1e6]), np.array([0.0]), 1e-3)
    assert frac_k.tolist() == [0.5]
    assert frac_c.tolist() == [1.0]


# ---------------------------------------------------------------- static sag


@pytest.mark.parametrize(("k", "mass_kg"), [(10.0, 0.009), (1000.0, 0.009), (1e5, 0.009), (1000.0, 0.5), (1e5, 0.5)])
def test_hanging_chain_sags_as_hookes_law_says(k: float, mass_kg: float) -> None:
    """Five pucks hang from a cursor string at (5, 8) on 0.3 m springs of stiffness k.

    At rest each spring holds the pucks below it: spring i (from the top,
    i = 1..4) stretches by (5 - i) m g / k, and the string by 5 m g / k_string.
    """
    table = AirTable()
    table.gravity_on = True
    n, length, top = 5, 0.3, (5.0, 8.0)
    chain = [_light_puck(table, (5.0, 8.0 - length * i), mass_kg) for i in range(n)]
    for p, q in zip(chain, chain[1:], strict=False):
        table.add_spring(p, q, length_m=length, k_Npm=k, damper_Nspm=math.sqrt(k * mass_kg))
    string = [Pull(chain[0].index, top, k, math.sqrt(k * mass_kg))]
    for _ in range(8):  # seconds: the soft chains need all 8; the stiff ones are still within one
        for _ in range(round(1.0 / DT_S)):
            table.step(DT_S, string)
        if np.abs(table.vel_mps).max() < 1e-9:
            break
    w = mass_kg * GRAVITY_MPS2
    expected = [top[1] - n * w / k]
    for i in range(1, n):
        expected.append(expected[-1] - length - (n - i) * w / k)
    unstretched = top[1] - length * np.arange(n)
    sag, got = unstretched - np.array(expected), unstretched - table.pos_m[:, 1]
    np.testing.assert_allclose(got, sag, rtol=1e-4)
    np.testing.assert_allclose(table.pos_m[:, 0], 5.0, atol=1e-12)
    assert np.abs(table.vel_mps).max() < 1e-4


def test_one_implicit_step_by_hand(monkeypatch) -> None:
    """Two 9 g pucks 0.1 m too far apart on a 1000 N/m spring, at rest: one step, worked by hand.

    (Taken implicitly as a spring beyond what substeps take would be: substeps off.)

    Each puck's springs take k dt^2 / m = 1000 / 240^2 / 0.009 = 1.93 > 0.25, so
    the spring is explicit only up to k_e = 0.25 m / dt^2 and the rest,
    k_i = k - k_e, is implicit. By symmetry dv_b = -dv_a, and
    (m + 2 dt^2 k_i) dv_a = dt k (d - L), along the line towards b.
    """
    m, k, dt = 0.009, 1000.0, DT_S
    monkeypatch.setattr(substeps, "MAX_SUBSTEPS", 1)
    table = AirTable()
    a = _light_puck(table, (4.0, 4.0), m)
    b = _light_puck(table, (5.1, 4.0), m)
    table.add_spring(a, b, length_m=1.0, k_Npm=k, damper_Nspm=0.0)
    table.step(dt)
    k_i = k - forces.EXPLICIT_STIFFNESS * m / dt**2
    dv = dt * k * 0.1 / (m + 2 * dt * dt * k_i)
    np.testing.assert_allclose(a.vel_mps, (dv, 0.0), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b.vel_mps, (-dv, 0.0), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(a.pos_m, (4.0 + dv * dt, 4.0), rtol=1e-13)


def test_stiff_cursor_string_holds_a_light_puck_where_hookes_law_says() -> None:
    """Mouse button 3 (k 1000 N/m, c 20 N s/m) on a 9 g puck under gravity: it hangs m g / k below the cursor."""
    table = AirTable()
    table.gravity_on = True
    puck = _light_puck(table, (5.0, 4.0), 0.009)
    pull = [Pull(puck.index, (5.0, 4.0), 1000.0, 20.0)]
    for _ in range(240):
        table.step(DT_S, pull)
    assert puck.pos_m[1] == pytest.approx(4.0 - 0.009 * GRAVITY_MPS2 / 1000.0, rel=1e-12)


# ---------------------------------------------------------------- bodies ring down

BODIES = {
    "jelly 5 x 5 with diagonals, k 1500": bench_hard.jelly_scene,
    "hub on 6 spokes, k 1000": lambda t: bench_hard.hub_scene(t, 6),
    "wheel of 12 spokes and a rim, k 2000": lambda t: bench_hard.hub_scene(t, 12, rim=True, k_Npm=2000.0),
    "wheel, k 1e7": lambda t: bench_hard.hub_scene(t, 12, rim=True, k_Npm=1e7),
}


def _internal_energy_J(table: AirTable) -> float:
    """Kinetic energy beyond the centre of mass's motion, plus the springs' energy."""
    rel = table.vel_mps - table.center_of_mass_vel_mps()
    return float(0.5 * np.dot(table.mass_kg, (rel * rel).sum(1))) + table.spring_energy_J()


@pytest.mark.parametrize("build", BODIES.values(), ids=BODIES.keys())
def test_spring_bodies_ring_down(build) -> None:
    """No puck ever moves faster than the kick, and the wobble's energy only decays (the dampers, c 2 N s/m).

    (A hub's sideways wobble across slack spokes has no damper along it, so it
    rings longest: pymunk keeps as much of it after 1 s.)
    """
    table = AirTable()
    build(table)
    kick = float(np.abs(table.vel_mps).max())
    momentum = table.momentum_Ns()
    energy = [_internal_energy_J(table)]
    for _ in range(240):
        table.step(DT_S)
        assert np.abs(table.vel_mps).max() <= kick
        energy.append(_internal_energy_J(table))
    assert energy[-1] < 0.1 * energy[0]
    assert np.diff(energy).max() <= 1e-6 * energy[0]  # (the explicit part may wiggle by round-off)
    np.testing.assert_allclose(table.momentum_Ns(), momentum, atol=1e-12)


def _jelly(table: AirTable, side: int, k: float, low_m: float = 0.5) -> None:
    """side x side pucks of 9 g, 0.4 m apart from (1, low_m), springs on edges and diagonals, one corner kicked."""
    grid = {
        (i, j): _light_puck(table, (1.0 + 0.4 * i, low_m + 0.4 * j), 0.009, 0.1)
        for i in range(side)
        for j in range(side)
    }
    for (i, j), p in grid.items():
        for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
            if (i + di, j + dj) in grid:
                table.add_spring(p, grid[i + di, j + dj], 0.4 * math.hypot(di, dj), k, 2.0, 0.05)
    grid[0, 0].vel_mps = (3.0, 1.0)


def test_ten_by_ten_jelly_keeps_its_shape() -> None:
    table = AirTable()
    _jelly(table, 10, 1500.0)
    for _ in range(240):
        table.step(DT_S)
        assert np.abs(table.vel_mps).max() <= 3.0
    d = table.pos_m[table.spring_pairs[:, 0]] - table.pos_m[table.spring_pairs[:, 1]]
    np.testing.assert_allclose(np.hypot(*d.T), table.spring_length_m, rtol=1e-3)


@pytest.mark.parametrize("k", [1500.0, 1e6])
def test_a_spinning_stiff_jelly_keeps_spinning(k: float) -> None:
    """Springs pull along the lines of centres only, so angular momentum about the centre of mass is kept exactly."""
    table = AirTable()
    _jelly(table, 5, k, low_m=2.5)
    centre = table.center_of_mass_m()
    r = table.pos_m - centre
    table.vel_mps[:] = 3.0 * np.stack([-r[:, 1], r[:, 0]], axis=1)  # turning at 3 rad/s as one body

    def spin() -> float:
        rel = table.pos_m - table.center_of_mass_m()
        return float(np.dot(table.mass_kg, rel[:, 0] * table.vel_mps[:, 1] - rel[:, 1] * table.vel_mps[:, 0]))

    spin0, ke0 = spin(), table.kinetic_energy_J()
    for _ in range(480):
        table.step(DT_S)
    assert spin() == pytest.approx(spin0, rel=1e-9)
    assert table.kinetic_energy_J() > 0.999 * ke0


# Each size (5: solved directly; 10: by conjugate gradients) with each stiffness and each wall, once.
@pytest.mark.parametrize(("side", "k", "cr_wall"), [(5, 1500.0, 1.0), (5, 1e5, 0.5), (10, 1500.0, 0.5), (10, 1e5, 1.0)])
def test_a_stiff_jelly_landing_on_the_floor_gains_no_energy(side: int, k: float, cr_wall: float) -> None:
    """Dropped from 1 m, it bounces off the floor and walls as one body: its energy never rises, speeds stay bounded.

    The free fall from 1 m gives sqrt(2 g h) = 4.4 m/s; with the 3 m/s kick no puck should pass 8 m/s.
    (Energy may swing by a little within a step: the explicit part of the
    springs is semi-implicit Euler, whose energy wiggles without drifting.)
    """
    table = AirTable()
    table.gravity_on = True
    table.cr_wall = cr_wall
    _jelly(table, side, k, low_m=1.0)
    start = table.kinetic_energy_J() + table.spring_energy_J() + table.gravity_energy_J()
    for _ in range(480):
        table.step(DT_S)
        energy = table.kinetic_energy_J() + table.spring_energy_J() + table.gravity_energy_J()
        assert energy <= 1.01 * start
        assert np.abs(table.vel_mps).max() < 8.0
    assert table.pos_m[:, 1].min() >= 0.1 - 1e-9


# ---------------------------------------------------------------- honest about softening


def test_a_spring_beyond_what_a_step_can_compute_is_softened_and_says_so_once() -> None:
    """k = 1e12 N/m between two 9 g pucks: softened to SOFTENING_LIMIT mu / dt^2 with mu = 4.5 g."""
    table = AirTable()
    a = _light_puck(table, (4.0, 4.0), 0.009)
    b = _light_puck(table, (5.0, 4.0), 0.009)
    soft = table.add_spring(a, b, length_m=1.0, k_Npm=20.0)
    hard = table.add_spring(a, b, length_m=0.9, k_Npm=1e12, damper_Nspm=0.0)
    k_eff = forces.SOFTENING_LIMIT * 0.0045 / DT_S**2
    assert hard.k_effective_Npm == pytest.approx(k_eff, rel=1e-12)
    assert soft.k_effective_Npm == soft.k_Npm == 20.0
    np.testing.assert_allclose(table.spring_k_effective_Npm, [20.0, k_eff], rtol=1e-12)
    # The energy uses the stiffness the step uses: 0.1 m stretched.
    assert table.spring_energy_J() == pytest.approx(0.5 * k_eff * 0.1**2, rel=1e-12)
    assert table.notices == []
    for _ in range(20):
        table.step(DT_S)
    softened = [s for s in table.notices if "Spring 1 " in s]
    assert len(softened) == 1
    assert f"{k_eff:.3g}" in softened[0]
    assert not any("Spring 0 " in s for s in table.notices)
    assert len(table.notices) == 2  # and one that some springs are solved implicitly
    assert table.springs_on(a) == table.springs_on(b) == (soft, hard)


def test_soft_springs_raise_no_notice_and_stay_explicit() -> None:
    table = AirTable()
    a = table.add_puck((2.0, 3.0), 0.4)
    b = table.add_puck((3.5, 4.5), 0.4)
    table.add_spring(a, b, 1.5, 20.0, 0.5)
    for _ in range(240):
        table.step(DT_S)
    assert table.notices == []
    table.clear()
    assert table.notices == []


def test_the_implicit_notice_comes_once_per_scene() -> None:
    # k 1e6 N/m on 9 g pucks: beyond what substeps.MAX_SUBSTEPS take, so solved implicitly.
    table = AirTable()
    bench_hard.jelly_scene(table, k_Npm=1e6)
    for _ in range(50):
        table.step(DT_S)
    assert len(table.notices) == 1 and "implicitly" in table.notices[0]
    table.clear()
    bench_hard.jelly_scene(table, k_Npm=1e6)
    table.step(DT_S)
    assert len(table.notices) == 1


# ---------------------------------------------------------------- springs on a contact


@pytest.mark.parametrize(("k", "no_bounce"), [(10.0, False), (100.0, True)])
def test_spring_pressing_touching_pucks_together_gains_no_energy(k: float, no_bounce: bool) -> None:
    """Two touching pucks (r 0.25 m) on a 0.3 m spring, with the table's defaults or no bounce: 20 s keeps the energy.

    The spring presses them together with k 0.2 N and the contact holds them: the energy, k 0.2^2 / 2, stays in
    the spring."""
    table = AirTable()
    if no_bounce:
        table.cr_puck = 0.0
        table.puck_correction = "perfect-kiss"
    a = table.add_puck((4.5, 4.0), 0.25)
    b = table.add_puck((5.0, 4.0), 0.25)
    table.add_spring(a, b, length_m=0.3, k_Npm=k, damper_Nspm=0.0)
    e0 = table.spring_energy_J()
    assert e0 == pytest.approx(0.5 * k * 0.2**2, rel=1e-12)
    for _ in range(round(20.0 / DT_S)):
        table.step(DT_S)
    e1 = table.kinetic_energy_J() + table.spring_energy_J()
    assert abs(e1 - e0) < 0.01 * e0
