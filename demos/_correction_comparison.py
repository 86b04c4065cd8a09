"""The scene shared by demos 1p, 2p and 3p: one fast glancing hit, three corrections.

Not a demo itself (the loader skips files starting with "_"). At a coarse 1/20 s
step the cue moves 1.25 m per step, so when the hit is detected the pucks already
overlap by about half a diameter, and the line of centres at that moment (the
"detected normal") is much steeper than the normal at the moment of first contact.
"""

import math

DT_S = 1 / 20
TRAILS = True

RADIUS_M = 0.45
SPEED_MPS = 25.0
IMPACT_PARAMETER_M = 0.5 * RADIUS_M  # cue's line of motion passes this far from the target's centre
START_GAP_M = 2.9  # cue to target along x: the hit is detected at 0.4 m, well past first contact at 0.87 m
THROW_TIME_S = 1.0

# Where the target should go with a perfect contact normal: sin(angle) = b / (2 r).
IDEAL_ANGLE_DEG = math.degrees(math.asin(IMPACT_PARAMETER_M / (2.0 * RADIUS_M)))


def build_scene(table, correction):
    """A still white target and an orange cue thrown at it along +x after 1 s."""
    table.puck_correction = correction
    y_m = table.height_m / 2.0
    cue = table.add_puck(pos_m=(1.5, y_m + IMPACT_PARAMETER_M), radius_m=RADIUS_M, color="orange")
    table.add_puck(pos_m=(1.5 + START_GAP_M, y_m), radius_m=RADIUS_M)

    def throw(table):
        cue.vel_mps = (SPEED_MPS, 0.0)

    table.schedule(THROW_TIME_S, throw)
    return cue
