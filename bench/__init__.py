"""Benchmarks of the engine, the app and the network: `python -m bench` (or `make bench`).

They live in the repository beside the package, not in the wheel students install.
Run them from the checkout's top folder, where `bench` and `airtable` both import.
"""

from pathlib import Path

# The checkout: child processes that run `python -m bench.X` start here, so `bench` imports.
ROOT = Path(__file__).resolve().parent.parent
