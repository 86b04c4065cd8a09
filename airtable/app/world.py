"""Change the world live (`LiveEdits`): freeze, time reversed, gravity, restitution, the correction
mode, and a puck's mass and radius, from keys.

The steps are pure functions (tested by hand numbers); the feature's actions
apply them to the host's table and say the new value on the message line.
The status line shows the restitution and the gravity (`gravity_label`).

- f freezes every puck, r flips every velocity (time reversed);
- g: gravity on or off (restitution 0.9 with it, 1.0 without); p, z: the correction mode;
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

import pygame

from airtable.app.feature import Binding, Feature
from airtable.model.momenta import puck_number
from airtable.physics.forces import GRAVITY_MPS2
from airtable.physics.pairs import CORRECTION_MODES
from airtable.physics.table import AirTable

if TYPE_CHECKING:
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


class LiveEdits(Feature):
    """The keys that change the world while it runs; the state they change is the table's."""

    def freeze(self) -> None:
        self.host.table.vel_mps[:] = 0.0

    def reverse_time(self) -> None:
        self.host.table.vel_mps[:] *= -1.0
        self.host.say("time reversed: every velocity flipped")

    def toggle_gravity(self) -> None:
        t = self.host.table
        t.gravity_on = not t.gravity_on
        t.cr_puck = t.cr_wall = 0.9 if t.gravity_on else 1.0
        # Said, as every key that changes the table says: the restitution a demo set is replaced.
        state = f"on ({t.gravity_mps2:g} m/s²)" if t.gravity_on else "off"
        self.host.say(f"gravity {state}; restitution of pucks and walls {t.cr_puck:g} (Shift+g: gravity only)")

    def toggle_correction(self) -> None:
        """The next correction mode: off, two-step, perfect kiss, off, ..."""
        t, modes = self.host.table, CORRECTION_MODES
        t.puck_correction = modes[(modes.index(t.puck_correction) + 1) % len(modes)]

    def toggle_perfect_kiss(self) -> None:
        t = self.host.table
        t.puck_correction = "two-step" if t.puck_correction == "perfect-kiss" else "perfect-kiss"

    def cycle_gravity(self) -> None:
        """Shift+g: off, Moon, Mars, Earth; the restitution stays as it is."""
        t = self.host.table
        strength, name = next_gravity(t.gravity_on, t.gravity_mps2)
        t.gravity_on = strength > 0.0
        if t.gravity_on:
            t.gravity_mps2 = strength
            self.host.say(f"gravity {strength:g} m/s² ({name})")
        else:
            self.host.say("gravity off")

    def _restitution(self, attr: str, what: str, direction: int) -> None:
        t = self.host.table
        setattr(t, attr, step_restitution(getattr(t, attr), direction))
        self.host.say(f"restitution of {what}: {getattr(t, attr):g}")

    def puck_restitution_down(self) -> None:
        self._restitution("cr_puck", "pucks (puck on puck)", -1)

    def puck_restitution_up(self) -> None:
        self._restitution("cr_puck", "pucks (puck on puck)", +1)

    def wall_restitution_down(self) -> None:
        self._restitution("cr_wall", "walls", -1)

    def wall_restitution_up(self) -> None:
        self._restitution("cr_wall", "walls", +1)

    def target_puck(self) -> Puck | None:
        """The puck the local user holds, else the one under the cursor."""
        held = self.host.local.held
        if held is not None and held.alive:
            return held
        return self.host.table.puck_at(self.host.env.to_world(self.host.mouse_px))

    def _change_puck(self, what: str, direction: int) -> None:
        puck, say = self.target_puck(), self.host.say
        if puck is None:
            say("put the cursor on a puck to change its mass (- / =) or radius ([ / ])")
            return
        t, row = self.host.table, puck.index
        if what == "mass":
            old = float(t.mass_kg[row])
            t.mass_kg[row] = ladder_step(old, direction, *MASS_RANGE_KG)
            say(f"puck {puck_number(row)}: mass {t.mass_kg[row]:g} kg (was {old:.3g} kg; its velocity kept)")
        else:
            old = float(t.radius_m[row])
            top = min(RADIUS_RANGE_M[1], 0.45 * min(t.width_m, t.height_m))
            puck.radius_m = ladder_step(old, direction, RADIUS_RANGE_M[0], top)  # wakes the sleepers
            say(f"puck {puck_number(row)}: radius {t.radius_m[row]:g} m (was {old:.3g} m; its mass kept)")

    def mass_down(self) -> None:
        self._change_puck("mass", -1)

    def mass_up(self) -> None:
        self._change_puck("mass", +1)

    def radius_down(self) -> None:
        self._change_puck("radius", -1)

    def radius_up(self) -> None:
        self._change_puck("radius", +1)

    bindings = (
        Binding("f", "freeze: all velocities to zero", {pygame.K_f: freeze}),
        Binding("g", "gravity on/off (restitution 0.9 with gravity, 1.0 without)", {pygame.K_g: toggle_gravity}),
        Binding("p", "correction: off, two-step, perfect kiss in turn", {pygame.K_p: toggle_correction}),
        Binding("z", "perfect kiss on/off", {pygame.K_z: toggle_perfect_kiss}),
        Binding("r", "reverse time: flip every velocity", {pygame.K_r: reverse_time}),
        Binding(
            "u / w",
            "restitution of pucks / walls down a tenth (with Shift: up)",
            {
                pygame.K_u: puck_restitution_down,
                (pygame.KMOD_SHIFT, pygame.K_u): puck_restitution_up,
                pygame.K_w: wall_restitution_down,
                (pygame.KMOD_SHIFT, pygame.K_w): wall_restitution_up,
            },
        ),
        Binding(
            "Shift+g",
            "gravity: off, Moon 1.62, Mars 3.71, Earth 9.8 m/s²",
            {(pygame.KMOD_SHIFT, pygame.K_g): cycle_gravity},
        ),
        Binding(
            "- / =, [ / ]",
            "mass, radius of the puck under the cursor: down / up",
            {
                pygame.K_MINUS: mass_down,
                pygame.K_KP_MINUS: mass_down,
                pygame.K_EQUALS: mass_up,
                pygame.K_PLUS: mass_up,
                pygame.K_KP_PLUS: mass_up,
                pygame.K_LEFTBRACKET: radius_down,
                pygame.K_RIGHTBRACKET: radius_up,
            },
        ),
    )
