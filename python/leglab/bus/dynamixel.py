"""DYNAMIXEL Protocol 2.0 as pure functions: whole frames in and out, no I/O.

The reference is the ROBOTIS e-Manual, "DYNAMIXEL Protocol 2.0"
(https://emanual.robotis.com/docs/en/dxl/protocol2/) and its "CRC Calculation" page
(https://emanual.robotis.com/docs/en/dxl/crc/). A frame is

    FF FF FD 00 | id | length (2 bytes LE) | instruction | [error] | params | CRC (2 bytes LE)

where length counts everything after itself (instruction, error, params, CRC) once byte stuffing
has been applied, the CRC covers every byte before it (header included, stuffing included), and a
status packet carries instruction 0x55 and an error byte. Multi-byte numbers are little endian.

The same names exist in leglab.bus.feetech, so code above this layer is protocol-agnostic.
"""

from collections.abc import Mapping, Sequence

from .errors import (Packet, ProtocolError, check_ids, parse_sync_write_blocks,
                     sync_write_blocks)

NAME = "dynamixel"
HEADER = b"\xff\xff\xfd\x00"
PREFIX_BYTES = 7  # header (4), id (1), length (2): enough to know the frame's size
BROADCAST_ID = 0xFE
MAX_ID = 0xFC  # 0..252 address one servo; 253 and 255 are never ids (they would mimic the header)

# Instruction codes (e-Manual Protocol 2.0, "Instruction").
PING = 0x01
READ = 0x02
WRITE = 0x03
REG_WRITE = 0x04
ACTION = 0x05
FACTORY_RESET = 0x06
REBOOT = 0x08
CLEAR = 0x10
STATUS = 0x55
SYNC_READ = 0x82
SYNC_WRITE = 0x83
BULK_READ = 0x92
BULK_WRITE = 0x93

# PING's status packet carries the model number and firmware version; Feetech's carries nothing.
PING_REPORTS_MODEL = True

CRC_POLYNOMIAL = 0x8005  # x^16 + x^15 + x^2 + 1, initial value 0, no reflection (CRC-16/BUYPASS)


def _crc_table(polynomial: int) -> tuple[int, ...]:
    """The 256 CRC-16 remainders of each leading byte, most significant bit first."""
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ polynomial) if crc & 0x8000 else (crc << 1)
        table.append(crc & 0xFFFF)
    return tuple(table)


_CRC_TABLE = _crc_table(CRC_POLYNOMIAL)


def crc16(data: bytes) -> int:
    """The Protocol 2.0 CRC (polynomial 0x8005, initial value 0, unreflected).

    Parameters
    ----------
    data : bytes
        The bytes it covers.

    Returns
    -------
    int
        The CRC-16.
    """
    crc = 0
    for byte in data:
        crc = ((crc << 8) & 0xFFFF) ^ _CRC_TABLE[(crc >> 8) ^ byte]
    return crc


def stuff(body: bytes) -> bytes:
    """Byte stuffing: each FF FF FD becomes FF FF FD FD, so that no header pattern appears inside
    a packet.

    Parameters
    ----------
    body : bytes
        The instruction, [error] and params.

    Returns
    -------
    bytes
        The stuffed body.
    """
    out = bytearray()
    ones = 0  # consecutive 0xFF bytes seen in `body`
    for byte in body:
        out.append(byte)
        if byte == 0xFD and ones >= 2:
            out.append(0xFD)
            ones = 0
        else:
            ones = ones + 1 if byte == 0xFF else 0
    return bytes(out)


def unstuff(body: bytes) -> bytes:
    """Byte stuffing removed (FF FF FD FD -> FF FF FD).

    Parameters
    ----------
    body : bytes
        A stuffed body.

    Returns
    -------
    bytes
        The body.

    Raises
    ------
    ProtocolError
        An FF FF FD not followed by its stuffing byte.
    """
    out = bytearray()
    ones = 0
    expect_stuffing = False
    for index, byte in enumerate(body):
        if expect_stuffing:
            if byte != 0xFD:
                raise ProtocolError(f"FF FF FD at byte {index - 3} of the body is not stuffed")
            expect_stuffing = False
            continue
        out.append(byte)
        if byte == 0xFD and ones >= 2:
            expect_stuffing = True
            ones = 0
        else:
            ones = ones + 1 if byte == 0xFF else 0
    if expect_stuffing:
        raise ProtocolError("the body ends in FF FF FD without its stuffing byte")
    return bytes(out)


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


