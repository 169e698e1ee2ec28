"""leglab.bus.physics, the emulated servo, against numbers worked out here independently of its
code: the makers' published figures (stall torque and current, no-load speed), a pendulum's
period and energy, a friction band's rest angle, the firmware's P law from its published
constants, and bit-for-bit determinism.

The published figures and firmware constants are restated here from their sources (ROBOTIS
e-manual XL330-M288 / XL430-W250 "Specifications" and "Position PID Gain"; the Feetech listings;
BAM's bam/dynamixel/actuator.py and bam/feetech/actuator.py), not read back from the module.
"""

import dataclasses
import math
import time

import pytest

from leglab.bus import physics

G = 9.80665
RPM = 2 * math.pi / 60
# key: (supply V, stall torque N m, stall current A or None (not published), no-load rad/s)
PUBLISHED = {
    "xl330-m288": (5.0, 0.52, 1.47, 103 * RPM),
    "xl430-w250": (11.1, 1.4, 1.3, 57 * RPM),
    "sts3215": (7.4, 19.5 * 0.0980665, 2.7, math.radians(60) / 0.192),
    "sts3250": (12.0, 50 * 0.0980665, None, math.radians(60) / 0.133),
}
BENCH_MASS_KG, BENCH_LENGTH_M = 0.49, 0.10  # the shipped BAM XL330 logs' pendulum
XL330 = physics.SPECS["xl330-m288"]


def frictionless(spec):
    """The spec with every friction term zero (the derived k and R kept)."""
    return dataclasses.replace(
        spec, coulomb_nm=0.0, static_nm=0.0, load_friction=0.0, load_friction_static=0.0,
        external_friction=0.0, external_friction_static=0.0, viscous_nm_s_rad=0.0)


def inertia(spec, mass_kg, length_m):
    """m L^2 + armature + the horn, kg m^2."""
    return mass_kg * length_m ** 2 + spec.armature_kgm2 + physics.HORN_INERTIA_KGM2


def state(servo):
    return (servo.angle_rad, servo.velocity_rad_s, servo.current_a, servo.duty, servo.time_s)


def test_the_four_servos_are_there_under_the_control_tables_keys():
    assert sorted(physics.SPECS) == sorted(PUBLISHED)
    for key, spec in physics.SPECS.items():
        volts, torque, current, speed = PUBLISHED[key]
        assert (spec.key, spec.voltage_v, spec.counts_per_rev) == (key, volts, 4096)
        assert spec.stall_torque_nm == pytest.approx(torque, rel=1e-12)
        assert spec.no_load_speed_rad_s == pytest.approx(speed, rel=1e-12)
        if current is not None:
            assert spec.stall_current_a == pytest.approx(current, rel=1e-12)
        assert 0.0 < spec.efficiency < 1.0
        assert spec.static_nm >= spec.coulomb_nm >= 0.0
        assert spec.motor_torque_constant_nm_a == pytest.approx(
            spec.torque_constant_nm_a / spec.gear_ratio)


@pytest.mark.parametrize("key", sorted(PUBLISHED))
def test_no_load_full_duty_runs_at_the_published_no_load_speed(key):
    spec = physics.SPECS[key]
    servo = physics.ServoPhysics(spec, 0.0, 0.0)
    servo.advance_open_loop(2.0, 1.0)
    # The no-load speed is the published one less nothing: the friction was folded into k.
    # The Stribeck term's tail at that speed is the only slack (under 0.1 %).
    assert servo.velocity_rad_s == pytest.approx(PUBLISHED[key][3], rel=0.01)
    assert 0.0 < servo.current_a < 0.3 * spec.stall_current_a  # the friction's current only


