"""The airtable wire protocol, version 2 (no pygame, no sockets).

Every message is a frame: ``[u32 big-endian length L][u8 type][L-1 payload bytes]``.
HELLO, WELCOME, ERROR and INPUT carry a JSON object; SNAPSHOT and LAYOUT carry
snapshot format 2 (codec.py: what moves, coded against what each player holds,
and what rarely changes); BYE is empty. README documents every byte.

Everything that comes off the network is checked here and turned into small
immutable values (`Hello`, `InputRecord`, `Welcome`; codec.py makes a `Scene`
with the bounds below); a bad message raises `ProtocolError` whose text is a
sentence a person can act on. Nothing is ever built from network bytes except
numbers, strings and numpy arrays of a fixed dtype.
"""

from __future__ import annotations

import json
import math
import re
import struct
import unicodedata
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from airtable.net.names import MAX_NAME_CHARS, looks_like_label
from airtable.physics.table import TABLE_HEIGHT_M, TABLE_WIDTH_M

PROTOCOL_VERSION = 2
DEFAULT_PORT = 8888
DEFAULT_TABLE_SIZE_M = (TABLE_WIDTH_M, TABLE_HEIGHT_M)  # until the game loop (or a WELCOME) says otherwise

HELLO = 1
WELCOME = 2
ERROR = 3
INPUT = 4
SNAPSHOT = 5
BYE = 6
LAYOUT = 7  # what rarely changes in a snapshot (codec.py), sent when it changes
AIDS = 10  # the teacher's teaching aids at a tick (aids_wire.py), after its SNAPSHOT while any aid is on
PREDICT = 8  # a student's guess in a predict-then-reveal round (predictions.py)
ROUND = 9  # the round's state, counts and, once revealed, every guess (predictions.py)
CHALLENGE = 13  # server: prove you hold the seat's token (a nonce), answering a HELLO with "seat"
PROOF = 14  # client: HMAC(token, nonce), so the token itself never crosses the network again (identity.py)
FRAME_NAMES = {
    HELLO: "HELLO",
    WELCOME: "WELCOME",
    ERROR: "ERROR",
    INPUT: "INPUT",
    SNAPSHOT: "SNAPSHOT",
    BYE: "BYE",
    LAYOUT: "LAYOUT",
    AIDS: "AIDS",
    PREDICT: "PREDICT",
    ROUND: "ROUND",
    CHALLENGE: "CHALLENGE",
    PROOF: "PROOF",
}
CLIENT_FRAMES = frozenset({HELLO, INPUT, BYE, PREDICT, PROOF})

# Bytes of L (type + payload) a client may send. A real INPUT is under 400
# bytes and a HELLO with the longest name and password under 1000, so a
# client cannot make the server parse more than it needs.
MAX_CLIENT_FRAME = 1024
# Snapshots grow with the number of pucks; this allows the
# drawing budget below with room to spare, while a bogus length cannot eat memory.
MAX_SERVER_FRAME = 16 * 1024 * 1024

MAX_PASSWORD_CHARS = 100
MAX_KEYS = 16
MAX_KEY_CHARS = 16
MAX_ERROR_CHARS = 500
MAX_TOKEN_CHARS = 48  # a seat token, "<number>-<32 hex digits>" (see identity.py)
MAX_SEAT = 999_999  # the highest seat number a token can name (six digits)
# A cursor may wander off the table (the view can be zoomed out), but not
# further than this many table sizes from it; the player clamps to the same box.
CURSOR_MARGIN_TABLES = 5.0
# What a player accepts from a server before it draws anything: a table from
# 1 cm to 10 km on a side, no longer than 100 times its width (or the other
# way round), and at most this many things to draw in one frame.
MIN_TABLE_M = 0.01
MAX_TABLE_M = 1e4
MAX_TABLE_ASPECT = 100.0
MAX_DRAWN_PUCKS = 20_000
MAX_DRAWN_SPRINGS = 10_000
MAX_DRAWN_CURSORS = 1_000
MIN_VIEW_ZOOM = 0.01
MAX_VIEW_ZOOM = 1000.0
MAX_VIEW_ORIGIN_M = 1e6  # the teacher may pan anywhere; the view travels clamped to 1000 km
MAX_DRAWN_TEXT_CHARS = 300  # a title or status line longer than this is cut, not drawn a mile wide

