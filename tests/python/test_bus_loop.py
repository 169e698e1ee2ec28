"""The whole path on an emulated servo, as a servo owner runs it: record the excitations, fit
them with `identify`, and run a motion no log holds (python3 -m leglab.bus, on virtual time:
the same bits every run). The emulated servo is a DC motor, a gearbox, friction, the firmware's
P law and a pendulum (leglab.bus.physics): not the model leglab fits."""

import json
import os

import numpy as np
import pytest

from conftest import read_csv, run_program

from leglab import servo
from leglab.bus import cli, trajectories

BAM_FOUR = ("lift_and_drop", "sin_time_square", "up_and_down", "sin_sin")

# (protocol, emulated model, the logs' motor name, kp register, mass_kg, length_m): an XL330 on
# BAM's pendulum, and an SO-101's STS3215 with a 0.5 kg load at 12 cm.
BENCHES = {
    "dynamixel": ("dynamixel", "xl330-m288", "xl330", 400, 0.49, 0.1),
    "feetech": ("feetech", "sts3215", "sts3215", 32, 0.5, 0.12),
}


def pick_and_place_csv(path):
    """The docs' pick-and-place motion (trajectories.pick_and_place_deg), written as a desired
    CSV; returns its angles."""
    desired = np.array(trajectories.pick_and_place_deg())
    trajectories.write_desired_csv(path, desired)
    return desired


def bus_args(bench, port=None):
    protocol, model, _, kp, mass, length = bench
    return ["--port", port or f"emulator:{model}", "--protocol", protocol, "--id", "1",
            "--kp", str(kp), "--mass-kg", str(mass), "--length-m", str(length)]


@pytest.fixture(scope="module", params=sorted(BENCHES))
def session(request, tmp_path_factory):
    """Recorded, fitted and run once per protocol: (bench, folder, {method: run.json})."""
    bench = BENCHES[request.param]
    folder = tmp_path_factory.mktemp(request.param)
    assert cli.main(["record", *bus_args(bench), "--motor", bench[2], "--trajectory",
                     ",".join(BAM_FOUR), "--out", str(folder / "logs")]) == 0
    fitted = run_program("identify", "--config", "experiments/configs/identify_logs.yaml",
                         "--out", folder / "fit", "--set", f"logs.train=[{folder / 'logs'}]",
                         "--set", "logs.cross_validate=none")
    assert fitted.returncode == 0, fitted.stderr
    pick_and_place_csv(folder / "pick.csv")
    runs = {}
    for method in ("direct", "model_based"):
        out = folder / f"run_{method}"
        assert cli.main(["run", *bus_args(bench), "--model", str(folder / "fit" / "log_fit.json"),
                         "--desired", str(folder / "pick.csv"), "--method", method,
                         *(["--online"] if method != "direct" else []),
                         "--out", str(out)]) == 0
        with open(out / "run.json") as f:
            runs[method] = json.load(f)
    return bench, folder, runs


def test_the_logs_carry_what_identify_needs(session):
    bench, folder, _ = session
    _, _, motor, kp, mass, length = bench
    for name in BAM_FOUR:
        log = servo.read_log(folder / "logs" / f"{name}_kp{kp}_id1.json")  # no extra keys
        assert (log.motor, log.kp, log.mass_kg, log.length_m, log.trajectory) == (
            motor, kp, mass, length, name)
        # One sample a tick of 5 ms, for the trajectory's 6 s; the request is the trajectory's
        # at the sample's time, to the count it was sent as.
        assert len(log) == 1201
        assert np.allclose(np.diff(log.time_s), 0.005, atol=1e-9)
        expected = [trajectories.sample(name, t) for t in log.time_s]
        torque = np.array([on for _, on in expected])
        assert np.array_equal(log.torque_enabled, torque)
        sent = log.request_deg[torque]
        assert np.max(np.abs(sent - np.array([r for r, _ in expected])[torque])) <= 360 / 4096


def test_online_model_based_halves_directs_error_on_a_motion_no_log_holds(session):
    _, _, runs = session
    assert runs["model_based"]["mae_deg"] <= 0.5 * runs["direct"]["mae_deg"]
    for run in runs.values():
        assert run["ended"] == "completed" and run["ticks"] == 620 and run["ticks_late"] == 0
        assert run["retries"] == 0 and run["errors"] == 0


