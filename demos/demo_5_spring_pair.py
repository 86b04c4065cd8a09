"""Demo 5: two pucks joined by a spring with a damper."""

KEY = "5"
TITLE = "Two pucks on a spring"
NOTES = """
The spring starts stretched (2.1 m apart, relaxed length 1.5 m), so the pucks pull
together and bounce. The damper takes energy out only while the spring is changing
length, so the bouncing dies away while the pair keeps drifting. Fling one puck and
watch the pair spin: the spring's pull is what bends their paths.
"""


def build(table, variation=0):
    """Pucks of radius 0.4 m at (2, 3) and (3.5, 4.5); k = 20 N/m, damper 0.5 N s/m."""
    p1 = table.add_puck(pos_m=(2.0, 3.0), radius_m=0.4)
    p2 = table.add_puck(pos_m=(3.5, 4.5), radius_m=0.4)
    table.add_spring(p1, p2, length_m=1.5, k_Npm=20.0, damper_Nspm=0.5, width_m=0.2, color="gold")