_HEADER = struct.Struct(">IB")


class ProtocolError(Exception):
    """A message broke the protocol; str(error) is a sentence for a person."""


# ---------------------------------------------------------------- frames


def encode_frame(frame_type: int, payload: bytes = b"") -> bytes:
    """One frame: length, type, payload."""
    if frame_type not in FRAME_NAMES:
        raise ValueError(f"unknown frame type {frame_type!r}")
    return _HEADER.pack(len(payload) + 1, frame_type) + payload


def _looks_like_text(head: bytes) -> bool:
    return len(head) > 0 and all(32 <= b < 127 or b in (9, 10, 13) for b in head)


class FrameReader:
    """Incremental frame decoder: feed it bytes as they arrive, get whole frames back.

    `max_frame` bounds L (type + payload); the server uses MAX_CLIENT_FRAME and
    the player MAX_SERVER_FRAME. `allowed` lists the frame types the peer may
    send. Errors are raised as early as the bytes show them (a huge length or a
    bad type byte before the payload arrives). After an error the reader is
    dead: the connection must be dropped. `sender` is "the server" on the
    player's side, which changes the hints to ones a student can act on.
    """

    def __init__(
        self, max_frame: int = MAX_CLIENT_FRAME, allowed: Iterable[int] = FRAME_NAMES, sender: str = "the client"
    ) -> None:
        self.max_frame = int(max_frame)
        self.allowed = frozenset(allowed)
        self.sender = sender
        self._from_server = sender == "the server"
        self._buf = bytearray()
        self._checked_header = False  # the frame at the buffer start has passed the checks

    @property
    def pending(self) -> int:
        """Bytes of a frame received but not yet complete."""
        return len(self._buf)

    def feed(self, data: bytes) -> list[tuple[int, bytes]]:
        """Add received bytes; return the frames they complete, in order."""
        buf = self._buf
        buf += data
        frames: list[tuple[int, bytes]] = []
        while len(buf) >= 4:
            length = int.from_bytes(buf[:4], "big")
            if not self._checked_header:
                self._check_length(length, bytes(buf[:4]))
                if len(buf) < 5:
                    break
                self._check_type(buf[4])
                self._checked_header = True
            if len(buf) < 4 + length:
                break
            frames.append((buf[4], bytes(buf[5 : 4 + length])))
            del buf[: 4 + length]
            self._checked_header = False
        return frames

    def _check_length(self, length: int, head: bytes) -> None:
        if self._from_server:
            hint = "this address and port run some other program: check them in the teacher's 'join with:' line"
            if _looks_like_text(head):
                hint = f"the answer looks like text ({head!r}), not an airtable message; {hint}"
        else:
            hint = "this port speaks the airtable protocol: join with airtable-client"
            if _looks_like_text(head):
                hint = (
                    f"the data looks like text ({head!r}), not an airtable message; {hint}, not a web browser or telnet"
                )
        if length == 0:
            raise ProtocolError(f"received an empty message (length 0); {hint}")
        if length > self.max_frame:
            raise ProtocolError(f"received a message of {length} bytes, over the {self.max_frame} byte limit; {hint}")

    def _check_type(self, frame_type: int) -> None:
        if frame_type in self.allowed:
            return
        allowed = ", ".join(f"{FRAME_NAMES[t]} ({t})" for t in sorted(self.allowed))
        if frame_type in FRAME_NAMES:
            raise ProtocolError(
                f"{self.sender} may not send {FRAME_NAMES[frame_type]} messages, only {allowed}; "
                "check that both sides run the same airtable version"
            )
        raise ProtocolError(
            f"unknown message type {frame_type}; airtable protocol {PROTOCOL_VERSION} has only {allowed} "
            "here: check that both sides run the same airtable version"
        )


# ---------------------------------------------------------------- JSON helpers


class _NonFiniteError(Exception):
    pass


class _DuplicateKeyError(Exception):
    pass


def _unique_keys(pairs: list[tuple[str, object]]) -> dict:
    """JSON keeps the last of two equal keys; we refuse them (they only hide data)."""
    message = dict(pairs)
    if len(message) != len(pairs):
        seen: set[str] = set()
        raise _DuplicateKeyError(next(k for k, _ in pairs if k in seen or seen.add(k)))
    return message