@pytest.mark.parametrize("key", sorted(PUBLISHED))
def test_a_locked_output_at_full_duty_gives_the_published_stall_torque_and_current(key):
    spec = physics.SPECS[key]
    servo = physics.ServoPhysics(spec, 0.0, 0.0)
    servo.locked = True
    servo.advance_open_loop(0.1, 1.0)  # past the XL330's PWM slope (18 ms at 5 V)
    assert servo.duty == 1.0
    assert servo.velocity_rad_s == 0.0
    volts, torque, current, _ = PUBLISHED[key]
    assert servo.shaft_torque_nm == pytest.approx(torque, rel=1e-9)
    assert servo.current_a == pytest.approx(volts / spec.resistance_ohm, rel=1e-12)
    if current is not None:
        assert servo.current_a == pytest.approx(current, rel=1e-9)
    assert servo.load_fraction() == pytest.approx(1.0, rel=1e-9)


def zero_crossings(servo, until_s, step_s=0.0005):
    """Times the angle crosses zero upward (linearly interpolated), advancing torque-off."""
    times, last_t, last_a = [], servo.time_s, servo.angle_rad
    while servo.time_s < until_s - 1e-12:
        servo.advance(servo.time_s + step_s, None, 0)
        if last_a < 0.0 <= servo.angle_rad:
            times.append(last_t + (servo.time_s - last_t) * -last_a / (servo.angle_rad - last_a))
        last_t, last_a = servo.time_s, servo.angle_rad
    return times


@pytest.mark.parametrize("key,mass,length", [("xl330-m288", BENCH_MASS_KG, BENCH_LENGTH_M),
                                             ("sts3250", 1.13, 0.12)])
def test_frictionless_small_swing_has_the_pendulum_period(key, mass, length):
    spec = frictionless(physics.SPECS[key])
    servo = physics.ServoPhysics(spec, mass, length, math.radians(3.0))
    crossings = zero_crossings(servo, 6.0)
    assert len(crossings) >= 5
    measured = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    expected = 2 * math.pi * math.sqrt(inertia(spec, mass, length) / (mass * G * length))
    assert measured == pytest.approx(expected, rel=0.005)


def test_frictionless_swing_keeps_its_energy():
    spec = frictionless(XL330)
    m, length = BENCH_MASS_KG, BENCH_LENGTH_M
    total_inertia = inertia(spec, m, length)
    servo = physics.ServoPhysics(spec, m, length, math.radians(20.0))

    def energy():
        return (0.5 * total_inertia * servo.velocity_rad_s ** 2 +
                m * G * length * (1 - math.cos(servo.angle_rad)))

    start = energy()
    worst = 0.0
    for n in range(1, 5001):  # 5 s, about 6 swings
        servo.advance(n * 0.001, None, 0)
        worst = max(worst, abs(energy() - start) / start)
        assert servo.current_a == 0.0  # torque off: the bridge open, no braking
    assert worst < 0.005


def test_with_friction_a_released_pendulum_ends_still_within_the_static_band():
    m, length = BENCH_MASS_KG, BENCH_LENGTH_M
    servo = physics.ServoPhysics(XL330, m, length, math.radians(20.0))
    crossings = zero_crossings(servo, 10.0)
    assert crossings  # it swings before it stops
    rest = servo.angle_rad
    servo.advance(11.0, None, 0)
    assert servo.velocity_rad_s == 0.0 and servo.angle_rad == rest
    # At rest with torque off: gravity m g L |sin| held by the static band
    # static_nm + external_friction_static * m g L |sin| (BAM XL330 m6: 0.00945 N m, 0.0808).
    weight = m * G * length
    assert weight * abs(math.sin(rest)) * (1 - 0.0808) <= 0.00477 + 0.00468 + 1e-12
    assert abs(math.degrees(rest)) < 20.0


def xl330_duty(kp, error):
    """The XL330's firmware duty, from its published constants: PWM = trunc(kp * error / 256)
    (BAM's XL330_KP_DIVISOR) of 885 = 100 % (e-manual, PWM Limit), saturating."""
    pwm = max(-885, min(885, math.trunc(kp * error / 256)))
    return pwm / 885


