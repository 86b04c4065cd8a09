"""Make the pictures in docs/ from the app itself: `python -m tools.doc_pictures [--out docs]`.

Each picture is the teacher's App on one demo, in a 1280x720 window (a projector), with the
keys a teacher would press, saved at a set simulated time: so the pictures show the app as
it is today, and the same run gives the same picture. The window is drawn with pygame's
dummy video driver, which draws exactly what a real window shows.
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass
from pathlib import Path

from airtable.desktop import prepare_for_pygame
from tools import ROOT

FRAME_S = 1.0 / 60.0
SIZE_PX = (1280, 720)


@dataclass(frozen=True)
class Picture:
    demo: str  # its key, as --demo takes it
    variation: int  # counting from 0, as the app does
    keys: tuple[str, ...]  # pygame key names, pressed at the start
    at_s: float  # simulated time of the picture


PICTURES = {
    "annotations.png": Picture("2p", 0, ("a",), 1.30),  # the fast hit, two-step: overlap and separation
    "energy_chart.png": Picture("5", 1, ("v", "c"), 6.0),  # the spring pair without its damper
    "help.png": Picture("1", 0, ("f1",), 0.5),
}


def take(name: str, picture: Picture, out: Path) -> Path:
    """Run the app for `picture` and save its frame at `picture.at_s` to out/name."""
    import pygame

    from airtable.app.app import App
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    demos, _ = discover([BUILTIN_DIR])
    app = App(demos, demo_key=picture.demo, variation=picture.variation, headless=True, window_size_px=SIZE_PX)
    for key in picture.keys:
        code = pygame.key.key_code(key)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=code, mod=0, unicode=key, scancode=0))
        pygame.event.post(pygame.event.Event(pygame.KEYUP, key=code, mod=0, unicode=key, scancode=0))
    for _ in range(round(picture.at_s / FRAME_S) + 1):  # bounded: one frame runs 1/60 s of the table
        if app.table.time_s >= picture.at_s - 1e-9:
            break
        app.frame(FRAME_S)
    app.frame(0.0)  # draw the moment itself, the keys' effects all shown
    return app.window.save_screenshot(out / name)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.doc_pictures", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs", help="the folder to write them to (default docs/)")
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"only these pictures (of {', '.join(PICTURES)})")
    args = parser.parse_args(argv)
    unknown = sorted(set(args.names) - set(PICTURES))
    if unknown:
        parser.error(f"no picture {', '.join(unknown)}; the pictures are {', '.join(PICTURES)}")
    prepare_for_pygame()
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.names or PICTURES:
        print(take(name, PICTURES[name], args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
