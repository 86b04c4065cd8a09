"""StepContext: what the stages of one step hand each other (step.py).

Built at the start of a step and dropped at its end (but for the collision
records, which `AirTable.last_collisions` reads), so the table keeps no
scratch between steps: Box2D v3 passes its b2StepContext the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from airtable.physics.collision import PairRecords
from airtable.physics.forces import Pull
from airtable.physics.rest_speeds import RestSpeeds


@dataclass(slots=True)
class StepContext:
    dt: float  # the step's length (s)
    pulls: Sequence[Pull]  # the cursor strings acting in this step
    began: np.ndarray | None = None  # the positions when the step began (the contacts start there)
    sleepers: np.ndarray | None = None  # the rows that sleep through this step (None: none)
    kick: np.ndarray | None = None  # the velocity the forces gave each puck ((N, 2), or (2,): all; None: nothing)
    rest: RestSpeeds | None = None  # which contacts rest instead of bouncing (None: every contact collides)
    wall_rest: np.ndarray | None = None  # (N, 2) rest.walls, infinite where a puck was held on a wall last step
    maybe_past: np.ndarray | None = None  # the rows that may be past a wall after the hits (None: any)
    bounced: list[int] = field(default_factory=list)  # the rows of this step's wall hits (the hit stage's)
    moved: np.ndarray | None = None  # the rows the pair stage moved (a row may repeat; None: none)
    records: list[PairRecords] = field(default_factory=list)  # what this step's puck-puck collisions did (raw)