def test_firmware_duty_follows_the_published_laws():
    fd = physics.firmware_duty
    assert fd(XL330, 2148, 2048, 400) == xl330_duty(400, 100) == 156 / 885
    assert fd(XL330, 1948, 2048, 400) == -156 / 885  # truncated toward zero
    assert fd(XL330, 2048 + 1024, 2048, 400) == 1.0
    xl430 = physics.SPECS["xl430-w250"]
    assert fd(xl430, 2058, 2048, 640) == pytest.approx(640 * 10 / 128 / 885)  # KPP = gain/128
    sts = physics.SPECS["sts3250"]
    per_rad = 0.166  # BAM's STS error_gain: duty per rad of error per unit of kp
    assert fd(sts, 2058, 2048, 32) == pytest.approx(32 * per_rad * 10 * 2 * math.pi / 4096)
    assert fd(sts, 2048 - 1024, 2048, 32) == -0.97  # BAM's STS max_pwm
    assert fd(XL330, 2048, 2048, 400) == 0.0


def xl330_k_over_r_and_mu():
    """The XL330's k / R (N m/V) and motor-side load friction mu, by hand from the published
    5 V figures and BAM's m6 friction (tau_c 0.00477 N m, b 0.00536 N m s/rad): the no-load
    balance (1 - mu) k (V - k w) / R = tau_c + b w and the stall one (1 - mu) k I = T + tau_c
    with R = V / I give k = V / w (1 - (tau_c + b w) / (T + tau_c))."""
    volts, torque, current, speed = PUBLISHED["xl330-m288"]
    tau_c, b = 0.00477, 0.00536
    k = volts / speed * (1 - (tau_c + b * speed) / (torque + tau_c))
    mu = 1 - (torque + tau_c) / (k * current)
    return k * current / volts, mu


def test_the_xl330s_derived_motor_constants_are_the_hand_worked_ones():
    k_over_r, mu = xl330_k_over_r_and_mu()
    assert XL330.torque_constant_nm_a / XL330.resistance_ohm == pytest.approx(k_over_r)
    assert XL330.load_friction == pytest.approx(mu)
    assert 0.10 < mu < 0.15  # BAM's own XL330 fits: 0.12 (m3) to 0.27 (m6)


def xl330_hold_band(goal_count, kp, volts, mass, length):
    """Errors (counts) at which the XL330 at rest is held by static friction with the goal
    goal_count counts from hanging: |motor - gravity| <= the static band, the motor's torque
    k u V / R at duty u, the band the XL330's BAM m6 static friction plus mu |motor|."""
    k_over_r, mu = xl330_k_over_r_and_mu()
    held = []
    for error in range(0, goal_count + 1):
        theta = (goal_count - error) * 2 * math.pi / 4096
        motor = k_over_r * volts * xl330_duty(kp, error)
        gravity = mass * G * length * math.sin(theta)
        band = 0.00477 + 0.00468 + mu * abs(motor) + 0.0808 * abs(gravity)
        if abs(motor - gravity) <= band:
            held.append(error)
    return held


def test_p_law_holds_the_bench_pendulum_where_duty_balances_gravity_within_the_band():
    goal = round(30 * 4096 / 360)  # 30 deg from hanging, counts
    servo = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    servo.advance(4.0, 2048 + goal, 400)
    error = goal - (servo.position_count() - 2048)
    servo.advance(5.0, 2048 + goal, 400)
    assert servo.velocity_rad_s == 0.0 and goal - (servo.position_count() - 2048) == error
    held = xl330_hold_band(goal, 400, 5.0, BENCH_MASS_KG, BENCH_LENGTH_M)
    assert held == list(range(held[0], held[-1] + 1))  # one contiguous band
    # Without friction the duty would balance gravity at one error, inside the band:
    k_over_r, _ = xl330_k_over_r_and_mu()
    weight = BENCH_MASS_KG * G * BENCH_LENGTH_M
    balance = min(range(goal + 1), key=lambda e: abs(
        k_over_r * 5.0 * xl330_duty(400, e) - weight * math.sin((goal - e) * 2 * math.pi / 4096)))
    assert held[0] <= balance <= held[-1]
    assert held[0] - 1 <= error <= held[-1] + 1  # +-1: the count's rounding of the angle
    assert error > 100  # the XL330's soft P law sags by many counts under this load


