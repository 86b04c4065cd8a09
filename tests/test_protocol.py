"""The wire protocol: framing, validation of every client field, WELCOME and ERROR, addresses.

Snapshots (format 2) are tested in test_codec.py."""

from __future__ import annotations

import json
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from airtable.net import protocol as proto


def assert_sentence(message: str, *hints: str) -> None:
    """A person can read it: one line of words, no traceback, naming what to do."""
    assert "\n" not in message and "Traceback" not in message
    assert len(message.split()) >= 5, message
    for hint in hints:
        assert hint.lower() in message.lower(), f"{hint!r} not in {message!r}"


def frame(frame_type: int, payload: bytes) -> bytes:
    return struct.pack(">IB", len(payload) + 1, frame_type) + payload


# ---------------------------------------------------------------- framing


def test_frames_survive_any_split():
    data = proto.encode_hello("Ann") + proto.encode_input((1.0, 2.0), 1, ["a"]) + proto.encode_bye()
    for chunk in (1, 2, 3, 7, len(data)):
        reader = proto.FrameReader()
        frames = []
        for i in range(0, len(data), chunk):
            frames += reader.feed(data[i : i + chunk])
        assert [t for t, _ in frames] == [proto.HELLO, proto.INPUT, proto.BYE]
        assert frames[2][1] == b""
        assert reader.pending == 0


def test_frame_header_is_big_endian_length_then_type():
    assert proto.encode_frame(proto.BYE) == b"\x00\x00\x00\x01\x06"
    assert proto.encode_frame(proto.INPUT, b"{}") == b"\x00\x00\x00\x03\x04{}"


@pytest.mark.parametrize(
    "data, hints",
    [
        (b"\x00\x00\x00\x00", ["empty", "airtable-client"]),
        (struct.pack(">IB", proto.MAX_CLIENT_FRAME + 1, 1), ["1024 byte limit"]),
        (b"GET / HTTP/1.1\r\n", ["looks like text", "web browser"]),
        (b"\x00\x00\x00\x02\x0cx", ["unknown message type 12", "same airtable version"]),
        (b"\x00\x00\x00\x02\x05x", ["may not send SNAPSHOT"]),
    ],
)
def test_bad_frames_are_refused_early(data, hints):
    reader = proto.FrameReader(proto.MAX_CLIENT_FRAME, proto.CLIENT_FRAMES, sender="a client")
    with pytest.raises(proto.ProtocolError) as err:
        reader.feed(data)
    assert_sentence(str(err.value), *hints)


def test_a_huge_length_is_refused_before_its_payload_arrives():
    reader = proto.FrameReader()
    with pytest.raises(proto.ProtocolError):
        reader.feed(struct.pack(">I", 10**9))


# ---------------------------------------------------------------- HELLO


def test_hello_round_trip():
    (t, payload), *_ = proto.FrameReader().feed(proto.encode_hello("  Ann  ", "pw"))
    assert t == proto.HELLO
    assert json.loads(payload) == {"protocol": 2, "name": "  Ann  ", "password": "pw"}
    assert proto.parse_hello(payload) == proto.Hello(2, "Ann", "pw")
    assert proto.parse_hello(b'{"protocol": 2}') == proto.Hello(2)


@pytest.mark.parametrize(
    "payload, hints",
    [
        (b"\xff\xfe{}", ["UTF-8"]),
        (b"{nope", ["not valid JSON", "protocol"]),
        (b"[1, 2]", ["JSON object"]),
        (b"{}", ["missing", "protocol"]),
        (b'{"protocol": 1}', ["protocol 1", "protocol 2", "same airtable version"]),
        (b'{"protocol": 3, "shiny": true}', ["protocol 3"]),  # the version is checked first
        (b'{"protocol": "1"}', ["whole number"]),
        (b'{"protocol": true}', ["whole number"]),
        (b'{"protocol": 2, "name": "' + b"x" * 21 + b'"}', ["name", "20"]),
        (b'{"protocol": 2, "name": "   "}', ["name"]),
        (b'{"protocol": 2, "name": "a\\u0007b"}', ["printable"]),
        (b'{"protocol": 2, "name": 7}', ["name must be text"]),
        (b'{"protocol": 2, "password": 1234}', ["password must be text"]),
        (b'{"protocol": 2, "colour": "red"}', ["unknown field", "protocol, name, password"]),
        (b"[" * 100000, ["not valid JSON"]),
        (b'{"protocol": ' + b"9" * 5000 + b"}", []),
    ],
)
def test_bad_hello(payload, hints):
    with pytest.raises(proto.ProtocolError) as err:
        proto.parse_hello(payload)
    assert_sentence(str(err.value), *hints)


