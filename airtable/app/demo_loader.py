"""Find and load demo files (no pygame).

A demo is one Python file that defines:

    KEY = "6"                 # the key that starts it: "1".."9", "0", "1p", ...
    TITLE = "Spring triangle"
    NOTES = "Two to four sentences a teacher can read out."
    VARIATIONS = ("n = 4", "n = 8")   # optional; Left/Right step through them
    DEFAULT_VARIATION = 0     # optional: the one its key starts (counting from 0)
    DT_S = 1 / 240            # optional fixed physics step
    TRAILS = False            # optional: start with trails (no erasing) on
    def build(table, variation=0): ...   # adds pucks, springs, settings, events

The list of demos comes from the files themselves, so the number keys, the
help screen and `--list-demos` can never drift from what is on disk. A
`DemoShelf` keeps them loaded and re-reads a file that changed on disk, so a
teacher can edit a demo and press its key again.
"""

from __future__ import annotations

import importlib.util
import re
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
    default_variation: int = 0  # the variation its key starts
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
    """A demo file that could not be loaded, built or run: where and why.

    `stage` is "load" (importing the file), "build" (its build function) or
    "event" (a timed event it scheduled).
    """

    path: Path
    line: int | None
    message: str
    stage: str = "load"

    def __str__(self) -> str:
        where = f"{self.path.name}, line {self.line}" if self.line else self.path.name
        return f"{where}: {self.message}"

    def one_line(self) -> str:
        """`file:line: message`, the form editors and terminals jump to."""
        where = f"{self.path}:{self.line}" if self.line else str(self.path)
        return f"{where}: {self.message}"


class DemoLoadError(Exception):
    def __init__(self, error: DemoError) -> None:
        super().__init__(str(error))
        self.error = error


def key_order(key: str) -> tuple:
    """Sort keys as on the keyboard: 1..9, 0, then the rest naturally (1p, 2p, t1, t2, t10)."""
    if key.isdigit() and len(key) == 1:
        return (0, (int(key) - 1) % 10, ())
    parts = re.split(r"(\d+)", key.lower())
    return (1, 0, tuple((0, int(p), "") if p.isdigit() else (1, 0, p) for p in parts if p))


def key_label(key: str) -> str:
    """How a person presses `key`: "1p" is Shift+1, anything else as it is."""
    if len(key) == 2 and key[0].isdigit() and key[1] == "p":
        return f"Shift+{key[0]}"
    return key


def has_own_key(key: str) -> bool:
    """Whether a key press starts the demo `key` ("7", "1p": a digit, with Shift); the others ("t",
    "t1", "s2") are picked in Tab's menu, where typing the key finds them."""
    return len(key) in (1, 2) and key[0].isdigit() and key[1:] in ("", "p")


def key_from_label(text: str) -> str:
    """What a person typed for a demo ("Shift+1", "shift + 1", "1p", "3") as its key ("1p", "3")."""
    plain = text.replace(" ", "")
    if plain.lower().startswith("shift+") and len(plain) == 7 and plain[-1].isdigit():
        return f"{plain[-1]}p"
    return text


def error_from_exception(path: Path, exc: BaseException, stage: str = "load") -> DemoError:
    """Point at the line of `path` where `exc` happened (or its syntax error)."""
    if isinstance(exc, SyntaxError) and Path(exc.filename or "").resolve() == path.resolve():
        return DemoError(path, exc.lineno, f"syntax error: {exc.msg}", stage)
    line = None
    for frame in traceback.extract_tb(exc.__traceback__):
        if Path(frame.filename).resolve() == path.resolve():
            line = frame.lineno
    return DemoError(path, line, f"{type(exc).__name__}: {exc}", stage)


def _import(path: Path):
    """Run the file as a fresh module, from its source (no cached bytecode, so an edit
    made within the same second is never missed and no __pycache__ lands beside it)."""
    name = f"airtable_demo_{abs(hash(str(path.resolve())))}_{path.stem}"
    try:
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None:
            raise ImportError(f"cannot import {path}")
        module = importlib.util.module_from_spec(spec)
        code = compile(path.read_bytes(), str(path), "exec", dont_inherit=True)
        sys.modules[name] = module
        exec(code, module.__dict__)  # the teacher's own demo file, never network data
    except Exception as exc:  # a teacher's file can fail in any way at all
        sys.modules.pop(name, None)
        raise DemoLoadError(error_from_exception(path, exc)) from exc
    return module


def _check(path: Path, module) -> float:
    """Raise DemoLoadError unless `module` defines a demo; returns its time step."""
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
    return float(dt_s)