def _reject_constant(name: str):
    raise _NonFiniteError(name)


def _short(value: object, limit: int = 40) -> str:
    """`value` as Python writes it, cut to about `limit` characters; a string keeps its closing quote."""
    text = repr(value)
    if len(text) <= limit:
        return text
    if isinstance(value, str):
        return repr(value[: limit - 6] + "...")  # (a user test: the cut name's quote was left open)
    return text[: limit - 3] + "..."


def encode_json(frame_type: int, message: dict) -> bytes:
    """A frame carrying `message` as compact UTF-8 JSON."""
    text = json.dumps(message, separators=(",", ":"), allow_nan=False, ensure_ascii=False)
    return encode_frame(frame_type, text.encode("utf-8"))


def parse_json(payload: bytes, what: str, example: str) -> dict:
    """Decode a JSON object strictly (UTF-8, no NaN/Infinity, an object at the top)."""
    try:
        text = payload.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ProtocolError(f"{what} is not UTF-8 text (bad byte at position {e.start}); send UTF-8 JSON") from None
    try:
        message = json.loads(text, parse_constant=_reject_constant, object_pairs_hook=_unique_keys)
    except _NonFiniteError as e:
        raise ProtocolError(f"{what} contains {e.args[0]}, which is not a finite number; send finite numbers") from None
    except _DuplicateKeyError as e:
        raise ProtocolError(f"{what} has the field {_short(e.args[0])} twice; send each field once") from None
    except (ValueError, RecursionError) as e:  # JSONDecodeError is a ValueError; so is a 5000-digit int
        detail = str(e)[:60]
        raise ProtocolError(f"{what} is not valid JSON ({detail}); send an object like {example}") from None
    if not isinstance(message, dict):
        raise ProtocolError(f"{what} must be a JSON object like {example}, not {type(message).__name__}")
    return message


def _check_fields(message: dict, what: str, required: Sequence[str], optional: Sequence[str] = ()) -> None:
    for key in required:
        if key not in message:
            raise ProtocolError(f'{what} is missing the field "{key}"; it needs {", ".join(required)}')
    for key in message:
        if key not in required and key not in optional:
            allowed = ", ".join([*required, *optional])
            raise ProtocolError(f"{what} has an unknown field {_short(key)}; the fields are {allowed}")


def _number(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ProtocolError(f"{what} must be a number, not {_short(value)}")
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x):
        raise ProtocolError(f"{what} must be a finite number, not {_short(value)}")
    return x


