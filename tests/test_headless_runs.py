"""`python -m airtable --headless --seconds 2 --screenshot x.png` for every demo shows its pucks.

With --headless and --no-server, --seconds counts simulated time (frames of 1/60 s run
back to back), so these runs take as long as the machine needs, not two seconds each.
"""

from __future__ import annotations

import numpy as np
import pygame
import pytest

from airtable.app.demo_loader import BUILTIN_DIR, discover
from airtable.app.environment import Environment
from airtable.cli import main
from airtable.physics.table import AirTable

DEMOS, _ = discover([BUILTIN_DIR])
HUD_PX = 30  # title line at the top, status bar at the bottom


def puck_colors(key: str) -> tuple[np.ndarray, int]:
    """The distinct RGB colours of the demo's pucks (each puck's ring is drawn in it)."""
    table = AirTable(10.0, Environment().view_height_m)
    DEMOS[key].build(table, 0)
    return np.unique(table.color_rgb, axis=0), len(table.pucks)


@pytest.mark.parametrize("key", list(DEMOS))
def test_headless_screenshot_shows_the_pucks(key, tmp_path):
    shot = tmp_path / f"demo_{key}.png"
    assert main(["--no-server", "--headless", "--seconds", "2", "--demo", key, "--screenshot", str(shot)]) == 0
    pygame.display.init()
    image = pygame.surfarray.array3d(pygame.image.load(str(shot)))  # (w, h, 3)
    table_area = image[:, HUD_PX:-HUD_PX].reshape(-1, 3)
    colors, n_pucks = puck_colors(key)
    in_puck_color = np.any(np.all(table_area[:, None, :] == colors[None], axis=2), axis=1)
    drawn = np.count_nonzero(in_puck_color)
    # Every puck is at least a small disc or a ring of a few dozen pixels.
    assert drawn >= 10 * min(n_pucks, 50), f"demo {key}: only {drawn} pixels in puck colours"