def load_demo_file(path: Path) -> Demo:
    """Import one demo file; raises DemoLoadError on any problem."""
    path = Path(path)
    module = _import(path)
    dt_s = _check(path, module)
    variations = tuple(str(v) for v in getattr(module, "VARIATIONS", ()))
    default = getattr(module, "DEFAULT_VARIATION", 0)
    if not isinstance(default, int) or not 0 <= default < max(1, len(variations)):
        raise DemoLoadError(
            DemoError(path, None, f"DEFAULT_VARIATION must count one of VARIATIONS from 0, not {default!r}")
        )
    return Demo(
        key=str(module.KEY),
        title=str(module.TITLE),
        notes=" ".join(str(getattr(module, "NOTES", "")).split()),
        build=module.build,
        variations=variations,
        dt_s=dt_s,
        default_variation=default,
        trails=bool(getattr(module, "TRAILS", False)),
        path=path,
    )


def demo_files(directories: Iterable[Path]) -> list[Path]:
    """The demo files of `directories`, in order (files starting with "_" are helpers)."""
    return [
        path
        for directory in directories
        for path in sorted(Path(directory).glob("*.py"))
        if not path.name.startswith("_")
    ]


def _stamp(path: Path) -> tuple[int, int] | None:
    try:
        st = path.stat()
    except OSError:
        return None
    return (st.st_mtime_ns, st.st_size)


class DemoShelf:
    """The demos of some folders, kept loaded; a file that changed on disk is read again.

    `refresh()` looks at every file (a stat each, cheap) and re-imports only
    those whose time or size changed, or that are new; `demos` and `errors`
    then describe the files as they are now. A shelf made `from_demos` knows
    only the files of the demos it was given.
    """

    def __init__(self, directories: Iterable[Path] = ()) -> None:
        self.directories = [Path(d) for d in directories]
        self._extra: list[Path] = []  # files given one by one (from_demos)
        self._fixed: dict[str, Demo] = {}  # demos with no file
        self._loaded: dict[Path, tuple[tuple[int, int] | None, Demo | DemoError]] = {}
        self._last_key: dict[Path, str] = {}  # the key each file had when it last loaded
        self.demos: dict[str, Demo] = {}
        self.errors: list[DemoError] = []
        self.refresh()

    @classmethod
    def from_demos(cls, demos: dict[str, Demo]) -> DemoShelf:
        shelf = cls()
        for key, demo in demos.items():
            if demo.path is None:
                shelf._fixed[key] = demo
            else:
                shelf._extra.append(Path(demo.path))
                shelf._loaded[Path(demo.path)] = (_stamp(Path(demo.path)), demo)
        shelf.refresh()
        return shelf

    def refresh(self) -> list[DemoError]:
        """Re-read the files that changed; returns the errors that are new with this look."""
        demos: dict[str, Demo] = dict(self._fixed)
        errors: list[DemoError] = []
        fresh: list[DemoError] = []
        for path in [*self._extra, *demo_files(self.directories)]:
            stamp = _stamp(path)
            known = self._loaded.get(path)
            if known is None or known[0] != stamp:
                try:
                    known = (stamp, load_demo_file(path))
                except DemoLoadError as exc:
                    known = (stamp, exc.error)
                    fresh.append(exc.error)
                self._loaded[path] = known
            if isinstance(known[1], Demo):
                demos[known[1].key] = known[1]
                self._last_key[path] = known[1].key
            else:
                errors.append(known[1])
        self.demos = {k: demos[k] for k in sorted(demos, key=key_order)}
        self.errors = errors
        return fresh

    def broken_keys(self) -> dict[str, DemoError]:
        """Each key a file gave that now fails to load, and no other file gives: its error."""
        return {
            self._last_key[path]: item
            for path, (_, item) in self._loaded.items()
            if isinstance(item, DemoError) and path in self._last_key and self._last_key[path] not in self.demos
        }

    def broken(self, key: str) -> DemoError | None:
        """The load error of the file that last gave demo `key`, if that file now fails."""
        for path, (_, item) in self._loaded.items():
            if isinstance(item, DemoError) and self._last_key.get(path) == key:
                return item
        return None


def discover(directories: Iterable[Path]) -> tuple[dict[str, Demo], list[DemoError]]:
    """Load every demo file in `directories`, later directories overriding keys.

    Returns the demos by key (in keyboard order) and the files that failed.
    """
    shelf = DemoShelf(directories)
    return shelf.demos, shelf.errors
