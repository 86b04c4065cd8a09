"""Demo 2: a 4 x 2 grid of big pucks with an orange cue in it."""

KEY = "2"
TITLE = "Grid of 8"
NOTES = """
Fling the orange puck into its neighbours. Every puck has the same mass, so in a
head-on hit the mover stops dead and the one it hits carries on at its speed. In a
glancing hit the two leave at right angles to each other.
"""


def build(table, variation=0):
    """Pucks of radius 0.75 m at (2(j+1), 2(k+1)); the one at (4, 4) is orange."""
    for j in range(4):
        for k in range(2):
            pos_m = (2.0 * (j + 1), 2.0 * (k + 1))
            color = "orange" if pos_m == (4.0, 4.0) else "white"
            table.add_puck(pos_m=pos_m, radius_m=0.75, color=color)
