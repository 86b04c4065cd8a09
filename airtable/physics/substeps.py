"""Substeps: springs stiffer than a step can follow are integrated in shorter steps.

Semi-implicit Euler (v += F/m h, then x += v h) keeps a spring's energy with
no drift and no damping, and its period, as long as the step h resolves the
spring's vibration. A backward-Euler (implicit) step is stable at any
stiffness but damps every mode it takes, the slow ones too: a 5 x 5 lattice
whose slowest mode took 12 steps lost 74 % of it each period. So a step
whose springs are too stiff for it is cut into n substeps of h = dt / n,
each the whole force-and-integrate stage, with n the least that brings
every puck's springs within SUBSTEP_STIFFNESS (sum of k h^2 / m): then
omega h <= 0.5 for a pair, and it rings at its own period to 1 %.

Springs that would need more than MAX_SUBSTEPS get none: the step takes
what is beyond its explicit budget implicitly, as before (forces.py,
implicit.py), stable for any k but damped, and the table says so once.
(Substeps with an implicit part left in them rang on: a stiff jelly landing
threw single pucks at 2.5 times its speed.)
"""

from __future__ import annotations

import math

import numpy as np

# Per puck, the sum of k h^2 / m each substep may take explicitly: a pair of equal
# pucks then has omega h = sqrt(2 k h^2 / m) <= 0.5, and semi-implicit Euler's
# period, 2 pi / omega times (omega h / 2) / asin(omega h / 2), is within 1.1 %.
SUBSTEP_STIFFNESS = 0.125
# At most this many substeps a step (a 5 x 5 lattice 100 times beyond the explicit limit needs 20).
MAX_SUBSTEPS = 32


def count(mass: np.ndarray, a: np.ndarray, b: np.ndarray, k: np.ndarray, dt_s: float) -> int:
    """How many substeps a step of dt_s needs for springs k (N/m) joining pucks a and b (mass in kg)."""
    if len(k) == 0:
        return 1
    per_puck = np.bincount(a, k, len(mass)) + np.bincount(b, k, len(mass))
    load = float((per_puck / mass).max()) * dt_s * dt_s / SUBSTEP_STIFFNESS
    if not 1.0 < load <= MAX_SUBSTEPS * MAX_SUBSTEPS:  # also NaN and inf: no substeps
        return 1
    return math.ceil(math.sqrt(load) * (1.0 - 1e-12))
