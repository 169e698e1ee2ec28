"""An emulated bus of servos that speaks Dynamixel Protocol 2.0 or Feetech STS byte for byte.

Each emulated servo is a control table in memory (`leglab.bus.tables`: the factory defaults,
the access rules) and a physical servo (`leglab.bus.physics`: a DC motor behind a gearbox with
friction, driven by the firmware's P law, swinging a pendulum), which leglab's own servo model
is not: a fit of leglab's model to its logs is a fit to physics it does not share.

The emulator is driven by time given to it: `Emulator.receive(data, now_s)` integrates the
physics up to `now_s`, answers the instructions in `data` and says when each reply goes out.
Two ways to run it:
- `VirtualPort`: in the same process, on a `VirtualClock` that advances by the bus's wire time,
  the servos' return delay, a reply's timeout and the loop's sleeps only: deterministic, the
  same bits on every run, as fast as the machine goes (the tests' and CI's way);
- `serve_pty`: on a pseudo-terminal in real time, for any program that opens a serial port.
"""

from __future__ import annotations

import collections
import math
import os
import random
import select
import time
import tty
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Optional

from . import physics, tables
from .bus import check_protocol, wire_time_s
from .errors import Packet, ProtocolError

HANG_COUNT = 2048
"""The position count at which an emulated load hangs still (180 deg on the servo's scale)."""

_DXL_ERRORS = {"result": 1, "instruction": 2, "crc": 3, "range": 4, "length": 5, "limit": 6,
               "access": 7}  # Protocol 2.0's error numbers (the status packet's bits 0-6)
_DXL_ALERT = 0x80
_OVERLOAD_BIT = 0x20  # hardware_error_status (Dynamixel) and status (Feetech): overload


@dataclass
class Faults:
    """Faults an emulator makes on demand, for tests.

    Rates are per reply, drawn from a random generator seeded with `seed` (the same faults on
    every run).

    Attributes
    ----------
    drop_rate : float
        A reply not sent.
    corrupt_rate : float
        A reply with one byte changed.
    silent_after_s : float
        From this time on, the servos in silent_ids answer nothing.
    silent_ids : tuple of int
        () with a finite silent_after_s: every servo.
    hardware_error_after_s : float
        From then on, an overload in every servo.
    seed : int
        The generator's seed.
    """

    drop_rate: float = 0.0         # a reply not sent
    corrupt_rate: float = 0.0      # a reply with one byte changed
    silent_after_s: float = math.inf  # from this time on, the servos in silent_ids answer nothing
    silent_ids: tuple[int, ...] = ()  # () with a finite silent_after_s: every servo
    hardware_error_after_s: float = math.inf  # from then on, an overload in every servo
    seed: int = 0

    def silent(self, servo_id: int, now_s: float) -> bool:
        """Whether a servo is silent.

        Parameters
        ----------
        servo_id : int
            The servo.
        now_s : float
            The emulator's time, s.

        Returns
        -------
        bool
            Whether it answers nothing at `now_s`.
        """
        return now_s >= self.silent_after_s and (not self.silent_ids or servo_id in self.silent_ids)


