"""The wire protocols of leglab.bus (Dynamixel Protocol 2.0, Feetech FT-SCS) and the servos'
control tables, against the manufacturers' documents: every example packet below is copied
byte for byte from the document and section named beside it, and the CRC is also checked
against a bitwise CRC-16 written here from its definition. Random packets (hypothesis) round
trip and a corrupted byte is always rejected. Pure Python, no serial port."""

import ast
import dataclasses
import pathlib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from leglab.bus import dynamixel as dxl
from leglab.bus import errors, tables
from leglab.bus import feetech as ft
from leglab.bus.errors import Packet, ProtocolError

SETTINGS = settings(max_examples=150, deadline=None, derandomize=True)

# ROBOTIS e-Manual, "DYNAMIXEL Protocol 2.0" (emanual.robotis.com/docs/en/dxl/protocol2/; source
# ROBOTIS-GIT/emanual/docs/en/dxl/protocol2.md), section "Instruction Details".
DXL_PING_1 = bytes.fromhex("FF FF FD 00 01 03 00 01 19 4E")  # Ping, Example 1
DXL_PING_BROADCAST = bytes.fromhex("FF FF FD 00 FE 03 00 01 31 42")  # Ping, Example 2
DXL_PING_STATUS_1 = bytes.fromhex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D")  # Ex. 1 and 2
DXL_PING_STATUS_2 = bytes.fromhex("FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D")  # Ping, Ex. 2
DXL_READ = bytes.fromhex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15")  # Read, Example
DXL_READ_STATUS = bytes.fromhex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0")  # Read
DXL_WRITE = bytes.fromhex("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89")  # Write, Example
DXL_EMPTY_STATUS = bytes.fromhex("FF FF FD 00 01 04 00 55 00 A1 0C")  # Write, Reg Write, Action
DXL_REG_WRITE = bytes.fromhex("FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E")  # Reg Write
DXL_ACTION = bytes.fromhex("FF FF FD 00 01 03 00 05 02 CE")  # Action, Example
DXL_FACTORY_RESET = bytes.fromhex("FF FF FD 00 01 04 00 06 01 A1 E6")  # Factory Reset, Example
DXL_REBOOT = bytes.fromhex("FF FF FD 00 01 03 00 08 2F 4E")  # Reboot, Example
DXL_CLEAR = bytes.fromhex("FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC")  # Clear, Example
DXL_SYNC_READ = bytes.fromhex("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA")  # Sync Read
DXL_SYNC_READ_STATUS_2 = bytes.fromhex("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE")
DXL_SYNC_WRITE = bytes.fromhex(  # Sync Write, Example
    "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87")
DXL_BULK_READ = bytes.fromhex(  # Bulk Read, Example
    "FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05")
DXL_BULK_READ_STATUS_1 = bytes.fromhex("FF FF FD 00 01 06 00 55 00 77 00 C3 69")
DXL_BULK_READ_STATUS_2 = bytes.fromhex("FF FF FD 00 02 05 00 55 00 24 8B A9")
DXL_BULK_WRITE = bytes.fromhex(  # Bulk Write, Example
    "FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00 02 1F 00 01 00 50 B7 68")
DXL_DOCUMENTED = [DXL_PING_1, DXL_PING_BROADCAST, DXL_PING_STATUS_1, DXL_PING_STATUS_2, DXL_READ,
                  DXL_READ_STATUS, DXL_WRITE, DXL_EMPTY_STATUS, DXL_REG_WRITE, DXL_ACTION,
                  DXL_FACTORY_RESET, DXL_REBOOT, DXL_CLEAR, DXL_SYNC_READ,
                  DXL_SYNC_READ_STATUS_2, DXL_SYNC_WRITE, DXL_BULK_READ, DXL_BULK_READ_STATUS_1,
                  DXL_BULK_READ_STATUS_2, DXL_BULK_WRITE]

