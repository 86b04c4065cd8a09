"""The physics engine: SI units, numpy, no pygame and no sockets."""