class EmulatedServo:
    """One servo: its control table's memory and its physics.

    Parameters
    ----------
    table : tables.ControlTable
        The servo's control table (tables.TABLES).
    spec : physics.MotorSpec
        Its motor (physics.SPECS).
    servo_id : int
        Its id.
    mass_kg, length_m : float
        The pendulum load (a point mass on an arm; 0 deg hanging down).
    kp : int, optional
        The gain register at power-on (None: the table's factory default).
    angle_deg : float, optional
        The load's angle from hanging at power-on.
    hang_count : int, optional
        The position count at which the load hangs (its encoder's mounting).
    """

    def __init__(self, table: tables.ControlTable, spec: physics.MotorSpec, servo_id: int,
                 mass_kg: float, length_m: float, kp: Optional[int] = None,
                 angle_deg: float = 0.0, hang_count: int = HANG_COUNT) -> None:
        self.table = table
        self.id = servo_id
        self.hang_count = hang_count
        size = max(it.address + it.size for it in table.items.values())
        self.memory = bytearray(size)
        for it in table.items.values():
            self.memory[it.address:it.address + it.size] = tables.encode(it, it.default)
        self.set("id", servo_id)
        if kp is not None:
            self.set("position_p_gain", kp)
        self.physics = physics.ServoPhysics(spec, mass_kg, length_m, math.radians(angle_deg))
        self._update_present(hardware_fault=False)
        # The firmware starts holding where the servo is, as both makers' servos do at power-on.
        self.set("goal_position", self.get("present_position"))
        self._profiled_goal = float(self.get("goal_position"))
        self._last_s = 0.0

    # ---- memory ----

    def get(self, name: str) -> int:
        """An item's raw value.

        Parameters
        ----------
        name : str
            The item.

        Returns
        -------
        int
            Its counts.
        """
        it = self.table.items[name]
        return tables.decode(it, bytes(self.memory[it.address:it.address + it.size]))

    def set(self, name: str, raw: int) -> None:
        """Sets an item, clamped to what the register holds.

        Parameters
        ----------
        name : str
            The item.
        raw : int
            Its counts.
        """
        it = self.table.items[name]
        low, high = _raw_range(it)
        raw = min(max(int(raw), low), high)
        self.memory[it.address:it.address + it.size] = tables.encode(it, raw)

    def _set_units(self, name: str, value: float) -> None:
        if name in self.table.items:
            it = self.table.items[name]
            self.set(name, round(value / it.scale))

    def read(self, address: int, size: int) -> bytes:
        """Bytes of the table's memory.

        Parameters
        ----------
        address, size : int
            Where and how many.

        Returns
        -------
        bytes
            `size` bytes from `address` (beyond the table: zeros).
        """
        data = bytes(self.memory[address:address + size])
        return data + bytes(size - len(data))

    def write(self, address: int, data: bytes) -> str:
        """Writes `data` at `address` as the firmware would.

        Parameters
        ----------
        address : int
            Where.
        data : bytes
            What.

        Returns
        -------
        str
            The error name of Protocol 2.0 ("access", "range", "limit") when refused, else ""
            (written).
        """
        end = address + len(data)
        touched = [it for it in self.table.items.values()
                   if it.address < end and address < it.address + it.size]
        if not touched:
            return "access"
        torque_on = self.get("torque_enable") != 0
        for it in touched:
            if it.access != "RW":
                return "access"
            if it.memory == "EEPROM" and torque_on and self.table.protocol == "dynamixel":
                return "access"  # Dynamixel X: the EEPROM area is locked while the torque is on
        new = bytearray(self.memory)
        new[address:end] = data
        names = [it.name for it in touched]
        if "goal_position" in names and not self._within_limits(new):
            return "limit"  # Dynamixel: data limit error; a goal beyond the limits is not taken
        if "torque_enable" in names:
            it = self.table.items["torque_enable"]
            if tables.decode(it, bytes(new[it.address:it.address + it.size])) not in (0, 1):
                return "range"
        self.memory[:] = new
        return ""

    def _within_limits(self, memory: bytearray) -> bool:
        """Whether Goal Position in `memory` is within the position limit registers (limits
        that hold no range, Feetech's multi-turn 0 and 0, take any goal)."""
        def value(name: str) -> int:
            it = self.table.items[name]
            return tables.decode(it, bytes(memory[it.address:it.address + it.size]))
        low, high = value("min_position_limit"), value("max_position_limit")
        return high <= low or low <= value("goal_position") <= high

    # ---- physics ----

    def return_delay_s(self) -> float:
        """The return delay register.

        Returns
        -------
        float
            The delay, s.
        """
        it = self.table.items["return_delay_time"]
        return tables.to_units(it, self.get("return_delay_time"))

    def advance(self, now_s: float, hardware_fault: bool = False) -> None:
        """Integrates the servo under its registers, then updates the present values (position
        quantised to counts).

        Parameters
        ----------
        now_s : float
            Up to when, s.
        hardware_fault : bool, optional
            An overload: the torque drops and the status says so.
        """
        dt = max(0.0, now_s - self._last_s)
        self._last_s = max(self._last_s, now_s)
        goal = self._goal(dt)
        on = self.get("torque_enable") != 0 and not hardware_fault
        self.physics.advance(now_s, goal if on else None, self.get("position_p_gain"),
                             self.hang_count)
        self._update_present(hardware_fault)

    def _goal(self, dt: float) -> int:
        """The goal the firmware steers to: Goal Position, reached at the profile velocity when
        that is not 0 (0: at once; the acceleration profile is not emulated)."""
        goal = float(self.get("goal_position"))
        if "profile_velocity" not in self.table.items or self.get("profile_velocity") == 0:
            self._profiled_goal = goal
        else:
            it = self.table.items["profile_velocity"]
            counts_per_s = tables.to_units(it, self.get("profile_velocity")) * 4096 / 360
            step = counts_per_s * dt
            self._profiled_goal += max(-step, min(step, goal - self._profiled_goal))
        return round(self._profiled_goal)

    def _update_present(self, hardware_fault: bool) -> None:
        p = self.physics
        count = p.position_count(self.hang_count)
        if self.table.protocol == "feetech":
            count %= 4096  # a single-turn encoder
        self.set("present_position", count)
        self._set_units("present_velocity", math.degrees(p.velocity_rad_s))
        self._set_units("present_current", p.current_a)
        self._set_units("present_load", 100.0 * p.load_fraction())
        self._set_units("present_pwm", 100.0 * p.duty)
        self._set_units("present_input_voltage", p.spec.voltage_v)
        self._set_units("present_temperature", 32.0)
        if "moving" in self.table.items:
            self.set("moving", 1 if abs(p.velocity_rad_s) > 0.02 else 0)
        self.set("hardware_error_status", _OVERLOAD_BIT if hardware_fault else 0)
        if hardware_fault:
            self.set("torque_enable", 0)  # both makers' firmware drops the torque on a fault