# Feetech, "Servo SCS Communication Protocol" (FT-SCS), as transcribed in the manufacturer's wiki
# (github.com/ftservo/ftservo-wiki/docs/en/reference/protocol/ft-scs.md), section 4.
FT_PING = bytes.fromhex("FF FF 01 02 01 FB")  # 4.1 PING, Example 1
FT_EMPTY_STATUS = bytes.fromhex("FF FF 01 02 00 FC")  # 4.1 Example 1, 4.3 Example 4
FT_READ = bytes.fromhex("FF FF 01 04 02 38 02 BE")  # 4.2 READ DATA, Example 2
FT_READ_STATUS = bytes.fromhex("FF FF 01 04 00 18 05 DD")  # 4.2 Example 2 (position 1304)
FT_WRITE_ID = bytes.fromhex("FF FF FE 04 03 05 01 F4")  # 4.3 WRITE DATA, Example 3
FT_WRITE_GOAL = bytes.fromhex("FF FF 01 09 03 2A 00 08 00 00 E8 03 D5")  # 4.3 Example 4
FT_REG_WRITE_2 = bytes.fromhex("FF FF 02 09 04 2A 00 08 00 00 E8 03 D3")  # 4.4 Example 5, ID 2
FT_ACTION = bytes.fromhex("FF FF FE 02 05 FA")  # 4.5 ACTION, Example 6
FT_SYNC_WRITE = bytes.fromhex(  # 4.6 SYNC WRITE, Example 7
    "FF FF FE 20 83 2A 06 01 00 08 00 00 E8 03 02 00 08 00 00 E8 03"
    " 03 00 08 00 00 E8 03 04 00 08 00 00 E8 03 58")
FT_SYNC_READ = bytes.fromhex("FF FF FE 06 82 38 08 01 02 36")  # 4.7 SYNC READ, Example 8
FT_SYNC_READ_STATUS_1 = bytes.fromhex("FF FF 01 0A 00 00 08 00 00 00 00 79 1E 55")  # Example 8
FT_SYNC_READ_STATUS_2 = bytes.fromhex("FF FF 02 0A 00 FF 07 00 00 00 00 77 23 53")  # Example 8
FT_REBOOT = bytes.fromhex("FF FF 01 02 08 F4")  # 4.12 Restart instruction, Example 13
FT_DOCUMENTED = [FT_PING, FT_EMPTY_STATUS, FT_READ, FT_READ_STATUS, FT_WRITE_ID, FT_WRITE_GOAL,
                 FT_REG_WRITE_2, FT_ACTION, FT_SYNC_WRITE, FT_SYNC_READ, FT_SYNC_READ_STATUS_1,
                 FT_SYNC_READ_STATUS_2, FT_REBOOT]


