"""Files the app ships with: the starter demo template and the window icon."""

from pathlib import Path

ASSETS_DIR = Path(__file__).resolve().parent
