"""`airtable-client HOST[:PORT] [--name NAME] [--password PW] [--headless] [--seconds S]
[--screenshot FILE.png]`: join a teacher's air table over the LAN."""

from __future__ import annotations

import argparse
import math
import os
import sys
import threading
from collections.abc import Sequence

from airtable.app.glyphs import name_refusal
from airtable.arguments import OneLineParser
from airtable.net import protocol as proto
from airtable.net.player import NetPlayer, PlayerError
from airtable.net.seat_memory import SeatMemory, default_path
from airtable.student.window import PlayerApp, joined_sentence

# A join that takes longer than this (s) says so on the terminal: the window opens only once the first
# handshake has ended (answered, refused or timed out), which on a slow link takes seconds.
JOIN_NOTICE_S = 1.0


def _parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = OneLineParser(
        prog="airtable-client",
        description="Join a teacher's air table: your mouse pulls pucks on the shared table "
        "(buttons 1, 2, 3 are the medium, soft and stiff cursor strings; Esc twice leaves; F11 fullscreen).",
    )
    parser.add_argument("server", metavar="HOST[:PORT]", help="the address from the teacher's 'join with:' line")
    parser.add_argument(
        "--port", type=int, help="the table's port, if the address has none (the teacher's --port; default 8888)"
    )
    parser.add_argument("--name", help=f"a name shown next to your cursor (up to {proto.MAX_NAME_CHARS} characters)")
    parser.add_argument("--password", help="the table's password, if the teacher set one")
    parser.add_argument("--headless", action="store_true", help="run without a window (for tests)")
    parser.add_argument("--seconds", type=float, help="quit after this many seconds")
    parser.add_argument("--screenshot", metavar="FILE.png", help="save the last frame here when quitting")
    return parser.parse_args(argv)


def _address(server: str, port: int | None) -> tuple[str, int]:
    """(host, port) from HOST[:PORT] and --port (a user test: `airtable-client HOST --port P`, as the
    teacher's command takes it, was refused); both may be given only if they agree."""
    host, given = proto.parse_host_port(server, default_port=0)
    if port is None:
        return host, given or proto.DEFAULT_PORT
    if not 1 <= port <= 65535:
        raise ValueError(f"--port {port} is not a port number (1-65535)")
    if given and given != port:
        raise ValueError(f"two ports: {given} in {server!r} and --port {port}; give one of them")
    return host, port


def main(argv: Sequence[str] | None = None) -> int:
    """The airtable-client command; returns the exit status."""
    args = _parse_args(argv)
    try:
        host, port = _address(args.server, args.port)
        if args.name is not None and not args.name.strip():  # (a script's unset $NAME, most likely)
            raise ValueError("--name is empty: give a name, like --name Ann, or leave --name out to join by seat")
        name = None if args.name is None else proto.check_name(args.name)
        refusal = None if name is None else name_refusal(name)
        if refusal is not None:  # the teacher's table would refuse it (it draws in the same default font)
            raise ValueError(refusal)
        if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds >= 0):
            raise ValueError("--seconds must be zero or a positive number")
    except (ValueError, proto.ProtocolError) as e:
        print(f"airtable-client: {e}", file=sys.stderr)
        return 2  # a bad argument, as argparse's own refusals
    net = NetPlayer(host, port, name=name, password=args.password, seat_memory=SeatMemory(default_path()))
    saying = f"airtable-client: joining the table at {net.address}..."
    joining = threading.Timer(JOIN_NOTICE_S, print, [saying], {"flush": True})
    joining.daemon = True
    joining.start()
    try:
        welcome = net.connect()
    except PlayerError as e:
        print(f"airtable-client: {e}", file=sys.stderr)
        return 2 if e.about else 1  # the table refused one of our arguments (its font lacks a letter of --name)
    except KeyboardInterrupt:
        return 1
    finally:
        joining.cancel()
    if welcome is None:
        leave = "Ctrl+C quits" if args.headless else "Esc to leave"  # no window: no Esc to press
        why = net.waiting_because or "waiting"
        print(f"airtable-client: {why[:-1]}; {leave})" if why.endswith(")") else f"airtable-client: {why} ({leave})")
    else:
        print(joined_sentence(net.address, welcome))
    if args.headless:
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # no screen: pygame's events still need a driver
    else:
        from airtable.app.window import prefer_plain_framebuffer

        prefer_plain_framebuffer()  # software OpenGL behind the window costs 11-35 ms a flip at 1920x1080
    try:
        return PlayerApp(net, headless=args.headless).run(seconds=args.seconds, screenshot=args.screenshot)
    finally:
        import pygame

        pygame.quit()


if __name__ == "__main__":
    sys.exit(main())
