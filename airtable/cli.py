"""The command line of the teacher's app: `python -m airtable [options]`.

Parses and checks the options (a bad one is a one-line message and exit
status 2, see arguments.py), lists demos, writes a starter demo, starts the network server and
runs the App.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from airtable.app.demo_loader import BUILTIN_DIR, Demo, DemoError, DemoShelf, key_from_label, key_label
from airtable.app.recorder import check_record_path
from airtable.app.saved_demo import DEFAULT_FOLDER as SAVED_DEMOS_DIR
from airtable.app.saved_demo import check_save_demo_path
from airtable.arguments import OneLineParser
from airtable.assets import ASSETS_DIR
from airtable.desktop import prepare_for_pygame
from airtable.memory import keep_freed_memory
from airtable.net.gate import PLAYERS_PER_ADDRESS
from airtable.net.server import validate_server_options

HEADLESS_FRAME_S = 1 / 60  # a headless run with no server: simulated frames of this length


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(
        prog="python -m airtable",
        description="The air table: pucks, springs and cursor strings. Students join with airtable-client HOST.",
        epilog="In the window: F1 lists the keys, Tab opens the demo menu, Esc closes what is open or quits.",
    )
    p.add_argument("--demo", default="1", metavar="KEY", help="demo to start with (see --list-demos); default 1")
    p.add_argument(
        "--variation",
        type=_positive_int,
        default=None,
        metavar="N",
        help="which variation of that demo, counting from 1 as --list-demos lists them (default: the demo's own)",
    )
    p.add_argument("--list-demos", action="store_true", help="list the demos and exit")
    _server_options(p)
    _run_options(p)
    _output_options(p)
    p.add_argument(
        "--demos",
        action="append",
        default=[],
        metavar="DIR",
        help="also load every demo file in DIR (a key already taken is replaced); may be repeated; Ctrl+S saves"
        " demos in the last DIR (without --demos: in ./my_demos, loaded when it exists)",
    )
    p.add_argument(
        "--new-demo", default=None, metavar="FILE.py", help="write a commented starter demo to FILE.py and exit"
    )
    return p


def _server_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", type=_port, default=8888, help="port students join on (default 8888)")
    p.add_argument("--host", default="0.0.0.0", help="address to listen on (default 0.0.0.0: every network)")
    p.add_argument("--password", default=None, help="students must give this password to join")
    p.add_argument("--max-clients", type=_positive_int, default=30, metavar="N", help="most students at once")
    p.add_argument(
        "--per-address",
        type=_positive_int,
        default=PLAYERS_PER_ADDRESS,
        metavar="N",
        help=f"most students from one address (default {PLAYERS_PER_ADDRESS}); a class behind one router shares"
        " one address: raise it to the class size (with --password the limit does not apply)",
    )
    p.add_argument("--snapshot-hz", type=_positive_float, default=30.0, metavar="HZ", help="snapshots per second")
    p.add_argument("--no-server", action="store_true", help="do not accept students over the network")


def _run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--headless", action="store_true", help="run the same loop without a window")
    p.add_argument(
        "--seconds",
        type=_positive_float,
        default=None,
        metavar="S",
        help="quit after S seconds; with --headless --no-server these are S seconds of simulated time, run as"
        " fast as the machine can (frames of 1/60 s); with a server, students need real time, so real seconds",
    )
    p.add_argument(
        "--screenshot",
        default=None,
        metavar="FILE.png",
        help="save the last frame to FILE.png at exit (.png is added if the name lacks it)",
    )
    p.add_argument("--fullscreen", action="store_true", help="open on the whole screen (F11 switches)")


def _output_options(p: argparse.ArgumentParser) -> None:
    """What a run leaves behind at exit."""
    p.add_argument(
        "--stats",
        action="store_true",
        help="at exit, print one line: frames, frame rate (median and slowest 5 %%), physics steps, CPU time"
        " and peak memory",
    )
    p.add_argument(
        "--record",
        default=None,
        metavar="FILE.csv",
        help="write every puck's state at every step to FILE.csv and the energies and momentum to"
        " FILE_energy.csv as the run goes, all of it however long (a demo started later: FILE-2.csv, ...)",
    )
    p.add_argument(
        "--save-demo",
        default=None,
        metavar="FILE.py",
        help="at exit, write the table as it is then as a new demo file FILE.py (load it with --demos FOLDER)",
    )


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


def _port(text: str) -> int:
    return _number(int, text, lambda v: 0 <= v <= 65535, "a port number (0-65535)")


def list_demos(demos: dict[str, Demo], errors: Sequence[DemoError]) -> str:
    lines = []
    for key, demo in demos.items():
        line = f"{key:>3}  {demo.title}"
        if key_label(key) != key:
            line += f"  ({key_label(key)}; --demo {key} or --demo {key_label(key)})"
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
    """Start the network server: (server, None), or (None, why students cannot join), also said on stderr."""
    from airtable.app.glyphs import NameCheck, drawable_characters
    from airtable.net.identity import load_key
    from airtable.net.server import GameServer

    server = GameServer(
        host=args.host,
        port=args.port,
        password=args.password,
        max_clients=args.max_clients,
        snapshot_hz=args.snapshot_hz,
        players_per_address=args.per_address,
        token_key=load_key(),  # kept in the config folder: students keep their seats across restarts
        name_refusal=NameCheck(drawable_characters()),  # names the projector would draw as boxes are refused
    )
    try:
        server.start()
    except OSError as exc:
        problem = f"students cannot join: {exc.strerror or exc}"
        print(f"airtable: {problem}", file=sys.stderr)
        return None, problem
    for line in server.join_lines():
        print(line)
    return server, None


def screenshot_path(text: str) -> Path:
    """Where --screenshot saves: `.png` added if missing; ValueError if it cannot be written."""
    path = Path(text)
    if path.is_dir():
        raise ValueError(f"--screenshot {text}: that is a folder; give a file name like shot.png")
    if path.suffix.lower() != ".png":
        path = path.with_name(path.name + ".png")
    folder = path.parent
    if not folder.is_dir():
        raise ValueError(f"--screenshot {path}: there is no folder {folder}")
    if path.is_dir() or not os.access(folder, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise ValueError(f"--screenshot {path}: cannot write there; choose a file in a folder you may write to")
    return path


NO_DISPLAY = "no display to open a window on (is DISPLAY set?); run with --headless to run without one"


def check_display() -> str | None:
    """None if a window can open; else a sentence saying why not and what to do."""
    asked = os.environ.get("SDL_VIDEODRIVER", "")
    if (
        sys.platform.startswith("linux")
        and not asked
        and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    ):
        return NO_DISPLAY  # asking SDL would only add its own messages
    import pygame

    try:
        pygame.display.init()
    except pygame.error as exc:
        return f"no display to open a window on ({exc}); run with --headless to run without one"
    if pygame.display.get_driver() in ("offscreen", "dummy") and asked not in ("offscreen", "dummy"):
        return NO_DISPLAY
    return None


def load_demos(parser: argparse.ArgumentParser, args: argparse.Namespace) -> DemoShelf:
    for directory in args.demos:
        if not Path(directory).is_dir():
            parser.error(f"--demos {directory}: no such folder")
    folders = [Path(d) for d in args.demos]
    if not folders and SAVED_DEMOS_DIR.is_dir():  # the demos Ctrl+S saved here before
        folders.append(SAVED_DEMOS_DIR)
    shelf = DemoShelf([BUILTIN_DIR, *folders])
    if args.list_demos:
        return shelf
    if args.demo not in shelf.demos:
        for error in shelf.errors:
            print(error.one_line(), file=sys.stderr)
        parser.error(f"there is no demo {args.demo!r}; choose one of: {', '.join(shelf.demos)}")
    variations = shelf.demos[args.demo].variations
    if args.variation is not None and args.variation > max(1, len(variations)):
        having = f"variations 1 to {len(variations)}" if variations else "no variations"
        parser.error(f"demo {args.demo} has {having}; --variation {args.variation} is not one of them")
    return shelf


def main(argv: Sequence[str] | None = None) -> int:
    prepare_for_pygame()  # no pygame banner; the taskbar says "Air Table"
    parser = build_parser()
    args = parser.parse_args(argv)
    args.demo = key_from_label(args.demo)  # --demo Shift+1 as the help and the menu write it
    if args.headless:
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # no screen: pygame's events still need a driver
    if not args.no_server:  # refuse what the server would, in the server's own words
        validate_server_options(args.port, args.max_clients, args.snapshot_hz, error=parser.error)
    if args.password == "":  # would silently mean no password at all
        parser.error("--password needs at least one character; leave it out for a table anyone may join")
    keep_freed_memory()  # the step's big temporary arrays are reused, not re-faulted (35 % at 10000 pucks)
    if args.new_demo:
        try:
            path = write_starter_demo(Path(args.new_demo))
        except (OSError, ValueError) as exc:
            parser.error(str(exc))
        print(f"wrote {path}; edit it, then run: python -m airtable --demos {path.parent}")
        return 0
    shelf = load_demos(parser, args)
    if args.list_demos:
        print(list_demos(shelf.demos, shelf.errors))
        return 0
    shot = None
    try:
        shot = screenshot_path(args.screenshot) if args.screenshot else None
        args.record = check_record_path(args.record) if args.record else None
        args.save_demo = check_save_demo_path(args.save_demo) if args.save_demo else None
    except ValueError as exc:
        print(f"airtable: {exc}", file=sys.stderr)
        return 1
    problem = None if args.headless else check_display()
    if problem:
        print(f"airtable: {problem}", file=sys.stderr)
        return 1
    if not args.headless:
        from airtable.app.window import prefer_plain_framebuffer

        prefer_plain_framebuffer()  # software OpenGL behind the window costs 11-35 ms a flip at 1920x1080
    return run_app(args, shelf, shot)


def write_outputs(app, args: argparse.Namespace) -> int:
    """At the end of a run: the --record files and the --save-demo file; 1 if one could not be written
    (said on stderr), else 0."""
    status = 0
    if args.save_demo is not None:
        if app.lessons.save_moment(args.save_demo) is None:
            print(f"airtable: {app.message}", file=sys.stderr)
            status = 1
        else:
            print(app.message)
    for rec in app.lessons.finish():  # --record: the files were written as the run went
        if rec.error is not None:
            print(f"airtable: could not write the recording {rec.puck_path}: {rec.error}", file=sys.stderr)
            status = 1
        else:
            print(f"recorded {rec.summary()} to {rec.puck_path} and {rec.energy_path}")
    return status


def run_app(args: argparse.Namespace, shelf: DemoShelf, shot: Path | None) -> int:
    """Start the server and the app; returns the exit status (1 if a demo failed in a headless run)."""
    import pygame

    from airtable.app.app import App

    # The server logs who joins and who is dropped (and why) for the teacher.
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    server, server_problem = (None, None) if args.no_server else start_server(args)
    # A timed headless run with nobody to serve simulates its time: it takes as long as the machine needs.
    simulated = args.headless and server is None and args.seconds is not None
    frame_dt_s = HEADLESS_FRAME_S if simulated else None
    status, app = 0, None
    try:
        app = App(
            shelf,
            demo_key=args.demo,
            variation=None if args.variation is None else args.variation - 1,  # the app counts from 0, a teacher from 1
            headless=args.headless,
            server=server,
            server_problem=server_problem,
            fullscreen=args.fullscreen,
            show_fps=args.stats,
        )
        if args.record is not None:
            app.lessons.record_into(args.record, app.table)  # streamed from the first step
        started = None
        if args.headless and args.seconds is None:  # no window to close: say how it ends

            def started():
                print("airtable: running without a window; Ctrl+C (or kill) stops it", flush=True)

        app.run(seconds=args.seconds, frame_dt_s=frame_dt_s, started=started)
        if shot is not None:
            try:
                print(f"screenshot saved to {app.window.save_screenshot(shot)}")
            except (OSError, pygame.error) as exc:
                print(f"airtable: could not save the screenshot {shot}: {exc}", file=sys.stderr)
                status = 1
        status = max(status, write_outputs(app, args))
        if args.headless and any(e.stage != "load" for e in app.errors):
            status = 1
    except KeyboardInterrupt:
        pass
    finally:
        if app is not None:
            app.lessons.finish()  # the rows still buffered, even after Ctrl+C
        if server is not None:
            server.stop()
        if args.stats and app is not None:
            print(app.stats.line(), flush=True)
        pygame.quit()
    return status