def _integer(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ProtocolError(f"{what} must be a whole number, not {_short(value)}")
    return value


# Hangul fillers count as letters but draw nothing; a name of them looks blank.
_INVISIBLE_LETTERS = frozenset("\u115f\u1160\u3164\uffa0")


def _visible(char: str) -> bool:
    return unicodedata.category(char)[0] in "LN" and char not in _INVISIBLE_LETTERS


def check_name(name: object) -> str:
    """A player name: 1-20 printable characters with a visible letter or digit, not
    like another player's "C<n>" label (names.py; spaces around are dropped)."""
    if not isinstance(name, str):
        raise ProtocolError(f"the name must be text, not {_short(name)}")
    name = unicodedata.normalize("NFC", name).strip()  # "Zoë" typed as e and a combining mark: one letter
    if not name:
        raise ProtocolError("the name is empty; pick a name with a letter or digit, like Ann")
    if len(name) > MAX_NAME_CHARS:
        raise ProtocolError(f"the name {_short(name)} is over {MAX_NAME_CHARS} characters; pick a shorter name")
    bad = next((c for c in name if not c.isprintable()), None)
    if bad is not None:
        raise ProtocolError(
            f"the name contains U+{ord(bad):04X}, which is not printable; use letters, digits and spaces"
        )
    if not any(_visible(c) for c in name):
        raise ProtocolError(
            f"the name {_short(name)} has no visible letter or digit; pick a name others can read, like Ann"
        )
    # Runs of spaces squeezed: "Ann  2" would show as "Ann 2" beside the real one.
    name = " ".join(part for part in name.split(" ") if part)
    if looks_like_label(name):  # also in look-alike letters: "С1" with a Cyrillic С, "C-1", "C¹"
        raise ProtocolError(
            f"the name {_short(name)} looks like a player label such as C7 or S7; "
            "pick a name without C or S and a number"
        )
    return name


def _text(value: object, what: str, limit: int) -> str:
    if not isinstance(value, str):
        raise ProtocolError(f"{what} must be text, not {_short(value)}")
    if len(value) > limit:
        raise ProtocolError(f"{what} is longer than {limit} characters")
    return value


def _color(value: object, what: str) -> tuple[int, int, int]:
    if not (isinstance(value, list) and len(value) == 3):
        raise ProtocolError(f"{what} must be [r, g, b], not {_short(value)}")
    rgb = tuple(_integer(v, what) for v in value)
    if not all(0 <= v <= 255 for v in rgb):
        raise ProtocolError(f"{what} components must be 0-255, not {_short(value)}")
    return rgb  # type: ignore[return-value]


# ---------------------------------------------------------------- HELLO


@dataclass(frozen=True)
class Hello:
    """A validated HELLO: protocol version, optional name and password."""

    protocol: int
    name: str | None = None
    password: str | None = None
    token: str | None = None  # from an earlier WELCOME, in clear (older clients): asks for the same seat again
    seat: int | None = None  # the seat whose token the client holds: the server sends a CHALLENGE first


HELLO_EXAMPLE = f'{{"protocol": {PROTOCOL_VERSION}, "name": "Ann"}}'
HELLO_FIELDS = ("name", "password", "token", "seat")  # besides "protocol"; an ERROR's "about" names one


def encode_hello(
    name: str | None = None,
    password: str | None = None,
    protocol: int = PROTOCOL_VERSION,
    token: str | None = None,
    seat: int | None = None,
) -> bytes:
    """A HELLO frame. `seat`: ask for that seat back, proving the token in a PROOF (never send `token`)."""
    message: dict = {"protocol": protocol}
    if name is not None:
        message["name"] = name
    if password is not None:
        message["password"] = password
    if token is not None:
        message["token"] = token
    if seat is not None:
        message["seat"] = seat
    return encode_json(HELLO, message)


def version_mismatch(theirs: object) -> str:
    return (
        f"this server speaks airtable protocol {PROTOCOL_VERSION} but the client speaks protocol {_short(theirs)}; "
        "install the same airtable version as the teacher's"
    )


def _with_example(error: ProtocolError, example: str) -> ProtocolError:
    """The error with an example of a good message, unless it already says what to do."""
    text = str(error)
    return error if ";" in text else ProtocolError(f"{text}; send something like {example}")


def validate_hello(message: dict) -> Hello:
    """Check a HELLO object; the protocol version is checked first, so a newer client
    with new fields still learns that the versions differ."""
    try:
        return _validate_hello(message)
    except ProtocolError as e:
        raise _with_example(e, HELLO_EXAMPLE) from None


def _validate_hello(message: dict) -> Hello:
    if "protocol" not in message:
        raise ProtocolError(f'HELLO is missing the field "protocol"; send {HELLO_EXAMPLE}')
    protocol = message["protocol"]
    if isinstance(protocol, bool) or not isinstance(protocol, int):
        raise ProtocolError(f'HELLO "protocol" must be a whole number like {PROTOCOL_VERSION}, not {_short(protocol)}')
    if protocol != PROTOCOL_VERSION:
        raise ProtocolError(version_mismatch(protocol))
    _check_fields(message, "HELLO", ("protocol",), HELLO_FIELDS)
    name = message.get("name")
    if name is not None:
        name = check_name(name)
    password = message.get("password")
    if password is not None:
        password = _text(password, "the password", MAX_PASSWORD_CHARS)
    token = message.get("token")
    if token is not None:
        token = _text(token, "the seat token", MAX_TOKEN_CHARS)
    seat = message.get("seat")
    if seat is not None and not (1 <= _integer(seat, 'HELLO "seat"') <= MAX_SEAT):
        raise ProtocolError(f'HELLO "seat" must be a seat number 1-{MAX_SEAT}, not {_short(seat)}')
    return Hello(protocol, name, password, token, seat)


def parse_hello(payload: bytes) -> Hello:
    return validate_hello(parse_json(payload, "HELLO", HELLO_EXAMPLE))


# ---------------------------------------------------------------- INPUT


@dataclass(frozen=True)
class InputRecord:
    """One client's input, validated: cursor in world metres, button 0-3, keys held."""

    cursor_m: tuple[float, float]
    button: int
    keys: frozenset[str] = frozenset()


INPUT_EXAMPLE = '{"cursor_m": [2.5, 4.0], "button": 1, "keys": ["a"]}'


def cursor_limits(width_m: float, height_m: float) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max): where a cursor may be, in metres."""
    margin = CURSOR_MARGIN_TABLES * max(width_m, height_m)
    return (-margin, -margin, width_m + margin, height_m + margin)


def clamp_cursor(cursor_m: Sequence[float], width_m: float, height_m: float) -> tuple[float, float]:
    """The cursor moved into `cursor_limits` (players send only positions the server accepts)."""
    x0, y0, x1, y1 = cursor_limits(width_m, height_m)
    x, y = (float(v) for v in cursor_m)
    x = x0 if not math.isfinite(x) else min(max(x, x0), x1)
    y = y0 if not math.isfinite(y) else min(max(y, y0), y1)
    return (x, y)


def is_button(value: object) -> bool:
    """0 (none) or a mouse button 1-3."""
    return not isinstance(value, bool) and isinstance(value, int) and 0 <= value <= 3


def is_key_name(value: object) -> bool:
    """A key name like "a" or "left shift": 1 to MAX_KEY_CHARS printable characters."""
    return isinstance(value, str) and 1 <= len(value) <= MAX_KEY_CHARS and value.isprintable()


def make_input(
    cursor_m: Sequence[float], button: int, keys: Iterable[str], table_size_m: Sequence[float]
) -> InputRecord:
    """An InputRecord the server accepts, whatever the local input: the cursor is
    clamped, an unknown button is 0, and only valid key names are kept."""
    names = sorted(k for k in keys if is_key_name(k))[:MAX_KEYS]
    return InputRecord(clamp_cursor(cursor_m, *table_size_m), button if is_button(button) else 0, frozenset(names))


def encode_input(cursor_m: Sequence[float], button: int = 0, keys: Iterable[str] = ()) -> bytes:
    """An INPUT frame."""
    return encode_json(
        INPUT,
        {"cursor_m": [float(cursor_m[0]), float(cursor_m[1])], "button": int(button), "keys": sorted(keys)},
    )


def validate_input(message: dict, table_size_m: Sequence[float] = DEFAULT_TABLE_SIZE_M) -> InputRecord:
    """Check an INPUT object against the table size (width_m, height_m)."""
    try:
        return _validate_input(message, table_size_m)
    except ProtocolError as e:
        raise _with_example(e, INPUT_EXAMPLE) from None


def _validate_input(message: dict, table_size_m: Sequence[float]) -> InputRecord:
    _check_fields(message, "INPUT", ("cursor_m", "button", "keys"))
    x0, y0, x1, y1 = cursor_limits(*table_size_m)
    where = f"within {x0:g}..{x1:g} m across and {y0:g}..{y1:g} m up"
    cursor = message["cursor_m"]
    if not (isinstance(cursor, list) and len(cursor) == 2):
        raise ProtocolError(f"INPUT cursor_m must be a pair [x, y] of numbers in metres, not {_short(cursor)}")
    x = _number(cursor[0], "INPUT cursor_m x")
    y = _number(cursor[1], "INPUT cursor_m y")
    if not (x0 <= x <= x1 and y0 <= y <= y1):
        raise ProtocolError(f"INPUT cursor_m {_short(cursor)} is too far off the table; it must be {where}")
    button = message["button"]
    if not is_button(button):
        raise ProtocolError(f"INPUT button must be 0 (none) or 1, 2, 3 (the mouse buttons), not {_short(button)}")
    keys = message["keys"]
    if not (isinstance(keys, list) and len(keys) <= MAX_KEYS):
        raise ProtocolError(f'INPUT keys must be a list of at most {MAX_KEYS} key names like ["a", "w"]')
    for key in keys:
        if not is_key_name(key):
            raise ProtocolError(
                f"INPUT keys must be key names of 1 to {MAX_KEY_CHARS} printable characters, not {_short(key)}"
            )
    return InputRecord((x, y), button, frozenset(keys))


def parse_input(payload: bytes, table_size_m: Sequence[float] = DEFAULT_TABLE_SIZE_M) -> InputRecord:
    return validate_input(parse_json(payload, "INPUT", INPUT_EXAMPLE), table_size_m)


# ---------------------------------------------------------------- WELCOME, ERROR, BYE


@dataclass(frozen=True)
class Welcome:
    """A validated WELCOME: the player's id ("C3") and name, colour, the table size (m),
    and the seat token to send in HELLO when reconnecting."""

    client: str
    color: tuple[int, int, int]
    width_m: float
    height_m: float
    protocol: int = PROTOCOL_VERSION
    name: str | None = None
    token: str | None = None
    udp_key: str | None = None  # where the server takes inputs over UDP too (datagrams.py)

    @property
    def label(self) -> str:
        """How the table labels this player's cursor: "C3 Ann", or "C3" without a name."""
        return f"{self.client} {self.name}" if self.name else self.client


