"""Demo 3p: the same fast glancing hit, resolved at the moment of first contact."""

from airtable.demos import _correction_comparison as scene

KEY = "3p"
TITLE = "Fast hit, perfect kiss"
NOTES = """
The same hit once more, but the pucks are backed up along their full motion to the
instant they first touched (the perfect kiss), and the normal is taken there. The
white puck now leaves at 14.5 degrees, where geometry says it must (sine of the angle
= offset / two radii), and the two paths still meet at 90 degrees. The answer no
longer depends on how deep the overlap was, so even a coarse step gets it right.
"""

DT_S = scene.DT_S
TRAILS = scene.TRAILS


def build(table, variation=0):
    """The shared scene with puck_correction = "perfect-kiss"."""
    scene.build_scene(table, "perfect-kiss")
