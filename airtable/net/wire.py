"""The low-level pieces of the binary messages (snapshots, aids): checked reading, raw deflate,
text from the wire and the residual byte planes. No pygame, no sockets.

Every read checks its size first, and anything wrong raises ProtocolError with a
sentence ("the snapshot has ...").
"""

from __future__ import annotations

import math
import zlib

import numpy as np

from airtable.net.protocol import ProtocolError


def bad(what: str) -> ProtocolError:
    return ProtocolError(f"the snapshot has {what}; the server may run a different airtable version")


def deflate(data: bytes) -> bytes:
    packer = zlib.compressobj(1, zlib.DEFLATED, -15)
    return packer.compress(data) + packer.flush()


def inflate(data: bytes, size: int, what: str) -> bytes:
    """Exactly `size` bytes from raw deflate data (never more are made)."""
    unpacker = zlib.decompressobj(-15)
    try:
        out = unpacker.decompress(data, size + 1)
    except zlib.error:
        raise bad(f"a damaged {what}") from None
    if len(out) != size or not unpacker.eof or unpacker.unused_data:
        raise bad(f"a {what} of the wrong size")
    return out


def wire_text(raw: bytes, what: str) -> str:
    """Text from the wire, checked: UTF-8 and printable, else a ProtocolError naming `what` ("a title")."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise bad(f"{what} that is not UTF-8") from None
    if not text.isprintable():
        raise bad(f"{what} that is not printable")
    return text


class Reader:
    """Consecutive fields of a byte string whose size is checked before each read."""

    def __init__(self, data: bytes, what: str) -> None:
        self.data = data
        self.offset = 0
        self.what = what

    def take(self, size: int) -> bytes:
        end = self.offset + size
        if size < 0 or end > len(self.data):
            raise ProtocolError(f"the {self.what} is cut short")
        chunk = self.data[self.offset : end]
        self.offset = end
        return chunk

    def array(self, dtype: str, shape: tuple[int, ...]) -> np.ndarray:
        dt = np.dtype(dtype)
        count = math.prod(shape)
        return np.frombuffer(self.take(count * dt.itemsize), dtype=dt).reshape(shape).copy()

    def text(self, limit: int, what: str) -> str:
        size = int.from_bytes(self.take(2), "little")
        if size > limit:
            raise bad(f"a {what} of {size} bytes (at most {limit})")
        return wire_text(self.take(size), f"a {what}")

    def done(self) -> None:
        if self.offset != len(self.data):
            raise bad(f"{len(self.data) - self.offset} bytes too many at the end of its {self.what}")


def zigzag(r: np.ndarray) -> np.ndarray:
    return ((r << 1) ^ (r >> 63)).astype(np.uint64)


def unzigzag(z: np.ndarray) -> np.ndarray:
    z = z.astype(np.int64)
    return (z >> 1) ^ -(z & 1)


def pack_residuals(residuals: np.ndarray) -> tuple[int, bytes, bool]:
    """(byte width 0-4, byte planes maybe deflated, deflated?) for int64 residuals."""
    z = zigzag(residuals)
    top = int(z.max()) if len(z) else 0
    width = (top.bit_length() + 7) // 8
    if width == 0:
        return 0, b"", False
    if width > 4:
        raise ValueError("residuals must fit 32 bits")
    planes = z.astype("<u4").view(np.uint8).reshape(-1, 4)[:, :width].T.tobytes()
    packed = deflate(planes)
    if len(packed) < len(planes):
        return width, packed, True
    return width, planes, False


def unpack_residuals(block: bytes, width: int, count: int, deflated: bool) -> np.ndarray:
    """The inverse of `pack_residuals`, with every size checked."""
    if width == 0:
        if block:
            raise bad("residual bytes where none were announced")
        return np.zeros(count, dtype=np.int64)
    if width > 4:
        raise bad(f"a residual width of {width} bytes (at most 4)")
    size = width * count
    raw = inflate(block, size, "residual block") if deflated else block
    if len(raw) != size:
        raise bad(f"{len(raw)} residual bytes where {size} were due")
    planes = np.frombuffer(raw, dtype=np.uint8).reshape(width, count).astype(np.uint64)
    z = np.zeros(count, dtype=np.uint64)
    for k in range(width):
        z |= planes[k] << np.uint64(8 * k)
    return unzigzag(z)
