"""Physics of an emulated hobby servo: a DC motor behind a gearbox, its firmware's position loop,
and a pendulum load, integrated at a fixed step.

This is the emulator's stand-in for a real servo (leglab.bus.emulator calls it between packets).
It is deliberately NOT leglab's joint model: it is built from the makers' published numbers and
from Rhoban's BAM identification ("Better Actuator Models for Robotics", Duclusaud, Passault,
Padois, Ly; github Rhoban/bam), so that a fit of leglab's own model to its logs is a fit to
physics leglab does not share. Standard library only; one step costs a few microseconds.

Model (SI units; angles at the output shaft; positive counter-clockwise, the way the position
count increases; 0 = the load hanging straight down):

- Motor: winding current i = (u V - k w) / R, u the H-bridge duty in [-1, 1], V the supply,
  w the output speed, k the torque constant seen at the output (N m/A; equal to the back-EMF
  constant, V s/rad, at the output). The winding inductance is neglected (its time constant,
  well under 1 ms for these motors, is shorter than the integration step). Motor torque at the
  output tau_m = k i.
- Gearbox and bearings: Coulomb friction with a load-dependent part, band
  F_kin = tau_c + mu_m |tau_m| + mu_e |tau_g|, a larger static band F_st (same form) at rest,
  blended by a Stribeck factor exp(-(w / w_s)^2), plus viscous friction b w. The joint sticks
  (w = 0 exactly) while the torque needed to stop it within the step is inside the band. The
  gearbox efficiency at a high load is 1 - mu_m (MotorSpec.efficiency).
- Load: a point mass m at length L, gravity tau_g = -m g L sin(theta); inertia m L^2 + the
  reflected rotor inertia ("armature") + a small horn inertia (HORN_INERTIA_KGM2).
- Torque off: the H-bridge is open (Dynamixel and Feetech both free the motor when Torque
  Enable is 0): no drive and no shorted-winding braking; the only current is through the
  bridge's body diodes, when the back-EMF exceeds the supply (diode drops neglected).
- Firmware: every firmware_period_s the position loop reads the quantised position count and
  sets the duty firmware_duty(...) (a P law on the count error, saturating); on the XL330 the
  duty then moves toward it at the PWM Slope register's default rate.
- Integration: semi-implicit (symplectic) Euler at DT_S = 0.5 ms, two steps a firmware tick.

Each MotorSpec states the sources of its numbers; where no maker publishes one (friction,
armature, the firmware's P-law scaling), it comes from BAM, and where neither does, the spec
says how it was derived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Callable, Optional

GRAVITY_M_S2 = 9.80665
KGF_CM_NM = 0.0980665  # one kgf cm in N m
RPM_RAD_S = 2.0 * math.pi / 60.0
# A servo horn and arm hub (about 10 g at a 2 cm radius, a disc): a small inertia always on the
# shaft, kg m^2. An estimate, not a published figure; it is under 0.1 % of any bench load.
HORN_INERTIA_KGM2 = 2.0e-6
DT_S = 0.0005  # integration step, s
_EPS_STEPS = 1e-9  # until_s / DT_S is floored with this slack (so 0.003 s is 6 steps)


@dataclass(frozen=True)
class MotorSpec:
    """One servo model's motor, gearbox, friction and firmware constants (SI units).

    The published fields (voltage_v, stall_torque_nm, stall_current_a, no_load_speed_rad_s,
    gear_ratio) are the maker's figures at voltage_v; torque_constant_nm_a, resistance_ohm and
    load_friction are derived from them and the friction (see make_spec) so that the model
    reproduces the published stall torque, stall current and no-load speed exactly. Build one
    with make_spec; dataclasses.replace gives variants (e.g. without friction) whose derived
    fields stay as they were.

    Attributes
    ----------
    key : str
        "xl330-m288", "xl430-w250", "sts3215", "sts3250" (the control tables' keys).
    voltage_v : float
        Supply the published figures are for, V.
    stall_torque_nm : float
        Published stall torque at voltage_v, N m.
    stall_current_a : float
        Stall current at voltage_v, A.
    no_load_speed_rad_s : float
        Published no-load speed at voltage_v, rad/s.
    gear_ratio : float
        Motor turns per output turn.
    torque_constant_nm_a : float
        k at the output, N m/A (= back-EMF constant, V s/rad).
    resistance_ohm : float
        Winding + bridge resistance, ohm.
    coulomb_nm : float
        Kinetic Coulomb friction at the output, N m.
    static_nm : float
        Static Coulomb friction at rest, N m (>= coulomb_nm).
    load_friction : float
        Kinetic friction per N m of motor torque (mu_m).
    load_friction_static : float
        The same at rest.
    external_friction : float
        Kinetic friction per N m of external (gravity) torque (mu_e).
    external_friction_static : float
        The same at rest.
    viscous_nm_s_rad : float
        Viscous friction at the output, N m s/rad.
    stribeck_rad_s : float
        Speed over which static friction fades to kinetic, rad/s.
    armature_kgm2 : float
        Reflected rotor inertia at the output, kg m^2.
    duty_per_count_kp : float
        Firmware duty per count of error per unit of the gain register.
    max_duty : float
        Firmware's duty limit (1 = full supply).
    pwm_steps : int
        The firmware's integer PWM full scale (885 on Dynamixel X), 0: continuous.
    pwm_slope_v_per_s : float
        Firmware's slew limit on the motor voltage, V/s (0: none).
    firmware_period_s : float
        Position loop period, s.
    counts_per_rev : int
        Encoder counts per output turn.
    """

    key: str  # "xl330-m288", "xl430-w250", "sts3215", "sts3250" (the control tables' keys)
    voltage_v: float  # supply the published figures are for, V
    stall_torque_nm: float  # published stall torque at voltage_v, N m
    stall_current_a: float  # stall current at voltage_v, A
    no_load_speed_rad_s: float  # published no-load speed at voltage_v, rad/s
    gear_ratio: float  # motor turns per output turn
    torque_constant_nm_a: float  # k at the output, N m/A (= back-EMF constant, V s/rad)
    resistance_ohm: float  # winding + bridge resistance, ohm
    coulomb_nm: float  # kinetic Coulomb friction at the output, N m
    static_nm: float  # static Coulomb friction at rest, N m (>= coulomb_nm)
    load_friction: float  # kinetic friction per N m of motor torque (mu_m)
    load_friction_static: float  # the same at rest
    external_friction: float  # kinetic friction per N m of external (gravity) torque (mu_e)
    external_friction_static: float  # the same at rest
    viscous_nm_s_rad: float  # viscous friction at the output, N m s/rad
    stribeck_rad_s: float  # speed over which static friction fades to kinetic, rad/s
    armature_kgm2: float  # reflected rotor inertia at the output, kg m^2
    duty_per_count_kp: float  # firmware duty per count of error per unit of the gain register
    max_duty: float  # firmware's duty limit (1 = full supply)
    pwm_steps: int  # the firmware's integer PWM full scale (885 on Dynamixel X), 0: continuous
    pwm_slope_v_per_s: float  # firmware's slew limit on the motor voltage, V/s (0: none)
    firmware_period_s: float = 0.001  # position loop period, s
    counts_per_rev: int = 4096  # encoder counts per output turn

    @property
    def motor_torque_constant_nm_a(self) -> float:
        """k at the motor shaft, N m/A (the output's k over the gear ratio)."""
        return self.torque_constant_nm_a / self.gear_ratio

    @property
    def efficiency(self) -> float:
        """The gearbox's efficiency at a high load, 1 - load_friction (the Coulomb and viscous
        parts lower it further at a light load)."""
        return 1.0 - self.load_friction


def _torque_constant(voltage_v: float, stall_torque_nm: float, no_load_speed_rad_s: float,
                     coulomb_nm: float, viscous: float) -> float:
    """k that makes the model's stall torque and no-load speed the published ones. With
    (1 - mu) k I_stall = T_stall + tau_c (driving, just at stall) and
    (1 - mu) k (V - k w_nl) / R = tau_c + b w_nl (no load), and I_stall = V / R:
    k = V / w_nl * (1 - (tau_c + b w_nl) / (T_stall + tau_c))."""
    loss = (coulomb_nm + viscous * no_load_speed_rad_s) / (stall_torque_nm + coulomb_nm)
    return voltage_v / no_load_speed_rad_s * (1.0 - loss)


def make_spec(key: str, *, voltage_v: float, stall_torque_nm: float,
              no_load_speed_rad_s: float, gear_ratio: float,
              stall_current_a: Optional[float] = None, load_friction: Optional[float] = None,
              **rest: Any) -> MotorSpec:
    """A MotorSpec from the published figures and the friction.

    k, R and one of stall_current_a / load_friction are derived (give exactly one of the two).

    Parameters
    ----------
    key : str
        The control table's key ("xl330-m288", ...).
    voltage_v, stall_torque_nm, no_load_speed_rad_s, gear_ratio : float
        The maker's figures: supply (V), stall torque (N m), no-load speed (rad/s), motor turns
        per output turn.
    stall_current_a, load_friction : float, optional
        Exactly one: the stall current (A) or the kinetic friction per N m of motor torque.
    **rest
        The other MotorSpec fields except the derived ones; load_friction_static defaults to
        load_friction.

    Returns
    -------
    MotorSpec
        The spec, reproducing the published stall torque, stall current and no-load speed.

    Raises
    ------
    ValueError
        Both or neither of stall_current_a and load_friction, or figures that give a load
        friction outside [0, 1).
    """
    if (stall_current_a is None) == (load_friction is None):
        raise ValueError(f"{key}: give exactly one of stall_current_a and load_friction")
    k = _torque_constant(voltage_v, stall_torque_nm, no_load_speed_rad_s, rest["coulomb_nm"],
                         rest["viscous_nm_s_rad"])
    drive_at_stall = stall_torque_nm + rest["coulomb_nm"]  # (1 - mu) k I_stall
    if stall_current_a is None:
        assert load_friction is not None  # exactly one of the two, checked above
        friction = load_friction
        stall_current_a = drive_at_stall / ((1.0 - friction) * k)
    else:
        friction = 1.0 - drive_at_stall / (k * stall_current_a)
    if not 0.0 <= friction < 1.0:
        raise ValueError(f"{key}: the published figures give a load friction {friction}")
    rest.setdefault("load_friction_static", friction)
    return MotorSpec(key=key, voltage_v=voltage_v, stall_torque_nm=stall_torque_nm,
                     stall_current_a=stall_current_a, no_load_speed_rad_s=no_load_speed_rad_s,
                     gear_ratio=gear_ratio, torque_constant_nm_a=k,
                     resistance_ohm=voltage_v / stall_current_a, load_friction=friction,
                     **rest)


# Dynamixel X firmware: Present PWM = KPP * (position error, counts), KPP = Position P Gain /
# divisor, in PWM units where 885 = 100 % duty and the PWM Limit register (default 885) caps it
# (ROBOTIS e-manual, XL330-M288 / XL430-W250, "PWM Limit(36)" and "Position PID Gain(80, 82,
# 84)": KPP = KPP(TBL) / 128). The XL330's divisor is 256, not 128: BAM's XL330 actuator
# (bam/dynamixel/actuator.py, XL330_KP_DIVISOR, "empirically observed"), and the shipped BAM
# XL330 logs (data/servo_logs/dynamixel-xl330) show Present PWM = kp * error / 256 at kp 100
# and 400 to a count. The XL430 keeps the manual's 128 (no measurement says otherwise).
_DXL_PWM_STEPS = 885
# XL330 PWM Slope(62): default 140, unit 1.977 mV/ms, i.e. 276.8 V/s on the motor voltage (e-manual
# XL330-M288, "PWM Slope(62)": 0 to 885 at 5 V takes 18 ms). The XL430 has no such register.
_XL330_PWM_SLOPE_V_PER_S = 140 * 1.977
# Feetech STS firmware: duty = 0.166 per rad of error per unit of the P coefficient register,
# saturating at 0.97 duty (BAM bam/feetech/actuator.py, STS3215Actuator: error_gain 0.166 and
# max_pwm 0.97, both measured with an oscilloscope on STS3215s). Per count: 0.166 * 2 pi / 4096.
# BAM's STS3250 actuator has no measured law of its own; the STS family shares firmware, so the
# STS3250 uses the STS3215's.
_STS_DUTY_PER_COUNT_KP = 0.166 * 2.0 * math.pi / 4096
_STS_MAX_DUTY = 0.97

# XL330-M288-T. Published (ROBOTIS e-manual xl330-m288 "Specifications", the 5.0 V row, the
# recommended supply): stall torque 0.52 N m at 1.47 A, no-load speed 103 rev/min, gear ratio
# 288.4:1. Friction and armature: BAM's XL330 identification, model m6 (bam/params/xl330/m6.json):
# friction_base 0.00477, + friction_stribeck 0.00468 at rest, friction_viscous 0.00536,
# dtheta_stribeck 2.89 rad/s, armature 0.00181, load_friction_external_stribeck 0.0808 (its
# kinetic external term is ~0). The motor-side load friction is derived from the published stall
# current (0.13; BAM's m6 finds 0.27, its m3 0.12 on a differently shaped term).
XL330_M288 = make_spec(
    "xl330-m288", voltage_v=5.0, stall_torque_nm=0.52, stall_current_a=1.47,
    no_load_speed_rad_s=103 * RPM_RAD_S, gear_ratio=288.4,
    coulomb_nm=0.00477, static_nm=0.00477 + 0.00468, viscous_nm_s_rad=0.00536,
    stribeck_rad_s=2.89, external_friction=0.0, external_friction_static=0.0808,
    armature_kgm2=0.00181, duty_per_count_kp=1.0 / (256 * _DXL_PWM_STEPS), max_duty=1.0,
    pwm_steps=_DXL_PWM_STEPS, pwm_slope_v_per_s=_XL330_PWM_SLOPE_V_PER_S)

# XL430-W250-T. Published (e-manual xl430-w250 "Specifications", the 11.1 V row, the recommended
# supply): stall torque 1.4 N m at 1.3 A, no-load speed 57 rev/min, gear ratio 258.5:1. No
# identification of its friction or armature is published: the XL330's (above) are scaled by the
# stall-torque ratio 1.4 / 0.52 (the dimensionless load terms kept), an estimate. The motor-side
# load friction is derived from the published stall current.
_XL430_SCALE = 1.4 / 0.52
XL430_W250 = make_spec(
    "xl430-w250", voltage_v=11.1, stall_torque_nm=1.4, stall_current_a=1.3,
    no_load_speed_rad_s=57 * RPM_RAD_S, gear_ratio=258.5,
    coulomb_nm=0.00477 * _XL430_SCALE, static_nm=(0.00477 + 0.00468) * _XL430_SCALE,
    viscous_nm_s_rad=0.00536 * _XL430_SCALE, stribeck_rad_s=2.89, external_friction=0.0,
    external_friction_static=0.0808, armature_kgm2=0.00181 * _XL430_SCALE,
    duty_per_count_kp=1.0 / (128 * _DXL_PWM_STEPS), max_duty=1.0, pwm_steps=_DXL_PWM_STEPS,
    pwm_slope_v_per_s=0.0)

# STS3215, the 7.4 V version (the one BAM identified). Published (Feetech/Waveshare ST3215
# 7.4 V listing): stall torque 19.5 kg cm at 7.4 V, no-load speed 0.192 s/60 deg at 7.4 V, gear
# ratio 1:345; locked-rotor current 2.7 A (Waveshare ST3215 wiki; R = 7.4 / 2.7 = 2.74 ohm,
# against BAM's identified 2.68). Friction and armature: BAM's identification
# (bam/params/feetech_sts3215_7_4V/m1.json): friction_base 0.0524, friction_viscous 0.0591,
# armature 0.0284; m1 has no static term: the static/kinetic ratio and the Stribeck speed are the
# STS3250's (BAM m6 below: (0.01334 + 0.01598) / 0.01334, 0.326 rad/s), the same family.
STS3215 = make_spec(
    "sts3215", voltage_v=7.4, stall_torque_nm=19.5 * KGF_CM_NM, stall_current_a=2.7,
    no_load_speed_rad_s=math.radians(60) / 0.192, gear_ratio=345.0,
    coulomb_nm=0.0524, static_nm=0.0524 * (0.01334 + 0.01598) / 0.01334,
    viscous_nm_s_rad=0.0591, stribeck_rad_s=0.326, external_friction=0.0,
    external_friction_static=0.0, armature_kgm2=0.0284,
    duty_per_count_kp=_STS_DUTY_PER_COUNT_KP, max_duty=_STS_MAX_DUTY, pwm_steps=0,
    pwm_slope_v_per_s=0.0)

# STS3250 (12 V). Published (Feetech STS3250 product specification, doc. 6384135881578380868917773
# A/0, as tabulated in Robonine's "Feetech STS3250 Smart Actuator: Evaluation of Accuracy, Torque
# and Backlash"): stall torque 50 kg cm at 12 V, no-load speed 0.133 s/60 deg at 12 V; gear ratio
# 1/345 (Robonine, "Practical Comparison of Smart Serial Servo Motors": the STS3215/3235/3250
# share it). Friction and armature: BAM's STS3250 identification, model m6 (Rhoban/bam history,
# params/feetech/m6.json, actuator "sts3250"): friction_base 0.01334 (+ 0.01598 at rest),
# load_friction_motor 0.0436 (+ 0.1870 at rest), load_friction_external 0.1161 (+ 0.1546 at rest),
# friction_viscous 0.0550, dtheta_stribeck 0.326, armature 0.00879 (its k and R were fitted with a
# wrong supply voltage and are not used). No stall current is published in the sources found: it
# is derived from BAM's motor-side load friction (about 3.7 A).
STS3250 = make_spec(
    "sts3250", voltage_v=12.0, stall_torque_nm=50 * KGF_CM_NM, load_friction=0.0436,
    no_load_speed_rad_s=math.radians(60) / 0.133, gear_ratio=345.0,
    coulomb_nm=0.01334, static_nm=0.01334 + 0.01598, load_friction_static=0.0436 + 0.1870,
    viscous_nm_s_rad=0.0550, stribeck_rad_s=0.326, external_friction=0.1161,
    external_friction_static=0.1161 + 0.1546, armature_kgm2=0.00879,
    duty_per_count_kp=_STS_DUTY_PER_COUNT_KP, max_duty=_STS_MAX_DUTY, pwm_steps=0,
    pwm_slope_v_per_s=0.0)

SPECS = MappingProxyType({s.key: s for s in (XL330_M288, XL430_W250, STS3215, STS3250)})


def firmware_duty(spec: MotorSpec, goal_count: float, present_count: float,
                  kp_register: float) -> float:
    """The duty the servo's position loop commands.

    Dynamixel's integer PWM is truncated toward zero as the firmware's integer arithmetic does.

    Parameters
    ----------
    spec : MotorSpec
        The servo.
    goal_count, present_count : float
        The goal and the present position, counts.
    kp_register : float
        The gain register (Dynamixel: Position P Gain; Feetech: P coefficient).

    Returns
    -------
    float
        The duty in [-max_duty, max_duty], a fraction of the supply, signed like the error
        goal_count - present_count.
    """
    duty = spec.duty_per_count_kp * kp_register * (goal_count - present_count)
    if spec.pwm_steps:
        duty = math.trunc(duty * spec.pwm_steps) / spec.pwm_steps
    return max(-spec.max_duty, min(spec.max_duty, duty))


class ServoPhysics:
    """One servo and its pendulum load, integrated at a fixed step DT_S.

    State (plain attributes, readable and settable): angle_rad (output angle, 0 = hanging down,
    positive counter-clockwise, the way the count increases), velocity_rad_s, locked (True:
    the output is clamped still, as on a stall bench). Read-only results of the last step:
    current_a (winding current, A, signed), duty (the H-bridge duty, 0 with torque off),
    shaft_torque_nm (while locked: the torque the drive puts on the clamp, net of the gearbox's
    kinetic friction), time_s (simulated time, s, a whole number of steps).

    Parameters
    ----------
    spec : MotorSpec
        The servo's motor.
    mass_kg, length_m : float
        The pendulum load: a point mass on an arm.
    angle_rad, velocity_rad_s : float, optional
        The initial state.
    supply_v : float, optional
        The supply voltage (None: the spec's).
    horn_inertia_kgm2 : float, optional
        The horn's inertia.

    Determinism: the state after advance(t, ...) depends only on the state before, on the
    whole number of steps floor(t / DT_S + 1e-9) and on the arguments; the firmware ticks on
    every (firmware_period_s / DT_S)-th step counted from time 0. So advance(t1, a);
    advance(t2, a) gives the same bits as advance(t2, a) for any t1 <= t2 with the same
    arguments a, and two objects given the same calls agree to the bit.
    """

    def __init__(self, spec: MotorSpec, mass_kg: float, length_m: float, angle_rad: float = 0.0,
                 velocity_rad_s: float = 0.0, *, supply_v: Optional[float] = None,
                 horn_inertia_kgm2: float = HORN_INERTIA_KGM2) -> None:
        self.spec = spec
        self.mass_kg = float(mass_kg)
        self.length_m = float(length_m)
        self.supply_v = float(spec.voltage_v if supply_v is None else supply_v)
        self.angle_rad = float(angle_rad)
        self.velocity_rad_s = float(velocity_rad_s)
        self.locked = False
        self.inertia_kgm2 = self.mass_kg * self.length_m ** 2 + spec.armature_kgm2 + \
            horn_inertia_kgm2
        self.current_a = 0.0
        self.duty = 0.0
        self.shaft_torque_nm = 0.0
        self._steps = 0
        self._bridge_on = False
        self._ticks_per_firmware = max(1, round(spec.firmware_period_s / DT_S))

    @property
    def time_s(self) -> float:
        """Simulated time, s (the number of steps taken times DT_S)."""
        return self._steps * DT_S

    def position_count(self, offset_count: int = 2048) -> int:
        """The quantised reading (Present Position).

        Parameters
        ----------
        offset_count : int, optional
            The count at which the load hangs.

        Returns
        -------
        int
            offset_count + round(angle * 4096 / 2 pi), halves rounded up.
        """
        return offset_count + math.floor(self.angle_rad * self.spec.counts_per_rev /
                                         (2.0 * math.pi) + 0.5)

    def load_fraction(self) -> float:
        """The load the servo reports.

        Returns
        -------
        float
            The winding current as a signed fraction of the spec's stall current (for the
            present load / current registers).
        """
        return self.current_a / self.spec.stall_current_a

    def advance(self, until_s: float, goal_count: Optional[float], kp_register: float,
                offset_count: int = 2048) -> None:
        """Integrates from time_s up to until_s under the firmware's P law.

        Parameters
        ----------
        until_s : float
            The end, s (whole steps; see the class note).
        goal_count : float or None
            The goal, counts on the scale where the load hangs at offset_count; None: torque
            off.
        kp_register : float
            The gain register.
        offset_count : int, optional
            The count at which the load hangs.
        """
        spec = self.spec

        def command() -> Optional[float]:
            if goal_count is None:
                return None
            return firmware_duty(spec, goal_count, self.position_count(offset_count),
                                 kp_register)
        self._run(until_s, command)

    def advance_open_loop(self, until_s: float, duty: Optional[float]) -> None:
        """Integrates up to until_s (as advance) with the H-bridge at a fixed duty.

        Parameters
        ----------
        until_s : float
            The end, s.
        duty : float or None
            In [-1, 1] (PWM control mode; the PWM slope still applies); None: torque off.
        """
        clamped = None if duty is None else max(-1.0, min(1.0, float(duty)))
        self._run(until_s, lambda: clamped)

    def _run(self, until_s: float, command: Callable[[], Optional[float]]) -> None:
        """Steps up to floor(until_s / DT_S); on each firmware tick, command() gives the target
        duty (None: bridge open)."""
        end = math.floor(until_s / DT_S + _EPS_STEPS)
        ticks = self._ticks_per_firmware
        while self._steps < end:
            if self._steps % ticks == 0:
                self._firmware_tick(command())
            self._step()
            self._steps += 1

    def _firmware_tick(self, target: Optional[float]) -> None:
        """Sets the bridge and the duty for the next firmware period: open on None, else the
        target duty reached at the spec's PWM slope at most."""
        if target is None:
            self._bridge_on, self.duty = False, 0.0
            return
        slope = self.spec.pwm_slope_v_per_s
        if slope > 0.0:
            reach = slope * self.spec.firmware_period_s / self.supply_v
            target = max(self.duty - reach, min(self.duty + reach, target))
        self._bridge_on, self.duty = True, target

    def _step(self) -> None:
        """One semi-implicit Euler step of DT_S."""
        s, w = self.spec, self.velocity_rad_s
        k, r, v = s.torque_constant_nm_a, s.resistance_ohm, self.supply_v
        if self._bridge_on:
            i = (self.duty * v - k * w) / r
        elif abs(k * w) > v:  # the body diodes conduct: the motor brakes into the supply
            i = -(k * w - math.copysign(v, w)) / r
        else:
            i = 0.0
        self.current_a = i
        tau_m = k * i
        tau_g = -self.mass_kg * GRAVITY_M_S2 * self.length_m * math.sin(self.angle_rad)
        if self.locked:
            self.velocity_rad_s = 0.0
            band = s.coulomb_nm + s.load_friction * abs(tau_m)
            self.shaft_torque_nm = math.copysign(max(abs(tau_m) - band, 0.0), tau_m)
            return
        free = tau_m + tau_g - s.viscous_nm_s_rad * w
        band = _friction_band(s, w, abs(tau_m), abs(tau_g))
        inertia = self.inertia_kgm2
        stop = inertia * w / DT_S + free  # the torque that would stop the joint in this step
        if -band <= stop <= band:
            w = 0.0
        else:
            w += (free - math.copysign(band, stop)) * DT_S / inertia
        self.velocity_rad_s = w
        self.angle_rad += w * DT_S


def _friction_band(spec: MotorSpec, w: float, motor_nm: float, external_nm: float) -> float:
    """The Coulomb friction bound at speed w (N m, >= 0): the kinetic band plus the static
    excess faded by exp(-(w / stribeck_rad_s)^2)."""
    kinetic = spec.coulomb_nm + spec.load_friction * motor_nm + \
        spec.external_friction * external_nm
    static = spec.static_nm + spec.load_friction_static * motor_nm + \
        spec.external_friction_static * external_nm
    if spec.stribeck_rad_s <= 0.0 or static <= kinetic:
        return kinetic
    x = w / spec.stribeck_rad_s
    return kinetic + (static - kinetic) * math.exp(-x * x)
