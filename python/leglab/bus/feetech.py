"""The Feetech FT-SCS protocol of the STS/SMS servos (STS3215, STS3250; "protocol 0" in
Feetech's SDKs) as pure functions: whole frames in and out, no I/O.

The reference is Feetech's "Servo SCS Communication Protocol", as transcribed in the
manufacturer's wiki (github.com/ftservo/ftservo-wiki, docs/en/reference/protocol/ft-scs.md).
A frame is

    FF FF | id | length | instruction (or, in a status packet, the error byte) | params | checksum

where length = len(params) + 2 and checksum = ~(id + length + instruction + params) & 0xFF.
Two-byte numbers of the magnetic-encoder servos (STS/SMS) are little endian; negative numbers
are sign-magnitude (a direction bit, see to_sign_magnitude). A status packet has the servo's
status bits where an instruction packet has its instruction, so nothing in the frame tells the
two apart: the caller says which it expects.

The same names exist in leglab.bus.dynamixel, so code above this layer is protocol-agnostic.
"""

from collections.abc import Mapping, Sequence

from .errors import (Packet, ProtocolError, check_ids, parse_sync_write_blocks,
                     sync_write_blocks)

NAME = "feetech"
HEADER = b"\xff\xff"
PREFIX_BYTES = 4  # header (2), id (1), length (1): enough to know the frame's size
BROADCAST_ID = 0xFE
MAX_ID = 0xFD  # 0..253 address one servo

# Instruction codes (FT-SCS protocol, "4 Instruction types").
PING = 0x01
READ = 0x02
WRITE = 0x03
REG_WRITE = 0x04
ACTION = 0x05
FACTORY_RESET = 0x06  # "parameter recovery": every parameter but the id
REBOOT = 0x08
BACKUP = 0x09
RESET = 0x0A  # resets the turn count
CALIBRATE = 0x0B  # current position := middle (or the given value)
SYNC_READ = 0x82
SYNC_WRITE = 0x83
# A status packet carries its error byte where an instruction packet carries its instruction;
# decoded status packets report this code as their instruction.
STATUS = 0x00

# Feetech's PING reply has no params: the model number is read from the control table.
PING_REPORTS_MODEL = False


def checksum(body: bytes) -> int:
    """The FT-SCS checksum: ~sum, lowest byte.

    Parameters
    ----------
    body : bytes
        The id through the last param.

    Returns
    -------
    int
        The checksum byte.
    """
    return ~sum(body) & 0xFF


def to_sign_magnitude(value: int, sign_bit: int) -> int:
    """A signed number as Feetech writes it: |value| in the bits below `sign_bit`, that bit set
    when negative (position and speed: bit 15; load: bit 10; position offset: bit 11).

    Parameters
    ----------
    value : int
        The number.
    sign_bit : int
        The sign's bit.

    Returns
    -------
    int
        The raw field.

    Raises
    ------
    ValueError
        |value| needs the sign bit.
    """
    magnitude = abs(value)
    if magnitude >= 1 << sign_bit:
        raise ValueError(f"{value} does not fit sign-magnitude with the sign in bit {sign_bit} "
                         f"(|value| <= {(1 << sign_bit) - 1})")
    return (magnitude | (1 << sign_bit)) if value < 0 else magnitude


def from_sign_magnitude(raw: int, sign_bit: int) -> int:
    """The signed number in a sign-magnitude field; bits above the sign bit are not part of the
    number and are ignored.

    Parameters
    ----------
    raw : int
        The raw field.
    sign_bit : int
        The sign's bit.

    Returns
    -------
    int
        The number.
    """
    magnitude = raw & ((1 << sign_bit) - 1)
    return -magnitude if raw & (1 << sign_bit) else magnitude


def _check_id(id: int, broadcast: bool) -> None:
    """TypeError unless `id` is an integer (bool is not), ValueError unless it addresses one servo
    (or, with `broadcast`, is BROADCAST_ID)."""
    if isinstance(id, bool) or not isinstance(id, int):
        raise TypeError(f"id: expected an integer, got {type(id).__name__}")
    if not (0 <= id <= MAX_ID or (broadcast and id == BROADCAST_ID)):
        allowed = f"0..{MAX_ID}" + (f" or {BROADCAST_ID}" if broadcast else "")
        raise ValueError(f"id {id!r} is not a servo id ({allowed})")