def _u16(value: int, what: str) -> bytes:
    """`value` as 2 bytes little endian; TypeError if it is not an integer, ValueError if it does
    not fit."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{what}: expected an integer, got {type(value).__name__}")
    if not 0 <= value <= 0xFFFF:
        raise ValueError(f"{what} {value!r} does not fit two bytes (0..65535)")
    return value.to_bytes(2, "little")


def _frame(id: int, area: bytes) -> bytes:
    """A whole frame around the unstuffed instruction area (instruction, [error], params)."""
    stuffed = stuff(area)
    length = len(stuffed) + 2
    if length > 0xFFFF:
        raise ValueError(f"{len(area)} bytes of instruction and params do not fit one packet")
    body = HEADER + bytes([id]) + length.to_bytes(2, "little") + stuffed
    return body + crc16(body).to_bytes(2, "little")


def encode_instruction(id: int, instruction: int, params: bytes = b"") -> bytes:
    """A whole instruction frame: header, id, length, stuffed instruction and params, CRC.

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
    return _frame(id, bytes([_byte(instruction, "instruction")]) + bytes(params))


def encode_status(id: int, error: int, params: bytes = b"") -> bytes:
    """A whole status frame, as a servo sends it: instruction STATUS, the error byte, the params.

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
    return _frame(id, bytes([STATUS, _byte(error, "error")]) + bytes(params))


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
    if bytes(prefix[:4]) != HEADER:
        raise ProtocolError(f"header {bytes(prefix[:4]).hex(' ')} is not ff ff fd 00")
    if prefix[4] in (0xFD, 0xFF):
        raise ProtocolError(f"id {prefix[4]:#04x} is never a packet id")
    length = int.from_bytes(prefix[5:7], "little")
    if length < 3:
        raise ProtocolError(f"length field {length} is below the minimum 3 (instruction, CRC)")
    return PREFIX_BYTES + length


def decode(frame: bytes, status: bool) -> Packet:
    """The packet in one whole frame, verified: header, id, length, CRC and byte stuffing.

    Parameters
    ----------
    frame : bytes
        One whole frame.
    status : bool
        True: a status packet (instruction STATUS, then its error byte); False: an instruction
        packet.

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
    expected, received = crc16(frame[:-2]), int.from_bytes(frame[-2:], "little")
    if expected != received:
        raise ProtocolError(f"CRC {received:#06x} does not match the frame's {expected:#06x}")
    area = unstuff(frame[PREFIX_BYTES:-2])
    id, instruction = frame[4], area[0]
    if not status:
        if instruction == STATUS:
            raise ProtocolError("a status packet where an instruction packet was expected")
        return Packet(id, instruction, 0, area[1:])
    if instruction != STATUS:
        raise ProtocolError(f"instruction {instruction:#04x} where a status packet was expected")
    if len(area) < 2:
        raise ProtocolError("status packet without its error byte")
    if id == BROADCAST_ID:
        raise ProtocolError("status packet from the broadcast id")
    return Packet(id, instruction, area[1], area[2:])


def ping(id: int) -> bytes:
    """PING a servo.

    Parameters
    ----------
    id : int
        The servo (or BROADCAST_ID: every servo answers, in id order).

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
    """The params of a servo's reply to PING.

    Parameters
    ----------
    model_number : int
        The servo's model number.
    firmware_version : int
        Its firmware.

    Returns
    -------
    bytes
        Model number (2 bytes LE), firmware version.
    """
    return _u16(model_number, "model number") + bytes([_byte(firmware_version, "firmware")])


def parse_ping_status(params: bytes) -> tuple[int, int]:
    """The model number and firmware of a reply to PING.

    Parameters
    ----------
    params : bytes
        The params of a reply to PING.

    Returns
    -------
    (int, int)
        (model number, firmware version).

    Raises
    ------
    ProtocolError
        Params of the wrong length.
    """
    if len(params) != 3:
        raise ProtocolError(f"PING reply has {len(params)} params, not 3")
    return int.from_bytes(params[:2], "little"), params[2]


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
    return encode_instruction(id, READ, _u16(address, "address") + _u16(size, "size"))


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
    return encode_instruction(id, WRITE, _u16(address, "address") + bytes(data))


def reboot(id: int) -> bytes:
    """REBOOT a servo: the only way to turn torque back on after a hardware-error shutdown.

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
    head = _u16(address, "address") + _u16(size, "size")
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
    params = bytearray(_u16(address, "address") + _u16(size, "size"))
    params += sync_write_blocks(size, data_by_id)
    return encode_instruction(BROADCAST_ID, SYNC_WRITE, bytes(params))