def reference_crc(data: bytes) -> int:
    """CRC-16 from its definition, bit by bit: polynomial 0x8005 (x^16 + x^15 + x^2 + 1),
    initial value 0, most significant bit first, no final XOR (e-Manual "CRC Calculation")."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


# --- both modules -------------------------------------------------------------------------

API = ["NAME", "HEADER", "PREFIX_BYTES", "BROADCAST_ID", "PING", "READ", "WRITE", "SYNC_READ",
       "SYNC_WRITE", "STATUS", "REBOOT", "PING_REPORTS_MODEL", "frame_length",
       "encode_instruction", "encode_status", "decode", "ping", "read", "write", "sync_read",
       "sync_write", "parse_sync_read", "parse_sync_write", "error_text", "error_is_hardware",
       "hardware_error_text", "ping_status_params", "parse_ping_status", "reboot"]


@pytest.mark.parametrize("module", [errors, dxl, ft, tables])
def test_modules_import_only_the_standard_library_and_each_other(module):
    """No module of the protocol layer pulls in the compiled core, leglab.servo or pyserial."""
    tree = ast.parse(pathlib.Path(module.__file__).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            assert node.module in ("errors", "feetech"), node.module
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module]
            for name in names:
                assert name.split(".")[0] in ("collections", "dataclasses", "math", "types",
                                              "typing"), name


@pytest.mark.parametrize("module", [dxl, ft])
def test_both_protocols_offer_the_same_names(module):
    """The Bus code is protocol-agnostic: every shared name exists in both modules."""
    missing = [name for name in API if not hasattr(module, name)]
    assert not missing
    assert module.BROADCAST_ID == 0xFE
    assert issubclass(ProtocolError, ValueError)


# --- Dynamixel Protocol 2.0 ---------------------------------------------------------------

def test_dynamixel_constants_are_the_documented_ones():
    """e-Manual Protocol 2.0, "Instruction Packet" and "Instruction" tables."""
    assert dxl.HEADER == b"\xff\xff\xfd\x00" and dxl.PREFIX_BYTES == 7
    assert (dxl.PING, dxl.READ, dxl.WRITE, dxl.REG_WRITE, dxl.ACTION) == (1, 2, 3, 4, 5)
    assert (dxl.FACTORY_RESET, dxl.REBOOT, dxl.CLEAR, dxl.STATUS) == (6, 8, 0x10, 0x55)
    assert (dxl.SYNC_READ, dxl.SYNC_WRITE, dxl.BULK_READ, dxl.BULK_WRITE) == (
        0x82, 0x83, 0x92, 0x93)


@pytest.mark.parametrize("frame", DXL_DOCUMENTED, ids=lambda f: f.hex())
def test_dynamixel_crc_of_every_documented_packet(frame):
    """The last two bytes (CRC_L, CRC_H) are the CRC of all before them, by crc16 and by the
    bitwise reference."""
    assert dxl.crc16(frame[:-2]) == int.from_bytes(frame[-2:], "little")
    assert reference_crc(frame[:-2]) == dxl.crc16(frame[:-2])


def test_dynamixel_crc_check_value():
    """CRC-16/BUYPASS (alias CRC-16/UMTS) of ASCII "123456789" is 0xFEE8 (Greg Cook's
    "Catalogue of parametrised CRC algorithms", reveng.sourceforge.io/crc-catalogue)."""
    assert dxl.crc16(b"123456789") == 0xFEE8 == reference_crc(b"123456789")


@given(st.binary(max_size=300))
@SETTINGS
def test_dynamixel_crc_matches_the_bitwise_reference(data):
    """The table-driven CRC equals the bit-by-bit definition on any bytes."""
    assert dxl.crc16(data) == reference_crc(data)


def test_dynamixel_instruction_builders_produce_the_documented_packets():
    """Each builder against the e-Manual's example of its instruction."""
    assert dxl.ping(1) == DXL_PING_1
    assert dxl.ping(dxl.BROADCAST_ID) == DXL_PING_BROADCAST
    assert dxl.read(1, 132, 4) == DXL_READ
    assert dxl.write(1, 116, (512).to_bytes(4, "little")) == DXL_WRITE
    assert dxl.reboot(1) == DXL_REBOOT
    assert dxl.sync_read(132, 4, [1, 2]) == DXL_SYNC_READ
    assert dxl.sync_write(116, 4, {1: (150).to_bytes(4, "little"),
                                   2: (170).to_bytes(4, "little")}) == DXL_SYNC_WRITE
    assert dxl.bulk_read([(1, 144, 2), (2, 146, 1)]) == DXL_BULK_READ
    assert dxl.encode_instruction(1, dxl.REG_WRITE, bytes.fromhex("6800C8000000")) == DXL_REG_WRITE
    assert dxl.encode_instruction(1, dxl.ACTION) == DXL_ACTION
    assert dxl.encode_instruction(1, dxl.FACTORY_RESET, b"\x01") == DXL_FACTORY_RESET
    assert dxl.encode_instruction(1, dxl.CLEAR, bytes.fromhex("0144584C22")) == DXL_CLEAR
    assert dxl.encode_instruction(0xFE, dxl.BULK_WRITE, DXL_BULK_WRITE[8:-2]) == DXL_BULK_WRITE


def test_dynamixel_status_packets_encode_and_decode_as_documented():
    """The servos' replies in the e-Manual's examples, both ways."""
    ping = dxl.ping_status_params(1030, 38)  # XM430-W210: model 1030, firmware 38
    cases = [(DXL_PING_STATUS_1, 1, ping), (DXL_PING_STATUS_2, 2, ping),
             (DXL_READ_STATUS, 1, (166).to_bytes(4, "little")),
             (DXL_SYNC_READ_STATUS_2, 2, (2079).to_bytes(4, "little")),
             (DXL_EMPTY_STATUS, 1, b""),
             (DXL_BULK_READ_STATUS_1, 1, (119).to_bytes(2, "little")),
             (DXL_BULK_READ_STATUS_2, 2, bytes([36]))]
    for frame, id, params in cases:
        assert dxl.encode_status(id, 0, params) == frame
        assert dxl.decode(frame, status=True) == Packet(id, dxl.STATUS, 0, params)
    assert dxl.parse_ping_status(dxl.decode(DXL_PING_STATUS_1, True).params) == (1030, 38)


def test_dynamixel_decodes_the_documented_instructions():
    """decode(status=False) of the e-Manual's instruction packets, and the emulator's parsers."""
    assert dxl.decode(DXL_READ, status=False) == Packet(1, dxl.READ, 0, bytes.fromhex("84000400"))
    assert dxl.decode(DXL_PING_BROADCAST, False) == Packet(0xFE, dxl.PING, 0, b"")
    assert dxl.parse_sync_read(dxl.decode(DXL_SYNC_READ, False).params) == (132, 4, [1, 2])
    assert dxl.parse_sync_write(dxl.decode(DXL_SYNC_WRITE, False).params) == (
        116, 4, {1: bytes([150, 0, 0, 0]), 2: bytes([170, 0, 0, 0])})
    assert dxl.parse_bulk_read(dxl.decode(DXL_BULK_READ, False).params) == [
        (1, 144, 2), (2, 146, 1)]


