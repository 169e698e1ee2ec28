"""The servos' control tables as data: where each register is, how wide, how its bytes encode a
number, what one count means, and its factory default (an emulator's initial memory).

Items carry leglab's names, shared across protocols where the meaning is the same (a Feetech
"running speed" is profile_velocity, its "status" hardware_error_status). Conversions to
leglab's units are raw * scale: positions in degrees on the servo's own 0..360 scale (counts *
360 / 4096, no offset), speeds in deg/s, accelerations in deg/s^2, voltages in V, temperatures
in C, currents in A, times in s, loads and PWM in %.

Sources. Dynamixel: ROBOTIS e-Manual control tables (emanual.robotis.com/docs/en/dxl/x/
xl330-m288/ and .../xl430-w250/, "Control Table of EEPROM Area" / "of RAM Area"). Feetech:
the STS3215 memory table (Feetech's spreadsheet, as linked from lerobot's feetech/tables.py) for
defaults, and Feetech's STS memory table (github.com/ftservo/ftservo-wiki,
docs/en/reference/parameter/memory-sts.md) for direction bits and status bits; where they
disagree the choice is noted at the item.
"""

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Optional

from .feetech import from_sign_magnitude, to_sign_magnitude

COUNTS_PER_REV = 4096
DEG_PER_COUNT = 360.0 / COUNTS_PER_REV


@dataclass(frozen=True)
class Item:
    """One register of a control table.

    Attributes
    ----------
    name : str
        leglab's name (shared across protocols where the meaning is the same).
    address, size : int
        Where it is and how many bytes (1, 2 or 4), little endian.
    encoding : str
        "unsigned", "signed" (two's complement) or "sign_magnitude".
    sign_bit : int
        For sign_magnitude, the bit holding the sign (15, 11 or 10); otherwise 0.
    unit : str
        What one raw count is, in the manufacturer's words.
    scale : float
        leglab units per raw count.
    leglab_unit : str
        The unit of raw * scale ("" for plain numbers).
    access : str
        "R" or "RW".
    memory : str
        "EEPROM" or "RAM".
    default : int
        The raw factory default (0 for present values and undocumented goals).
    """

    name: str
    address: int
    size: int
    encoding: str
    sign_bit: int
    unit: str
    scale: float
    leglab_unit: str
    access: str
    memory: str
    default: int


@dataclass(frozen=True)
class ControlTable:
    """One servo model's control table.

    Attributes
    ----------
    key : str
        leglab's key ("xl330-m288", "xl430-w250", "sts3215", "sts3250").
    model : str
        The manufacturer's model name.
    protocol : str
        "dynamixel" or "feetech".
    model_number : int
        What the servo reports (Dynamixel: PING and address 0; Feetech: address 3).
    firmware_version : int
        A plausible current firmware number, for an emulator.
    counts_per_rev : int
        Encoder counts per output revolution.
    items : mapping of str to Item
        The registers by leglab name.
    aliases : mapping of str to str
        {name: other name} for the items that are another name of the same register.
    """

    key: str
    model: str
    protocol: str
    model_number: int
    firmware_version: int
    counts_per_rev: int
    items: Mapping[str, Item] = field(repr=False)
    aliases: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}), repr=False)

    def item(self, name: str) -> Item:
        """An item by name.

        Parameters
        ----------
        name : str
            leglab's name of the item.

        Returns
        -------
        Item
            The register.

        Raises
        ------
        TypeError
            `name` not a str.
        ValueError
            No such item, naming the table and the valid names.
        """
        if not isinstance(name, str):
            raise TypeError(f"item: expected a str (an item's name), got {type(name).__name__}")
        try:
            return self.items[name]
        except KeyError:
            raise ValueError(f"{self.key} has no item {name!r}; it has: "
                             f"{', '.join(sorted(self.items))}") from None


