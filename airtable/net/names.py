"""Names that cannot pass for others: look-alike letters folded before names are compared.

The projector labels each cursor "C<n> name". A name that reads like a seat
label ("C1", "С1" with a Cyrillic С, "C-1", "C¹", "Ｃ１") or like another
student's name ("Αnn" with a Greek Alpha beside "Ann") would let one student
pass for another. So names are compared by their *skeleton*: NFKC (which
turns superscripts, fullwidth and other compatibility forms into plain
ones), then the look-alike table below, then casefold, spaces squeezed and
dashes made one.

The table is a small part of Unicode's confusables list
(https://www.unicode.org/Public/security/latest/confusables.txt, UTS #39
"skeleton"): the Cyrillic and Greek letters that look Latin in common fonts,
dotless i, capital I against small l, "rn" against "m", and the dashes. It is
not the whole list (that is 6,000 lines, mostly scripts a class will not
mix); it covers what a student can type on a school keyboard to imitate a
classmate. No pygame, no sockets.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable

MAX_NAME_CHARS = 20  # the longest name a player may give (protocol.py checks it on the wire)

# confusables.txt entries, source character -> the Latin one it passes for.
_LOOK_ALIKES = {
    # Cyrillic capitals
    "А": "A", "В": "B", "С": "C", "Е": "E", "Н": "H", "І": "l", "Ј": "J", "К": "K", "М": "M", "О": "O",
    "Р": "P", "Ѕ": "S", "Т": "T", "Х": "X", "У": "Y", "Ү": "Y", "Ԛ": "Q", "Ԝ": "W", "Ӏ": "l",
    # Cyrillic small letters
    "а": "a", "с": "c", "е": "e", "і": "i", "ј": "j", "о": "o", "р": "p", "ѕ": "s", "х": "x", "у": "y",
    "һ": "h", "ԁ": "d", "ԛ": "q", "ԝ": "w", "ӏ": "l", "ү": "y",
    # Greek capitals
    "Α": "A", "Β": "B", "Ε": "E", "Ζ": "Z", "Η": "H", "Ι": "l", "Κ": "K", "Μ": "M", "Ν": "N", "Ο": "O",
    "Ρ": "P", "Τ": "T", "Υ": "Y", "Χ": "X",
    # Greek small letters
    "α": "a", "ι": "i", "ν": "v", "ο": "o", "ρ": "p", "υ": "u", "γ": "y",
    # Latin look-alikes
    "ı": "i", "I": "l", "ɑ": "a", "ɡ": "g", "ǀ": "l",
    # dashes and minus signs
    "‐": "-", "‑": "-", "‒": "-", "–": "-", "—": "-", "―": "-", "−": "-", "⁃": "-", "﹘": "-", "ー": "-",
}  # fmt: skip
_FOLD = str.maketrans(_LOOK_ALIKES)
_SPACES = re.compile(r"\s+")
# A seat label in a skeleton: C or S, maybe a dash, dot or space, then digits, as a word of its own.
_LABEL = re.compile(r"(?<![^\W_])[cs][\s\-_.·]*\d+(?![^\W_])")


def skeleton(name: str) -> str:
    """What `name` looks like, for comparing: equal skeletons read alike on the projector."""
    text = unicodedata.normalize("NFKC", name).translate(_FOLD).casefold()
    text = unicodedata.normalize("NFKC", text).replace("rn", "m")
    return _SPACES.sub(" ", text).strip()


# Letters and digits that pass for each other, one way for each question: a seat label is
# made of digits, so for it the bars (I, l, |) read as 1; names are made of letters, so for
# them 0 and 1 read as o and l ("B0b" beside "Bob"). Not o as 0 for labels: "Sol" is a name.
_AS_DIGITS = str.maketrans({"l": "1", "|": "1"})
_AS_LETTERS = str.maketrans({"0": "o", "1": "l", "|": "l"})


def looks_like_label(name: str) -> bool:
    """Whether `name` holds something that reads like a seat label, C7 or S7 (in any look-alike
    letters, "Cl" with a small L or "CI" with a capital i too)."""
    return _LABEL.search(skeleton(name).translate(_AS_DIGITS)) is not None


def _reads_as(name: str) -> str:
    """What a name reads as beside others: its skeleton, digits as the letters they pass for, and
    no spaces ("Ann2" beside "Ann 2")."""
    return skeleton(name).translate(_AS_LETTERS).replace(" ", "")


def distinct_name(name: str, taken: Iterable[str]) -> str:
    """`name`, or "name 2" (3, ...) when it reads like one of the names `taken` ("Ann" -> "Ann 2").

    At most MAX_NAME_CHARS characters: a long name is cut to make room for the number."""
    seen = {_reads_as(t) for t in taken}
    if _reads_as(name) not in seen:
        return name
    for k in range(2, len(seen) + 3):  # len(seen) + 1 numbers cannot all be taken
        candidate = _numbered(name, f" {k}")
        if looks_like_label(candidate):  # "C" -> "C 2" would read as a seat label: "C (2)"
            candidate = _numbered(name, f" ({k})")
        if _reads_as(candidate) not in seen:
            return candidate
    raise AssertionError("unreachable: more numbers were tried than names are taken")


def _numbered(name: str, suffix: str) -> str:
    return name[: MAX_NAME_CHARS - len(suffix)].rstrip() + suffix