def test_dynamixel_frame_length():
    """The size from the first 7 bytes: 7 + the length field; impossible prefixes refused."""
    assert dxl.frame_length(DXL_SYNC_WRITE[:7]) == len(DXL_SYNC_WRITE) == 7 + 0x11
    assert dxl.frame_length(DXL_PING_1) == 10
    for bad in (b"\xff\xff\xfd\x01\x01\x03\x00", b"\xff\xff\xfd\x00\x01\x02\x00",
                b"\xff\xff\xfd\x00\xff\x03\x00", b"\xff\xff\xfd\x00\x01"):
        with pytest.raises(ProtocolError):
            dxl.frame_length(bad)


def test_dynamixel_byte_stuffing_as_documented():
    """e-Manual Protocol 2.0, "Packet Process": FF FF FD becomes FF FF FD FD in the instruction
    and parameter fields; the length counts the stuffed bytes and the CRC covers them."""
    assert dxl.stuff(b"\xff\xff\xfd") == b"\xff\xff\xfd\xfd"
    assert dxl.stuff(b"\xff\xff\xfd\xfd") == b"\xff\xff\xfd\xfd\xfd"
    assert dxl.stuff(b"\xff\xfd\xff\xff\xff\xfd") == b"\xff\xfd\xff\xff\xff\xfd\xfd"
    frame = dxl.write(1, 0x0102, b"\xff\xff\xfd\x07")
    body = bytes.fromhex("FF FF FD 00 01 0A 00 03 02 01 FF FF FD FD 07")  # length 10: 8 + CRC
    assert frame == body + reference_crc(body).to_bytes(2, "little")
    assert dxl.decode(frame, False).params == b"\x02\x01\xff\xff\xfd\x07"
    with pytest.raises(ProtocolError):
        dxl.unstuff(b"\x03\xff\xff\xfd\x07")  # an unstuffed header pattern inside a packet


def test_dynamixel_error_byte_in_words():
    """e-Manual Protocol 2.0, "Status Packet" > "Error": bit 7 alert, bits 6..0 the number."""
    assert dxl.error_text(0) == ""
    assert dxl.error_text(0x03) == "CRC error"
    assert dxl.error_text(0x87) == "alert (hardware error), access error"
    assert dxl.error_is_hardware(0x80) and not dxl.error_is_hardware(0x07)
    # Hardware Error Status bits (e-Manual control table, "Shutdown"): 0x05 = voltage + heat.
    assert dxl.hardware_error_text(0x05) == "input voltage, overheating"


PATTERNS = st.sampled_from([b"\xff\xff\xfd", b"\xff\xff\xfd\xfd", b"\xff", b"\xfd", b"\x00"])
PARAMS = st.lists(st.one_of(PATTERNS, st.binary(max_size=6)), max_size=12).map(b"".join)


@given(st.integers(0, 252) | st.just(254), st.integers(0, 255).filter(lambda i: i != 0x55),
       PARAMS, st.data())
@SETTINGS
def test_dynamixel_instruction_round_trip_and_corruption(id, instruction, params, data):
    """decode(encode(x)) == x, with params full of header patterns; any one byte changed is
    rejected."""
    frame = dxl.encode_instruction(id, instruction, params)
    assert dxl.decode(frame, status=False) == Packet(id, instruction, 0, params)
    assert dxl.frame_length(frame[:7]) == len(frame)
    index, flip = data.draw(st.integers(0, len(frame) - 1)), data.draw(st.integers(1, 255))
    corrupted = bytearray(frame)
    corrupted[index] ^= flip
    with pytest.raises(ProtocolError):
        dxl.decode(bytes(corrupted), status=False)


@given(st.integers(0, 252), st.integers(0, 255), PARAMS)
@SETTINGS
def test_dynamixel_status_round_trip(id, error, params):
    """A status frame decodes to what was encoded, and is no instruction packet."""
    frame = dxl.encode_status(id, error, params)
    assert dxl.decode(frame, status=True) == Packet(id, dxl.STATUS, error, params)
    with pytest.raises(ProtocolError):
        dxl.decode(frame, status=False)


@given(PARAMS)
@SETTINGS
def test_dynamixel_stuffing_round_trip(body):
    """unstuff undoes stuff, and a stuffed body holds no FF FF FD that is not followed by FD."""
    stuffed = dxl.stuff(body)
    assert dxl.unstuff(stuffed) == body
    start = stuffed.find(b"\xff\xff\xfd")
    while start >= 0:
        assert stuffed[start + 3:start + 4] == b"\xfd"
        start = stuffed.find(b"\xff\xff\xfd", start + 4)


