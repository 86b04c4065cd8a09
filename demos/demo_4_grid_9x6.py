"""Demo 4: a 9 x 6 grid of small heavy pucks; try it with gravity."""

KEY = "4"
TITLE = "Grid of 54, heavy"
NOTES = """
Fling the orange puck through the pack and watch the chain of collisions, then press
g to turn gravity on. The pucks fall and pile up at the bottom, like balls in a box:
the pile only stays still because every overlap is pushed apart each step.
"""


def build(table, variation=0):
    """Pucks of radius 0.25 m and density 5 kg/m^2 at (j+1, k+1); the one at (3, 3) is orange."""
    for j in range(9):
        for k in range(6):
            pos_m = (j + 1.0, k + 1.0)
            color = "orange" if pos_m == (3.0, 3.0) else "white"
            table.add_puck(pos_m=pos_m, radius_m=0.25, density_kgpm2=5.0, color=color)