def _byte(value: int, what: str) -> int:
    """`value` checked to be an integer (TypeError) that fits one byte (ValueError)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{what}: expected an integer, got {type(value).__name__}")
    if not 0 <= value <= 0xFF:
        raise ValueError(f"{what} {value!r} does not fit one byte (0..255)")
    return value


def _frame(id: int, code: int, params: bytes) -> bytes:
    """A whole frame: header, id, length, `code` (instruction or error), params, checksum."""
    if len(params) > 253:
        raise ValueError(f"{len(params)} params do not fit one packet (at most 253)")
    body = bytes([id, len(params) + 2, code]) + bytes(params)
    return HEADER + body + bytes([checksum(body)])


def encode_instruction(id: int, instruction: int, params: bytes = b"") -> bytes:
    """A whole instruction frame: header, id, length, instruction, params, checksum.

    Parameters
    ----------
    id : int
        The servo (or BROADCAST_ID).
    instruction : int
        The instruction code.
    params : bytes, optional
        Its parameters.

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    _check_id(id, broadcast=True)
    return _frame(id, _byte(instruction, "instruction"), params)


def encode_status(id: int, error: int, params: bytes = b"") -> bytes:
    """A whole status frame, as a servo sends it: its status bits, then the params.

    Parameters
    ----------
    id : int
        The servo.
    error : int
        The status packet's error byte.
    params : bytes, optional
        Its parameters.

    Returns
    -------
    bytes
        The whole status frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    _check_id(id, broadcast=False)
    return _frame(id, _byte(error, "error"), params)


def frame_length(prefix: bytes) -> int:
    """The total size in bytes of the frame that starts with `prefix`.

    Parameters
    ----------
    prefix : bytes
        Its first PREFIX_BYTES bytes or more.

    Returns
    -------
    int
        The frame's size, bytes.

    Raises
    ------
    ProtocolError
        The header, id or length field cannot start a packet.
    """
    if len(prefix) < PREFIX_BYTES:
        raise ProtocolError(f"{len(prefix)} bytes are too few to size a frame ({PREFIX_BYTES})")
    if bytes(prefix[:2]) != HEADER:
        raise ProtocolError(f"header {bytes(prefix[:2]).hex(' ')} is not ff ff")
    if prefix[2] == 0xFF:
        raise ProtocolError("id 0xff is never a packet id")
    if prefix[3] < 2:
        raise ProtocolError(f"length field {prefix[3]} is below the minimum 2")
    return PREFIX_BYTES + prefix[3]


def decode(frame: bytes, status: bool) -> Packet:
    """The packet in one whole frame, verified: header, id, length and checksum.

    Parameters
    ----------
    frame : bytes
        One whole frame.
    status : bool
        True: a status packet (its error byte; instruction reported as STATUS); False: an
        instruction packet.

    Returns
    -------
    Packet
        Its id, instruction, error byte and params.

    Raises
    ------
    ProtocolError
        What is wrong with the frame.
    """
    frame = bytes(frame)
    size = frame_length(frame)
    if len(frame) != size:
        raise ProtocolError(f"frame is {len(frame)} bytes but its length field makes it {size}")
    expected = checksum(frame[2:-1])
    if frame[-1] != expected:
        raise ProtocolError(f"checksum {frame[-1]:#04x} does not match the frame's "
                            f"{expected:#04x}")
    id, code, params = frame[2], frame[4], frame[5:-1]
    if not status:
        return Packet(id, code, 0, params)
    if id == BROADCAST_ID:
        raise ProtocolError("status packet from the broadcast id")
    return Packet(id, STATUS, code, params)


def ping(id: int) -> bytes:
    """PING a servo.

    Parameters
    ----------
    id : int
        The servo (the broadcast id works only with a single servo on the bus).

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    return encode_instruction(id, PING)


def ping_status_params(model_number: int, firmware_version: int) -> bytes:
    """The params of a servo's reply to PING: none (the arguments are for the same call in
    leglab.bus.dynamixel; a Feetech servo's model number is in its control table).

    Parameters
    ----------
    model_number : int
        The servo's model number.
    firmware_version : int
        Its firmware.

    Returns
    -------
    bytes
        Empty.
    """
    return b""


def parse_ping_status(params: bytes) -> None:
    """Checks a reply to PING, which carries no model number on Feetech (read `model_number`).

    Parameters
    ----------
    params : bytes
        The params of a reply to PING.

    Returns
    -------
    None
        Nothing.

    Raises
    ------
    ProtocolError
        Params of the wrong length.
    """
    if params:
        raise ProtocolError(f"PING reply has {len(params)} params, not 0")


def read(id: int, address: int, size: int) -> bytes:
    """READ bytes from a servo's control table.

    Parameters
    ----------
    id : int
        The servo.
    address : int
        The first byte's address.
    size : int
        How many bytes (at least 1).

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    if isinstance(size, int) and size < 1:  # another type: TypeError below
        raise ValueError(f"read size {size} is below 1")
    return encode_instruction(id, READ, bytes([_byte(address, "address"), _byte(size, "size")]))


def write(id: int, address: int, data: bytes) -> bytes:
    """WRITE bytes into a servo's control table.

    Parameters
    ----------
    id : int
        The servo (BROADCAST_ID writes every servo, no reply).
    address : int
        The first byte's address.
    data : bytes
        The bytes (at least one).

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    if not data:
        raise ValueError("write of no data")
    return encode_instruction(id, WRITE, bytes([_byte(address, "address")]) + bytes(data))