def encode_welcome(
    client: str,
    color: Sequence[int],
    width_m: float,
    height_m: float,
    name: str | None = None,
    token: str | None = None,
    udp_key: str | None = None,
) -> bytes:
    """A WELCOME frame; `client` is the id alone ("C3"), `name` the name the player gave,
    `token` the seat token a reconnecting client sends back in HELLO, `udp_key` the key of
    this session's input datagrams (datagrams.py), when the server takes them."""
    message = {
        "protocol": PROTOCOL_VERSION,
        "client": client,
        "color": [int(c) for c in color],
        "table": {"width_m": float(width_m), "height_m": float(height_m)},
    }
    if name:
        message["name"] = name
    if token is not None:
        message["token"] = token
    if udp_key is not None:
        message["udp_key"] = udp_key
    return encode_json(WELCOME, message)


def parse_welcome(payload: bytes) -> Welcome:
    """Check a WELCOME from the server (the player trusts no bytes either)."""
    message = parse_json(payload, "the server's WELCOME", f'{{"protocol": {PROTOCOL_VERSION}, ...}}')
    protocol = message.get("protocol")
    if protocol != PROTOCOL_VERSION or isinstance(protocol, bool):
        raise ProtocolError(
            f"the server speaks airtable protocol {_short(protocol)} but this client speaks protocol "
            f"{PROTOCOL_VERSION}; install the same airtable version as the teacher's"
        )
    _check_fields(
        message, "the server's WELCOME", ("protocol", "client", "color", "table"), ("name", "token", "udp_key")
    )
    client = message["client"]
    if not (isinstance(client, str) and re.fullmatch(r"C[1-9][0-9]{0,5}", client)):
        raise ProtocolError(f"the server's WELCOME has a bad client id {_short(client)} (it should be like C3)")
    name = message.get("name")
    if name is not None:
        name = check_name(name)
    token = message.get("token")
    if token is not None and not (isinstance(token, str) and len(token) <= MAX_TOKEN_CHARS and token.isprintable()):
        raise ProtocolError("the server's WELCOME has a bad seat token")
    udp_key = message.get("udp_key")
    if udp_key is not None and not (isinstance(udp_key, str) and re.fullmatch(r"[0-9a-f]{32}", udp_key)):
        raise ProtocolError("the server's WELCOME has a bad udp_key (it should be 32 hex digits)")
    color = _color(message["color"], "the server's WELCOME colour")
    table = message["table"]
    if not isinstance(table, dict):
        raise ProtocolError("the server's WELCOME has no table size")
    _check_fields(table, "the server's WELCOME table", ("width_m", "height_m"))
    w = _number(table["width_m"], "the table width")
    h = _number(table["height_m"], "the table height")
    problem = table_size_problem(w, h)
    if problem:
        raise ProtocolError(f"the server's WELCOME has {problem}")
    return Welcome(client, color, w, h, protocol, name, token, udp_key)


