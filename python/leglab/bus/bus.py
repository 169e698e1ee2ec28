"""A serial bus of servos: instructions out, status packets back, items by name.

`Bus` speaks one protocol (`dynamixel`: Protocol 2.0; `feetech`: STS/SMS) on one port, at one
baud rate. Items are named as the control tables in `leglab.bus.tables` name them and read and
written in leglab's units (degrees on the servo's own 0-360 scale, seconds, volts, degrees C);
`read_raw`/`write_raw` take the register's counts. A reply that is missing or corrupt is asked
for again, at most `retries` times (each counted in `Bus.stats`); after that a `BusError` names
the port, the servo and the item in one line.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Optional, Union

from . import dynamixel, feetech, tables
from .errors import Packet, ProtocolError

PROTOCOLS: dict[str, ModuleType] = {"dynamixel": dynamixel, "feetech": feetech}
"""The protocols a Bus speaks, by name."""

MAX_ID = 252
"""The highest servo id on both protocols (253 and up are reserved, 254 is broadcast)."""

BAUD_RATES = (9600, 19200, 38400, 57600, 115200, 500000, 1000000, 2000000, 3000000, 4000000)
"""Baud rates a Bus accepts (those both protocols' servos offer, the adapters' common ones)."""

_GARBAGE_BYTES = 64  # bytes skipped while looking for a reply's header before it counts as corrupt
_STALE_REPLIES = 2 * (MAX_ID + 1)  # other servos' late replies dropped while waiting for one
_STALE_LIMIT = object()  # _skip_stale's "too many"


class BusError(Exception):
    """A servo that did not answer, answered with an error, or a port that failed.

    Its message is one line naming the port, the servo id and the item.
    """


class NoReply(BusError):
    """A servo that gave no valid reply after every retry."""


class HardwareError(BusError):
    """A servo that reports a hardware fault (its status packets' alert or error bits)."""


@dataclass
class BusStats:
    """What a Bus has sent and retried since it was opened (or since `reset`).

    Attributes
    ----------
    instructions : int
        Instruction packets sent, retries included.
    retries : int
        Instructions sent again after a missing or corrupt reply.
    missing : int
        Replies that did not come within the timeout.
    corrupt : int
        Replies with a bad header, length or checksum.
    stale : int
        Late replies to an earlier instruction, dropped.
    errors : int
        Instructions that failed after every retry.
    """

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
    """A servo found on the bus.

    Attributes
    ----------
    id : int
        Its id.
    model_number : int
        Its model number.
    firmware_version : int
        Its firmware.
    table : tables.ControlTable or None
        Its control table (None when leglab has no table for its model number).
    error : str
        The PING reply's error byte in words ("" when clear).
    """

    id: int
    model_number: int
    firmware_version: int
    table: "tables.ControlTable | None"
    error: str = ""  # the PING reply's error byte in words ("" when clear)


def check_protocol(name: str) -> ModuleType:
    """The protocol module of `name`.

    Parameters
    ----------
    name : {"dynamixel", "feetech"}
        The protocol.

    Returns
    -------
    module
        leglab.bus.dynamixel or leglab.bus.feetech.

    Raises
    ------
    TypeError
        `name` not a str.
    ValueError
        An unknown protocol, listing the valid names.
    """
    if not isinstance(name, str):
        raise TypeError(f"protocol: expected a str ({', '.join(PROTOCOLS)}), got "
                        f"{type(name).__name__}")
    if name not in PROTOCOLS:
        raise ValueError(f"unknown protocol {name!r} (valid: {', '.join(PROTOCOLS)})")
    return PROTOCOLS[name]


def wire_time_s(byte_count: int, baud: int) -> float:
    """Seconds `byte_count` bytes take on a UART at `baud` (10 bits a byte: start, 8, stop).

    Parameters
    ----------
    byte_count : int
        The bytes sent.
    baud : int
        The baud rate.

    Returns
    -------
    float
        The time on the wire, s.
    """
    return byte_count * 10.0 / baud


def _open_serial(port: str, baud: int, timeout_s: float) -> Any:
    # pyserial (untyped): imported here so that the emulator and protocols need none.
    import serial

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
    """Servos on one serial port, by id and item name.

    A context manager: the port is closed on leaving it.

    Parameters
    ----------
    port : str, os.PathLike or port object
        A device path (opened with pyserial, exclusively), or an object with pyserial's
        `write`, `read`, `reset_input_buffer`, `close`, `timeout` and `name` (such as the
        emulator's VirtualPort).
    protocol : {"dynamixel", "feetech"}
        The servos' protocol.
    baud : int, optional
        The bus's baud rate, one of BAUD_RATES (the servos' own setting; 1 Mbaud is both
        makers' default).
    timeout_s : float, optional
        How long a reply is waited for, in (0, 10] s; on a USB adapter add its latency timer.
    retries : int, optional
        How many times (0 to 100) an instruction is sent again after a missing or corrupt
        reply.

    Attributes
    ----------
    stats : BusStats
        What it has sent and retried.
    torque_on : set of int
        The ids this Bus has turned the torque on in, and not off since.
    port_name : str
        The port, for messages.

    Raises
    ------
    TypeError
        An argument of the wrong type (bool is not an integer).
    ValueError
        An unknown protocol, a baud rate not in BAUD_RATES, `timeout_s` or `retries` out of
        range.
    BusError
        The port cannot be opened.
    """

    def __init__(self, port: Union[str, os.PathLike[str], Any], protocol: str,
                 baud: int = 1_000_000, timeout_s: float = 0.02, retries: int = 2) -> None:
        self.protocol = check_protocol(protocol)
        if isinstance(baud, bool) or not isinstance(baud, int):
            raise TypeError(f"baud: expected an integer, got {type(baud).__name__}")
        if baud not in BAUD_RATES:
            raise ValueError(f"baud {baud!r} is not one of {', '.join(map(str, BAUD_RATES))}")
        if isinstance(timeout_s, bool) or not isinstance(timeout_s, (int, float)):
            raise TypeError(f"timeout_s: expected a number, got {type(timeout_s).__name__}")
        if not 0 < timeout_s <= 10:
            raise ValueError(f"timeout_s must be in (0, 10] s, got {timeout_s!r}")
        if isinstance(retries, bool) or not isinstance(retries, int):
            raise TypeError(f"retries: expected an integer, got {type(retries).__name__}")
        if not 0 <= retries <= 100:
            raise ValueError(f"retries must be an integer in [0, 100], got {retries!r}")
        self.baud = baud
        self.retries = retries
        self.stats = BusStats()
        self.torque_on: set[int] = set()  # ids it turned the torque on in, and not off since
        self._tables: dict[int, tables.ControlTable] = {}
        self.port_name: str
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
        """Closes the port (again: nothing).

        Raises
        ------
        Exception
            What the port's close raises.
        """
        if self._port is not None:
            try:
                self._port.close()
            finally:
                self._port = None

    @property
    def timeout_s(self) -> float:
        """How long a reply is waited for, s."""
        return float(self._port.timeout)

    @timeout_s.setter
    def timeout_s(self, value: float) -> None:
        self._port_call("__setattr__", "timeout", value)

    # ---- the servos' tables ----

    def table(self, servo_id: int) -> tables.ControlTable:
        """The control table of a servo, from its model number (asked once, then kept).

        Parameters
        ----------
        servo_id : int
            The servo, 0 to MAX_ID.

        Returns
        -------
        tables.ControlTable
            Its table.

        Raises
        ------
        TypeError
            `servo_id` not an integer.
        ValueError
            `servo_id` out of range.
        BusError
            No table for its model; NoReply when it does not answer.
        """
        if servo_id not in self._tables:
            info = self.ping(servo_id)
            if info.table is None:
                raise BusError(f"port {self.port_name}: servo {servo_id} is model number "
                               f"{info.model_number}, which leglab has no control table for "
                               f"(known: {_known_models(self.protocol.NAME)})")
            self._tables[servo_id] = info.table
        return self._tables[servo_id]

    def set_table(self, servo_id: int, table: tables.ControlTable) -> None:
        """Takes `table` as a servo's without asking it (a servo known in advance).

        Parameters
        ----------
        servo_id : int
            The servo.
        table : tables.ControlTable
            Its table.
        """
        self._tables[servo_id] = table

    # ---- instructions ----

    def ping(self, servo_id: int, retries: Optional[int] = None) -> ServoInfo:
        """What a servo says it is.

        A servo that reports a hardware error still answers: its ServoInfo.error says what.

        Parameters
        ----------
        servo_id : int
            The servo, 0 to MAX_ID.
        retries : int, optional
            Retries of this instruction (None: the Bus's).

        Returns
        -------
        ServoInfo
            Its id, model number, firmware and table.

        Raises
        ------
        TypeError
            `servo_id` not an integer.
        ValueError
            `servo_id` out of range.
        NoReply
            It does not answer.
        """
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
             timeout_s: Optional[float] = None) -> list[ServoInfo]:
        """The servos that answer a PING (each asked once, no retry).

        Parameters
        ----------
        ids : iterable of int, optional
            The ids to ask (default: all).
        timeout_s : float, optional
            The reply timeout while scanning (None: the Bus's).

        Returns
        -------
        list of ServoInfo
            One for each servo that answered.

        Raises
        ------
        TypeError
            An id not an integer.
        ValueError
            An id out of range.
        BusError
            The port failed.
        """
        saved = self.timeout_s
        if timeout_s is not None:
            self.timeout_s = timeout_s
        found: list[ServoInfo] = []
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
        """An item of a servo as the register holds it.

        Parameters
        ----------
        servo_id : int
            The servo.
        item : str
            The item's name in the servo's control table.

        Returns
        -------
        int
            The register's counts.

        Raises
        ------
        ValueError
            An item the servo's table lacks.
        BusError
            The servo refused or did not answer (NoReply), or reports a hardware fault
            (HardwareError).
        """
        it = self.table(servo_id).item(item)
        (reply,) = self._transact(self.protocol.read(servo_id, it.address, it.size), [servo_id],
                                  f"read {item}", size=it.size)
        return tables.decode(it, reply.params)

    def read(self, servo_id: int, item: str) -> float:
        """An item of a servo, in leglab's units (tables.to_units).

        Parameters
        ----------
        servo_id : int
            The servo.
        item : str
            The item's name in the servo's control table.

        Returns
        -------
        float
            The value, in the item's unit (deg, deg/s, V, C, s, ...).

        Raises
        ------
        ValueError
            An item the servo's table lacks.
        BusError
            As read_raw.
        """
        it = self.table(servo_id).item(item)
        return tables.to_units(it, self.read_raw(servo_id, item))

    def write_raw(self, servo_id: int, item: str, raw: int, check: bool = True) -> None:
        """Writes register counts to an item of a servo.

        Parameters
        ----------
        servo_id : int
            The servo.
        item : str
            The item's name in the servo's control table.
        raw : int
            The counts.
        check : bool, optional
            False: a hardware alert or error in the reply is not raised (the write was
            answered).

        Raises
        ------
        ValueError
            An item the servo's table lacks, counts that do not fit it.
        BusError
            As read_raw.
        """
        it = self.table(servo_id).item(item)
        self._transact(self.protocol.write(servo_id, it.address, tables.encode(it, raw)),
                       [servo_id], f"write {item}", check=check)
        self._note_torque(item, {servo_id: raw})

    def write(self, servo_id: int, item: str, value: float) -> None:
        """Writes a value in leglab's units to an item of a servo.

        Parameters
        ----------
        servo_id : int
            The servo.
        item : str
            The item's name in the servo's control table.
        value : float
            The value, in the item's unit.

        Raises
        ------
        TypeError
            `value` not a number.
        ValueError
            An item the servo's table lacks; a value not finite or out of the item's range.
        BusError
            As read_raw.
        """
        it = self.table(servo_id).item(item)
        self.write_raw(servo_id, item, tables.from_units(it, value))

    def sync_read_raw(self, ids: Iterable[int], item: str) -> dict[int, int]:
        """An item of several servos as their registers hold it, in one SYNC_READ.

        Parameters
        ----------
        ids : iterable of int
            The servos (one reply each).
        item : str
            The item's name, at one address on all of them.

        Returns
        -------
        dict of int to int
            {id: counts}.

        Raises
        ------
        ValueError
            No ids, an item a table lacks.
        BusError
            As read_raw; the item at different addresses.
        """
        ids = list(ids)
        it = self._common_item(ids, item)
        replies = self._transact(self.protocol.sync_read(it.address, it.size, ids), ids,
                                 f"sync read {item}", size=it.size)
        return {r.id: tables.decode(it, r.params) for r in replies}

    def sync_read(self, ids: Iterable[int], item: str) -> dict[int, float]:
        """An item of several servos, in leglab's units, in one SYNC_READ.

        Parameters
        ----------
        ids : iterable of int
            The servos.
        item : str
            The item's name, at one address on all of them.

        Returns
        -------
        dict of int to float
            {id: value}.

        Raises
        ------
        ValueError, BusError
            As sync_read_raw.
        """
        ids = list(ids)
        it = self._common_item(ids, item)
        return {i: tables.to_units(it, raw) for i, raw in self.sync_read_raw(ids, item).items()}

    def sync_write_raw(self, item: str, raw_by_id: Mapping[int, int]) -> None:
        """Writes register counts to an item of several servos, in one SYNC_WRITE.

        The servos answer none.

        Parameters
        ----------
        item : str
            The item's name, at one address on all of them.
        raw_by_id : mapping of int to int
            {id: counts}.

        Raises
        ------
        ValueError
            No ids, an item a table lacks, counts that do not fit.
        BusError
            The port failed; the item at different addresses.
        """
        it = self._common_item(list(raw_by_id), item)
        frame = self.protocol.sync_write(
            it.address, it.size, {i: tables.encode(it, raw) for i, raw in raw_by_id.items()})
        self._send(frame, f"sync write {item}")
        self._note_torque(item, raw_by_id)

    def sync_write(self, item: str, value_by_id: Mapping[int, float]) -> None:
        """Writes values in leglab's units to an item of several servos, in one SYNC_WRITE.

        Parameters
        ----------
        item : str
            The item's name, at one address on all of them.
        value_by_id : mapping of int to float
            {id: value}.

        Raises
        ------
        TypeError
            A value not a number.
        ValueError, BusError
            As sync_write_raw; a value not finite or out of range.
        """
        it = self._common_item(list(value_by_id), item)
        self.sync_write_raw(item, {i: tables.from_units(it, v) for i, v in value_by_id.items()})

    def _note_torque(self, item: str, raw_by_id: Mapping[int, int]) -> None:
        """Keeps torque_on: the servos whose torque this Bus has turned on (a sync write, which
        is not answered, counted as done)."""
        if item == "torque_enable":
            for servo_id, raw in raw_by_id.items():
                (self.torque_on.add if raw else self.torque_on.discard)(servo_id)

    # ---- the wire ----

    def _common_item(self, ids: list[int], item: str) -> tables.Item:
        """The item `item` of the servos `ids`, which a sync instruction needs at one address."""
        if not ids:
            raise ValueError(f"{item}: no servo ids given")
        found = {self.table(i).item(item) for i in ids}
        first = self.table(ids[0]).item(item)
        if any((f.address, f.size) != (first.address, first.size) for f in found):
            raise BusError(f"port {self.port_name}: {item} is not at one address on servos "
                           f"{', '.join(map(str, ids))}: read them one at a time")
        return first

    def _port_call(self, method: str, *args: Any) -> Any:
        """The port's `method`(*args); a failure of the port (unplugged, closed, its driver's
        error) is a BusError naming it."""
        if self._port is None:
            raise BusError(f"port {self.port_name}: closed")
        try:
            return getattr(self._port, method)(*args)
        except OSError as e:
            raise BusError(f"port {self.port_name}: lost: "
                           f"{e.strerror or errno.errorcode.get(e.errno or 0, str(e))}") from None
        except Exception as e:  # pyserial's SerialException, termios.error
            raise BusError(f"port {self.port_name}: lost: {first_line(e)}") from None

    def _send(self, frame: bytes, what: str) -> None:
        self.stats.instructions += 1
        self._port_call("write", frame)

    def _read_exact(self, count: int) -> bytes:
        return bytes(self._port_call("read", count))

    def _read_status(self) -> Optional[Packet]:
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
        packet: Packet = self.protocol.decode(bytes(buf + rest), status=True)
        return packet

    def _transact(self, frame: bytes, ids: list[int], what: str, retries: Optional[int] = None,
                  check: bool = True, size: Optional[int] = None) -> list[Packet]:
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
            replies: list[Packet] = []
            problem, bad_id = "", ids[0]
            for servo_id in ids:
                bad_id = servo_id
                reply: Union[Packet, None, object]
                try:
                    reply = self._read_status()
                    if reply is not None and reply.id != servo_id:
                        reply = self._skip_stale(servo_id)
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
                assert isinstance(reply, Packet)
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

    def _skip_stale(self, servo_id: int) -> Union[Packet, None, object]:
        """The next reply from `servo_id` after another servo's: a reply that came after its
        instruction's timeout (one master on the bus: no other reply is for us), so dropped and
        counted. None on a timeout, _STALE_LIMIT after too many; ProtocolError as
        _read_status."""
        for _ in range(_STALE_REPLIES):
            self.stats.stale += 1
            reply = self._read_status()
            if reply is None or reply.id == servo_id:
                return reply
        return _STALE_LIMIT

    def _check_status(self, reply: Packet, what: str) -> None:
        if not reply.error:
            return
        text = self.protocol.error_text(reply.error)
        if self.protocol.error_is_hardware(reply.error):
            raise HardwareError(f"port {self.port_name}: servo {reply.id} reports a hardware "
                                f"error ({self._hardware_error(reply.id) or text}) at {what}")
        raise BusError(f"port {self.port_name}: servo {reply.id} refused to {what}: {text}")

    def _hardware_error(self, servo_id: int) -> str:
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
        text: str = self.protocol.hardware_error_text(tables.decode(it, reply.params))
        return text


def _check_id(servo_id: object) -> None:
    """TypeError unless `servo_id` is an integer (bool is not), ValueError unless it is in
    [0, MAX_ID]."""
    if isinstance(servo_id, bool) or not isinstance(servo_id, int):
        raise TypeError(f"servo id: expected an integer in [0, {MAX_ID}], got "
                        f"{type(servo_id).__name__}")
    if not 0 <= servo_id <= MAX_ID:
        raise ValueError(f"servo id must be an integer in [0, {MAX_ID}], got {servo_id!r}")


def _feetech_item(name: str) -> tables.Item:
    table = next(t for t in tables.TABLES.values() if t.protocol == "feetech")
    return table.item(name)


def _known_models(protocol: str) -> str:
    return ", ".join(f"{t.model} ({t.model_number})" for t in tables.TABLES.values()
                     if t.protocol == protocol)


def first_line(error: BaseException) -> str:
    """An exception's message in one line.

    Parameters
    ----------
    error : BaseException
        The exception.

    Returns
    -------
    str
        The first line of its message (its type's name when it has none).
    """
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__