@given(st.integers(0, 0xFFFF), st.integers(1, 8),
       st.lists(st.integers(0, 252), min_size=1, max_size=10, unique=True), st.data())
@SETTINGS
def test_dynamixel_sync_round_trip(address, size, ids, data):
    """parse_sync_read/parse_sync_write give back what sync_read/sync_write were given."""
    frame = dxl.sync_read(address, size, ids)
    assert dxl.parse_sync_read(dxl.decode(frame, False).params) == (address, size, ids)
    payload = {id: data.draw(st.binary(min_size=size, max_size=size)) for id in ids}
    frame = dxl.sync_write(address, size, payload)
    assert dxl.parse_sync_write(dxl.decode(frame, False).params) == (address, size, payload)


def test_dynamixel_refuses_bad_arguments():
    """Values that do not fit their fields are ValueErrors, never wrong frames."""
    for call in (lambda: dxl.ping(253), lambda: dxl.read(1, 70000, 4),
                 lambda: dxl.write(1, 0, b""), lambda: dxl.sync_write(0, 4, {1: b"\x00"}),
                 lambda: dxl.sync_read(0, 4, [1, 1]),
                 lambda: dxl.encode_status(dxl.BROADCAST_ID, 0)):
        with pytest.raises(ValueError):
            call()


# --- Feetech FT-SCS -----------------------------------------------------------------------

def test_feetech_constants_are_the_documented_ones():
    """FT-SCS protocol, "2 Instruction frame" and "4 Instruction types"."""
    assert ft.HEADER == b"\xff\xff" and ft.PREFIX_BYTES == 4
    assert (ft.PING, ft.READ, ft.WRITE, ft.REG_WRITE, ft.ACTION) == (1, 2, 3, 4, 5)
    assert (ft.SYNC_READ, ft.SYNC_WRITE, ft.REBOOT, ft.RESET) == (0x82, 0x83, 0x08, 0x0A)


@pytest.mark.parametrize("frame", FT_DOCUMENTED, ids=lambda f: f.hex())
def test_feetech_checksum_of_every_documented_packet(frame):
    """The last byte is ~(id + length + instruction/status + params) & 0xFF."""
    assert ft.checksum(frame[2:-1]) == frame[-1]


def test_feetech_instruction_builders_produce_the_documented_packets():
    """Each builder against the FT-SCS protocol's example of its instruction."""
    goal = bytes.fromhex("0008 0000 E803")  # position 2048, time 0, speed 1000, low byte first
    assert ft.ping(1) == FT_PING
    assert ft.read(1, 0x38, 2) == FT_READ
    assert ft.write(ft.BROADCAST_ID, 5, b"\x01") == FT_WRITE_ID
    assert ft.write(1, 0x2A, goal) == FT_WRITE_GOAL
    assert ft.encode_instruction(2, ft.REG_WRITE, b"\x2a" + goal) == FT_REG_WRITE_2
    assert ft.encode_instruction(ft.BROADCAST_ID, ft.ACTION) == FT_ACTION
    assert ft.sync_write(0x2A, 6, {1: goal, 2: goal, 3: goal, 4: goal}) == FT_SYNC_WRITE
    assert ft.sync_read(0x38, 8, [1, 2]) == FT_SYNC_READ
    assert ft.reboot(1) == FT_REBOOT


def test_feetech_status_packets_encode_and_decode_as_documented():
    """The servos' replies in the FT-SCS examples; PING's reply carries no params."""
    cases = [(FT_EMPTY_STATUS, 1, b""), (FT_READ_STATUS, 1, b"\x18\x05"),
             (FT_SYNC_READ_STATUS_1, 1, bytes.fromhex("0008 0000 0000 791E")),
             (FT_SYNC_READ_STATUS_2, 2, bytes.fromhex("FF07 0000 0000 7723"))]
    for frame, id, params in cases:
        assert ft.encode_status(id, 0, params) == frame
        assert ft.decode(frame, status=True) == Packet(id, ft.STATUS, 0, params)
    assert ft.parse_ping_status(ft.decode(FT_EMPTY_STATUS, True).params) is None
    assert ft.ping_status_params(777, 3) == b""
    # Example 2: "the current position is 1304".
    item = tables.TABLES["sts3215"].item("present_position")
    assert tables.decode(item, ft.decode(FT_READ_STATUS, True).params) == 1304


