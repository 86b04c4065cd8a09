"""A prediction round as the teacher's app, the server and the students' windows know it:
its state, the guesses, the revealed arrows (the wire format is net/predictions.py)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

STATES = ("open", "revealed", "closed")
MAX_PREDICT_SPEED_MPS = 100.0  # far above any demo; a bigger guess is a mistake, not physics
MAX_ROUND_PUCKS = 256  # pucks a round offers for prediction (a class predicts a handful)
ARROW_S = 1.0  # a prediction arrow is drawn as far as the puck would go in this time


@dataclass(frozen=True)
class Prediction:
    """One validated guess: in round `round_id`, puck `puck` leaves with `vel_mps`."""

    round_id: int
    puck: int
    vel_mps: tuple[float, float]


@dataclass(frozen=True)
class Arrow:
    """One revealed prediction: whose (label, colour), which puck, what velocity."""

    puck: int
    vel_mps: tuple[float, float]
    color: tuple[int, int, int]
    label: str = ""


@dataclass(frozen=True)
class RoundInfo:
    """What a ROUND message says (the server's and every student's view of the round)."""

    round_id: int
    state: str  # "open", "revealed" or "closed"
    pucks: int  # pucks 0 .. pucks-1 may be predicted
    predicted: int = 0  # students who predicted at least one puck
    players: int = 0  # students at the table
    arrows: tuple[Arrow, ...] = ()
    truth: tuple[tuple[float, float], ...] = ()  # every predictable puck's velocity after the collision
    summary: tuple[str, ...] = field(default=())
    from_m: tuple[tuple[float, float], ...] = ()  # where each predictable puck stood when the round opened


def clamp_speed(vel_mps: Sequence[float]) -> tuple[float, float]:
    """`vel_mps` cut to MAX_PREDICT_SPEED_MPS (the player sends only what the server accepts)."""
    vx, vy = (float(v) for v in vel_mps)
    speed = math.hypot(vx, vy)
    if speed > MAX_PREDICT_SPEED_MPS:
        vx, vy = vx * MAX_PREDICT_SPEED_MPS / speed, vy * MAX_PREDICT_SPEED_MPS / speed
    return (vx, vy)
