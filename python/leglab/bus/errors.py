"""What the two wire protocols (leglab.bus.dynamixel, leglab.bus.feetech) share: the error a
bad frame raises, the decoded packet, and the id lists and per-servo blocks of their SYNC
instructions (each protocol frames the address and size its own way around them). Standard
library only."""

from collections.abc import Callable, Mapping, Sequence
from typing import NamedTuple


class ProtocolError(ValueError):
    """A frame that is not a valid packet: bad header, length, id, CRC or checksum, byte
    stuffing, or parameters that do not fit their instruction. The message says what is wrong
    in one line."""


class Packet(NamedTuple):
    """One decoded packet, instruction or status.

    Attributes
    ----------
    id : int
        The servo's id (0xFE is broadcast).
    instruction : int
        The instruction code; a status packet carries its module's STATUS constant.
    error : int
        A status packet's error byte (see the module's error_text); 0 for instructions.
    params : bytes
        The parameter bytes (Dynamixel: after byte stuffing has been removed).
    """

    id: int
    instruction: int
    error: int
    params: bytes


def check_ids(ids: Sequence[int], check_id: Callable[[int, bool], None]) -> None:
    """Checks the ids of a SYNC instruction.

    Parameters
    ----------
    ids : sequence of int
        One or more distinct servo ids.
    check_id : callable
        The protocol's own check of one id, called as check_id(id, False).

    Raises
    ------
    TypeError
        An id not an integer (check_id's).
    ValueError
        No ids, an id repeated, an id `check_id` refuses.
    """
    if not ids:
        raise ValueError("no ids")
    for id in ids:
        check_id(id, False)
    if len(set(ids)) != len(ids):
        raise ValueError(f"ids {list(ids)} repeat an id")


def sync_write_blocks(size: int, data_by_id: Mapping[int, bytes]) -> bytes:
    """SYNC_WRITE's per-servo blocks.

    Parameters
    ----------
    size : int
        The bytes each servo is given.
    data_by_id : mapping of int to bytes
        {id: data}.

    Returns
    -------
    bytes
        Each id, then its `size` bytes of data.

    Raises
    ------
    ValueError
        A servo's data is not `size` bytes.
    """
    blocks = bytearray()
    for id, data in data_by_id.items():
        if len(data) != size:
            raise ValueError(f"id {id}: {len(data)} bytes of data, not {size}")
        blocks += bytes([id]) + bytes(data)
    return bytes(blocks)


def parse_sync_write_blocks(rest: bytes, size: int) -> dict[int, bytes]:
    """The data of SYNC_WRITE's per-servo blocks.

    Parameters
    ----------
    rest : bytes
        The blocks.
    size : int
        The bytes each servo is given.

    Returns
    -------
    dict of int to bytes
        {id: data}.

    Raises
    ------
    ProtocolError
        The blocks are not whole.
    """
    if size < 1 or not rest or len(rest) % (size + 1):
        raise ProtocolError(f"SYNC_WRITE data of {len(rest)} bytes is not whole (id + {size})")
    step = size + 1
    return {rest[i]: bytes(rest[i + 1:i + step]) for i in range(0, len(rest), step)}