@pytest.mark.parametrize(
    "name, hints",
    [
        ("\u3164", ["no visible letter or digit", "like Ann"]),  # Hangul filler: a letter that draws nothing
        ("\u3164\u3164 \uffa0", ["no visible letter or digit"]),
        ("\u2800\u2800", ["no visible letter or digit"]),  # Braille blank
        ("...", ["no visible letter or digit"]),
        ("C7 C1", ["looks like a player label", "C7"]),
        ("c12", ["player label"]),
        ("Ann C3", ["player label"]),
        ("a\u0007b", ["U+0007", "not printable", "letters, digits"]),
        ("Ann\u200b", ["U+200B", "not printable"]),
        ("line\nbreak", ["U+000A", "not printable"]),
        ("x" * 21, ["over 20 characters", "shorter"]),
        ("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmn", ["'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefgh...' is over 20 characters"]),
        ("  ", ["empty"]),
    ],
)
def test_names_need_a_visible_letter_or_digit_and_may_not_imitate_a_player(name, hints):
    with pytest.raises(proto.ProtocolError) as err:
        proto.check_name(name)
    assert_sentence(str(err.value), *hints)
    if "printable" in hints:
        assert "shorter" not in str(err.value)


@pytest.mark.parametrize("name", ["Ann", "Zoë", "李雷", "Ωmega 2", "C3PO", "Claire 2", "דנה", "  Bo  "])
def test_ordinary_names_in_any_script_are_welcome(name):
    assert proto.check_name(name) == name.strip()


# ---------------------------------------------------------------- INPUT


def test_input_round_trip():
    (t, payload), *_ = proto.FrameReader().feed(proto.encode_input((1.5, -2), 3, ["w", "a"]))
    assert t == proto.INPUT
    assert json.loads(payload) == {"cursor_m": [1.5, -2.0], "button": 3, "keys": ["a", "w"]}
    record = proto.parse_input(payload)
    assert record == proto.InputRecord((1.5, -2.0), 3, frozenset({"a", "w"}))
    with pytest.raises(AttributeError):
        record.button = 1  # frozen: the game loop can share it safely


def _input(cursor="[1, 2]", button="1", keys="[]") -> bytes:
    return f'{{"cursor_m": {cursor}, "button": {button}, "keys": {keys}}}'.encode()


@pytest.mark.parametrize(
    "payload, hints",
    [
        (_input(cursor="[NaN, 1]"), ["NaN", "finite"]),
        (_input(cursor="[1, Infinity]"), ["Infinity", "finite"]),
        (_input(cursor="[-Infinity, 1]"), ["finite"]),
        (_input(cursor="[1e308, 1]"), ["too far off the table", "within"]),
        (_input(cursor="[1e400, 1]"), ["finite"]),
        (_input(cursor='["5", 1]'), ["must be a number"]),
        (_input(cursor="[true, 1]"), ["must be a number"]),
        (_input(cursor="[1, 2, 3]"), ["pair"]),
        (_input(cursor='{"x": 1}'), ["pair"]),
        (_input(cursor="[1, " + "9" * 400 + "]"), ["finite"]),
        (_input(button="7"), ["button must be 0", "mouse buttons"]),
        (_input(button="-1"), ["button must be 0"]),
        (_input(button="1.0"), ["button must be 0"]),
        (_input(button="true"), ["button must be 0"]),
        (_input(button='"1"'), ["button must be 0"]),
        (_input(keys='"abc"'), ["list"]),
        (_input(keys=json.dumps(["k"] * 17)), ["at most 16"]),
        (_input(keys='["' + "x" * 17 + '"]'), ["1 to 16"]),
        (_input(keys="[1]"), ["key names"]),
        (_input(keys='[""]'), ["key names"]),
        (b'{"cursor_m": [1, 2], "button": 1}', ["missing", "keys"]),
        (b'{"button": 1, "keys": []}', ["missing", "cursor_m"]),
        (b'{"cursor_m": [1, 2], "button": 1, "keys": [], "extra": 1}', ["unknown field"]),
        (b"null", ["JSON object"]),
    ],
)
def test_bad_input(payload, hints):
    with pytest.raises(proto.ProtocolError) as err:
        proto.parse_input(payload, (10.0, 8.7556))
    assert_sentence(str(err.value), *hints)