def _raw_range(item: tables.Item) -> tuple[int, int]:
    bits = 8 * item.size
    if item.encoding == "unsigned":
        return 0, (1 << bits) - 1
    if item.encoding == "signed":
        return -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    magnitude = (1 << item.sign_bit) - 1
    return -magnitude, magnitude


class Emulator:
    """Servos on one emulated bus.

    Parameters
    ----------
    protocol : {"dynamixel", "feetech"}
        What the bus speaks.
    servos : list of EmulatedServo
        With distinct ids, each with a table of `protocol`.
    baud : int, optional
        The bus's baud rate.
    faults : Faults, optional
        Faults to make (None: none).

    Raises
    ------
    TypeError
        `protocol` not a str.
    ValueError
        An unknown protocol, two servos of one id, a servo of another protocol.
    """

    def __init__(self, protocol: str, servos: list[EmulatedServo], baud: int = 1_000_000,
                 faults: Optional[Faults] = None) -> None:
        self.protocol = check_protocol(protocol)
        self.baud = baud
        self.servos = {s.id: s for s in servos}
        if len(self.servos) != len(servos):
            raise ValueError("emulator: two servos have the same id")
        for s in servos:
            if s.table.protocol != protocol:
                raise ValueError(f"emulator: servo {s.id} is a {s.table.model}, which speaks "
                                 f"{s.table.protocol}, not {protocol}")
        self.faults = faults or Faults()
        self._random = random.Random(self.faults.seed)
        self._buffer = bytearray()
        self.now_s = 0.0
        self.instructions = 0  # whole instruction packets received

    def advance(self, now_s: float) -> None:
        """Integrates every servo's physics.

        Parameters
        ----------
        now_s : float
            Up to when, s.
        """
        self.now_s = max(self.now_s, now_s)
        fault = self.now_s >= self.faults.hardware_error_after_s
        for servo in self.servos.values():
            servo.advance(self.now_s, hardware_fault=fault)

    def receive(self, data: bytes, now_s: float) -> list[tuple[float, bytes]]:
        """Takes bytes from the bus and answers the whole instructions among them.

        Parameters
        ----------
        data : bytes
            What came on the bus.
        now_s : float
            When, s (the servos are integrated up to then).

        Returns
        -------
        list of (float, bytes)
            The replies, [(delay_s, frame)], each delay from the end of the instruction to the
            start of its reply (return delays and the replies before it on the wire).
        """
        self.advance(now_s)
        self._buffer += data
        replies: list[tuple[float, bytes]] = []
        for frame in self._frames():
            replies += self._answer(frame)
        return replies

    def _frames(self) -> Iterator[bytes]:
        """Whole frames at the buffer's start; bytes before a header are line noise, dropped."""
        header, need = self.protocol.HEADER, self.protocol.PREFIX_BYTES
        while True:
            start = self._buffer.find(header)
            if start < 0:
                del self._buffer[:max(0, len(self._buffer) - len(header) + 1)]
                return
            del self._buffer[:start]
            if len(self._buffer) < need:
                return
            try:
                total = self.protocol.frame_length(bytes(self._buffer[:need]))
            except ProtocolError:
                del self._buffer[:1]
                continue
            if len(self._buffer) < total:
                return
            frame = bytes(self._buffer[:total])
            del self._buffer[:total]
            yield frame

    def _answer(self, frame: bytes) -> list[tuple[float, bytes]]:
        p = self.protocol
        try:
            packet: Packet = p.decode(frame, status=False)
        except ProtocolError:
            return []  # a servo ignores a packet it cannot trust
        self.instructions += 1
        if packet.instruction == p.SYNC_READ:
            address, size, ids = p.parse_sync_read(packet.params)
            return self._replies([(i, p.encode_status(i, self._status_error(i),
                                                      self.servos[i].read(address, size)))
                                  for i in ids if i in self.servos])
        if packet.instruction == p.SYNC_WRITE:
            address, size, data_by_id = p.parse_sync_write(packet.params)
            for i, data in data_by_id.items():
                if i in self.servos and not self._silent(i):
                    self.servos[i].write(address, data)
            return []
        targets = (sorted(self.servos) if packet.id == p.BROADCAST_ID
                   else [packet.id] if packet.id in self.servos else [])
        answers = [(i, self._single(i, packet)) for i in targets]
        if packet.id == p.BROADCAST_ID and packet.instruction != p.PING:
            return []  # only a broadcast PING is answered
        return self._replies([(i, frame) for i, frame in answers if frame is not None])

    def _single(self, servo_id: int, packet: Packet) -> Optional[bytes]:
        """The status frame servo `servo_id` sends for `packet` (None: no reply)."""
        p, servo = self.protocol, self.servos[servo_id]
        if packet.instruction == p.PING:
            params = b""
            if p.NAME == "dynamixel":
                params = (servo.table.model_number.to_bytes(2, "little")
                          + bytes([servo.table.firmware_version]))
            status: bytes = p.encode_status(servo_id, self._status_error(servo_id), params)
            return status
        if packet.instruction == p.READ:
            address, size = _read_params(p.NAME, packet.params)
            return p.encode_status(servo_id, self._status_error(servo_id),
                                   servo.read(address, size))
        if packet.instruction == p.WRITE:
            address, data = _write_params(p.NAME, packet.params)
            refused = servo.write(address, data)
            error = self._status_error(servo_id)
            if refused and p.NAME == "dynamixel":
                error |= _DXL_ERRORS[refused]
            return p.encode_status(servo_id, error, b"")
        if p.NAME == "dynamixel":
            return p.encode_status(servo_id, self._status_error(servo_id) | _DXL_ERRORS[
                "instruction"], b"")
        return None

    def _status_error(self, servo_id: int) -> int:
        hardware = self.servos[servo_id].get("hardware_error_status")
        if not hardware:
            return 0
        return _DXL_ALERT if self.protocol.NAME == "dynamixel" else hardware

    def _silent(self, servo_id: int) -> bool:
        return self.faults.silent(servo_id, self.now_s)

    def _replies(self, frames: list[tuple[int, bytes]]) -> list[tuple[float, bytes]]:
        """[(delay_s, frame)] for replies sent one after another, each after its servo's return
        delay; faults applied."""
        out: list[tuple[float, bytes]] = []
        delay = 0.0
        for servo_id, frame in frames:
            if self._silent(servo_id):
                continue
            delay += self.servos[servo_id].return_delay_s()
            if self._random.random() < self.faults.drop_rate:
                continue  # dropped: the next servo still waits its turn (no wire time taken)
            if self._random.random() < self.faults.corrupt_rate:
                frame = _corrupted(frame, self._random)
            out.append((delay, frame))
            delay += wire_time_s(len(frame), self.baud)
        return out


