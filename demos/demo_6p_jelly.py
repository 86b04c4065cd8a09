"""Demo 6p: a block of jelly, pucks held by springs along the edges and diagonals, dropped under gravity."""

import math

KEY = "6p"
TITLE = "Jelly"
NOTES = """
Twenty-five pucks joined by springs along every edge and diagonal (the diagonals stop the
squares folding flat) act like a block of jelly: it falls, lands, wobbles and settles, and
you can grab a puck and throw it at a wall. The jellies vibrate faster than one step can
follow, so their springs are stepped in substeps (2, 4 and 9 a step): each wobble rings and
dies as k and the dampers say, and the sag under its own weight is the one k gives (2 cm
when soft, a millimetre when stiff: too little to see). Pull a puck right through its
neighbours and the block stays tangled, as pucks on springs still collide; press the key
again to start over. Left and Right change the stiffness.
"""

VARIATIONS = ("soft: k 60 N/m", "k 300 N/m", "stiff: k 1500 N/m")
DEFAULT_VARIATION = 1
STIFFNESS_NPM = (60.0, 300.0, 1500.0)
DAMPER_NSPM = (0.1, 0.5, 1.0)
SIDE = 5  # pucks along each side of the block
PITCH_M = 0.5  # their spacing
RADIUS_M = 0.15
DENSITY_KGPM2 = 0.3  # a puck of 21 g
SPIN_RADPS = 1.5  # the block is thrown up and sideways, turning


def build(table, variation=0):
    """A 5 x 5 block at the table's upper left, thrown up to the right while turning, gravity on."""
    table.gravity_on = True
    table.cr_wall = 0.7
    table.cr_puck = 0.7
    k, c = STIFFNESS_NPM[variation], DAMPER_NSPM[variation]
    centre = (2.5, 5.5)
    grid = {}
    for i in range(SIDE):
        for j in range(SIDE):
            x = centre[0] + PITCH_M * (i - (SIDE - 1) / 2)
            y = centre[1] + PITCH_M * (j - (SIDE - 1) / 2)
            # Thrown at (2, 2) m/s and turning: v = v_centre + omega x r.
            vel = (2.0 - SPIN_RADPS * (y - centre[1]), 2.0 + SPIN_RADPS * (x - centre[0]))
            grid[i, j] = table.add_puck((x, y), RADIUS_M, DENSITY_KGPM2, vel, color="palegreen3")
    for (i, j), p in grid.items():
        for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
            q = grid.get((i + di, j + dj))
            if q is not None:
                length = PITCH_M * math.hypot(di, dj)
                table.add_spring(p, q, length_m=length, k_Npm=k, damper_Nspm=c, width_m=0.04, color="green")