def test_cursor_limits_scale_with_the_table_and_clamp_matches():
    assert proto.parse_input(_input(cursor="[-40, 45]"), (10, 8)).cursor_m == (-40.0, 45.0)
    with pytest.raises(proto.ProtocolError):
        proto.parse_input(_input(cursor="[-40, 45]"), (1, 1))
    x, y = proto.clamp_cursor((1e9, float("nan")), 1, 1)
    assert proto.parse_input(_input(cursor=json.dumps([x, y])), (1, 1)).cursor_m == (x, y)


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=4),
    max_leaves=8,
)


@given(st.dictionaries(st.sampled_from(["cursor_m", "button", "keys", "x"]), json_values))
@settings(max_examples=200, deadline=None)
def test_input_validation_only_ever_raises_protocol_error(message):
    try:
        record = proto.validate_input(message)
    except proto.ProtocolError:
        return
    assert isinstance(record, proto.InputRecord)


# ---------------------------------------------------------------- WELCOME and ERROR


def test_welcome_has_the_fields_of_the_design():
    (t, payload), *_ = proto.FrameReader().feed(proto.encode_welcome("C3", (0, 255, 255), 10.0, 8.7556))
    assert t == proto.WELCOME
    assert json.loads(payload) == {
        "protocol": 2,
        "client": "C3",
        "color": [0, 255, 255],
        "table": {"width_m": 10.0, "height_m": 8.7556},
    }
    assert proto.parse_welcome(payload) == proto.Welcome("C3", (0, 255, 255), 10.0, 8.7556)


def test_welcome_from_a_newer_server_names_the_versions():
    payload = json.dumps({"protocol": 3, "client": "C1"}).encode()
    with pytest.raises(proto.ProtocolError) as err:
        proto.parse_welcome(payload)
    assert_sentence(str(err.value), "protocol 3", "same airtable version")


def test_error_sentences_come_back_printable():
    (t, payload), *_ = proto.FrameReader().feed(proto.encode_error("server full\nreally"))
    assert t == proto.ERROR
    assert proto.parse_error(payload) == "server full really"
    assert "unreadable" in proto.parse_error(b"\xff")


# ---------------------------------------------------------------- addresses


@pytest.mark.parametrize(
    "text, expected",
    [
        ("192.168.1.23", ("192.168.1.23", 8888)),
        ("teacher-laptop:9000", ("teacher-laptop", 9000)),
        ("[::1]:9000", ("::1", 9000)),
        ("[fe80::1]", ("fe80::1", 8888)),
        ("fe80::1", ("fe80::1", 8888)),
    ],
)
def test_parse_host_port(text, expected):
    assert proto.parse_host_port(text) == expected


@pytest.mark.parametrize("text", ["", "host:", "host:http", "host:70000", "[::1", ":80"])
def test_parse_host_port_refuses(text):
    with pytest.raises(ValueError):
        proto.parse_host_port(text)


def test_runs_of_spaces_in_a_name_become_one():
    # "Ann  2" would show as "Ann  2 2" beside an "Ann 2", reading like a third Ann numbered twice.
    assert proto.check_name("Ann  2") == "Ann 2"
    assert proto.check_name(" Mary   Jo ") == "Mary Jo"
