"""Demo 7: Newton's cradle on the table's diagonal."""

import math

KEY = "7"
TITLE = "Newton's cradle"
NOTES = """
After one second the orange cue is thrown down the diagonal at two pucks in a row.
All three have the same mass, so each head-on hit hands the whole velocity on: the
cue stops dead, the middle puck hardly moves, and the last one leaves at the cue's
speed. Momentum and kinetic energy are both passed on intact, which is the only way
to conserve both at once.
"""

RADIUS_M = 0.45
SPEED_MPS = 4.0
GAP_M = 0.001  # a hair apart, so the still pair do not start overlapping


def build(table, variation=0):
    """Two still pucks on the diagonal; the cue is thrown at them after 1 s."""
    length = math.hypot(table.width_m, table.height_m)
    along = (table.width_m / length, table.height_m / length)  # unit vector up the diagonal

    def on_diagonal(s_m):
        return (s_m * along[0], s_m * along[1])

    cue = table.add_puck(pos_m=on_diagonal(2.5), radius_m=RADIUS_M, color="orange")
    for n in range(2):
        table.add_puck(pos_m=on_diagonal(7.0 + n * (2 * RADIUS_M + GAP_M)), radius_m=RADIUS_M)

    def throw(table):
        cue.vel_mps = (SPEED_MPS * along[0], SPEED_MPS * along[1])

    table.schedule(1.0, throw)
