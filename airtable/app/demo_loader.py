"""Find and load demo files (no pygame).

A demo is one Python file that defines:

    KEY = "6"                 # the key that starts it: "1".."9", "0", "1p", ...
    TITLE = "Spring triangle"
    NOTES = "Two to four sentences a teacher can read out."
    VARIATIONS = ("n = 4", "n = 8")   # optional; Left/Right step through them
    DT_S = 1 / 240            # optional fixed physics step
    TRAILS = False            # optional: start with trails (no erasing) on
    def build(table, variation=0): ...   # adds pucks, springs, settings, events

The list of demos comes from the files themselves, so the number keys, the
help screen and `--list-demos` can never drift from what is on disk.
"""

from __future__ import annotations

import importlib.util
import sys
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import airtable.demos

BUILTIN_DIR = Path(airtable.demos.__file__).resolve().parent
DEFAULT_DT_S = 1 / 240


@dataclass(frozen=True)
class Demo:
    key: str
    title: str
    notes: str
    build: Callable = field(repr=False)
    variations: tuple[str, ...] = ()
    dt_s: float = DEFAULT_DT_S
    trails: bool = False
    path: Path | None = None

    def label(self, variation: int = 0) -> str:
        """'Demo 8: Pool line (cue 10 % off the line)' style caption text."""
        text = f"Demo {self.key}: {self.title}"
        if self.variations:
            text += f" ({self.variations[variation % len(self.variations)]})"
        return text


@dataclass(frozen=True)
class DemoError:
    """A demo file that could not be loaded or built: where and why."""

    path: Path
    line: int | None
    message: str

    def __str__(self) -> str:
        where = f"{self.path.name}, line {self.line}" if self.line else self.path.name
        return f"{where}: {self.message}"


class DemoLoadError(Exception):
    def __init__(self, error: DemoError) -> None:
        super().__init__(str(error))
        self.error = error


def key_order(key: str) -> tuple:
    """Sort keys as on the keyboard: 1..9, 0, then the rest (1p, 2p, ...)."""
    if key.isdigit() and len(key) == 1:
        return (0, (int(key) - 1) % 10, "")
    return (1, 0, key)


def key_label(key: str) -> str:
    """How a person presses `key`: "1p" is Shift+1, anything else as it is."""
    if len(key) == 2 and key[0].isdigit() and key[1] == "p":
        return f"Shift+{key[0]}"
    return key


def error_from_exception(path: Path, exc: BaseException) -> DemoError:
    """Point at the line of `path` where `exc` happened (or its syntax error)."""
    if isinstance(exc, SyntaxError):
        return DemoError(path, exc.lineno, f"syntax error: {exc.msg}")
    line = None
    for frame in traceback.extract_tb(exc.__traceback__):
        if Path(frame.filename).resolve() == path.resolve():
            line = frame.lineno
    return DemoError(path, line, f"{type(exc).__name__}: {exc}")


def load_demo_file(path: Path) -> Demo:
    """Import one demo file; raises DemoLoadError on any problem."""
    path = Path(path)
    name = f"airtable_demo_{abs(hash(str(path.resolve())))}_{path.stem}"
    try:
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise ImportError(f"cannot import {path}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    except Exception as exc:  # a teacher's file can fail in any way at all
        sys.modules.pop(name, None)
        raise DemoLoadError(error_from_exception(path, exc)) from exc
    missing = [attr for attr in ("KEY", "TITLE", "build") if not hasattr(module, attr)]
    if missing:
        raise DemoLoadError(DemoError(path, None, f"a demo file must define {', '.join(missing)}"))
    if not callable(module.build):
        raise DemoLoadError(DemoError(path, None, "build must be a function build(table, variation=0)"))
    dt_s = getattr(module, "DT_S", DEFAULT_DT_S)
    if not (isinstance(dt_s, (int, float)) and 0.0 < dt_s <= 1.0):
        raise DemoLoadError(
            DemoError(path, None, f"DT_S must be a time step in seconds, above 0 and at most 1, not {dt_s!r}")
        )
    if not str(module.KEY).strip():
        raise DemoLoadError(DemoError(path, None, 'KEY must name the key that starts the demo, like "7" or "t1"'))
    return Demo(
        key=str(module.KEY),
        title=str(module.TITLE),
        notes=" ".join(str(getattr(module, "NOTES", "")).split()),
        build=module.build,
        variations=tuple(str(v) for v in getattr(module, "VARIATIONS", ())),
        dt_s=float(dt_s),
        trails=bool(getattr(module, "TRAILS", False)),
        path=path,
    )


def discover(directories: Iterable[Path]) -> tuple[dict[str, Demo], list[DemoError]]:
    """Load every demo file in `directories`, later directories overriding keys.

    Returns the demos by key (in keyboard order) and the files that failed.
    """
    demos: dict[str, Demo] = {}
    errors: list[DemoError] = []
    for directory in directories:
        for path in sorted(Path(directory).glob("*.py")):
            if path.name.startswith("_"):
                continue
            try:
                demo = load_demo_file(path)
            except DemoLoadError as exc:
                errors.append(exc.error)
                continue
            demos[demo.key] = demo
    ordered = {k: demos[k] for k in sorted(demos, key=key_order)}
    return ordered, errors