# Units: (the manufacturer's words, leglab units per count, leglab unit).
PLAIN = ("", 1.0, "")
DXL_POSITION = ("1 pulse (0.088 deg)", DEG_PER_COUNT, "deg")
DXL_VELOCITY = ("0.229 rev/min", 0.229 * 360 / 60, "deg/s")
# Velocity-based profile (Drive Mode bit 2 clear, the default); time-based: 1 ms per count.
DXL_ACCELERATION = ("214.577 rev/min^2", 214.577 * 360 / 3600, "deg/s^2")
DXL_PWM = ("0.113 %", 0.113, "%")
DXL_LOAD = ("0.1 %", 0.1, "%")
MILLIAMP = ("1 mA", 0.001, "A")
DECIVOLT = ("0.1 V", 0.1, "V")
CELSIUS = ("1 C", 1.0, "C")
TWO_MICROSECONDS = ("2 us", 2e-6, "s")
MILLISECOND = ("1 ms", 0.001, "s")
TWENTY_MS = ("20 ms", 0.02, "s")
STS_POSITION = ("1 step (0.087 deg)", DEG_PER_COUNT, "deg")
# Phase bit 2 set (as shipped: phase 12) selects 1 step/s = 0.0146 rev/min; clear, 50 step/s.
STS_SPEED = ("1 step/s (0.0146 rev/min)", DEG_PER_COUNT, "deg/s")
STS_ACCELERATION = ("100 step/s^2 (8.7 deg/s^2)", 100 * DEG_PER_COUNT, "deg/s^2")
PERMILLE = ("0.1 %", 0.1, "%")
PERCENT = ("1 %", 1.0, "%")
STS_CURRENT = ("6.5 mA", 0.0065, "A")
TEN_MS = ("10 ms", 0.01, "s")


def _table(key: str, model: str, protocol: str, identity: tuple[int, int], eeprom_end: int,
           rows: Iterable[tuple[Any, ...]], variant: int,
           aliases: Optional[dict[str, str]] = None) -> ControlTable:
    """A ControlTable of model number and firmware `identity`, from rows (name, address, size,
    access, default, encoding, unit); its items come in address order. A default given as a
    tuple holds one value per model sharing the rows; `variant` picks this model's. Encoding is
    "u", "s" (two's complement) or an int: the sign bit of sign-magnitude. Addresses below
    `eeprom_end` are EEPROM."""
    items: dict[str, Item] = {}
    for name, address, size, access, default, encoding, (unit, scale, leglab_unit) in sorted(
            rows, key=lambda row: row[1]):
        kind = {"u": "unsigned", "s": "signed"}.get(encoding, "sign_magnitude")
        items[name] = Item(name, address, size, kind, encoding if isinstance(encoding, int) else 0,
                           unit, scale, leglab_unit, access,
                           "EEPROM" if address < eeprom_end else "RAM",
                           default[variant] if isinstance(default, tuple) else default)
    for alias, name in (aliases or {}).items():
        items[alias] = replace(items[name], name=alias)
    return ControlTable(key, model, protocol, *identity, COUNTS_PER_REV,
                        MappingProxyType(items), MappingProxyType(dict(aliases or {})))


# (model number, a plausible firmware version): the e-Manual's model numbers; firmware 50 is the
# 330 family's current release (an XC330 update from v46 to v50 on forum.robotis.com), 52 a
# plausible X430 one.
XL330_IDENTITY = (1200, 50)
XL430_IDENTITY = (1060, 52)

