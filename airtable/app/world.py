"""Change the world live: restitution, the strength of gravity, and a puck's mass and radius, from keys.

The steps are pure functions (tested by hand numbers); the actions below
apply them to the app's table and say the new value on the message line.
The status line shows the restitution and the gravity (`gravity_label`).

- restitution of pucks (u) and of walls (w): down a tenth, with Shift up, 0 to 1;
- gravity (Shift+g): off, Moon, Mars, Earth, off, ...;
- the mass (- / =) and radius ([ / ]) of the puck under the cursor (or the one
  held): to the next value down or up of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k.
  A new radius keeps the mass and a new mass keeps the velocity, so a student
  sees one thing change at a time.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from airtable.model.momenta import puck_number
from airtable.physics.forces import GRAVITY_MPS2
from airtable.physics.table import AirTable

if TYPE_CHECKING:
    from airtable.app.app import App
    from airtable.physics.bodies import Puck

GRAVITY_STEPS = ((0.0, "off"), (1.62, "Moon"), (3.71, "Mars"), (GRAVITY_MPS2, "Earth"))
LADDER = (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)  # round steps per decade
MASS_RANGE_KG = (0.001, 1000.0)
RADIUS_RANGE_M = (0.05, 2.0)


def step_restitution(value: float, direction: int) -> float:
    """`value` to the next tenth up (+1) or down (-1), within 0..1 (0.93 goes down to 0.9 and up to 1.0)."""
    tenths = value * 10.0
    target = math.floor(tenths + 1e-9) + 1 if direction > 0 else math.ceil(tenths - 1e-9) - 1
    return min(10, max(0, target)) / 10.0


def next_gravity(on: bool, g_mps2: float) -> tuple[float, str]:
    """The step after the gravity now (off, or on at `g_mps2`): (strength, name); 0.0 means off."""
    now = g_mps2 if on else 0.0
    for strength, name in GRAVITY_STEPS:
        if strength > now + 1e-9:
            return strength, name
    return GRAVITY_STEPS[0]


def gravity_label(table: AirTable) -> str:
    """The status line's gravity: "gravity off", "gravity on" (Earth's), or its strength and name."""
    if not table.gravity_on:
        return "gravity off"
    if table.gravity_mps2 == GRAVITY_MPS2:
        return "gravity on"
    names = {g: n for g, n in GRAVITY_STEPS}
    name = f" ({names[table.gravity_mps2]})" if table.gravity_mps2 in names else ""
    return f"gravity {table.gravity_mps2:g} m/s²{name}"


def ladder_step(value: float, direction: int, lo: float, hi: float) -> float:
    """The next value of LADDER x 10^k above (+1) or below (-1) `value`, kept within lo..hi."""
    e = math.floor(math.log10(value))
    rungs = [float(f"{m:g}e{k}") for k in range(e - 1, e + 2) for m in LADDER]  # 1.2e-1 is 0.12 exactly
    if direction > 0:
        found = min((r for r in rungs if r > value * (1 + 1e-9)), default=hi)
    else:
        found = max((r for r in rungs if r < value * (1 - 1e-9)), default=lo)
    return min(hi, max(lo, found))


# ---------------------------------------------------------------- actions


def _restitution(app: App, attr: str, what: str, direction: int) -> None:
    t = app.table
    setattr(t, attr, step_restitution(getattr(t, attr), direction))
    app.say(f"restitution of {what}: {getattr(t, attr):g}")


def puck_restitution_down(app: App) -> None:
    _restitution(app, "cr_puck", "pucks (puck on puck)", -1)


def puck_restitution_up(app: App) -> None:
    _restitution(app, "cr_puck", "pucks (puck on puck)", +1)


def wall_restitution_down(app: App) -> None:
    _restitution(app, "cr_wall", "walls", -1)


def wall_restitution_up(app: App) -> None:
    _restitution(app, "cr_wall", "walls", +1)


def cycle_gravity(app: App) -> None:
    """Shift+g: off, Moon, Mars, Earth; the restitution stays as it is."""
    t = app.table
    strength, name = next_gravity(t.gravity_on, t.gravity_mps2)
    t.gravity_on = strength > 0.0
    if t.gravity_on:
        t.gravity_mps2 = strength
        app.say(f"gravity {strength:g} m/s² ({name})")
    else:
        app.say("gravity off")


def target_puck(app: App) -> Puck | None:
    """The puck the local user holds, else the one under the cursor."""
    held = app.local.held
    if held is not None and held.alive:
        return held
    return app.table.puck_at(app.env.to_world(app.mouse_px))


def _change_puck(app: App, what: str, direction: int) -> None:
    puck = target_puck(app)
    if puck is None:
        app.say("put the cursor on a puck to change its mass (- / =) or radius ([ / ])")
        return
    t, row = app.table, puck.index
    if what == "mass":
        old = float(t.mass_kg[row])
        t.mass_kg[row] = ladder_step(old, direction, *MASS_RANGE_KG)
        app.say(f"puck {puck_number(row)}: mass {t.mass_kg[row]:g} kg (was {old:.3g} kg; its velocity kept)")
    else:
        old = float(t.radius_m[row])
        top = min(RADIUS_RANGE_M[1], 0.45 * min(t.width_m, t.height_m))
        t.radius_m[row] = ladder_step(old, direction, RADIUS_RANGE_M[0], top)
        app.say(f"puck {puck_number(row)}: radius {t.radius_m[row]:g} m (was {old:.3g} m; its mass kept)")


def mass_down(app: App) -> None:
    _change_puck(app, "mass", -1)


def mass_up(app: App) -> None:
    _change_puck(app, "mass", +1)


def radius_down(app: App) -> None:
    _change_puck(app, "radius", -1)


def radius_up(app: App) -> None:
    _change_puck(app, "radius", +1)
