"""A serial bus of servos: instructions out, status packets back, items by name.

`Bus` speaks one protocol (`dynamixel`: Protocol 2.0; `feetech`: STS/SMS) on one port, at one
baud rate. Items are named as the control tables in `leglab.bus.tables` name them and read and
written in leglab's units (degrees on the servo's own 0-360 scale, seconds, volts, degrees C);
`read_raw`/`write_raw` take the register's counts. A reply that is missing or corrupt is asked
for again, at most `retries` times (each counted in `Bus.stats`); after that a `BusError` names
the port, the servo and the item in one line.
"""

import errno
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from . import dynamixel, feetech, tables
from .errors import ProtocolError

PROTOCOLS = {"dynamixel": dynamixel, "feetech": feetech}
"""The protocols a Bus speaks, by name."""

MAX_ID = 252
"""The highest servo id on both protocols (253 and up are reserved, 254 is broadcast)."""

BAUD_RATES = (9600, 19200, 38400, 57600, 115200, 500000, 1000000, 2000000, 3000000, 4000000)
"""Baud rates a Bus accepts (those both protocols' servos offer, the adapters' common ones)."""

_GARBAGE_BYTES = 64  # bytes skipped while looking for a reply's header before it counts as corrupt
_STALE_REPLIES = 2 * (MAX_ID + 1)  # other servos' late replies dropped while waiting for one
_STALE_LIMIT = object()  # _skip_stale's "too many"


class BusError(Exception):
    """A servo that did not answer, answered with an error, or a port that failed: one line
    naming the port, the servo id and the item."""


class NoReply(BusError):
    """A servo that gave no valid reply after every retry."""


class HardwareError(BusError):
    """A servo that reports a hardware fault (its status packets' alert or error bits)."""


@dataclass
class BusStats:
    """What a Bus has sent and retried since it was opened (or since `reset`)."""

    instructions: int = 0  # instruction packets sent, retries included
    retries: int = 0       # instructions sent again after a missing or corrupt reply
    missing: int = 0       # replies that did not come within the timeout
    corrupt: int = 0       # replies with a bad header, length or checksum
    stale: int = 0         # late replies to an earlier instruction, dropped
    errors: int = 0        # instructions that failed after every retry

    def reset(self) -> None:
        """Counts from zero again."""
        self.instructions = self.retries = self.missing = self.corrupt = self.stale = 0
        self.errors = 0


@dataclass(frozen=True)
class ServoInfo:
    """A servo found on the bus: its id, model number, firmware and control table (None when
    leglab has no table for its model number)."""

    id: int
    model_number: int
    firmware_version: int
    table: "tables.ControlTable | None"
    error: str = ""  # the PING reply's error byte in words ("" when clear)


def check_protocol(name: str) -> ModuleType:
    """The protocol module of `name`; ValueError listing the valid names otherwise."""
    if name not in PROTOCOLS:
        raise ValueError(f"unknown protocol {name!r} (valid: {', '.join(PROTOCOLS)})")
    return PROTOCOLS[name]


def wire_time_s(byte_count: int, baud: int) -> float:
    """Seconds `byte_count` bytes take on a UART at `baud` (10 bits a byte: start, 8, stop)."""
    return byte_count * 10.0 / baud


def _open_serial(port, baud, timeout_s):
    import serial  # pyserial: imported here so that the emulator and protocols need none

    if not os.path.exists(port):
        raise BusError(f"port {port}: no such device (is the adapter plugged in? "
                       "`ls /dev/serial/by-id/` lists the USB ones)")
    try:
        return serial.Serial(port, baudrate=baud, timeout=timeout_s, write_timeout=1.0,
                             exclusive=True)
    except (serial.SerialException, OSError, ValueError) as e:
        reason = getattr(e, "strerror", None) or first_line(e)
        raise BusError(f"port {port}: cannot be opened: {reason}") from None


