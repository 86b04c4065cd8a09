"""Named colours as RGB triples, without importing pygame.

The physics and the network layer store colours as RGB so that snapshots and
tests never need a display library. The names are pygame's (X11) names for the
colours the course uses.
"""

from __future__ import annotations

from collections.abc import Sequence

NAMED_RGB: dict[str, tuple[int, int, int]] = {
    "black": (0, 0, 0),
    "white": (255, 255, 255),
    "grey": (128, 128, 128),
    "darkgrey": (64, 64, 64),
    "lightgrey": (200, 200, 200),
    "red": (255, 0, 0),
    "orangered": (255, 69, 0),
    "orange": (255, 165, 0),
    "yellow": (255, 255, 0),
    "gold": (255, 215, 0),
    "tan": (210, 180, 140),
    "green": (0, 255, 0),
    "palegreen3": (124, 205, 124),
    "blue": (0, 0, 255),
    "dodgerblue": (30, 144, 255),
    "cyan": (0, 255, 255),
    "magenta": (255, 0, 255),
    "pink": (255, 192, 203),
    "coral": (255, 127, 80),
    "maroon1": (255, 52, 179),
    "palevioletred2": (238, 121, 159),
    "peachpuff": (255, 218, 185),
    "rosybrown3": (205, 155, 155),
    "brown": (165, 42, 42),
    "purple": (160, 32, 240),
    "skyblue": (135, 206, 235),
    "steelblue": (70, 130, 180),
    "violet": (238, 130, 238),
    "salmon": (250, 128, 114),
    "khaki": (240, 230, 140),
}


def rgb(color: str | Sequence[int]) -> tuple[int, int, int]:
    """Return `color` (a name from NAMED_RGB or an (r, g, b) triple) as an RGB tuple."""
    if isinstance(color, str):
        try:
            return NAMED_RGB[color.lower().replace(" ", "")]
        except KeyError:
            known = ", ".join(sorted(NAMED_RGB))
            raise ValueError(f"unknown colour {color!r}; use an (r, g, b) triple or one of: {known}") from None
    try:
        r, g, b = (int(c) for c in color)
    except (TypeError, ValueError):
        raise ValueError(f"colour {color!r} is neither a colour name nor an (r, g, b) triple") from None
    if not all(0 <= c <= 255 for c in (r, g, b)):
        raise ValueError(f"colour {color!r} has a component outside 0..255")
    return (r, g, b)