def _read_params(protocol: str, params: bytes) -> tuple[int, int]:
    if protocol == "dynamixel":
        return int.from_bytes(params[0:2], "little"), int.from_bytes(params[2:4], "little")
    return params[0], params[1]


def _write_params(protocol: str, params: bytes) -> tuple[int, bytes]:
    if protocol == "dynamixel":
        return int.from_bytes(params[0:2], "little"), bytes(params[2:])
    return params[0], bytes(params[1:])


def _corrupted(frame: bytes, rng: random.Random) -> bytes:
    """`frame` with one byte after the header changed (a noisy line)."""
    data = bytearray(frame)
    at = rng.randrange(2, len(data))
    data[at] ^= 1 << rng.randrange(8)
    return bytes(data)


def make_emulator(protocol: str, model: str, ids: list[int], mass_kg: float, length_m: float,
                  kp: Optional[int] = None, baud: int = 1_000_000,
                  faults: Optional[Faults] = None, angle_deg: float = 0.0,
                  loads: Optional[dict[int, tuple[float, float]]] = None,
                  hang_count: int = HANG_COUNT) -> Emulator:
    """An emulated bus of servos of one model.

    Parameters
    ----------
    protocol : {"dynamixel", "feetech"}
        What the bus speaks.
    model : str
        A key of tables.TABLES and physics.SPECS ("xl330-m288", ...).
    ids : list of int
        The servos' ids.
    mass_kg, length_m : float
        Each servo's pendulum load.
    kp : int, optional
        The gain register at power-on (None: the factory default).
    baud : int, optional
        The bus's baud rate.
    faults : Faults, optional
        Faults to make.
    angle_deg : float, optional
        The loads' angle from hanging at power-on.
    loads : dict, optional
        {id: (mass_kg, length_m)} gives some servos their own load.
    hang_count : int, optional
        The position count at which a load hangs.

    Returns
    -------
    Emulator
        The bus.

    Raises
    ------
    TypeError
        `protocol` or `model` not a str.
    ValueError
        An unknown protocol or model, ids that repeat, a model of another protocol.
    """
    if not isinstance(model, str):
        raise TypeError(f"model: expected a str, got {type(model).__name__}")
    if model not in tables.TABLES or model not in physics.SPECS:
        known = ", ".join(k for k in tables.TABLES if k in physics.SPECS)
        raise ValueError(f"unknown servo model {model!r} (valid: {known})")
    loads = loads or {}
    servos = [EmulatedServo(tables.TABLES[model], physics.SPECS[model], i,
                            *loads.get(i, (mass_kg, length_m)), kp=kp, angle_deg=angle_deg,
                            hang_count=hang_count)
              for i in ids]
    return Emulator(protocol, servos, baud, faults)