def test_feetech_decodes_the_documented_instructions():
    """decode(status=False) of the FT-SCS instruction packets, and the emulator's parsers."""
    assert ft.decode(FT_READ, status=False) == Packet(1, ft.READ, 0, b"\x38\x02")
    assert ft.decode(FT_WRITE_ID, False) == Packet(0xFE, ft.WRITE, 0, b"\x05\x01")
    assert ft.parse_sync_read(ft.decode(FT_SYNC_READ, False).params) == (0x38, 8, [1, 2])
    goal = bytes.fromhex("0008 0000 E803")
    assert ft.parse_sync_write(ft.decode(FT_SYNC_WRITE, False).params) == (
        0x2A, 6, {1: goal, 2: goal, 3: goal, 4: goal})


def test_feetech_frame_length():
    """The size from the first 4 bytes: 4 + the length field; impossible prefixes refused."""
    assert ft.frame_length(FT_SYNC_WRITE[:4]) == len(FT_SYNC_WRITE) == 4 + 0x20
    for bad in (b"\xff\xfe\x01\x02", b"\xff\xff\x01\x01", b"\xff\xff\xff\x02", b"\xff\xff\x01"):
        with pytest.raises(ProtocolError):
            ft.frame_length(bad)


def test_feetech_status_byte_in_words():
    """STS memory table, "3.2 Servo Status": bit 0 voltage, 1 magnetic encoder, 2 temperature,
    3 current, 5 load; its example: over/under-voltage with overheating gives 4 + 1 = 5."""
    assert ft.error_text(0) == ""
    assert ft.error_text(5) == "voltage, temperature"
    assert ft.error_text(0x20) == "overload" and ft.error_is_hardware(0x20)
    assert ft.error_is_hardware(0x08) and not ft.error_is_hardware(0x10)


def test_sign_magnitude_documented_values():
    """STS memory table: position and speed have their direction in BIT15, load in BIT10, the
    position offset in bit 11 ("Bit11 is the direction bit", STS3215 memory table)."""
    assert ft.to_sign_magnitude(-1, 15) == 0x8001
    assert ft.from_sign_magnitude(0x8001, 15) == -1
    assert ft.to_sign_magnitude(2047, 15) == 0x07FF  # Example 8, ID 2's position FF 07
    assert ft.to_sign_magnitude(-1000, 10) == 0x0400 | 1000
    assert ft.to_sign_magnitude(-2047, 11) == 0x0FFF
    assert ft.from_sign_magnitude(0x8000, 15) == 0
    with pytest.raises(ValueError):
        ft.to_sign_magnitude(1024, 10)


@given(st.sampled_from([10, 11, 15]), st.data())
@SETTINGS
def test_sign_magnitude_round_trip(sign_bit, data):
    """from(to(v)) == v for every value the bits hold, and to(from(r)) == r for raw r."""
    limit = (1 << sign_bit) - 1
    value = data.draw(st.integers(-limit, limit))
    assert ft.from_sign_magnitude(ft.to_sign_magnitude(value, sign_bit), sign_bit) == value
    raw = data.draw(st.integers(0, (2 << sign_bit) - 1).filter(lambda r: r != 1 << sign_bit))
    assert ft.to_sign_magnitude(ft.from_sign_magnitude(raw, sign_bit), sign_bit) == raw


@given(st.integers(0, 253) | st.just(254), st.integers(0, 255), st.binary(max_size=60),
       st.data())
@SETTINGS
def test_feetech_round_trip_and_corruption(id, code, params, data):
    """decode(encode(x)) == x for instructions and status packets; any one byte changed is
    rejected."""
    frame = ft.encode_instruction(id, code, params)
    assert ft.decode(frame, status=False) == Packet(id, code, 0, params)
    if id != ft.BROADCAST_ID:
        assert ft.decode(ft.encode_status(id, code, params), True) == Packet(id, ft.STATUS,
                                                                             code, params)
    index, flip = data.draw(st.integers(0, len(frame) - 1)), data.draw(st.integers(1, 255))
    corrupted = bytearray(frame)
    corrupted[index] ^= flip
    with pytest.raises(ProtocolError):
        ft.decode(bytes(corrupted), status=False)


@given(st.integers(0, 255), st.integers(1, 8),
       st.lists(st.integers(0, 253), min_size=1, max_size=10, unique=True), st.data())
@SETTINGS
def test_feetech_sync_round_trip(address, size, ids, data):
    """parse_sync_read/parse_sync_write give back what sync_read/sync_write were given."""
    frame = ft.sync_read(address, size, ids)
    assert ft.parse_sync_read(ft.decode(frame, False).params) == (address, size, ids)
    payload = {id: data.draw(st.binary(min_size=size, max_size=size)) for id in ids}
    frame = ft.sync_write(address, size, payload)
    assert ft.parse_sync_write(ft.decode(frame, False).params) == (address, size, payload)