# The X-series rows the XL330-M288 and XL430-W250 share; tuple defaults are (XL330, XL430)
# (e-Manual control tables).
_X_SERIES: list[tuple[Any, ...]] = [
    ("model_number", 0, 2, "R", (XL330_IDENTITY[0], XL430_IDENTITY[0]), "u", PLAIN),
    ("firmware_version", 6, 1, "R", (XL330_IDENTITY[1], XL430_IDENTITY[1]), "u", PLAIN),
    ("id", 7, 1, "RW", 1, "u", PLAIN),
    ("baud_rate", 8, 1, "RW", 1, "u", PLAIN),  # 1 = 57600 bps
    ("return_delay_time", 9, 1, "RW", 250, "u", TWO_MICROSECONDS),
    ("drive_mode", 10, 1, "RW", 0, "u", PLAIN),
    ("operating_mode", 11, 1, "RW", 3, "u", PLAIN),  # 3 = position control
    ("secondary_id", 12, 1, "RW", 255, "u", PLAIN),
    ("protocol_type", 13, 1, "RW", 2, "u", PLAIN),
    ("homing_offset", 20, 4, "RW", 0, "s", DXL_POSITION),
    ("moving_threshold", 24, 4, "RW", 10, "u", DXL_VELOCITY),
    ("temperature_limit", 31, 1, "RW", (70, 72), "u", CELSIUS),
    ("max_voltage_limit", 32, 2, "RW", (70, 140), "u", DECIVOLT),
    ("min_voltage_limit", 34, 2, "RW", (35, 60), "u", DECIVOLT),
    ("pwm_limit", 36, 2, "RW", 885, "u", DXL_PWM),
    ("velocity_limit", 44, 4, "RW", (445, 265), "u", DXL_VELOCITY),
    ("max_position_limit", 48, 4, "RW", 4095, "u", DXL_POSITION),
    ("min_position_limit", 52, 4, "RW", 0, "u", DXL_POSITION),
    ("startup_configuration", 60, 1, "RW", 0, "u", PLAIN),
    ("shutdown", 63, 1, "RW", (53, 52), "u", PLAIN),
    ("torque_enable", 64, 1, "RW", 0, "u", PLAIN),
    ("led", 65, 1, "RW", 0, "u", PLAIN),
    ("status_return_level", 68, 1, "RW", 2, "u", PLAIN),
    ("registered_instruction", 69, 1, "R", 0, "u", PLAIN),
    ("hardware_error_status", 70, 1, "R", 0, "u", PLAIN),
    ("velocity_i_gain", 76, 2, "RW", (1600, 1000), "u", PLAIN),
    ("velocity_p_gain", 78, 2, "RW", (180, 100), "u", PLAIN),
    ("position_d_gain", 80, 2, "RW", (0, 4000), "u", PLAIN),
    ("position_i_gain", 82, 2, "RW", 0, "u", PLAIN),
    ("position_p_gain", 84, 2, "RW", (400, 640), "u", PLAIN),
    ("feedforward_2nd_gain", 88, 2, "RW", 0, "u", PLAIN),
    ("feedforward_1st_gain", 90, 2, "RW", 0, "u", PLAIN),
    ("bus_watchdog", 98, 1, "RW", 0, "u", TWENTY_MS),
    ("goal_pwm", 100, 2, "RW", 0, "s", DXL_PWM),
    ("goal_velocity", 104, 4, "RW", 0, "s", DXL_VELOCITY),
    ("profile_acceleration", 108, 4, "RW", 0, "u", DXL_ACCELERATION),
    ("profile_velocity", 112, 4, "RW", 0, "u", DXL_VELOCITY),
    ("goal_position", 116, 4, "RW", 0, "s", DXL_POSITION),
    ("realtime_tick", 120, 2, "R", 0, "u", MILLISECOND),
    ("moving", 122, 1, "R", 0, "u", PLAIN),
    ("moving_status", 123, 1, "R", 0, "u", PLAIN),
    ("present_pwm", 124, 2, "R", 0, "s", DXL_PWM),
    ("present_velocity", 128, 4, "R", 0, "s", DXL_VELOCITY),
    ("present_position", 132, 4, "R", 0, "s", DXL_POSITION),
    ("velocity_trajectory", 136, 4, "R", 0, "s", DXL_VELOCITY),
    ("position_trajectory", 140, 4, "R", 0, "s", DXL_POSITION),
    ("present_input_voltage", 144, 2, "R", 0, "u", DECIVOLT),
    ("present_temperature", 146, 1, "R", 0, "u", CELSIUS),
    ("backup_ready", 147, 1, "R", 0, "u", PLAIN),
]

# XL330-only registers (e-Manual XL330-M288 control table). Current: the table's unit, 1 mA
# (the page's Goal Current description says "about 2.69 mA"; the table row is followed here).
# Address 126 is Present Current here, Present Load (0.1 %) on the XL430; the XL330's
# present_load is its present_current under leglab's shared name.
_XL330_ONLY: list[tuple[Any, ...]] = [
    ("current_limit", 38, 2, "RW", 1750, "u", MILLIAMP),
    ("pwm_slope", 62, 1, "RW", 140, "u", ("1.977 mV/ms", 1.977, "V/s")),
    ("goal_current", 102, 2, "RW", 0, "s", MILLIAMP),
    ("present_current", 126, 2, "R", 0, "s", MILLIAMP),
]
_XL430_ONLY: list[tuple[Any, ...]] = [
    ("present_load", 126, 2, "R", 0, "s", DXL_LOAD),
]

XL330_M288 = _table("xl330-m288", "XL330-M288-T", "dynamixel", XL330_IDENTITY, 64,
                    _X_SERIES + _XL330_ONLY, 0, aliases={"present_load": "present_current"})
XL430_W250 = _table("xl430-w250", "XL430-W250-T", "dynamixel", XL430_IDENTITY, 64,
                    _X_SERIES + _XL430_ONLY, 1)

# (model number, firmware major version): the STS3215 spreadsheet's servo version 9.3 (model
# 3 * 256 + 9) and firmware 3.6; the STS3250's model number from lerobot's feetech tables.
STS3215_IDENTITY = (777, 3)
STS3250_IDENTITY = (2825, 3)

