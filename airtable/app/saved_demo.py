"""Save the moment as a demo: the table as it is now, written as a demo file a teacher can read and edit (no pygame).

The file is plain Python data (settings, a list of pucks, a list of springs)
and a short build() that adds them, so it loads like any demo, is listed by
`--list-demos`, and can be edited by hand. Every float is written with repr,
the shortest text that reads back as the same number, so loading the file
gives the very same positions, velocities, masses and settings, bit for bit.
The table's clock starts again at 0, and timed events a demo had scheduled
are not saved (they are code, not data).
"""

from __future__ import annotations

import os
import time
from collections.abc import Collection
from pathlib import Path

from airtable.physics.table import AirTable

DEFAULT_FOLDER = Path("my_demos")  # where saved demos go when the app was given no --demos folder
KEY_PREFIX = "s"  # saved demos get the keys s1, s2, ... (Tab menu: type s1)

# (constant in the file, AirTable attribute): the settings a saved demo restores.
SETTINGS = (
    ("GRAVITY_ON", "gravity_on"),
    ("GRAVITY_MPS2", "gravity_mps2"),
    ("RESTITUTION_PUCKS", "cr_puck"),
    ("RESTITUTION_WALLS", "cr_wall"),
    ("WALL_CORRECTION", "wall_correction"),
    ("PUCK_CORRECTION", "puck_correction"),
    ("PUCK_COLLISIONS", "puck_collisions"),
)

BUILD = '''


def build(table, variation=0):
    """Put the settings, pucks and springs above on the table, exactly as they were saved."""
{settings}
    pucks = []
    for p in PUCKS:
        r, m = p["radius_m"], p["mass_kg"]
        puck = table.add_puck(p["pos_m"], r, m / (math.pi * r * r), p["vel_mps"], p["color"])
        table.mass_kg[puck.index] = m  # the saved mass exactly (density * pi r^2 may round differently)
        pucks.append(puck)
    for s in SPRINGS:
        i, j = s["pucks"]
        table.add_spring(pucks[i], pucks[j], s["length_m"], s["k_Npm"], s["damper_Nspm"], s["width_m"], s["color"])
'''


def _pair(v) -> str:
    return f"({float(v[0])!r}, {float(v[1])!r})"


def _rgb(c) -> str:
    return f"({int(c[0])}, {int(c[1])}, {int(c[2])})"


def puck_lines(table: AirTable) -> list[str]:
    return [
        f'    {{"pos_m": {_pair(table.pos_m[k])}, "vel_mps": {_pair(table.vel_mps[k])}, '
        f'"radius_m": {float(table.radius_m[k])!r}, "mass_kg": {float(table.mass_kg[k])!r}, '
        f'"color": {_rgb(table.color_rgb[k])}}},'
        for k in range(len(table.pos_m))
    ]


def spring_lines(table: AirTable) -> list[str]:
    pairs = table.spring_pairs
    return [
        f'    {{"pucks": ({int(pairs[s, 0])}, {int(pairs[s, 1])}), '
        f'"length_m": {float(table.spring_length_m[s])!r}, "k_Npm": {float(table.spring_k_Npm[s])!r}, '
        f'"damper_Nspm": {float(table.spring_damper_Nspm[s])!r}, "width_m": {float(table.spring_width_m[s])!r}, '
        f'"color": {_rgb(table.spring_color_rgb[s])}}},'
        for s in range(len(pairs))
    ]


def demo_source(table: AirTable, *, key: str, title: str, dt_s: float, origin: str = "") -> str:
    """The text of a demo file that rebuilds `table` as it is now, under `key`."""
    saved = time.strftime("%Y-%m-%d %H:%M")
    notes = f"Saved {origin} at t = {table.time_s:.2f} s on {saved}." if origin else f"Saved on {saved}."
    notes += " Every number below can be edited; press the demo's key again to load the edit."
    head = [
        f'"""{title}: a moment saved from the air table.',
        "",
        "Plain data: edit the numbers, then press the demo's key again (Tab, then its key).",
        "Positions in m (x to the right, y up, from the bottom-left corner), velocities in m/s,",
        'radii in m, masses in kg, colours as (red, green, blue) from 0 to 255."""',
        "",
        "import math",
        "",
        f"KEY = {key!r}",
        f"TITLE = {title!r}",
        f"NOTES = {notes!r}",
        f"DT_S = {float(dt_s)!r}  # the physics time step, s",
        "",
        *(f"{const} = {getattr(table, attr)!r}" for const, attr in SETTINGS),
        "",
        "# One per puck.",
        "PUCKS = [",
        *puck_lines(table),
        "]",
        "",
        '# One per spring: "pucks" are the two it joins, by their place in PUCKS (the first is 0).',
        "SPRINGS = [",
        *spring_lines(table),
        "]",
    ]
    settings = "\n".join(f"    table.{attr} = {const}" for const, attr in SETTINGS)
    return "\n".join(head) + BUILD.format(settings=settings)


def free_key(taken: Collection[str], folder: Path) -> str:
    """The first of s1, s2, ... that no demo has and that names no file in `folder`."""
    n = 1
    while f"{KEY_PREFIX}{n}" in taken or (folder / f"{KEY_PREFIX}{n}.py").exists():
        n += 1
    return f"{KEY_PREFIX}{n}"


def save_folder(directories: Collection[Path], builtin: Path) -> Path:
    """Where saved demos go: the last demo folder the teacher gave (never the built-in one), else DEFAULT_FOLDER."""
    own = [Path(d) for d in directories if Path(d).resolve() != Path(builtin).resolve()]
    return own[-1] if own else DEFAULT_FOLDER


def write_demo(path: Path, source: str) -> Path:
    """Write `source` to `path`, never over an existing file (FileExistsError); OSError if it cannot."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "x", encoding="utf-8") as f:
        f.write(source)
    return path


def check_save_demo_path(text: str) -> Path:
    """Where `--save-demo` writes; ValueError with a sentence if it cannot."""
    path = Path(text)
    if path.suffix != ".py":
        raise ValueError(f"--save-demo {text}: a demo file name must end in .py")
    if path.exists():
        raise ValueError(f"--save-demo {text}: that file already exists; choose another name or delete it first")
    if not path.parent.is_dir():
        raise ValueError(f"--save-demo {text}: there is no folder {path.parent}")
    if not os.access(path.parent, os.W_OK):
        raise ValueError(f"--save-demo {text}: cannot write in {path.parent}; choose a folder you may write to")
    return path