# --- control tables -----------------------------------------------------------------------

# (table, item, address, size, sign bit or None, default or None), from the documents:
# Dynamixel: e-Manual XL330-M288 / XL430-W250 pages, "Control Table of EEPROM/RAM Area".
# Feetech: STS3215 memory table (Feetech spreadsheet linked from lerobot) and STS memory table
# (ftservo-wiki/docs/en/reference/parameter/memory-sts.md) for the direction bits.
DOCUMENTED_ITEMS = [
    ("xl330-m288", "model_number", 0, 2, None, 1200),
    ("xl330-m288", "return_delay_time", 9, 1, None, 250),
    ("xl330-m288", "operating_mode", 11, 1, None, 3),
    ("xl330-m288", "hardware_error_status", 70, 1, None, 0),
    ("xl330-m288", "torque_enable", 64, 1, None, 0),
    ("xl330-m288", "position_p_gain", 84, 2, None, 400),
    ("xl330-m288", "profile_acceleration", 108, 4, None, 0),
    ("xl330-m288", "profile_velocity", 112, 4, None, 0),
    ("xl330-m288", "goal_position", 116, 4, None, None),
    ("xl330-m288", "present_current", 126, 2, None, None),
    ("xl330-m288", "present_position", 132, 4, None, None),
    ("xl330-m288", "present_input_voltage", 144, 2, None, None),
    ("xl330-m288", "present_temperature", 146, 1, None, None),
    ("xl430-w250", "model_number", 0, 2, None, 1060),
    ("xl430-w250", "return_delay_time", 9, 1, None, 250),
    ("xl430-w250", "temperature_limit", 31, 1, None, 72),
    ("xl430-w250", "position_d_gain", 80, 2, None, 4000),
    ("xl430-w250", "position_p_gain", 84, 2, None, 640),
    ("xl430-w250", "present_load", 126, 2, None, None),
    ("xl430-w250", "present_position", 132, 4, None, None),
    ("sts3215", "model_number", 3, 2, None, 777),
    ("sts3215", "return_delay_time", 7, 1, None, 0),
    ("sts3215", "position_p_gain", 21, 1, None, 32),
    ("sts3215", "position_d_gain", 22, 1, None, 32),
    ("sts3215", "position_i_gain", 23, 1, None, 0),
    ("sts3215", "position_offset", 31, 2, 11, 0),
    ("sts3215", "operating_mode", 33, 1, None, 0),
    ("sts3215", "torque_enable", 40, 1, None, 0),
    ("sts3215", "profile_acceleration", 41, 1, None, 0),
    ("sts3215", "goal_position", 42, 2, 15, None),
    ("sts3215", "profile_velocity", 46, 2, 15, None),
    ("sts3215", "lock", 55, 1, None, None),
    ("sts3215", "present_position", 56, 2, 15, None),
    ("sts3215", "present_velocity", 58, 2, 15, None),
    ("sts3215", "present_load", 60, 2, 10, None),
    ("sts3215", "present_input_voltage", 62, 1, None, None),
    ("sts3215", "present_temperature", 63, 1, None, None),
    ("sts3215", "hardware_error_status", 65, 1, None, None),
    ("sts3215", "moving", 66, 1, None, None),
    ("sts3215", "present_current", 69, 2, None, None),
    ("sts3250", "model_number", 3, 2, None, 2825),
]


@pytest.mark.parametrize("key,name,address,size,sign_bit,default", DOCUMENTED_ITEMS)
def test_documented_items(key, name, address, size, sign_bit, default):
    """Address, size, direction bit and default as the manufacturers' tables give them."""
    item = tables.TABLES[key].item(name)
    assert (item.address, item.size) == (address, size)
    if sign_bit is not None:
        assert (item.encoding, item.sign_bit) == ("sign_magnitude", sign_bit)
    if default is not None:
        assert item.default == default


def test_model_numbers_as_documented():
    """e-Manual: XL330-M288 1200, XL430-W250 1060 (Model Number(0) initial value). STS3215:
    servo main version 9 (address 3) and sub version 3 (address 4) in its memory table, read
    as one little-endian number 3 * 256 + 9 = 777; STS3250 2825 (lerobot's
    MODEL_NUMBER_TABLE, src/lerobot/motors/feetech/tables.py)."""
    expected = {"xl330-m288": ("dynamixel", 1200), "xl430-w250": ("dynamixel", 1060),
                "sts3215": ("feetech", 3 * 256 + 9), "sts3250": ("feetech", 2825)}
    for key, (protocol, number) in expected.items():
        table = tables.TABLES[key]
        assert (table.protocol, table.model_number) == (protocol, number)
        assert table.item("model_number").default == number
        assert tables.table_for(protocol, number) is table
        assert table.counts_per_rev == 4096
    assert tables.table_for("feetech", 1200) is None