def bulk_read(items: Sequence[tuple[int, int, int]]) -> bytes:
    """BULK_READ: bytes of several servos, each its own; each answers with its own status packet,
    in the order of `items`.

    Parameters
    ----------
    items : sequence of (int, int, int)
        (id, address, size) of each servo.

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
    check_ids([id for id, _, _ in items], _check_id)
    params = bytearray()
    for id, address, size in items:
        if size < 1:
            raise ValueError(f"id {id}: read size {size} is below 1")
        params += bytes([id]) + _u16(address, "address") + _u16(size, "size")
    return encode_instruction(BROADCAST_ID, BULK_READ, bytes(params))


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
    if len(params) < 5:
        raise ProtocolError(f"SYNC_READ has {len(params)} params, fewer than 5")
    address, size = int.from_bytes(params[:2], "little"), int.from_bytes(params[2:4], "little")
    return address, size, list(params[4:])


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
    if len(params) < 4:
        raise ProtocolError(f"SYNC_WRITE has {len(params)} params, fewer than 4")
    address, size = int.from_bytes(params[:2], "little"), int.from_bytes(params[2:4], "little")
    rest = params[4:]
    return address, size, parse_sync_write_blocks(rest, size)


def parse_bulk_read(params: bytes) -> list[tuple[int, int, int]]:
    """What a BULK_READ instruction asks.

    Parameters
    ----------
    params : bytes
        The instruction's params.

    Returns
    -------
    list of (int, int, int)
        [(id, address, size), ...].

    Raises
    ------
    ProtocolError
        Params that are not a BULK_READ's.
    """
    if not params or len(params) % 5:
        raise ProtocolError(f"BULK_READ has {len(params)} params, not a multiple of 5")
    return [(params[i], int.from_bytes(params[i + 1:i + 3], "little"),
             int.from_bytes(params[i + 3:i + 5], "little")) for i in range(0, len(params), 5)]


# The status packet's error byte: bit 7 is the alert (see Hardware Error Status), bits 6..0
# the error number (e-Manual Protocol 2.0, "Status Packet", "Error").
ALERT = 0x80
ERROR_NUMBERS = {
    0x01: "result fail",
    0x02: "instruction error",
    0x03: "CRC error",
    0x04: "data range error",
    0x05: "data length error",
    0x06: "data limit error",
    0x07: "access error",
}

# Hardware Error Status (X-series address 70): the bits the e-Manual's Shutdown section names.
HARDWARE_ERROR_BITS = {
    0x01: "input voltage",
    0x04: "overheating",
    0x08: "motor encoder",
    0x10: "electrical shock",
    0x20: "overload",
}


def error_text(error: int) -> str:
    """The status error byte in words.

    Parameters
    ----------
    error : int
        The byte.

    Returns
    -------
    str
        "" when 0, e.g. "alert (hardware error), CRC error".
    """
    words = ["alert (hardware error)"] if error & ALERT else []
    number = error & 0x7F
    if number:
        words.append(ERROR_NUMBERS.get(number, f"error number {number}"))
    return ", ".join(words)


def error_is_hardware(error: int) -> bool:
    """Whether the status error byte reports a fault of the servo itself.

    Parameters
    ----------
    error : int
        The byte.

    Returns
    -------
    bool
        Whether it raises the alert: the servo has a hardware error (read hardware_error_status for
        which) and has turned its torque off until rebooted.
    """
    return bool(error & ALERT)


def hardware_error_text(status: int) -> str:
    """The Hardware Error Status register in words.

    Parameters
    ----------
    status : int
        The register's value.

    Returns
    -------
    str
        "" when 0, e.g. "overheating, overload".
    """
    return ", ".join(HARDWARE_ERROR_BITS.get(1 << bit, f"bit {bit}")
                     for bit in range(8) if status & (1 << bit))