# ---- in the same process, on virtual time ----

class VirtualClock:
    """Time that passes only when told to: the emulator's wire and delays, the loop's sleeps.

    Parameters
    ----------
    start_s : float, optional
        The time it starts at, s.
    """

    def __init__(self, start_s: float = 0.0) -> None:
        self._now = start_s

    def now(self) -> float:
        """The time.

        Returns
        -------
        float
            Seconds since the clock's start.
        """
        return self._now

    def sleep(self, seconds: float) -> None:
        """Passes time.

        Parameters
        ----------
        seconds : float
            How long (nothing when not positive).
        """
        if seconds > 0:
            self._now += seconds

    def advance_to(self, t_s: float) -> None:
        """Passes time up to a moment.

        Parameters
        ----------
        t_s : float
            The moment, s (nothing when that is past).
        """
        self._now = max(self._now, t_s)


class RealClock:
    """The machine's monotonic clock; sleep() wakes within tens of microseconds of the time
    asked (the last 0.3 ms waited in a loop, as a tick needs)."""

    def now(self) -> float:
        """The time.

        Returns
        -------
        float
            Monotonic seconds.
        """
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        """Waits.

        Parameters
        ----------
        seconds : float
            How long.
        """
        end = time.monotonic() + seconds
        if seconds > 0.0003:
            time.sleep(seconds - 0.0003)
        while time.monotonic() < end:
            pass