@pytest.mark.parametrize("table", list(tables.TABLES.values()), ids=lambda t: t.key)
def test_items_do_not_overlap_and_defaults_fit(table):
    """Within a table no two registers share a byte (a declared alias is the same register
    under a second name), every default fits its register, and the names are the keys."""
    for alias, name in table.aliases.items():
        assert dataclasses.replace(table.items[alias], name=name) == table.items[name]
    items = sorted((i for n, i in table.items.items() if n not in table.aliases),
                   key=lambda i: i.address)
    for before, after in zip(items, items[1:]):
        assert before.address + before.size <= after.address, (before.name, after.name)
    for name, item in table.items.items():
        assert item.name == name and item.size in (1, 2, 4)
        assert item.access in ("R", "RW") and item.memory in ("EEPROM", "RAM")
        assert item.encoding in ("unsigned", "signed", "sign_magnitude")
        assert (item.sign_bit != 0) == (item.encoding == "sign_magnitude")
        tables.encode(item, item.default)


def test_the_names_the_package_uses_exist():
    """The items the rest of leglab.bus reads and writes, on every table."""
    common = ["model_number", "firmware_version", "id", "baud_rate", "return_delay_time",
              "operating_mode", "min_position_limit", "max_position_limit", "temperature_limit",
              "max_voltage_limit", "min_voltage_limit", "torque_enable",
              "hardware_error_status", "position_p_gain", "position_i_gain", "position_d_gain",
              "profile_acceleration", "profile_velocity", "goal_position", "present_load",
              "present_velocity", "present_position", "present_input_voltage",
              "present_temperature", "moving"]
    dynamixel = ["drive_mode", "pwm_limit", "led", "goal_pwm", "present_pwm", "homing_offset",
                 "velocity_limit"]
    feetech = ["torque_limit", "lock", "position_offset", "minimum_startup_force",
               "cw_dead_zone", "ccw_dead_zone", "present_current"]
    for table in tables.TABLES.values():
        for name in common + (dynamixel if table.protocol == "dynamixel" else feetech):
            table.item(name)
    tables.TABLES["xl330-m288"].item("present_current")


def test_units():
    """Worked conversions: 2048 counts are 180 deg; 0.229 rev/min is 1.374 deg/s; a return
    delay of 250 is 500 us (e-Manual, Return Delay Time); 0.1 V counts."""
    xl430, sts = tables.TABLES["xl430-w250"], tables.TABLES["sts3215"]
    assert tables.to_units(xl430.item("present_position"), 2048) == 180.0
    assert tables.to_units(sts.item("present_position"), 2048) == 180.0
    assert tables.to_units(xl430.item("present_velocity"), 1) == pytest.approx(1.374)
    assert tables.to_units(xl430.item("return_delay_time"), 250) == pytest.approx(500e-6)
    assert tables.to_units(sts.item("present_input_voltage"), 74) == pytest.approx(7.4)
    assert tables.from_units(sts.item("goal_position"), -90.0) == -1024
    assert tables.encode(sts.item("goal_position"), -1024) == bytes([0x00, 0x84])
    assert tables.encode(xl430.item("goal_position"), -1) == b"\xff\xff\xff\xff"
    # e-Manual Read example: Present Position bytes A6 00 00 00 are 166.
    assert tables.decode(xl430.item("present_position"), bytes.fromhex("A6000000")) == 166
    for bad in (float("nan"), 1e9):
        with pytest.raises(ValueError):
            tables.from_units(sts.item("goal_position"), bad)
    with pytest.raises(ValueError, match="sts3215"):
        sts.item("no_such_item")
    with pytest.raises(ValueError, match="goal_position"):
        tables.encode(sts.item("goal_position"), 40000)


ALL_ITEMS = [item for table in tables.TABLES.values() for item in table.items.values()]


@given(st.sampled_from(ALL_ITEMS), st.data())
@SETTINGS
def test_item_round_trips(item, data):
    """decode(encode(r)) == r and from_units(to_units(r)) == r for any raw value that fits."""
    low, high = tables.raw_range(item)
    raw = data.draw(st.integers(low, high))
    assert tables.decode(item, tables.encode(item, raw)) == raw
    assert tables.from_units(item, tables.to_units(item, raw)) == raw