def encode_error(sentence: str, retry: bool = False, about: str | None = None) -> bytes:
    """An ERROR frame (the server closes the connection after it). `retry` tells the
    client that trying again later can work (the table is full or busy); `about` names
    the HELLO field refused ("name"), so a command can say its argument was bad."""
    message: dict = {"error": sentence[:MAX_ERROR_CHARS]}
    if retry:
        message["retry"] = True
    if about is not None:
        message["about"] = about
    return encode_json(ERROR, message)


def parse_error_message(payload: bytes) -> tuple[str, bool, str | None]:
    """(sentence, retry, about) of an ERROR: the sentence made safe to print on one line; `about` the
    HELLO field it refused ("name"), or None."""
    try:
        message = parse_json(payload, "the server's ERROR", '{"error": "..."}')
    except ProtocolError as e:
        return f"the server sent an unreadable error ({e})", False, None
    sentence = message.get("error")
    retry = message.get("retry") is True
    about = message.get("about") if message.get("about") in HELLO_FIELDS else None
    if not isinstance(sentence, str) or not sentence:
        return "the server sent an error without a reason", retry, about
    return printable(sentence[:MAX_ERROR_CHARS]), retry, about


def parse_error(payload: bytes) -> str:
    """The sentence of an ERROR, made safe to print on one line."""
    return parse_error_message(payload)[0]


