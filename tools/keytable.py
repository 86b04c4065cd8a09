"""Print the README's key table from the app's key table: `python -m tools.keytable`.

The help screen (F1) and the README show the same keys: both come from `BINDINGS` in
airtable/app/app.py, gathered from the features' bindings in controls.HELP_ORDER. After
changing a binding, paste this output over the table under "## Keys" in README.md
(tests/test_app.py checks every key is there).
"""

from __future__ import annotations

import sys

from airtable.desktop import prepare_for_pygame


def key_table() -> str:
    """The markdown table: one row per binding, its label and its help text."""
    prepare_for_pygame()  # no pygame banner in the output
    from airtable.app.app import BINDINGS

    rows = ["| key | action |", "|---|---|"]
    rows += [f"| {b.label} | {b.help} |" for b in BINDINGS]
    return "\n".join(rows)


if __name__ == "__main__":
    sys.stdout.write(key_table() + "\n")
