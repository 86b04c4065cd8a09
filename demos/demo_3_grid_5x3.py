"""Demo 3: a 5 x 3 grid of middle-sized pucks with an orange cue in the middle."""

KEY = "3"
TITLE = "Grid of 15"
NOTES = """
Fling the orange puck in the middle and watch the motion spread through the grid.
Each collision passes momentum along the line joining the two centres, so the total
momentum of all the pucks (press c for the chart) only changes when a puck hits a wall.
"""


def build(table, variation=0):
    """Pucks of radius 0.55 m at (1.5(j+1), 1.5(k+1)); the one at (4.5, 4.5) is orange."""
    for j in range(5):
        for k in range(3):
            pos_m = (1.5 * (j + 1), 1.5 * (k + 1))
            color = "orange" if pos_m == (4.5, 4.5) else "white"
            table.add_puck(pos_m=pos_m, radius_m=0.55, color=color)