# The STS memory table (the STS3215 and STS3250 share it, as lerobot has them) with the STS3215
# spreadsheet's defaults; tuple defaults are (STS3215, STS3250). The STS3250 (9-12.6 V) has no
# published memory table of its own: its maximum-voltage default 140 (a 12 V servo's) is an
# assumption.
_STS: list[tuple[Any, ...]] = [
    ("firmware_version", 0, 1, "R", 3, "u", PLAIN),  # major; the spreadsheet's 3.6
    ("firmware_minor_version", 1, 1, "R", 6, "u", PLAIN),
    ("model_number", 3, 2, "R", (STS3215_IDENTITY[0], STS3250_IDENTITY[0]), "u", PLAIN),
    ("id", 5, 1, "RW", 1, "u", PLAIN),
    ("baud_rate", 6, 1, "RW", 0, "u", PLAIN),  # 0 = 1 Mbps
    # The STS3215 spreadsheet: return delay, 2 us, default 0; the newer STS table lists
    # address 7 as reserved. Followed: the spreadsheet.
    ("return_delay_time", 7, 1, "RW", 0, "u", TWO_MICROSECONDS),
    ("status_return_level", 8, 1, "RW", 1, "u", PLAIN),
    ("min_position_limit", 9, 2, "RW", 0, "u", STS_POSITION),
    ("max_position_limit", 11, 2, "RW", 4095, "u", STS_POSITION),
    ("temperature_limit", 13, 1, "RW", 70, "u", CELSIUS),
    ("max_voltage_limit", 14, 1, "RW", (80, 140), "u", DECIVOLT),
    ("min_voltage_limit", 15, 1, "RW", 40, "u", DECIVOLT),
    ("torque_limit", 16, 2, "RW", 1000, "u", PERMILLE),  # "maximum torque", to 48 at power-on
    ("phase", 18, 1, "RW", 12, "u", PLAIN),
    ("unloading_condition", 19, 1, "RW", 44, "u", PLAIN),
    ("led_alarm_condition", 20, 1, "RW", 47, "u", PLAIN),
    ("position_p_gain", 21, 1, "RW", 32, "u", PLAIN),
    ("position_d_gain", 22, 1, "RW", 32, "u", PLAIN),
    ("position_i_gain", 23, 1, "RW", 0, "u", PLAIN),
    # 2 bytes in the STS3215 spreadsheet (and lerobot); the newer STS table makes it 1 byte
    # with an integral limit (default 0) at 25. Followed: the spreadsheet.
    ("minimum_startup_force", 24, 2, "RW", 16, "u", PERMILLE),
    ("cw_dead_zone", 26, 1, "RW", 1, "u", STS_POSITION),
    ("ccw_dead_zone", 27, 1, "RW", 1, "u", STS_POSITION),
    ("protection_current", 28, 2, "RW", 500, "u", STS_CURRENT),
    ("angular_resolution", 30, 1, "RW", 1, "u", PLAIN),
    ("position_offset", 31, 2, "RW", 0, 11, STS_POSITION),
    ("operating_mode", 33, 1, "RW", 0, "u", PLAIN),  # 0 = position servo
    ("protective_torque", 34, 1, "RW", 20, "u", PERCENT),
    ("protection_time", 35, 1, "RW", 200, "u", TEN_MS),
    ("overload_torque", 36, 1, "RW", 80, "u", PERCENT),
    ("velocity_p_gain", 37, 1, "RW", 10, "u", PLAIN),
    ("overcurrent_protection_time", 38, 1, "RW", 200, "u", TEN_MS),
    ("velocity_i_gain", 39, 1, "RW", 10, "u", PLAIN),
    ("torque_enable", 40, 1, "RW", 0, "u", PLAIN),
    ("profile_acceleration", 41, 1, "RW", 0, "u", STS_ACCELERATION),  # 0 = the maximum
    ("goal_position", 42, 2, "RW", 0, 15, STS_POSITION),
    ("profile_velocity", 46, 2, "RW", 0, 15, STS_SPEED),  # "running speed"; 0 = the maximum
    ("active_torque_limit", 48, 2, "RW", 1000, "u", PERMILLE),  # RAM copy of torque_limit
    # Lock: the STS3215 spreadsheet says 0, the newer STS table 1 (EEPROM writes do not
    # persist until 0 is written). Followed: the newer table.
    ("lock", 55, 1, "RW", 1, "u", PLAIN),
    ("present_position", 56, 2, "R", 0, 15, STS_POSITION),
    ("present_velocity", 58, 2, "R", 0, 15, STS_SPEED),
    ("present_load", 60, 2, "R", 0, 10, PERMILLE),
    ("present_input_voltage", 62, 1, "R", 0, "u", DECIVOLT),
    ("present_temperature", 63, 1, "R", 0, "u", CELSIUS),
    ("registered_instruction", 64, 1, "R", 0, "u", PLAIN),
    ("hardware_error_status", 65, 1, "R", 0, "u", PLAIN),  # "servo status"
    ("moving", 66, 1, "R", 0, "u", PLAIN),
    ("present_current", 69, 2, "R", 0, "u", STS_CURRENT),
]