def test_a_small_step_moves_no_faster_than_the_no_load_speed():
    """From the hold at a 30 deg goal, a 15 deg step up (a 5 deg step stays inside the static
    band: the XL330's soft P law needs some 40 more counts of error to break it here)."""
    goal = round(30 * 4096 / 360)
    servo = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    servo.advance(4.0, 2048 + goal, 400)
    before = servo.angle_rad
    fastest = 0.0
    for n in range(1, 1001):
        servo.advance(4.0 + n * 0.001, 2048 + goal + 171, 400)  # 15 deg up
        fastest = max(fastest, abs(servo.velocity_rad_s))
    assert servo.angle_rad > before
    assert 0.0 < fastest <= PUBLISHED["xl330-m288"][3]


def test_a_goal_90_degrees_away_saturates_the_duty():
    servo = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    servo.advance(0.010, 2048 + 1024, 400)
    assert 0.0 < servo.duty < 1.0  # still on the PWM slope: 276.8 V/s over 5 V, 18 ms to full
    servo.advance(0.050, 2048 + 1024, 400)
    assert servo.duty == 1.0
    assert servo.current_a > 0.0


def test_torque_off_frees_the_motor_below_the_supply_voltage():
    spec = XL330
    slow = physics.ServoPhysics(spec, 0.0, 0.0, velocity_rad_s=5.0)
    slow.advance(0.001, None, 0)
    assert slow.current_a == 0.0
    # Back-driven past V / k the back-EMF exceeds the supply: the body diodes conduct and brake.
    fast = physics.ServoPhysics(spec, 0.0, 0.0, velocity_rad_s=1.5 * 5.0 /
                                spec.torque_constant_nm_a)
    fast.advance(0.0005, None, 0)
    assert fast.current_a < 0.0


def test_position_count_is_the_rounded_angle_on_the_offset_scale():
    servo = physics.ServoPhysics(XL330, 0.0, 0.0, math.radians(90.0))
    assert servo.position_count() == 2048 + 1024
    assert servo.position_count(0) == 1024
    servo.angle_rad = -0.4 * 2 * math.pi / 4096
    assert servo.position_count() == 2048
    servo.angle_rad = -0.6 * 2 * math.pi / 4096
    assert servo.position_count() == 2047


def drive(servo, stops):
    """A goal sequence with torque off in the middle, advanced to each of `stops` in turn."""
    for t in stops:
        if t <= 1.0:
            servo.advance(t, 2048 + 600, 400)
        elif t <= 2.0:
            servo.advance(t, None, 0)
        else:
            servo.advance(t, 2048 - 300, 800)


def test_same_inputs_give_the_same_bits_however_the_time_is_cut():
    ends = [1.0, 2.0, 3.0]
    one = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    drive(one, ends)
    two = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    drive(two, ends)
    assert state(one) == state(two)
    # Cut at odd times (not step boundaries) inside each segment: the same bits.
    cuts = sorted(ends + [0.00037, 0.3333, 0.9999, 1.2345, 1.5, 2.0001, 2.71828])
    many = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    drive(many, cuts)
    assert state(many) == state(one)
    assert one.time_s == 3.0


def test_cost_per_step_is_reported():
    servo = physics.ServoPhysics(XL330, BENCH_MASS_KG, BENCH_LENGTH_M)
    start = time.perf_counter()
    servo.advance(10.0, 2048 + 600, 400)
    per_step_us = (time.perf_counter() - start) / (10.0 / physics.DT_S) * 1e6
    print(f"\nphysics: {per_step_us:.2f} us per {physics.DT_S * 1e3:g} ms step")
