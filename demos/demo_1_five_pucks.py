"""Demo 1: five pucks of different sizes, at rest, for flinging with the mouse."""

KEY = "1"
TITLE = "Five pucks"
NOTES = """
Grab a puck with the mouse and fling it into another one. All five have the same
density, so mass grows with the area: the big puck is over 40 times heavier than
the small orange one. In a hit both pucks get the same push, so the heavy one barely
changes speed while the light one bounces off fast: momentum is shared, not speed.
"""

# (x, y) in metres, radius in metres, colour: the course's layout.
PUCKS = (
    ((2.5, 7.5), 0.25, "orange"),
    ((6.0, 2.5), 0.45, "white"),
    ((7.5, 2.5), 0.65, "white"),
    ((2.5, 5.5), 1.65, "white"),
    ((7.5, 7.5), 0.95, "white"),
)


def build(table, variation=0):
    """Add the five pucks, all at rest."""
    for pos_m, radius_m, color in PUCKS:
        table.add_puck(pos_m=pos_m, radius_m=radius_m, density_kgpm2=0.3, color=color)
