"""The command line of the teacher's app: `python -m airtable [options]`.

Parses and checks the options (a bad one is a one-line message and exit
status 2), lists demos, writes a starter demo, starts the network server and
runs the App.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from collections.abc import Sequence
from pathlib import Path

import pygame

from airtable.app.app import App
from airtable.app.demo_loader import BUILTIN_DIR, Demo, DemoError, discover, key_order
from airtable.assets import ASSETS_DIR
from airtable.memory import keep_freed_memory


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m airtable",
        description="The air table: pucks, springs and cursor strings. Students join with airtable-client HOST.",
    )
    p.add_argument("--demo", default="1", metavar="KEY", help="demo to start with (see --list-demos); default 1")
    p.add_argument("--variation", type=_non_negative_int, default=0, metavar="N", help="variation of that demo")
    p.add_argument("--list-demos", action="store_true", help="list the demos and exit")
    p.add_argument("--port", type=_port, default=8888, help="port students join on (default 8888)")
    p.add_argument("--host", default="0.0.0.0", help="address to listen on (default 0.0.0.0: every network)")
    p.add_argument("--password", default=None, help="students must give this password to join")
    p.add_argument("--max-clients", type=_positive_int, default=30, metavar="N", help="most students at once")
    p.add_argument("--snapshot-hz", type=_positive_float, default=30.0, metavar="HZ", help="snapshots per second")
    p.add_argument("--no-server", action="store_true", help="do not accept students over the network")
    p.add_argument("--headless", action="store_true", help="run the same loop without a window")
    p.add_argument("--seconds", type=_positive_float, default=None, metavar="S", help="quit after S seconds")
    p.add_argument("--screenshot", default=None, metavar="FILE.png", help="save the last frame to FILE.png at exit")
    p.add_argument(
        "--demos",
        action="append",
        default=[],
        metavar="DIR",
        help="also load every demo file in DIR (a key already taken is replaced); may be repeated",
    )
    p.add_argument(
        "--new-demo", default=None, metavar="FILE.py", help="write a commented starter demo to FILE.py and exit"
    )
    return p


def _number(kind, text: str, check, what: str):
    try:
        value = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not {what}") from None
    if not check(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not {what}")
    return value


def _positive_float(text: str) -> float:
    return _number(float, text, lambda v: math.isfinite(v) and v > 0, "a positive number")


def _positive_int(text: str) -> int:
    return _number(int, text, lambda v: v > 0, "a positive whole number")


def _non_negative_int(text: str) -> int:
    return _number(int, text, lambda v: v >= 0, "a whole number, 0 or more")


def _port(text: str) -> int:
    return _number(int, text, lambda v: 0 <= v <= 65535, "a port number (0-65535)")


def list_demos(demos: dict[str, Demo], errors: Sequence[DemoError]) -> str:
    lines = []
    for key, demo in demos.items():
        line = f"{key:>3}  {demo.title}"
        if demo.variations:
            line += f"  [variations: {', '.join(demo.variations)}]"
        lines.append(line)
    lines.extend(f"  !  could not load {e}" for e in errors)
    return "\n".join(lines)


def write_starter_demo(path: Path) -> Path:
    """Copy the commented starter demo to `path` (never over an existing file)."""
    if path.suffix != ".py":
        raise ValueError(f"{path}: a demo file name must end in .py")
    if path.exists():
        raise ValueError(f"{path} already exists; choose another name or delete it first")
    starter = ASSETS_DIR / "starter_demo.py.txt"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(starter.read_text(encoding="utf-8"), encoding="utf-8")
    return path


def start_server(args):
    """Start the network server, or explain on stderr why students cannot join."""
    try:
        from airtable.net.server import GameServer
    except ImportError:
        return None
    server = GameServer(
        host=args.host,
        port=args.port,
        password=args.password,
        max_clients=args.max_clients,
        snapshot_hz=args.snapshot_hz,
    )
    try:
        server.start()
    except OSError as exc:
        print(f"airtable: students cannot join: {exc}", file=sys.stderr)
        return None
    for line in server.join_lines():
        print(line)
    return server


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    keep_freed_memory()  # the step's big temporary arrays are reused, not re-faulted (35 % at 10000 pucks)
    if args.new_demo:
        try:
            path = write_starter_demo(Path(args.new_demo))
        except (OSError, ValueError) as exc:
            parser.error(str(exc))
        print(f"wrote {path}; edit it, then run: python -m airtable --demos {path.parent}")
        return 0
    for directory in args.demos:
        if not Path(directory).is_dir():
            parser.error(f"--demos {directory}: no such folder")
    demos, errors = discover([BUILTIN_DIR, *map(Path, args.demos)])
    if args.list_demos:
        print(list_demos(demos, errors))
        return 0
    if args.demo not in demos:
        parser.error(f"there is no demo {args.demo!r}; choose one of: {', '.join(sorted(demos, key=key_order))}")
    variations = demos[args.demo].variations
    if args.variation and args.variation >= max(1, len(variations)):
        parser.error(f"demo {args.demo} has {len(variations) or 'no'} variations; --variation must be below that")
    # The server logs who joins and who is dropped (and why) for the teacher.
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    server = None if args.no_server else start_server(args)
    app = App(
        demos, demo_key=args.demo, variation=args.variation, headless=args.headless, server=server, demo_errors=errors
    )
    try:
        app.run(seconds=args.seconds)
        if args.screenshot:
            path = app.window.save_screenshot(args.screenshot)
            print(f"screenshot saved to {path}")
    except KeyboardInterrupt:
        pass
    finally:
        if server is not None:
            server.stop()
        pygame.quit()
    return 0
