"""Demo 6: a triangle of pucks held by stiff springs, and a free puck to throw at it."""

import math

KEY = "6"
TITLE = "Spring triangle"
NOTES = """
Three pucks joined by stiff, well damped springs act almost like one solid body.
Throw the big free puck at the triangle: the triangle moves off and starts to spin,
and it wobbles only briefly. Puck restitution is 0.7 here, so every puck-puck hit
loses some kinetic energy, and the total kinetic energy on the chart (c) drops.
"""

DENSITY_KGPM2 = 0.9
SIDE_M = 2.5  # the springs' rest length


def build(table, variation=0):
    """A free puck (r 0.9 m) above a triangle of pucks (r 0.75 m) on 2.5 m springs, at rest length."""
    table.cr_puck = 0.7
    table.add_puck(pos_m=(3.5, 7.0), radius_m=0.9, density_kgpm2=DENSITY_KGPM2)
    corners = [
        table.add_puck(pos_m=pos_m, radius_m=0.75, density_kgpm2=DENSITY_KGPM2)
        for pos_m in ((2.0, 3.0), (3.25, 3.0 + SIDE_M * math.sqrt(3.0) / 2.0), (4.5, 3.0))
    ]  # an equilateral triangle of side SIDE_M: every spring at its rest length, nothing stored at the start
    # One spring per side: corner 0-1, 1-2, 2-0.
    for n, color in enumerate(("red", "tan", "gold")):
        p1, p2 = corners[n], corners[(n + 1) % 3]
        table.add_spring(p1, p2, length_m=SIDE_M, k_Npm=250.0, damper_Nspm=5.0, width_m=0.07, color=color)
