"""Demo Shift+0: a gas of pucks whose speeds spread out into Maxwell's distribution.

`gas_scene` is also the scene of the benchmark (`python -m bench`) and of many tests.
"""

import math

import numpy as np

from airtable.physics.table import AirTable

KEY = "0p"
TITLE = "Gas: Maxwell speeds"
NOTES = """
Every puck starts at the same speed, 1 m/s, each in a random direction, and every
collision is elastic. Within a few seconds the collisions spread the speeds out: some
pucks almost stop, a few move twice as fast, and the total kinetic energy stays the same.
The spread settles into Maxwell's distribution for a gas in two dimensions: the most likely
speed is 0.71 m/s, the mean 0.89 m/s, and about 63 % of the pucks go slower than 1 m/s.
Follow the orange puck's random walk; Left and Right change the number of pucks.
"""

COUNTS = (500, 2000, 5000, 10000)
VARIATIONS = tuple(f"{n} pucks" for n in COUNTS)
DEFAULT_VARIATION = 1  # 2000 pucks: Maxwell's law shows well, in real time on a laptop
# At 10000 pucks (radius 2.9 cm) a puck at 1 m/s moves a seventh of its radius in a step: hardly any is
# fast enough for its hits to need resolving one by one (events.FAST_FRACTION), so the step stays cheap.
DT_S = 1.0 / 240.0

# The gas (units in the names).
RADIUS_M = 0.1
DENSITY_KGPM2 = 0.3
COVERAGE = 0.3  # fraction of the table area covered by pucks
SPEED_MPS = 1.0
ASPECT = 8.0 / 7.0  # width / height, as the default window


def build(table, variation=0):
    """COUNTS[variation] pucks covering 30 % of the table at 1 m/s in random directions; one is orange."""
    n = COUNTS[variation % len(COUNTS)]
    radius_m = math.sqrt(COVERAGE * table.width_m * table.height_m / (n * math.pi))
    gas_scene(table, radius_m=radius_m)
    table.pucks[0].color = "orange"


def gas_scene(
    table_or_n: AirTable | int,
    *,
    radius_m: float = RADIUS_M,
    density_kgpm2: float = DENSITY_KGPM2,
    coverage: float = COVERAGE,
    speed_mps: float = SPEED_MPS,
    seed: int = 0,
) -> AirTable:
    """A gas: equal pucks covering `coverage` of the table, all at `speed_mps` in random directions.

    Given a puck count N, makes a table with aspect 8:7 and area
    N pi r^2 / coverage (m^2). Given a table, clears it and fills it with as
    many pucks as give that coverage. Pucks start on a jittered grid (no two
    overlap, none touches a wall); the settings are those of the benchmark:
    restitution 1, no gravity, two-step correction. Deterministic for a seed.
    """
    r = float(radius_m)
    puck_area = math.pi * r * r
    if isinstance(table_or_n, AirTable):
        table = table_or_n
        table.clear()
        n = int(round(coverage * table.width_m * table.height_m / puck_area))
    else:
        n = int(table_or_n)
        if n < 1:
            raise ValueError(f"a gas needs at least one puck, not {table_or_n!r}")
        area = n * puck_area / coverage
        table = AirTable(width_m=math.sqrt(area * ASPECT), height_m=math.sqrt(area / ASPECT))
    table.reset_settings()
    table.gravity_on = False
    table.cr_puck = table.cr_wall = 1.0
    table.puck_correction = "two-step"

    w, h = table.width_m, table.height_m
    nx = max(1, math.ceil(math.sqrt(n * w / h)))
    ny = max(1, math.ceil(n / nx))
    cw, ch = w / nx, h / ny
    if min(cw, ch) < 2.0 * r:
        raise ValueError(f"{n} pucks of radius {r} m do not fit on a grid in a {w:.3g} x {h:.3g} m table")
    rng = np.random.default_rng(seed)
    cells = np.sort(rng.choice(nx * ny, size=n, replace=False))  # spread the empty cells
    centre = np.column_stack([(cells // ny + 0.5) * cw, (cells % ny + 0.5) * ch])
    # Jitter stays 1 % short of the cell edge, so neighbours never touch.
    room = 0.99 * np.array([cw / 2.0 - r, ch / 2.0 - r])
    pos = centre + rng.uniform(-1.0, 1.0, size=(n, 2)) * room
    angle = rng.uniform(0.0, 2.0 * math.pi, size=n)
    vel = speed_mps * np.column_stack([np.cos(angle), np.sin(angle)])
    for p, v in zip(pos, vel, strict=True):
        table.add_puck(pos_m=p, radius_m=r, density_kgpm2=density_kgpm2, vel_mps=v, color="white")
    return table
