"""A quiet table: nothing moves and nothing acts on it, so a step changes nothing but the time.

Without gravity a puck at rest never sleeps (sleep.py): it stays exactly still
anyway, but every step still ran each stage over it. A table of still pucks
(demo 4 before the teacher's first throw) then cost a quarter of a core while
nothing happened on it. So once a whole step left the table as it was, with
every puck at rest and nothing acting on it, the following steps only advance
the time, for as long as the table stays exactly so: the same positions,
radii, masses and settings, no velocity, no force, no cursor string, no
spring, no gravity and no contact held. A step is a function of that state,
so a step from the same state again changes nothing. The state is compared,
not tracked: a write anywhere (a setter, an array written directly, a
restore) ends the quiet by itself.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from airtable.physics.forces import Pull

if TYPE_CHECKING:
    from airtable.physics.storage import Storage


@dataclass(frozen=True)
class Quiet:
    """The table as a step that changed nothing found it."""

    pos: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    settings: tuple

    def holds(self, table: Storage, pulls: Sequence[Pull]) -> bool:
        """Whether `table` is still exactly as it was, at rest with nothing acting on it."""
        return (
            at_rest(table, pulls)
            and self.settings == _settings(table)
            and np.array_equal(self.pos, table.pos_m)
            and np.array_equal(self.radius, table.radius_m)
            and np.array_equal(self.mass, table.mass_kg)
        )


def at_rest(table: Storage, pulls: Sequence[Pull]) -> bool:
    """No puck moves and nothing acts: no velocity, force, cursor string, spring, gravity or held contact."""
    return (
        not pulls
        and not table.gravity_on
        and table.n_springs == 0
        and not table.vel_mps.any()
        and not table.force_N.any()
        and not table.contact_solver.pressing()
    )


def before_step(table: Storage, pulls: Sequence[Pull]) -> Quiet | None:
    """The table as this step finds it, if at rest (else None): the step may show it quiet."""
    if not at_rest(table, pulls):
        return None
    return Quiet(table.pos_m.copy(), table.radius_m.copy(), table.mass_kg.copy(), _settings(table))


def after_step(table: Storage, before: Quiet | None, hits: int) -> Quiet | None:
    """`before` if the step changed nothing (no hit, every puck where it was and at rest), else None."""
    if before is None or hits or not before.holds(table, ()):
        return None
    return before


def _settings(table: Storage) -> tuple:
    return (
        table.n_pucks,
        table.width_m,
        table.height_m,
        table.puck_correction,
        table.puck_collisions,
        table.wall_correction,
        table.cr_puck,
        table.cr_wall,
        table.rest_speed_mps,
    )
