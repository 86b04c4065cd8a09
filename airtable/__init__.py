"""airtable: a 2D air-table physics engine and multiplayer teaching app.

`import airtable` gives the physics and the network client without importing
pygame; the window lives in `airtable.app.window`.
"""

from airtable.app.environment import Environment
from airtable.model.client import Client
from airtable.physics.bodies import Puck, Spring
from airtable.physics.table import AirTable

__all__ = ["AirTable", "Puck", "Spring", "Environment", "Client"]
__version__ = "0.1.0"
