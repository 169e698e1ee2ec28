"""What the two wire protocols (leglab.bus.dynamixel, leglab.bus.feetech) share: the error a
bad frame raises and the decoded packet. Standard library only."""

from typing import NamedTuple


class ProtocolError(ValueError):
    """A frame that is not a valid packet: bad header, length, id, CRC or checksum, byte
    stuffing, or parameters that do not fit their instruction. The message says what is wrong
    in one line."""


class Packet(NamedTuple):
    """One decoded packet, instruction or status.

    id: the servo's id (0xFE is broadcast).
    instruction: the instruction code; a status packet carries its module's STATUS constant.
    error: a status packet's error byte (see the module's error_text); 0 for instructions.
    params: the parameter bytes (Dynamixel: after byte stuffing has been removed).
    """

    id: int
    instruction: int
    error: int
    params: bytes
