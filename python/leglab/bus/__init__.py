"""leglab.bus: your servo on its bus. Dynamixel Protocol 2.0 and Feetech STS/SMS servos on a
serial port (pyserial), from a scan to a recording, a fit and a run of planned requests.

    from leglab import bus
    with bus.Bus("/dev/ttyUSB0", "dynamixel") as b:
        print(b.scan(range(1, 10)))
        angle = b.read(1, "present_position")          # deg on the servo's 0-360 scale
        b.sync_write("goal_position", {1: 180.0, 2: 170.0})

The command line is `python3 -m leglab.bus scan|record|run|emulate` (leglab.bus.cli). An
emulated bus (`emulator.make_emulator`, on a `VirtualPort` or a pseudo-terminal) stands in for
real servos: a DC motor, gearbox, friction, the firmware's P law and a pendulum load, none of
which is leglab's own model. See docs/real-servos.md ("On your bus") and docs/python.md.
"""

from . import dynamixel, emulator, feetech, physics, tables, trajectories
from .bus import (
    BAUD_RATES,
    MAX_ID,
    PROTOCOLS,
    Bus,
    BusError,
    BusStats,
    HardwareError,
    NoReply,
    ServoInfo,
)
from .emulator import (
    EmulatedServo,
    Emulator,
    Faults,
    RealClock,
    VirtualClock,
    VirtualPort,
    make_emulator,
    serve_pty,
)
from .errors import Packet, ProtocolError

__all__ = ["Bus", "BusError", "NoReply", "HardwareError", "BusStats", "ServoInfo", "PROTOCOLS",
           "BAUD_RATES", "MAX_ID", "Packet", "ProtocolError", "Emulator", "EmulatedServo",
           "Faults", "VirtualPort", "VirtualClock", "RealClock", "make_emulator", "serve_pty",
           "dynamixel", "feetech", "tables", "physics", "trajectories", "emulator"]