@dataclass
class VirtualPort:
    """The emulator behind pyserial's calls (write, read, reset_input_buffer, close, timeout).

    On a VirtualClock: each byte takes its wire time, a missing reply its timeout.

    Parameters
    ----------
    emulator : Emulator
        The servos.
    clock : VirtualClock
        The time.
    name : str, optional
        The port's name, for messages.
    timeout : float, optional
        The read timeout, s.
    """

    emulator: Emulator
    clock: VirtualClock
    name: str = "emulator"
    timeout: float = 0.02
    _incoming: collections.deque[tuple[float, int]] = field(default_factory=collections.deque)

    def write(self, data: bytes) -> int:
        """Sends bytes; the emulator answers when the last byte is in.

        Parameters
        ----------
        data : bytes
            What to send.

        Returns
        -------
        int
            The bytes sent.
        """
        baud = self.emulator.baud
        end = self.clock.now() + wire_time_s(len(data), baud)
        self.clock.advance_to(end)
        byte_s = wire_time_s(1, baud)
        for delay, frame in self.emulator.receive(bytes(data), end):
            start = max(end + delay, self._incoming[-1][0] if self._incoming else 0.0)
            self._incoming.extend((start + (i + 1) * byte_s, b) for i, b in enumerate(frame))
        return len(data)

    def read(self, count: int) -> bytes:
        """Reads bytes.

        Parameters
        ----------
        count : int
            How many.

        Returns
        -------
        bytes
            All of them when they arrive within the timeout (the clock then at the last one's
            arrival), else those that did (the clock at the timeout).
        """
        deadline = self.clock.now() + self.timeout
        out = bytearray()
        last = self.clock.now()
        while self._incoming and len(out) < count and self._incoming[0][0] <= deadline:
            last, byte = self._incoming.popleft()
            out.append(byte)
        self.clock.advance_to(last if len(out) == count else deadline)
        return bytes(out)

    def reset_input_buffer(self) -> None:
        """Drops the bytes that have arrived."""
        now = self.clock.now()
        while self._incoming and self._incoming[0][0] <= now:
            self._incoming.popleft()

    def close(self) -> None:
        """Nothing to close."""


# ---- on a pseudo-terminal, in real time ----

def serve_pty(emulator: Emulator, on_ready: Callable[[str], object],
              should_stop: Callable[[], bool] = lambda: False,
              link: Optional[str] = None) -> None:
    """Serves an emulator on a new pseudo-terminal in real time.

    Replies go out when they would have arrived on a real bus at the emulator's baud (the
    instruction's and the reply's wire time and the return delays).

    Parameters
    ----------
    emulator : Emulator
        The servos.
    on_ready : callable
        Called with the terminal's path (open it as the servos' port).
    should_stop : callable, optional
        Serving ends when it returns True.
    link : str, optional
        A new path to make a symbolic link to the terminal at, removed at the end.

    Raises
    ------
    FileExistsError
        Something is at `link`.
    """
    master, slave = os.openpty()
    tty.setraw(slave)  # bytes as they are: no echo, no line editing
    path = os.ttyname(slave)
    if link:
        os.symlink(path, link)
    on_ready(path)
    start = time.monotonic()
    pending: list[tuple[float, bytes]] = []  # [(send_at_s, frame)], in order
    try:
        while not should_stop():
            now = time.monotonic() - start
            wait = 0.002 if not pending else max(0.0, min(0.002, pending[0][0] - now))
            ready, _, _ = select.select([master], [], [], wait)
            now = time.monotonic() - start
            if ready:
                data = os.read(master, 4096)
                end = now + wire_time_s(len(data), emulator.baud)
                for delay, frame in emulator.receive(data, now):
                    at = end + delay + wire_time_s(len(frame), emulator.baud)
                    pending.append((max(at, pending[-1][0] if pending else 0.0), frame))
            else:
                emulator.advance(now)
            while pending and pending[0][0] <= time.monotonic() - start:
                os.write(master, pending.pop(0)[1])
    finally:
        os.close(master)
        os.close(slave)
        if link and os.path.islink(link):
            os.unlink(link)
