"""Tools beside the product: the load tool, its raw players, and the classroom-link check.

They live in the repository, not in the wheel students install; run them from the
checkout's top folder as `python -m tools.loadtest` and `python -m tools.fairness`.
"""

from pathlib import Path

# The checkout: child processes that run `python -m tools.X` start here, so `tools` imports.
ROOT = Path(__file__).resolve().parent.parent
