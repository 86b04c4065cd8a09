"""Rest speeds: which contacts rest instead of bouncing, written once for every stage.

A contact rests (the contact stage holds it, contacts.py) when it approaches
slower than its rest speed; faster, it is a collision (events.py, pairs.py).
The rest speed comes from what presses the pucks together: this step's
forces. A puck the forces kicked by dv presses along dv only, so a contact
rests by as much as its normal n lies along the kick: |press . n|, where
`press` is the puck's rest speed (resting.rest_speeds) along dv. Under
gravity a puck landing on another, or on the floor, rests; two pucks sliding
along the floor into each other, or a puck into a side wall, collide at
their restitution however slowly (rested every way, two such pucks met at
0.15 m/s and stuck together, and a 5 cm/s puck stopped dead at a sleeping
one, its momentum gone). A puck in a pile, though (one in a contact with another puck
in the last step), is pressed every way by its neighbours: its contacts rest
by its whole rest speed, whatever their direction, so that a pile settles
instead of its pucks bouncing off their neighbours at a few cm/s. `floor`
(the table's rest_speed_mps) rests contacts in every direction.

The restitution then scales it: a contact rests when its bounce, cr times
its approach, would be slower than the rest speed, so when it approaches
slower than rest / cr. At cr = 0 every contact of a pressed puck rests, in any
direction and however fast: a perfectly inelastic hit and a resting contact
ask the same (no approach after it), and only the contact stage solves them
all together, as a stack or a slab landing needs (pair by pair, a chain of 6
pucks takes more passes than a step has). Not pressed: left to the collision
stages.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from airtable.physics import either

# A pair that pressed on each other in the last step (ContactSolver.held) rests however it approaches, so that a pile
# whose contacts have not quite converged does not start to bounce (they leave it some 0.2 m/s off at the most); up
# to this approach (m/s). Faster, something hit one of them in this step: a collision (a puck bounced off a third
# ran 20 mm into one it had rested on, as the pair was left to the contact stage).
HELD_MPS = 1.0


def still_held(held, approach):
    """Which of the pairs that pressed in the last step (`held`: bools, arrays or one) rest still, approaching at
    `approach` (m/s, positive: closing): those slower than HELD_MPS."""
    return held & (approach < HELD_MPS)


def for_restitution(rest, cr: float, pressed):
    """Rest speeds (an array, or one number) for contacts of restitution cr (see the module docstring);
    `pressed`: whether the forces press the contact's pucks at all, in any direction (at cr = 0 such a
    contact rests whatever its direction: the contact stage then solves a landing slab as one)."""
    if cr >= 1.0:
        return rest
    if cr <= 0.0:
        if isinstance(pressed, np.ndarray):
            return np.where(pressed, np.inf, 0.0)
        return math.inf if pressed else 0.0
    return rest / cr


@dataclass(frozen=True)
class RestSpeeds:
    """The step's rest speeds: each puck's `press` ((N,) complex: its rest speed along the direction the
    forces kicked it; 0 where nothing did), the table's `floor` (m/s, every direction), the restitutions."""

    press: np.ndarray
    floor: float
    cr_puck: float
    cr_wall: float
    piled: np.ndarray | None = None  # (N,) the pucks in a pile (ContactSolver.piled): pressed every way

    def pairs(self, a, b, d):
        """The rest speeds of the pairs (a, b) whose centres are `d` apart (complex, b to a, any length):
        numpy arrays of rows, or one pair in Python numbers, by the same lines (either.py)."""
        pa, pb = either.take(self.press, a), either.take(self.press, b)
        every_way = either.maximum(either.take(self.size, a), either.take(self.size, b))
        if self.piled is not None:  # (in a settling pile, most pairs: no direction to work out)
            piled = either.take(self.piled, a) | either.take(self.piled, b)
            if isinstance(piled, np.ndarray) and piled.all() or piled is True:
                return self._scaled(every_way, a, b)
        length = abs(d)
        apart = length > 0.0
        safe = either.where(apart, length, 1.0)
        nx, ny = d.real / safe, d.imag / safe
        rest = either.maximum(abs(pa.real * nx + pa.imag * ny), abs(pb.real * nx + pb.imag * ny))
        if self.piled is not None:
            apart = either.where(piled, False, apart)
        return self._scaled(either.where(apart, rest, every_way), a, b)  # (on one spot: no direction)

    def _scaled(self, rest, a, b):
        """`rest` of the pairs (a, b) with the floor and the pucks' restitution (for_restitution)."""
        pressed = either.take(self.size, a) > 0.0 if self.floor == 0.0 else True
        pressed = pressed | (either.take(self.size, b) > 0.0)
        return for_restitution(either.maximum(rest, self.floor), self.cr_puck, pressed)

    @cached_property
    def size(self) -> np.ndarray:
        """(N,) each puck's rest speed, whatever the direction."""
        return np.abs(self.press)

    @cached_property
    def pressed(self) -> np.ndarray | None:
        """(N,) which pucks this step's forces press (None: every one; the floor presses all). A contact
        needs one: of two pucks nothing presses, a touch is a collision and a gap no stage closes (a
        puck dragged through a gas of 10000 made every near pair of the gas a contact, 40-130 ms a step)."""
        if self.floor > 0.0:
            return None
        pressed = self.size > 0.0
        return None if pressed.all() else pressed

    @cached_property
    def walls(self) -> np.ndarray:
        """(N, 2) rest speeds towards the walls across x and across y (one array a step: the contacts
        keep their answer by it, ContactSolver.wall_rest)."""
        rest = np.column_stack((np.abs(self.press.real), np.abs(self.press.imag)))
        if self.piled is not None:
            rest[self.piled] = np.abs(self.press.take(np.flatnonzero(self.piled)))[:, None]
        pressed = ((self.press != 0.0) | (self.floor > 0.0))[:, None]
        return for_restitution(np.maximum(rest, self.floor), self.cr_wall, np.broadcast_to(pressed, rest.shape))
