"""Demo 8: a cue shot along a line of 20 pucks, on the line and a little off it."""

KEY = "8"
TITLE = "Pool line"
NOTES = """
The orange cue is shot along a line of 20 touching pucks. Dead on the line, the whole
row passes the motion along and only the last puck leaves. Use the left and right
arrows to start the cue a little off the line: every hit sends the next puck a bit
further off, the error grows down the row, and the line falls apart, which is why
long chains of pool shots are so hard.
"""

OFFSETS_PCT = (0, 10, 20, 40, 50)  # how far the cue starts off the line, in % of a radius
VARIATIONS = tuple(
    "cue on the line (0 % of a radius)" if pct == 0 else f"cue {pct} % of a radius off the line" for pct in OFFSETS_PCT
)

RADIUS_M = 0.1
COUNT = 20
GAP_M = 0.001  # a hair apart, so neighbours do not start overlapping
SPEED_MPS = 4.0


def build(table, variation=0):
    """A row of 20 pucks at mid height; the cue is shot along it after 1 s."""
    y_m = table.height_m / 2.0
    for n in range(COUNT):
        table.add_puck(pos_m=(3.5 + n * (2 * RADIUS_M + GAP_M), y_m), radius_m=RADIUS_M)
    offset_m = OFFSETS_PCT[variation % len(OFFSETS_PCT)] / 100.0 * RADIUS_M
    cue = table.add_puck(pos_m=(1.0, y_m + offset_m), radius_m=RADIUS_M, color="orange")

    def shoot(table):
        cue.vel_mps = (SPEED_MPS, 0.0)

    table.schedule(1.0, shoot)
