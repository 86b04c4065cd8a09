"""Demo 5: two pucks joined by a spring, drifting together; with and without a damper."""

KEY = "5"
TITLE = "Two pucks on a spring"
NOTES = """
The spring starts stretched (2.1 m apart, relaxed length 1.5 m) and the pair drifts
up and to the right at 0.22 m/s. The damper takes energy out only while the spring
changes length, so the bouncing dies away within a second or two while the pair
keeps drifting: a damper inside the pair cannot stop its centre of mass. Press Right
for no damper: the bouncing goes on, and the chart's total swings by about 3 % without
drifting (semi-implicit Euler). Fling one puck and watch the pair spin.
"""

VARIATIONS = ("damper 0.5 N s/m", "no damper")
DRIFT_MPS = (0.2, 0.1)  # small enough that the pair stays off the walls for 20 s


def build(table, variation=0):
    """Pucks of radius 0.4 m at (2, 3) and (3.5, 4.5), both drifting; k = 20 N/m, damper 0.5 or 0 N s/m."""
    damper_Nspm = (0.5, 0.0)[variation % len(VARIATIONS)]
    p1 = table.add_puck(pos_m=(2.0, 3.0), radius_m=0.4, vel_mps=DRIFT_MPS)
    p2 = table.add_puck(pos_m=(3.5, 4.5), radius_m=0.4, vel_mps=DRIFT_MPS)
    table.add_spring(p1, p2, length_m=1.5, k_Npm=20.0, damper_Nspm=damper_Nspm, width_m=0.2, color="gold")
