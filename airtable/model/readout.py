"""Numbers a class can read: a value below the scene's round-off shows as 0 (no pygame).

A settled spring triangle keeps `1.7e-16 J` of kinetic energy and `1.8e-15 N s`
of momentum: the round-off of sums of numbers near 1, not motion. What is
round-off depends on the scene, so each scene keeps its scale (`SceneScale`):
the largest energy and momentum it has had since it started. A value of at
most ROUND_OFF times that scale is shown as 0, by `readable`, the one
function every readout uses (the energy chart's legend and axis, the values
panel, the momenta diagram's totals).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# Double precision keeps 16 digits; sums over a step or a few thousand steps keep about 9-12 of them.
ROUND_OFF = 1e-9


def fixed(value: float, decimals: int) -> str:
    """`value` with `decimals` decimals, never "-0.0" (a gap of -1e-9 mm is no gap)."""
    return f"{round(float(value), decimals) + 0.0:.{decimals}f}"


def figures(value: float, digits: int = 3) -> str:
    """`value` to `digits` significant figures as a class reads it: no exponent from 0.001 to a million
    ("2000", "1390", "0.0123", where "{:.3g}" wrote "2e+03" and "1.39e+03"), every digit of a whole number
    of more figures; an exponent beyond that range, where there is no other way."""
    value = float(value)
    if value == 0.0 or not math.isfinite(value):
        return f"{value + 0.0:g}"
    if 1e-3 <= abs(value) < 1e6:
        if abs(value) >= 10 ** (digits - 1):
            return f"{round(value) + 0:d}"
        return f"{value:.{digits}g}"
    return f"{value:.{digits}g}"


def readable(value: float, scale: float) -> float:
    """`value`, or 0.0 when it is within ROUND_OFF times `scale` of 0 (never -0.0)."""
    value = float(value)
    return 0.0 if abs(value) <= ROUND_OFF * scale else value + 0.0


@dataclass
class SceneScale:
    """The largest energy (J) and momentum (N s) the scene has had since it started: the scale of its
    round-off. The momentum scale is also at least that of the energy scale in all the pucks' mass,
    sqrt(2 M E), so a scene whose total momentum is always near 0 (a spring triangle) has one."""

    energy_J: float = 0.0
    momentum_Ns: float = 0.0

    def clear(self) -> None:
        self.energy_J = self.momentum_Ns = 0.0

    def observe(self, energies_J, momentum_Ns: float, mass_kg: float = 0.0) -> None:
        """One moment: its energies (kinetic, spring, gravity; J), the size of its momentum (N s) and the
        pucks' total mass (kg; 0 when not known)."""
        energy = sum(abs(e) for e in energies_J if math.isfinite(e))
        self.energy_J = max(self.energy_J, energy)
        p = abs(momentum_Ns) if math.isfinite(momentum_Ns) else 0.0
        from_energy = math.sqrt(2.0 * mass_kg * self.energy_J) if mass_kg > 0 else 0.0
        self.momentum_Ns = max(self.momentum_Ns, p, from_energy)

    def energy(self, value_J: float) -> float:
        return readable(value_J, self.energy_J)

    def momentum(self, value_Ns: float) -> float:
        return readable(value_Ns, self.momentum_Ns)