def reboot(id: int) -> bytes:
    """Restart a servo (no reply; Feetech advises turning torque off first).

    Parameters
    ----------
    id : int
        The servo.

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    return encode_instruction(id, REBOOT)


def sync_read(address: int, size: int, ids: Sequence[int]) -> bytes:
    """SYNC_READ: the same bytes of several servos, each answering with its own status packet in
    the order of `ids`.

    Parameters
    ----------
    address : int
        The first byte's address.
    size : int
        How many bytes (at least 1).
    ids : sequence of int
        The servos, distinct.

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    check_ids(ids, _check_id)
    if isinstance(size, int) and size < 1:  # another type: TypeError below
        raise ValueError(f"read size {size} is below 1")
    head = bytes([_byte(address, "address"), _byte(size, "size")])
    return encode_instruction(BROADCAST_ID, SYNC_READ, head + bytes(ids))


def sync_write(address: int, size: int, data_by_id: Mapping[int, bytes]) -> bytes:
    """SYNC_WRITE: bytes into several servos at one address (no reply).

    Parameters
    ----------
    address : int
        The first byte's address.
    size : int
        The bytes each servo is given.
    data_by_id : mapping of int to bytes
        {id: data}, exactly `size` bytes each.

    Returns
    -------
    bytes
        The whole instruction frame.

    Raises
    ------
    TypeError
        An argument that is not an integer (bool is not one).
    ValueError
        An id that is not a servo's, or a field that does not fit.
    """
    check_ids(list(data_by_id), _check_id)
    params = bytearray([_byte(address, "address"), _byte(size, "size")])
    params += sync_write_blocks(size, data_by_id)
    return encode_instruction(BROADCAST_ID, SYNC_WRITE, bytes(params))


def parse_sync_read(params: bytes) -> tuple[int, int, list[int]]:
    """What a SYNC_READ instruction asks.

    Parameters
    ----------
    params : bytes
        The instruction's params.

    Returns
    -------
    (int, int, list of int)
        (address, size, ids).

    Raises
    ------
    ProtocolError
        Params that are not a SYNC_READ's.
    """
    if len(params) < 3:
        raise ProtocolError(f"SYNC_READ has {len(params)} params, fewer than 3")
    return params[0], params[1], list(params[2:])


def parse_sync_write(params: bytes) -> tuple[int, int, dict[int, bytes]]:
    """What a SYNC_WRITE instruction writes.

    Parameters
    ----------
    params : bytes
        The instruction's params.

    Returns
    -------
    (int, int, dict of int to bytes)
        (address, size, {id: data}).

    Raises
    ------
    ProtocolError
        Params that are not a SYNC_WRITE's.
    """
    if len(params) < 2:
        raise ProtocolError(f"SYNC_WRITE has {len(params)} params, fewer than 2")
    address, size, rest = params[0], params[1], params[2:]
    return address, size, parse_sync_write_blocks(rest, size)


# The status byte of a status packet, also the servo status register (address 65): a set bit is
# an active fault. Names as Feetech's STS memory table gives them ("3.2 Servo Status"); bit 4
# ("angle") is named only in the older STS3215 memory table, which lists the bits as "voltage,
# sensor, temperature, current, angle, overload".
ERROR_BITS = {
    0x01: "voltage",
    0x02: "sensor (magnetic encoder)",
    0x04: "temperature",
    0x08: "current",
    0x10: "angle",
    0x20: "overload",
}
# The bits that mean the servo itself is in trouble (as opposed to a rejected command).
HARDWARE_BITS = 0x01 | 0x02 | 0x04 | 0x08 | 0x20


def error_text(error: int) -> str:
    """The status byte in words.

    Parameters
    ----------
    error : int
        The byte.

    Returns
    -------
    str
        "" when 0, e.g. "voltage, temperature".
    """
    return ", ".join(ERROR_BITS.get(1 << bit, f"bit {bit}")
                     for bit in range(8) if error & (1 << bit))


def error_is_hardware(error: int) -> bool:
    """Whether the status byte reports a fault of the servo itself.

    Parameters
    ----------
    error : int
        The byte.

    Returns
    -------
    bool
        Voltage, magnetic encoder, temperature, current or overload.
    """
    return bool(error & HARDWARE_BITS)


def hardware_error_text(status: int) -> str:
    """The status register (hardware_error_status); the same bits as error_text in words.

    Parameters
    ----------
    status : int
        The register's value.

    Returns
    -------
    str
        "" when 0, e.g. "overload".
    """
    return error_text(status)
