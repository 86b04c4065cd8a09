"""Demo 1p: a fast glancing hit at a coarse time step, with no penetration correction."""

from airtable.demos import _correction_comparison as scene

KEY = "1p"
TITLE = "Fast hit, no correction"
NOTES = """
A very fast cue at a coarse time step: by the step the hit is found, the two pucks
overlap by half a diameter, and with no correction the trail shows them left inside
each other. The velocities are worked out along the line of centres at that moment,
which is much steeper than at first contact, so the white puck leaves at about 29
degrees instead of the true 14.5. Compare with Shift+2 and Shift+3.
"""

DT_S = scene.DT_S
TRAILS = scene.TRAILS


def build(table, variation=0):
    """The shared scene with puck_correction = "off"."""
    scene.build_scene(table, "off")
