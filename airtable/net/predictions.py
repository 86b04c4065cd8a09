"""Predict, then reveal, on the wire: PREDICT (8, client -> server) and ROUND (9, server -> client).

No pygame, no sockets. Both messages are compact UTF-8 JSON objects, like
HELLO and INPUT; README documents them byte by byte.

PREDICT  {"round": 3, "puck": 0, "vel_mps": [1.25, -0.5]}
         a student's guess of puck 0's velocity once the coming collision is over.
ROUND    {"round": 3, "state": "open", "pucks": 2, "predicted": 17, "players": 28,
          "arrows": [[puck, vx, vy, r, g, b, "label"], ...], "truth": [[vx, vy], ...],
          "summary": ["puck 1: median 12 deg off; ..."], "from_m": [[x, y], ...]}
         "arrows", "truth" and "summary" are empty until the reveal.

`PredictionBook` keeps the predictions on the server, per student per puck,
latest wins; it is shared between the network thread and the game loop.
Nothing in it ever reaches the physics: the game loop only draws it and
works out how far it was from what happened.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence

from airtable.model.rounds import (  # noqa: F401  (the round's data, here where it travels)
    MAX_PREDICT_SPEED_MPS,
    MAX_ROUND_PUCKS,
    STATES,
    Arrow,
    Prediction,
    RoundInfo,
    clamp_speed,
)
from airtable.net import protocol as proto

PREDICT = proto.PREDICT  # 8
ROUND = proto.ROUND  # 9
MAX_ROUND_ARROWS = 4000  # arrows a revealed ROUND carries (about 40 bytes each)
MAX_SUMMARY_LINES = 32
MAX_SUMMARY_CHARS = 120
MAX_LABEL_CHARS = 2 * proto.MAX_NAME_CHARS + 8
MAX_ROUND_ID = 2**31 - 1
PREDICT_EXAMPLE = '{"round": 1, "puck": 0, "vel_mps": [1.5, -0.25]}'


def encode_predict(round_id: int, puck: int, vel_mps: Sequence[float]) -> bytes:
    """A PREDICT frame (under 100 bytes)."""
    vx, vy = (float(v) for v in vel_mps)
    return proto.encode_json(PREDICT, {"round": int(round_id), "puck": int(puck), "vel_mps": [vx, vy]})


def validate_predict(message: dict, pucks: int) -> Prediction:
    """Check a PREDICT object against a round offering `pucks` pucks (the round id is checked by the caller)."""
    try:
        return _validate_predict(message, pucks)
    except proto.ProtocolError as e:
        raise proto._with_example(e, PREDICT_EXAMPLE) from None


def _validate_predict(message: dict, pucks: int) -> Prediction:
    proto._check_fields(message, "PREDICT", ("round", "puck", "vel_mps"))
    round_id = proto._integer(message["round"], "PREDICT round")
    puck = proto._integer(message["puck"], "PREDICT puck")
    if not 0 <= puck < pucks:
        raise proto.ProtocolError(f"PREDICT puck {puck} is not on the table; this round has pucks 0 to {pucks - 1}")
    vel = message["vel_mps"]
    if not (isinstance(vel, list) and len(vel) == 2):
        raise proto.ProtocolError(f"PREDICT vel_mps must be a pair [vx, vy] of numbers in m/s, not {proto._short(vel)}")
    vx = proto._number(vel[0], "PREDICT vel_mps x")
    vy = proto._number(vel[1], "PREDICT vel_mps y")
    if math.hypot(vx, vy) > MAX_PREDICT_SPEED_MPS:
        raise proto.ProtocolError(
            f"PREDICT vel_mps {proto._short(vel)} is faster than {MAX_PREDICT_SPEED_MPS:g} m/s; predict a slower speed"
        )
    return Prediction(round_id, puck, (vx, vy))


def parse_predict(payload: bytes, pucks: int) -> Prediction:
    return validate_predict(proto.parse_json(payload, "PREDICT", PREDICT_EXAMPLE), pucks)


# ---------------------------------------------------------------- ROUND


def encode_round(info: RoundInfo) -> bytes:
    """A ROUND frame; arrows and summary are cut to their bounds, so its size is bounded too."""
    message = {
        "round": int(info.round_id),
        "state": info.state,
        "pucks": int(info.pucks),
        "predicted": int(info.predicted),
        "players": int(info.players),
        "arrows": [
            [
                a.puck,
                round(a.vel_mps[0], 4),
                round(a.vel_mps[1], 4),
                *a.color,
                proto.printable(a.label)[:MAX_LABEL_CHARS],
            ]
            for a in info.arrows[:MAX_ROUND_ARROWS]
        ],
        "truth": [[round(vx, 4), round(vy, 4)] for vx, vy in info.truth[:MAX_ROUND_PUCKS]],
        "summary": [proto.printable(s)[:MAX_SUMMARY_CHARS] for s in info.summary[:MAX_SUMMARY_LINES]],
        "from_m": [[round(x, 5), round(y, 5)] for x, y in info.from_m[:MAX_ROUND_PUCKS]],
    }
    return proto.encode_json(ROUND, message)


def _bad_round(what: str) -> proto.ProtocolError:
    return proto.ProtocolError(f"the server's ROUND has {what}; the server may run a different airtable version")


def _velocity(value: object, what: str) -> tuple[float, float]:
    vx, vy = (proto._number(v, what) for v in value)
    if math.hypot(vx, vy) > 10 * MAX_PREDICT_SPEED_MPS:
        raise _bad_round(f"a {what} too fast to draw")
    return (vx, vy)


def _position(value: list) -> tuple[float, float]:
    x, y = (proto._number(v, "a puck position") for v in value)
    if max(abs(x), abs(y)) > 10 * proto.MAX_TABLE_M:
        raise _bad_round("a puck position far off any table")
    return (x, y)


def _arrow(row: object) -> Arrow:
    if not (isinstance(row, list) and len(row) == 7 and isinstance(row[6], str)):
        raise _bad_round("an arrow that is not [puck, vx, vy, r, g, b, label]")
    puck = proto._integer(row[0], "arrow puck")
    if not 0 <= puck < MAX_ROUND_PUCKS:
        raise _bad_round(f"an arrow for puck {puck}")
    color = proto._color(row[3:6], "arrow colour")
    label = row[6][:MAX_LABEL_CHARS]
    if not label.isprintable():
        raise _bad_round("an unprintable arrow label")
    return Arrow(puck, _velocity(row[1:3], "arrow velocity"), color, label)


def parse_round(payload: bytes) -> RoundInfo:
    """Check a ROUND from the server: every count and number bounded before anything draws it."""
    message = proto.parse_json(payload, "the server's ROUND", '{"round": 1, "state": "open", ...}')
    fields = ("round", "state", "pucks", "predicted", "players", "arrows", "truth", "summary", "from_m")
    proto._check_fields(message, "the server's ROUND", fields)
    round_id = proto._integer(message["round"], "the round id")
    state = message["state"]
    pucks = proto._integer(message["pucks"], "the round's puck count")
    predicted = proto._integer(message["predicted"], "the round's prediction count")
    players = proto._integer(message["players"], "the round's player count")
    if not (0 <= round_id <= MAX_ROUND_ID and state in STATES and 0 <= pucks <= MAX_ROUND_PUCKS):
        raise _bad_round(f"round {proto._short(round_id)} in state {proto._short(state)} with {pucks} pucks")
    if not (0 <= predicted <= max(players, 0) <= 100_000):
        raise _bad_round(f"{predicted} of {players} students predicted")
    arrows, truth, summary = message["arrows"], message["truth"], message["summary"]
    if not (isinstance(arrows, list) and len(arrows) <= MAX_ROUND_ARROWS):
        raise _bad_round("too many arrows")
    if not (
        isinstance(truth, list) and len(truth) <= pucks and all(isinstance(t, list) and len(t) == 2 for t in truth)
    ):
        raise _bad_round("true velocities that are not pairs, one per puck")
    if not (isinstance(summary, list) and len(summary) <= MAX_SUMMARY_LINES):
        raise _bad_round("too many summary lines")
    from_m = message["from_m"]
    if not (
        isinstance(from_m, list) and len(from_m) <= pucks and all(isinstance(p, list) and len(p) == 2 for p in from_m)
    ):
        raise _bad_round("puck positions that are not pairs, one per puck")
    lines = tuple(proto.printable(proto._text(s, "a summary line", MAX_SUMMARY_CHARS)) for s in summary)
    return RoundInfo(
        round_id,
        state,
        pucks,
        predicted,
        players,
        tuple(_arrow(a) for a in arrows),
        tuple(_velocity(t, "true velocity") for t in truth),
        lines,
        tuple(_position(p) for p in from_m),
    )


# ---------------------------------------------------------------- the server's book


class PredictionBook:
    """The current round's predictions, per student per puck (latest wins); thread-safe.

    The network thread `add`s validated predictions and `forget`s students who
    leave; the game loop opens and closes rounds and reads the arrows. A
    prediction for an older round (it crossed the reveal on the wire) is
    ignored; one for a round that never was is refused.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.round_id = 0  # the newest round opened (0: none yet)
        self.state = "closed"
        self.pucks = 0
        self._by_student: dict[int, tuple[str, tuple[int, int, int], dict[int, tuple[float, float]]]] = {}

    def open(self, round_id: int, pucks: int) -> None:
        with self._lock:
            self.round_id, self.state, self.pucks = int(round_id), "open", min(int(pucks), MAX_ROUND_PUCKS)
            self._by_student.clear()

    def set_state(self, state: str) -> None:
        with self._lock:
            self.state = state

    def accepts(self) -> tuple[int, int] | None:
        """(round id, puck count) while a round takes predictions, else None."""
        with self._lock:
            return (self.round_id, self.pucks) if self.state == "open" else None

    def add(self, student: int, label: str, color: tuple[int, int, int], prediction: Prediction) -> bool:
        """Keep `prediction` (True), or ignore it because its round is no longer open (False).

        Raises ProtocolError for a round id that was never opened."""
        with self._lock:
            if prediction.round_id > self.round_id or prediction.round_id < 1:
                raise proto.ProtocolError(
                    f"PREDICT round {prediction.round_id} was never opened; the current round is {self.round_id}"
                )
            if prediction.round_id != self.round_id or self.state != "open":
                return False
            if prediction.puck >= self.pucks:
                raise proto.ProtocolError(
                    f"PREDICT puck {prediction.puck} is not on the table; this round has pucks 0 to {self.pucks - 1}"
                )
            entry = self._by_student.setdefault(student, (label, color, {}))
            entry[2][prediction.puck] = prediction.vel_mps
            return True

    def forget(self, student: int) -> None:
        with self._lock:
            self._by_student.pop(student, None)

    def count(self) -> int:
        """Students who predicted at least one puck."""
        with self._lock:
            return sum(1 for _, _, guesses in self._by_student.values() if guesses)

    def arrows(self) -> list[Arrow]:
        """Every prediction, student by student in the order they first predicted."""
        with self._lock:
            return [
                Arrow(puck, vel, color, label)
                for label, color, guesses in self._by_student.values()
                for puck, vel in sorted(guesses.items())
            ]