class Bus:
    """Servos on one serial port, by id and item name. A context manager: the port is closed
    on leaving it.

    port: a device path (opened with pyserial, exclusively), or an object with pyserial's
        `write`, `read`, `reset_input_buffer`, `close`, `timeout` and `name` (such as the
        emulator's VirtualPort).
    protocol: "dynamixel" or "feetech".
    baud: the bus's baud rate (the servos' own setting; 1 Mbaud is both makers' default).
    timeout_s: how long a reply is waited for; on a USB adapter add its latency timer.
    retries: how many times an instruction is sent again after a missing or corrupt reply.
    """

    def __init__(self, port: "str | os.PathLike | Any", protocol: str, baud: int = 1_000_000,
                 timeout_s: float = 0.02, retries: int = 2) -> None:
        self.protocol = check_protocol(protocol)
        if baud not in BAUD_RATES:
            raise ValueError(f"baud {baud!r} is not one of {', '.join(map(str, BAUD_RATES))}")
        if not (isinstance(timeout_s, (int, float)) and 0 < timeout_s <= 10):
            raise ValueError(f"timeout_s must be in (0, 10] s, got {timeout_s!r}")
        if not (isinstance(retries, int) and 0 <= retries <= 100):
            raise ValueError(f"retries must be an integer in [0, 100], got {retries!r}")
        self.baud = baud
        self.retries = retries
        self.stats = BusStats()
        self.torque_on = set()  # ids this Bus has turned the torque on in, and not off since
        self._tables = {}
        if isinstance(port, (str, os.PathLike)):
            self.port_name = os.fspath(port)
            self._port = _open_serial(self.port_name, baud, timeout_s)
        else:
            self.port_name = getattr(port, "name", "port")
            self._port = port
            self._port.timeout = timeout_s

    # ---- context and port ----

    def __enter__(self) -> "Bus":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Closes the port (again: nothing)."""
        if self._port is not None:
            try:
                self._port.close()
            finally:
                self._port = None

    @property
    def timeout_s(self) -> float:
        """How long a reply is waited for, s."""
        return self._port.timeout

    @timeout_s.setter
    def timeout_s(self, value: float) -> None:
        self._port_call("__setattr__", "timeout", value)

    # ---- the servos' tables ----

    def table(self, servo_id: int) -> tables.ControlTable:
        """The control table of `servo_id`, from its model number (asked once, then kept)."""
        if servo_id not in self._tables:
            info = self.ping(servo_id)
            if info.table is None:
                raise BusError(f"port {self.port_name}: servo {servo_id} is model number "
                               f"{info.model_number}, which leglab has no control table for "
                               f"(known: {_known_models(self.protocol.NAME)})")
            self._tables[servo_id] = info.table
        return self._tables[servo_id]

    def set_table(self, servo_id: int, table: tables.ControlTable) -> None:
        """Takes `table` as servo `servo_id`'s without asking it (a servo known in advance)."""
        self._tables[servo_id] = table

    # ---- instructions ----

    def ping(self, servo_id: int, retries: "int | None" = None) -> ServoInfo:
        """The ServoInfo of `servo_id`; NoReply if it does not answer. A servo that reports a
        hardware error still answers: its ServoInfo.error says what."""
        _check_id(servo_id)
        (reply,) = self._transact(self.protocol.ping(servo_id), [servo_id], "PING", retries,
                                  check=False)
        error = self.protocol.error_text(reply.error)
        if self.protocol.NAME == "dynamixel":
            model = int.from_bytes(reply.params[0:2], "little")
            firmware = reply.params[2] if len(reply.params) > 2 else 0
        else:  # Feetech's PING has no parameters: the model is a register
            model_item = _feetech_item("model_number")
            firmware_item = _feetech_item("firmware_version")
            (reply,) = self._transact(
                self.protocol.read(servo_id, model_item.address, model_item.size), [servo_id],
                "read model_number", retries, check=False)
            model = tables.decode(model_item, reply.params)
            (reply,) = self._transact(
                self.protocol.read(servo_id, firmware_item.address, firmware_item.size),
                [servo_id], "read firmware_version", retries, check=False)
            firmware = tables.decode(firmware_item, reply.params)
        return ServoInfo(servo_id, model, firmware, tables.table_for(self.protocol.NAME, model),
                         error)

    def scan(self, ids: Iterable[int] = range(0, MAX_ID + 1),
             timeout_s: "float | None" = None) -> list[ServoInfo]:
        """ServoInfo of every servo in `ids` that answers a PING (each asked once, no retry)."""
        saved = self.timeout_s
        if timeout_s is not None:
            self.timeout_s = timeout_s
        found = []
        try:
            for servo_id in ids:
                try:
                    info = self.ping(servo_id, retries=0)
                except NoReply:
                    continue
                found.append(info)
                if info.table is not None:
                    self._tables[servo_id] = info.table
        finally:
            self.timeout_s = saved
            self.stats.missing = 0  # absent ids are not a fault of the bus
        return found

    def read_raw(self, servo_id: int, item: str) -> int:
        """Item `item` of servo `servo_id` as the register holds it (an int)."""
        it = self.table(servo_id).item(item)
        (reply,) = self._transact(self.protocol.read(servo_id, it.address, it.size), [servo_id],
                                  f"read {item}", size=it.size)
        return tables.decode(it, reply.params)

    def read(self, servo_id: int, item: str) -> float:
        """Item `item` of servo `servo_id`, in leglab's units (tables.to_units)."""
        it = self.table(servo_id).item(item)
        return tables.to_units(it, self.read_raw(servo_id, item))

    def write_raw(self, servo_id: int, item: str, raw: int, check: bool = True) -> None:
        """Writes `raw` (register counts) to item `item` of servo `servo_id`. check=False: a
        hardware alert or error in the reply is not raised (the write was answered)."""
        it = self.table(servo_id).item(item)
        self._transact(self.protocol.write(servo_id, it.address, tables.encode(it, raw)),
                       [servo_id], f"write {item}", check=check)
        self._note_torque(item, {servo_id: raw})

    def write(self, servo_id: int, item: str, value: float) -> None:
        """Writes `value` (leglab's units) to item `item` of servo `servo_id`."""
        it = self.table(servo_id).item(item)
        self.write_raw(servo_id, item, tables.from_units(it, value))

    def sync_read_raw(self, ids: Iterable[int], item: str) -> dict[int, int]:
        """{id: raw} of `item` on every servo of `ids`, in one SYNC_READ (one reply each)."""
        ids = list(ids)
        it = self._common_item(ids, item)
        replies = self._transact(self.protocol.sync_read(it.address, it.size, ids), ids,
                                 f"sync read {item}", size=it.size)
        return {r.id: tables.decode(it, r.params) for r in replies}

    def sync_read(self, ids: Iterable[int], item: str) -> dict[int, float]:
        """{id: value} of `item` (leglab's units) on every servo of `ids`, in one SYNC_READ."""
        it = self._common_item(list(ids), item)
        return {i: tables.to_units(it, raw) for i, raw in self.sync_read_raw(ids, item).items()}

    def sync_write_raw(self, item: str, raw_by_id: Mapping[int, int]) -> None:
        """Writes {id: raw} to `item` in one SYNC_WRITE (no reply: the servos answer none)."""
        it = self._common_item(list(raw_by_id), item)
        frame = self.protocol.sync_write(
            it.address, it.size, {i: tables.encode(it, raw) for i, raw in raw_by_id.items()})
        self._send(frame, f"sync write {item}")
        self._note_torque(item, raw_by_id)

    def sync_write(self, item: str, value_by_id: Mapping[int, float]) -> None:
        """Writes {id: value} (leglab's units) to `item` in one SYNC_WRITE."""
        it = self._common_item(list(value_by_id), item)
        self.sync_write_raw(item, {i: tables.from_units(it, v) for i, v in value_by_id.items()})

    def _note_torque(self, item, raw_by_id):
        """Keeps torque_on: the servos whose torque this Bus has turned on (a sync write, which
        is not answered, counted as done)."""
        if item == "torque_enable":
            for servo_id, raw in raw_by_id.items():
                (self.torque_on.add if raw else self.torque_on.discard)(servo_id)

    # ---- the wire ----

    def _common_item(self, ids, item):
        """The item `item` of the servos `ids`, which a sync instruction needs at one address."""
        if not ids:
            raise ValueError(f"{item}: no servo ids given")
        found = {self.table(i).item(item) for i in ids}
        first = self.table(ids[0]).item(item)
        if any((f.address, f.size) != (first.address, first.size) for f in found):
            raise BusError(f"port {self.port_name}: {item} is not at one address on servos "
                           f"{', '.join(map(str, ids))}: read them one at a time")
        return first

    def _port_call(self, method, *args):
        """The port's `method`(*args); a failure of the port (unplugged, closed, its driver's
        error) is a BusError naming it."""
        if self._port is None:
            raise BusError(f"port {self.port_name}: closed")
        try:
            return getattr(self._port, method)(*args)
        except OSError as e:
            raise BusError(f"port {self.port_name}: lost: "
                           f"{e.strerror or errno.errorcode.get(e.errno, e)}") from None
        except Exception as e:  # pyserial's SerialException, termios.error
            raise BusError(f"port {self.port_name}: lost: {first_line(e)}") from None

    def _send(self, frame, what):
        self.stats.instructions += 1
        self._port_call("write", frame)

    def _read_exact(self, count):
        return self._port_call("read", count)

    def _read_status(self):
        """One status packet from the port, or None (nothing within the timeout), or raises
        ProtocolError (bytes that are not a valid packet)."""
        header = self.protocol.HEADER
        need = self.protocol.PREFIX_BYTES
        buf = self._read_exact(need)
        if not buf:
            return None
        skipped = 0
        while not buf.startswith(header):
            if len(buf) < need:
                raise ProtocolError("a reply cut short")
            skipped += 1
            if skipped > _GARBAGE_BYTES:
                raise ProtocolError("no packet header in the reply")
            buf = buf[1:] + self._read_exact(1)
        total = self.protocol.frame_length(buf)
        rest = self._read_exact(total - len(buf))
        if len(rest) != total - len(buf):
            raise ProtocolError("a reply cut short")
        return self.protocol.decode(bytes(buf + rest), status=True)

    def _transact(self, frame, ids, what, retries=None, check=True, size=None):
        """Sends `frame` and reads one status packet from each of `ids`, in order. A missing or
        corrupt reply (or, with `size`, one whose data is not `size` bytes: an earlier read's,
        late) sends it again (at most `retries` times). With `check`, an instruction the servo
        refuses raises BusError at once, and a hardware alert HardwareError."""
        retries = self.retries if retries is None else retries
        problem = ""
        for attempt in range(retries + 1):
            if attempt:
                self.stats.retries += 1
            self._port_call("reset_input_buffer")
            self._send(frame, what)
            replies, problem, bad_id = [], "", ids[0]
            for servo_id in ids:
                bad_id = servo_id
                try:
                    reply = self._read_status()
                    if reply is not None and reply.id != servo_id:
                        reply = self._skip_stale(reply, servo_id)
                except ProtocolError as e:
                    self.stats.corrupt += 1
                    problem = f"gave a corrupt reply ({e})"
                    break
                if reply is None:
                    self.stats.missing += 1
                    problem = "did not answer"
                    break
                if reply is _STALE_LIMIT:
                    self.stats.corrupt += 1
                    problem = "was drowned by replies of other servos"
                    break
                if size is not None and len(reply.params) != size and not reply.error:
                    self.stats.corrupt += 1
                    problem = f"gave {len(reply.params)} bytes where {size} were asked"
                    break
                replies.append(reply)
            if not problem:
                for reply in replies:
                    if check:
                        self._check_status(reply, what)
                return replies
        self.stats.errors += 1
        tries = f"{retries + 1} {'try' if retries == 0 else 'tries'}"
        raise NoReply(f"port {self.port_name}: servo {bad_id} {problem} to {what} ({tries})")

    def _skip_stale(self, reply, servo_id):
        """The next reply from `servo_id` after `reply`, another servo's: a reply that came
        after its instruction's timeout (one master on the bus: no other reply is for us), so
        dropped and counted. None on a timeout, _STALE_LIMIT after too many; ProtocolError as
        _read_status."""
        for _ in range(_STALE_REPLIES):
            self.stats.stale += 1
            reply = self._read_status()
            if reply is None or reply.id == servo_id:
                return reply
        return _STALE_LIMIT

    def _check_status(self, reply, what):
        if not reply.error:
            return
        text = self.protocol.error_text(reply.error)
        if self.protocol.error_is_hardware(reply.error):
            raise HardwareError(f"port {self.port_name}: servo {reply.id} reports a hardware "
                                f"error ({self._hardware_error(reply.id) or text}) at {what}")
        raise BusError(f"port {self.port_name}: servo {reply.id} refused to {what}: {text}")

    def _hardware_error(self, servo_id):
        """The servo's hardware error register in words ("" when it cannot be read)."""
        table = self._tables.get(servo_id)
        if table is None or "hardware_error_status" not in table.items:
            return ""
        it = table.items["hardware_error_status"]
        try:
            (reply,) = self._transact(self.protocol.read(servo_id, it.address, it.size),
                                      [servo_id], "read hardware_error_status", check=False)
        except BusError:
            return ""
        return self.protocol.hardware_error_text(tables.decode(it, reply.params))


def _check_id(servo_id):
    if isinstance(servo_id, bool) or not isinstance(servo_id, int) or not 0 <= servo_id <= MAX_ID:
        raise ValueError(f"servo id must be an integer in [0, {MAX_ID}], got {servo_id!r}")


def _feetech_item(name):
    table = next(t for t in tables.TABLES.values() if t.protocol == "feetech")
    return table.item(name)


def _known_models(protocol):
    return ", ".join(f"{t.model} ({t.model_number})" for t in tables.TABLES.values()
                     if t.protocol == protocol)


def first_line(error: BaseException) -> str:
    """An exception's message in one line (its type's name when it has none)."""
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__

