"""Demo 0: a burst of tiny pucks leaving the centre in every direction."""

import math

KEY = "0"
TITLE = "Burst"
NOTES = """
Tiny pucks leave the centre at 1.4 m/s in evenly spaced directions, so they form an
expanding ring. Puck-puck collisions are off because they all start on top of each
other; each puck just goes straight and bounces off the walls, and the reflected
parts of the ring are circles centred on mirror images of the centre. Step through
the variations to see how many pucks the computer can move and draw.
"""

COUNTS = (4, 8, 16, 32, 64, 128, 256, 512, 1000, 2000, 5000, 10000)
VARIATIONS = tuple(f"n = {n}" for n in COUNTS)

RADIUS_M = 0.05
SPEED_MPS = 1.4


def build(table, variation=0):
    """n pucks at the centre moving radially outwards at 1.4 m/s; collisions off."""
    table.puck_collisions = False
    n = COUNTS[variation % len(COUNTS)]
    centre = (table.width_m / 2.0, table.height_m / 2.0)
    for k in range(n):
        angle = 2.0 * math.pi * k / n
        vel_mps = (SPEED_MPS * math.cos(angle), SPEED_MPS * math.sin(angle))
        table.add_puck(pos_m=centre, radius_m=RADIUS_M, vel_mps=vel_mps, color="orange" if k == 0 else "white")