def encode_bye() -> bytes:
    return encode_frame(BYE)


# ---------------------------------------------------------------- CHALLENGE, PROOF (a seat's token, proven)

_NONCE = re.compile(r"[0-9a-f]{32}")
_PROOF = re.compile(r"[0-9a-f]{64}")


def encode_challenge(nonce: str) -> bytes:
    """A CHALLENGE: `nonce` is 32 lowercase hex digits, new for every connection."""
    return encode_json(CHALLENGE, {"nonce": nonce})


def parse_challenge(payload: bytes) -> str:
    """The nonce of the server's CHALLENGE."""
    message = parse_json(payload, "the server's CHALLENGE", '{"nonce": "<32 hex digits>"}')
    _check_fields(message, "the server's CHALLENGE", ("nonce",))
    nonce = message["nonce"]
    if not (isinstance(nonce, str) and _NONCE.fullmatch(nonce)):
        raise ProtocolError("the server's CHALLENGE has a bad nonce (it should be 32 hex digits)")
    return nonce


def encode_proof(proof: str) -> bytes:
    """A PROOF: `proof` is identity.seat_proof(token, nonce), 64 lowercase hex digits."""
    return encode_json(PROOF, {"proof": proof})


def parse_proof(payload: bytes) -> str:
    """The proof of a client's PROOF."""
    example = '{"proof": "<64 hex digits>"}'
    message = parse_json(payload, "PROOF", example)
    _check_fields(message, "PROOF", ("proof",))
    proof = message["proof"]
    if not (isinstance(proof, str) and _PROOF.fullmatch(proof)):
        raise ProtocolError(f"PROOF must be 64 lowercase hex digits; send {example}")
    return proof


# ---------------------------------------------------------------- what a player can draw


def printable(text: str) -> str:
    """`text` with every unprintable character (newline, NUL, ...) replaced by a space."""
    text = str(text)
    return text if text.isprintable() else "".join(c if c.isprintable() else " " for c in text)


def table_size_problem(width_m: float, height_m: float) -> str | None:
    """What is wrong with a table size a server sent (None: it can be drawn)."""
    ok = all(math.isfinite(v) and MIN_TABLE_M <= v <= MAX_TABLE_M for v in (width_m, height_m))
    if not ok or max(width_m, height_m) > MAX_TABLE_ASPECT * min(width_m, height_m):
        return (
            f"a table size of {width_m:g} x {height_m:g} m, which cannot be drawn (sides must be "
            f"{MIN_TABLE_M:g} to {MAX_TABLE_M:g} m and at most {MAX_TABLE_ASPECT:g} times each other)"
        )
    return None


def parse_host_port(text: str, default_port: int = DEFAULT_PORT) -> tuple[str, int]:
    """'host', 'host:port', '[v6addr]:port' or a bare IPv6 address -> (host, port)."""
    text = text.strip()
    if not text:
        raise ValueError("no server address given; use HOST or HOST:PORT, e.g. 192.168.1.23:8888")
    host, port_text = text, None
    if text.startswith("["):
        close = text.find("]")
        if close < 0:
            raise ValueError(f"{text!r} is missing the closing ']' of an IPv6 address")
        host, rest = text[1:close], text[close + 1 :]
        if rest:
            if not rest.startswith(":"):
                raise ValueError(f"{text!r} is not HOST:PORT")
            port_text = rest[1:]
    elif text.count(":") == 1:
        host, port_text = text.split(":")
    if not host:
        raise ValueError(f"{text!r} has no host name")
    if port_text is None:
        return host, default_port
    if not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise ValueError(f"{port_text!r} is not a port number (1-65535)")
    return host, int(port_text)