STS3215 = _table("sts3215", "STS3215", "feetech", STS3215_IDENTITY, 40, _STS, 0)
STS3250 = _table("sts3250", "STS3250", "feetech", STS3250_IDENTITY, 40, _STS, 1)

TABLES: Mapping[str, ControlTable] = MappingProxyType(
    {table.key: table for table in (XL330_M288, XL430_W250, STS3215, STS3250)})


def table_for(protocol: str, model_number: int) -> Optional[ControlTable]:
    """The table of a servo model.

    Parameters
    ----------
    protocol : {"dynamixel", "feetech"}
        The protocol it speaks.
    model_number : int
        The model number it reports.

    Returns
    -------
    ControlTable or None
        Its table, or None when leglab has none.
    """
    for table in TABLES.values():
        if table.protocol == protocol and table.model_number == model_number:
            return table
    return None


def raw_range(item: Item) -> tuple[int, int]:
    """The raw values a register holds.

    Parameters
    ----------
    item : Item
        The register.

    Returns
    -------
    (int, int)
        The smallest and the largest.
    """
    bits = 8 * item.size
    if item.encoding == "signed":
        return -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    if item.encoding == "sign_magnitude":
        return -((1 << item.sign_bit) - 1), (1 << item.sign_bit) - 1
    return 0, (1 << bits) - 1


def encode(item: Item, raw: int) -> bytes:
    """A raw value as the register's bytes.

    Parameters
    ----------
    item : Item
        The register.
    raw : int
        The counts.

    Returns
    -------
    bytes
        Its `size` bytes, little endian.

    Raises
    ------
    TypeError
        `raw` not an integer.
    ValueError
        `raw` does not fit the register.
    """
    low, high = raw_range(item)
    if not isinstance(raw, int):
        raise TypeError(f"{item.name}: expected an integer count, got {type(raw).__name__}")
    if not low <= raw <= high:
        raise ValueError(f"{item.name}: {raw!r} does not fit ({low}..{high})")
    if item.encoding == "sign_magnitude":
        raw = to_sign_magnitude(raw, item.sign_bit)
    return raw.to_bytes(item.size, "little", signed=item.encoding == "signed")


def decode(item: Item, data: bytes) -> int:
    """The raw number in a register's bytes.

    Parameters
    ----------
    item : Item
        The register.
    data : bytes
        Exactly `item.size` bytes, little endian.

    Returns
    -------
    int
        The counts.

    Raises
    ------
    ValueError
        `data` of another length.
    """
    if len(data) != item.size:
        raise ValueError(f"{item.name}: {len(data)} bytes, not {item.size}")
    raw = int.from_bytes(data, "little", signed=item.encoding == "signed")
    return from_sign_magnitude(raw, item.sign_bit) if item.encoding == "sign_magnitude" else raw


def to_units(item: Item, raw: int) -> float:
    """A raw value in leglab units.

    Parameters
    ----------
    item : Item
        The register.
    raw : int
        The counts.

    Returns
    -------
    float
        raw * scale (positions: degrees on the servo's 0..360 scale).
    """
    return raw * item.scale


def from_units(item: Item, value: float) -> int:
    """The raw count nearest a value in leglab units.

    Parameters
    ----------
    item : Item
        The register.
    value : float
        The value, in the item's leglab_unit.

    Returns
    -------
    int
        The counts.

    Raises
    ------
    TypeError
        `value` not a number.
    ValueError
        `value` not finite, or the register cannot hold it.
    """
    if isinstance(value, (str, bytes)) or not isinstance(value, (int, float)) and \
            not hasattr(value, "__float__"):
        raise TypeError(f"{item.name}: expected a number, got {type(value).__name__}")
    if not math.isfinite(value):
        raise ValueError(f"{item.name}: {value!r} is not a finite number")
    raw = round(value / item.scale)
    low, high = raw_range(item)
    if not low <= raw <= high:
        unit = f" {item.leglab_unit}" if item.leglab_unit else ""
        raise ValueError(f"{item.name}: {value}{unit} is {raw} counts, outside {low}..{high} "
                         f"({low * item.scale:g}..{high * item.scale:g}{unit})")
    return raw
