"""Demo 2p: the same fast glancing hit, with the two-step penetration correction."""

from airtable.demos import _correction_comparison as scene

KEY = "2p"
TITLE = "Fast hit, two-step correction"
NOTES = """
The same hit with the course's two-step correction: both pucks are backed up along
the normal to where they touched and moved on with their new velocities, so the
overlap is replaced by an equal separation. The normal is still the one taken from
the overlapping pucks, so the white puck leaves at the same wrong 29 degrees as with
no correction. The two-step fix removes stickiness; only a smaller time step or the
perfect kiss (Shift+3) fixes the direction.
"""

DT_S = scene.DT_S
TRAILS = scene.TRAILS


def build(table, variation=0):
    """The shared scene with puck_correction = "two-step"."""
    scene.build_scene(table, "two-step")
