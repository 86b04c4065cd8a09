"""The table's strength of gravity (AirTable.gravity_mps2): the step, the energy and the forces use it."""

import pytest

from airtable.physics.forces import GRAVITY_MPS2
from airtable.physics.table import AirTable


def test_gravity_strength_defaults_to_earth_and_resets():
    t = AirTable()
    assert t.gravity_mps2 == GRAVITY_MPS2 == 9.8
    t.gravity_mps2 = 1.62
    t.reset_settings()
    assert t.gravity_mps2 == 9.8


def test_moon_gravity_in_the_step_energy_and_forces():
    t = AirTable()
    t.gravity_on, t.gravity_mps2 = True, 1.62
    p = t.add_puck((5.0, 4.0), radius_m=0.5, density_kgpm2=2.0 / 3.141592653589793 / 0.25)  # 2 kg
    assert p.mass_kg == pytest.approx(2.0)
    assert t.gravity_energy_J() == pytest.approx(2.0 * 1.62 * 4.0)  # m g y = 12.96 J
    assert t.forces_on(p)["gravity"][1] == pytest.approx(-2.0 * 1.62)
    for _ in range(60):  # 1 s in steps of 1/60 s: v = -g t exactly (no walls reached)
        t.step(1 / 60)
    assert p.vel_mps[1] == pytest.approx(-1.62)
    # semi-implicit Euler: y = y0 - g dt^2 (1 + 2 + ... + 60) = 4 - 1.62 * 1830 / 3600
    assert p.pos_m[1] == pytest.approx(4.0 - 1.62 * 1830 / 3600)
