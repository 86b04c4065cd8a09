"""Demo 9: a cut shot on the top puck of a ring of 13."""

import math

KEY = "9"
TITLE = "Trick shot"
NOTES = """
After one second the orange cue clips the top puck of the ring so that the line of
centres points at the ring's middle. A puck at rest always leaves along the line of
centres, so the top puck drops straight through the middle while the cue goes off at
90 degrees to it: equal masses, one at rest, restitution 1. Then watch the top puck
break the ring open from the inside.
"""

COUNT = 13
RADIUS_M = 0.4
RING_M = 2.2  # radius of the ring of centres
SPEED_MPS = 5.0


def build(table, variation=0):
    """Thirteen pucks on a ring centred on the table; the cue is thrown at the top one after 1 s."""
    cx, cy = table.width_m / 2.0, table.height_m / 2.0
    for n in range(COUNT):
        angle = math.pi / 2.0 + 2.0 * math.pi * n / COUNT  # n = 0 is the top puck
        table.add_puck(pos_m=(cx + RING_M * math.cos(angle), cy + RING_M * math.sin(angle)), radius_m=RADIUS_M)

    # Aim so the cue touches the top puck from straight above it: then the line of
    # centres at contact is vertical and points through the ring's middle.
    start = (cx - 2.25, table.height_m - RADIUS_M - 0.15)
    contact = (cx, cy + RING_M + 2.0 * RADIUS_M)
    dx, dy = contact[0] - start[0], contact[1] - start[1]
    scale = SPEED_MPS / math.hypot(dx, dy)
    cue = table.add_puck(pos_m=start, radius_m=RADIUS_M, color="orange")

    def throw(table):
        cue.vel_mps = (dx * scale, dy * scale)

    table.schedule(1.0, throw)