def test_run_json_is_run_csvs_errors(session):
    _, folder, runs = session
    for method, summary in runs.items():
        rows = read_csv(folder / f"run_{method}" / "run.csv")
        assert list(rows) == ["time_s", "desired_deg", "request_deg", "measured_deg", "late"]
        error = rows["measured_deg"] - rows["desired_deg"]
        assert summary["mae_deg"] == pytest.approx(np.mean(np.abs(error)), rel=1e-12)
        assert summary["rms_deg"] == pytest.approx(np.sqrt(np.mean(error ** 2)), rel=1e-12)
        assert summary["max_abs_deg"] == pytest.approx(np.max(np.abs(error)), rel=1e-12)
        # Angles are read and sent as whole counts of the servo's 4096 a turn.
        zero = summary["servos"]["1"]["zero_deg"]
        for column in ("measured_deg", "request_deg"):
            counts = (rows[column] + zero) * 4096 / 360
            assert np.allclose(counts, np.round(counts), atol=1e-6)
        if method == "direct":  # the desired angles sent as they are, to the count
            assert np.max(np.abs(rows["request_deg"] - rows["desired_deg"])) <= 360 / 4096 / 2


def test_virtual_time_gives_the_same_bits(session, tmp_path):
    bench = session[0]
    logs = []
    for n in range(2):
        assert cli.main(["record", *bus_args(bench), "--motor", bench[2], "--trajectory",
                         "steps", "--out", str(tmp_path / str(n))]) == 0
        with open(tmp_path / str(n) / f"steps_kp{bench[3]}_id1.json", "rb") as f:
            logs.append(f.read())
    assert logs[0] == logs[1]


def test_six_servos_each_with_its_own_load_and_motion_one_read_and_write_a_tick(session,
                                                                               tmp_path):
    bench, folder, _ = session
    protocol, model, motor, kp, _, _ = bench
    pick = pick_and_place_csv(tmp_path / "pick.csv")
    with open(tmp_path / "mirror.csv", "w") as f:  # the same motion, mirrored
        f.write("time_s,desired_deg\n")
        f.writelines(f"{k * 0.005!r},{-d!r}\n" for k, d in enumerate(pick))
    loads = {1: 0.1, 2: 0.2, 3: 0.3, 4: 0.4, 5: 0.5, 6: 0.6}
    lines = ["servos:"] + [
        f"  {i}: {{kp: {kp}, mass_kg: {m}, length_m: 0.1, desired: "
        f"{'mirror.csv' if i % 2 == 0 else 'pick.csv'}}}" for i, m in loads.items()]
    (tmp_path / "servos.yaml").write_text("\n".join(lines) + "\n")
    assert cli.main(["run", "--port", f"emulator:{model}", "--protocol", protocol, "--servos",
                     str(tmp_path / "servos.yaml"), "--model", str(folder / "fit" / "log_fit.json"),
                     "--motor", motor, "--method", "model_based", "--online",
                     "--out", str(tmp_path / "out")]) == 0
    with open(tmp_path / "out" / "run.json") as f:
        summary = json.load(f)
    assert sorted(summary["servos"]) == [str(i) for i in loads]
    for i, m in loads.items():
        rows = read_csv(tmp_path / "out" / f"run_id{i}.csv")
        assert len(rows["time_s"]) == 620
        sign = -1 if i % 2 == 0 else 1
        assert np.allclose(rows["desired_deg"], sign * pick, atol=1e-6)  # on the model tick
        assert summary["servos"][str(i)]["mass_kg"] == m
    # One sync read and one sync write a tick (no retry on a clean bus).
    assert summary["instructions"] == 2 * summary["ticks"] and summary["retries"] == 0


def test_the_example_drives_the_emulated_servo_closer_with_the_model(tmp_path):
    import subprocess
    import sys

    from conftest import SOURCE_DIR
    done = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "python" /
                                               "your_servo.py"), "--iterations", "100"],
                          capture_output=True, text=True, env={**os.environ}, timeout=300)
    assert done.returncode == 0, done.stderr
    measured = {line.split()[0]: float(line.split()[1]) for line in done.stdout.splitlines()
                if line.endswith("ticks late)")}
    assert measured["model_based"] < 0.5 * measured["direct"], done.stdout


def test_online_optimals_default_budget_on_a_port_is_half_the_tick_shared_among_the_servos():
    """Online optimal spends its budget, and a session's planners run one after another in the
    tick: on a port each of n servos gets half the tick over n; --budget-ms is each one's; an
    emulator's virtual time none (the iteration cap alone)."""
    from leglab.bus import verbs
    parser = cli.parser()
    port = parser.parse_args(["run", "--port", "/dev/ttyUSB0", "--id", "1", "--model", "m.json",
                              "--desired", "d.csv", "--method", "optimal", "--online", "--kp",
                              "400", "--mass-kg", "0.49", "--length-m", "0.1", "--out", "o"])
    tick_s = 0.0053
    assert verbs.budget_s(port, tick_s, 1) == tick_s / 2
    assert verbs.budget_s(port, tick_s, 6) == tick_s / 12
    port.budget_ms = 1.5
    assert verbs.budget_s(port, tick_s, 6) == 0.0015
    port.budget_ms = None
    port.port = "emulator:xl330-m288"
    assert verbs.budget_s(port, tick_s, 6) == 0.0
