"""leglab.bus against the faults a real bus has: lost and corrupt replies, a servo that stops
answering, a hardware error, a port that is missing or is no servo bus, bad input, a signal.
Each ends as the contract says: a retry that is counted and never a wrong angle, or exit 2
with one line naming the port and the servo, the torque off and the log kept."""

import json
import math
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import SOURCE_DIR, read_csv, run_program

from leglab import bus as lb
from leglab.bus import cli, trajectories
from test_bus_loop import BENCHES, bus_args, pick_and_place_csv

PYTHON_ENV = {**os.environ, "PYTHONPATH": os.environ.get("PYTHONPATH", "")}


def emulated_bus(protocol="dynamixel", model="xl330-m288", ids=(1,), faults=None, retries=2):
    emulator = lb.make_emulator(protocol, model, list(ids), 0.49, 0.1, faults=faults)
    clock = lb.VirtualClock()
    return lb.Bus(lb.VirtualPort(emulator, clock), protocol, retries=retries), emulator, clock


@pytest.mark.parametrize("protocol,model", [("dynamixel", "xl330-m288"), ("feetech", "sts3215")])
def test_lost_and_corrupt_replies_are_retried_and_never_a_wrong_angle(protocol, model):
    bus, _, _ = emulated_bus(protocol, model, faults=lb.Faults(drop_rate=0.2, corrupt_rate=0.2,
                                                               seed=3), retries=20)
    # Torque off, the load hanging still at its power-on count: every reading is that count.
    angles = [bus.read(1, "present_position") for _ in range(300)]
    assert set(angles) == {180.0}  # count 2048 of 4096
    assert bus.stats.retries > 50 and bus.stats.errors == 0
    assert bus.stats.retries == bus.stats.missing + bus.stats.corrupt
    assert bus.stats.corrupt > 0 and bus.stats.missing > 0


def test_a_reply_that_never_comes_names_port_servo_and_item():
    bus, _, _ = emulated_bus(faults=lb.Faults(silent_after_s=0.0))
    bus.set_table(1, lb.tables.TABLES["xl330-m288"])  # known, so no PING before the read
    with pytest.raises(lb.NoReply) as error:
        bus.read_raw(1, "present_position")
    assert str(error.value) == ("port emulator: servo 1 did not answer to read present_position "
                                "(3 tries)")
    assert bus.stats.retries == 2 and bus.stats.errors == 1


def test_an_eeprom_write_with_the_torque_on_is_refused_as_the_firmware_does():
    bus, emulator, _ = emulated_bus()
    bus.write_raw(1, "torque_enable", 1)
    with pytest.raises(lb.BusError, match="servo 1 refused to write return_delay_time: "
                                          "access error"):
        bus.write_raw(1, "return_delay_time", 0)
    assert emulator.servos[1].get("return_delay_time") == 250
    bus.write_raw(1, "torque_enable", 0)
    bus.write_raw(1, "return_delay_time", 0)
    assert emulator.servos[1].get("return_delay_time") == 0


def keep_emulators(monkeypatch):
    """The emulators the command line makes from now on, in a list it fills."""
    made = []
    real = cli.emulated_port

    def keep(*args, **kwargs):
        port, clock = real(*args, **kwargs)
        made.append(port.emulator)
        return port, clock

    monkeypatch.setattr(cli, "emulated_port", keep)
    return made


def run_with(tmp_path, monkeypatch, bench, port_spec, ids="1", method="direct"):
    """`run` on an emulated bus `port_spec`; returns (status, the emulator)."""
    made = keep_emulators(monkeypatch)
    model = str(tmp_path / "fit" / "log_fit.json")
    args = bus_args(bench, port_spec)
    args[args.index("--id") + 1] = ids
    status = cli.main(["run", *args, "--model", model, "--desired", str(tmp_path / "pick.csv"),
                       "--method", method, *(["--online"] if method != "direct" else []),
                       "--out", str(tmp_path / "out")])
    return status, made[0] if made else None


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """An XL330 bench recorded and fitted once (the module's runs need a model)."""
    folder = tmp_path_factory.mktemp("fitted")
    bench = BENCHES["dynamixel"]
    assert cli.main(["record", *bus_args(bench), "--motor", "xl330", "--trajectory",
                     "sin_time_square,up_and_down", "--out", str(folder / "logs")]) == 0
    assert run_program("identify", "--config", "experiments/configs/identify_logs.yaml", "--out",
                       folder / "fit", "--set", f"logs.train=[{folder / 'logs'}]", "--set",
                       "logs.cross_validate=none").returncode == 0
    pick_and_place_csv(folder / "pick.csv")
    return folder


@pytest.fixture
def bench_dir(fitted, tmp_path):
    for name in ("fit", "pick.csv"):
        os.symlink(fitted / name, tmp_path / name)
    return tmp_path


def test_lost_replies_in_a_run_are_retried_and_counted(bench_dir, monkeypatch, capsys):
    summaries = []
    for spec in ("emulator:xl330-m288", "emulator:xl330-m288,drop_rate=0.01,corrupt_rate=0.01"):
        status, _ = run_with(bench_dir, monkeypatch, BENCHES["dynamixel"], spec,
                             method="model_based")
        assert status == 0, capsys.readouterr().err
        with open(bench_dir / "out" / "run.json") as f:
            summaries.append(json.load(f))
    clean, faulty = summaries
    assert faulty["ended"] == "completed" and faulty["errors"] == 0 and clean["retries"] == 0
    assert faulty["retries"] > 0 and faulty["retries"] == faulty["missing"] + faulty["corrupt"]
    # A retry waits half a tick at most, so it fits in the tick: no tick is late, and the run
    # is near the clean one (a retried tick's request goes out up to half a tick later).
    rows = read_csv(bench_dir / "out" / "run.csv")
    assert faulty["ticks_late"] == int(rows["late"].sum()) == 0
    assert faulty["mae_deg"] <= 1.1 * clean["mae_deg"]


def test_a_servo_that_stops_answering_ends_the_run_with_the_others_torque_off(
        bench_dir, monkeypatch, capsys):
    status, emulator = run_with(bench_dir, monkeypatch, BENCHES["dynamixel"],
                                "emulator:xl330-m288,silent_after_s=4,silent_ids=2", ids="1,2")
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert len(err) == 1 and "port emulator:xl330-m288: servo 2 did not answer" in err[0], err
    assert emulator.servos[1].get("torque_enable") == 0
    for servo_id in (1, 2):  # the log, up to the fault
        rows = read_csv(bench_dir / "out" / f"run_id{servo_id}.csv")
        assert 0 < len(rows["time_s"]) < 620
    with open(bench_dir / "out" / "run.json") as f:
        assert "servo 2 did not answer" in json.load(f)["ended"]


def test_a_hardware_error_stops_the_run(bench_dir, monkeypatch, capsys):
    status, emulator = run_with(bench_dir, monkeypatch, BENCHES["dynamixel"],
                                "emulator:xl330-m288,hardware_error_after_s=4")
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "servo 1 reports a hardware error (overload)" in err[0], err
    assert 0 < len(read_csv(bench_dir / "out" / "run.csv")["time_s"]) < 620


def test_a_desired_angle_beyond_the_limits_is_refused_before_the_port_is_opened(bench_dir, capsys):
    args = bus_args(BENCHES["dynamixel"], "/dev/no-such-port")
    status = cli.main(["run", *args, "--model", str(bench_dir / "fit" / "log_fit.json"),
                       "--desired", str(bench_dir / "pick.csv"), "--method", "direct",
                       "--min-deg", "-20", "--out", str(bench_dir / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "the desired angle -20.0" in err[0] or "outside [--min-deg, --max-deg]" in err[0], err
    assert not (bench_dir / "out").exists()


def python_bus(*args, **kwargs):
    return subprocess.run([sys.executable, "-m", "leglab.bus", *map(str, args)],
                          capture_output=True, text=True, env=PYTHON_ENV, cwd=SOURCE_DIR, **kwargs)


def test_a_missing_port_is_one_line_and_exit_2():
    done = python_bus("scan", "--port", "/dev/no-such-port", timeout=60)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "leglab.bus scan: port /dev/no-such-port: no such device (is the adapter plugged in? "
        "`ls /dev/serial/by-id/` lists the USB ones)"]


def test_a_port_with_no_servo_on_it_is_one_line_and_exit_2():
    master, slave = os.openpty()  # a terminal nobody answers on
    try:
        path = os.ttyname(slave)
        done = python_bus("scan", "--port", path, "--ids", "1,2,3", timeout=60)
        assert done.returncode == 2
        assert done.stderr.strip().splitlines() == [
            f"leglab.bus scan: port {path}: no servo answered a PING (ids 1-3, dynamixel at "
            "1000000 baud): check the power, the protocol and the baud rate"]
        done = python_bus("record", "--port", path, "--id", "1", "--motor", "x", "--kp", "400",
                          "--mass-kg", "0.1", "--length-m", "0.1", "--trajectory", "steps",
                          "--out", "/tmp/never", timeout=60)
        assert done.returncode == 2
        assert done.stderr.strip().splitlines() == [
            f"leglab.bus record: port {path}: servo 1 did not answer to PING (3 tries)"]
    finally:
        os.close(master)
        os.close(slave)


def test_usage_errors_are_one_line_and_exit_2():
    done = python_bus("record", "--port", "x", "--id", "1,1", timeout=60)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "servo ids are distinct integers" in done.stderr


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_turns_the_torque_off_and_keeps_the_log(fitted, tmp_path, stop):
    """Sent mid-motion: exit 2, one line, the torque off (the line says so only when every
    servo acknowledged its torque-off write), run.csv up to there. On virtual time, so that a
    loaded machine cannot turn the test into one of the bus's timing."""
    long = tmp_path / "long.csv"
    trajectories.write_desired_csv(long, trajectories.pick_and_place_deg() * 40)  # 124 s
    run = subprocess.Popen(
        [sys.executable, "-m", "leglab.bus", "run", *bus_args(BENCHES["dynamixel"]), "--model",
         fitted / "fit" / "log_fit.json", "--desired", long, "--method", "model_based",
         "--online", "--zero-deg", "180", "--out", tmp_path / "out"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=PYTHON_ENV)
    assert run.stdout.readline().startswith("servo 1: ")  # the set-up: the loop comes next
    time.sleep(1.0)
    run.send_signal(stop)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 2, err
    assert err.strip().splitlines() == [
        f"leglab.bus run: stopped by {stop.name}; the torque is off and the log is written up "
        "to there"]
    rows = read_csv(tmp_path / "out" / "run.csv")
    assert 0 < len(rows["time_s"]) < 40 * 620


def test_a_session_on_a_pseudo_terminal_in_real_time(fitted, tmp_path):
    """The emulator on a pseudo-terminal, driven through pyserial as a real port: a run
    completes and leaves the torque off. Retries are generous: on a loaded machine the
    terminal's own kernel work can hold a reply for milliseconds."""
    emulate = subprocess.Popen(
        [sys.executable, "-m", "leglab.bus", "emulate", "--protocol", "dynamixel", "--motor",
         "xl330-m288", "--ids", "1", "--mass-kg", "0.49", "--length-m", "0.1"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=PYTHON_ENV)
    try:
        port = emulate.stdout.readline().strip()
        assert port.startswith("/dev/pts/"), port
        done = python_bus("run", *bus_args(BENCHES["dynamixel"], port), "--retries", "20",
                          "--model", fitted / "fit" / "log_fit.json", "--desired",
                          fitted / "pick.csv", "--method", "model_based", "--online",
                          "--zero-deg", "180", "--out", tmp_path, timeout=120)
        assert done.returncode == 0, done.stderr
        assert len(read_csv(tmp_path / "run.csv")["time_s"]) == 620
        scan = python_bus("scan", "--port", port, "--ids", "1", timeout=60)
        assert scan.returncode == 0, scan.stderr
        header, row = scan.stdout.splitlines()[:2]
        assert row.split()[header.split().index("torque")] == "0"
    finally:
        emulate.send_signal(signal.SIGTERM)
        emulate.wait(timeout=30)


def test_a_limit_of_minus_one_is_a_limit(bench_dir, capsys):
    args = bus_args(BENCHES["dynamixel"], "emulator:xl330-m288")
    status = cli.main(["run", *args, "--model", str(bench_dir / "fit" / "log_fit.json"),
                       "--desired", str(bench_dir / "pick.csv"), "--method", "direct",
                       "--min-deg", "-40", "--max-deg", "-1", "--out", str(bench_dir / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "is outside [--min-deg, --max-deg] = [-40, -1] deg: nothing moved" in err[0], err


def test_a_zero_near_the_encoders_seam_reads_across_it_and_limits_the_motion(bench_dir, capsys):
    """An STS3215 (one turn of 4096 counts, position limits 0 and 4095) whose load hangs at
    1 deg of its scale: the zero is found there, the readings either side of it are the angles
    next to it, and a motion below it, past the limit at 0, is refused before anything moves."""
    desired = bench_dir / "up.csv"
    with open(desired, "w") as f:  # 0 -> 40 -> 0 deg over 2 s: above the zero only
        f.write("time_s,desired_deg\n")
        f.writelines(f"{k * 0.005!r},{40 * math.sin(math.pi * k / 400)!r}\n" for k in range(401))
    protocol, _, _, kp, mass, length = BENCHES["feetech"]
    common = ["--protocol", protocol, "--id", "1", "--kp", str(kp), "--mass-kg", str(mass),
              "--length-m", str(length), "--model", str(bench_dir / "fit" / "log_fit.json"),
              "--method", "direct", "--out", str(bench_dir / "out")]
    for hang, motion, status in ((1, desired, 0), (1, bench_dir / "pick.csv", 2)):
        result = cli.main(["run", "--port", f"emulator:sts3215,hang_deg={hang}", *common,
                           "--desired", str(motion)])
        err = capsys.readouterr().err.strip().splitlines()
        assert result == status, err
    assert "outside the servo's position limits from its zero = [-0.9" in err[0], err
    with open(bench_dir / "out" / "run.json") as f:
        summary = json.load(f)
    assert summary["servos"]["1"]["zero_deg"] == pytest.approx(1.0, abs=0.1)
    assert summary["mae_deg"] < 10  # read across the seam, an angle would be 360 deg off
    # Released 20 deg off a hanging point on the seam itself: it swings across it and comes
    # to rest within its static friction band, and the zero is found there (not half a turn
    # away, the mean of readings near 4095 and near 0).
    from leglab.bus import emulator, session
    emulated = emulator.make_emulator("feetech", "sts3215", [1], 0.5, 0.12, hang_count=0,
                                      angle_deg=20.0)
    clock = lb.VirtualClock()
    with lb.Bus(lb.VirtualPort(emulated, clock), "feetech") as b:
        zero = session.find_zero(b, clock, [1], lambda line: None)[1]
    assert min(zero, 360 - zero) < 10
    # A reading one count either side of the seam is the angle one count from the zero.
    assert session.from_count(4095, 0.0) == -360 / 4096
    assert session.from_count(0, 360 - 360 / 4096) == 360 / 4096


@pytest.mark.parametrize("args,words", [
    (["--port", "emulator:foo"], "unknown servo model 'foo'"),
    (["--port", "emulator:xl330-m288", "--protocol", "feetech"], "speaks dynamixel, not feetech"),
    (["--port", "emulator:xl330-m288,angle_deg=nan"], "angle_deg=nan"),
    (["--port", "emulator:xl330-m288,drop_rate=2"], "drop_rate=2"),
    (["--port", "emulator:xl330-m288", "--out", ""], "--out: an empty path"),
])
def test_bad_emulator_specs_and_paths_are_one_line_and_exit_2(args, words, capsys, tmp_path):
    base = ["record", "--port", "emulator:xl330-m288", "--id", "1", "--motor", "m", "--kp",
            "400", "--mass-kg", "0.1", "--length-m", "0.1", "--trajectory", "steps", "--out",
            str(tmp_path / "logs")]
    for flag_at in range(0, len(args), 2):  # the case's flags replace or join the base's
        flag = args[flag_at]
        if flag in base:
            base[base.index(flag) + 1] = args[flag_at + 1]
        else:
            base += args[flag_at:flag_at + 2]
    assert cli.main(base) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err


def test_a_model_file_of_the_wrong_shape_is_one_line(bench_dir, capsys, tmp_path):
    for text in ("[]", '{"models": 5}'):
        (tmp_path / "bad.json").write_text(text)
        args = bus_args(BENCHES["dynamixel"], "emulator:xl330-m288")
        assert cli.main(["run", *args, "--model", str(tmp_path / "bad.json"), "--desired",
                         str(bench_dir / "pick.csv"), "--method", "direct", "--out",
                         str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("leglab.bus run: --model: "), err


def test_an_output_that_is_not_a_regular_file_is_refused_before_the_port_is_opened(
        bench_dir, capsys, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / "run.csv")
    args = bus_args(BENCHES["dynamixel"], "/dev/no-such-port")
    assert cli.main(["run", *args, "--model", str(bench_dir / "fit" / "log_fit.json"),
                     "--desired", str(bench_dir / "pick.csv"), "--method", "direct",
                     "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"leglab.bus run: '{out / 'run.csv'}': exists and is not a regular file; "
                   "leglab replaces only its own files"]


def test_a_port_that_fails_is_a_bus_error_naming_it():
    class Unplugged:
        name, timeout = "/dev/ttyUSB9", 0.02

        def reset_input_buffer(self):
            raise OSError(5, "Input/output error")

        def close(self):
            pass

    with lb.Bus(Unplugged(), "dynamixel") as bus:
        with pytest.raises(lb.BusError, match=r"^port /dev/ttyUSB9: lost: Input/output error$"):
            bus.ping(1)


def test_a_trajectory_beyond_the_servos_position_limits_is_refused_before_it_moves(
        tmp_path, capsys, monkeypatch):
    made = keep_emulators(monkeypatch)
    status = cli.main(["record", "--port", "emulator:sts3215,hang_deg=30", "--protocol",
                       "feetech", "--id", "1", "--motor", "s", "--kp", "32", "--mass-kg", "0.5",
                       "--length-m", "0.12", "--trajectory", "sin_sin", "--out",
                       str(tmp_path / "logs")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "trajectory sin_sin spans [-100.795, 100.795] deg, beyond the servo's position " \
           "limits from its zero" in err[0], err
    assert made[0].servos[1].get("torque_enable") == 0  # never turned on
    assert not (tmp_path / "logs").exists()  # refused before it recorded: nothing left


def _hostile_files(folder):
    """The files the hostile cases below name, made in `folder`."""
    (folder / "afile").write_text("x")
    (folder / "realdir").mkdir()
    os.symlink(folder / "realdir", folder / "linkdir")
    os.mkfifo(folder / "fifo")
    (folder / "twice.yaml").write_text("servos:\n  1: {kp: 400}\n  1: {kp: 300}\n")
    (folder / "deep.yaml").write_text("servos:\n  1: {kp: " + "[" * 3000 + "\n")
    (folder / "binary.csv").write_bytes(bytes(range(256)) * 4)


HOSTILE = [  # (extra arguments of `run` on the XL330 bench, words its one line holds)
    (["--out", "{d}/afile/"], "exists and is not a folder"),
    (["--out", "{d}/linkdir"], "is a symbolic link"),
    (["--out", "/proc"], "cannot be written"),
    (["--out", "{d}/o", "--desired", "{d}/o/run.csv"], "no such file"),
    (["--out", "{d}", "--desired", "{d}/run.csv"], "is the input file"),
    (["--servos", "{d}/twice.yaml"], "the key 1 is given twice"),
    (["--servos", "{d}/deep.yaml"], "--servos"),
    (["--servos", "{d}/fifo"], "is not a regular file"),
    (["--model", "{d}/fifo"], "--model '"),
    (["--desired", "{d}/fifo"], "is not a regular file"),
    (["--desired", "{d}/binary.csv"], "--desired"),
    (["--kp", "0"], "kp must be in"),
    (["--method", "optimal", "--online", "--preview-ticks", "0"], "too short for the optimal"),
    (["--preview-ticks", "5"], "--preview-ticks: only with --online"),
    (["--online"], "--online: only with a planned method"),
    (["--port", "emulator:xl330-m288,hang_deg=inf"], "hang_deg=inf"),
    (["--port", "emulator:xl330-m288,kp=99999"], "kp=99999"),
    (["--port", "emulator:xl330-m288,silent_ids=9"], "silent_ids=9"),
    (["--port", "emulator:xl330-m288,seed=1,seed=2"], "given twice"),
]


@pytest.mark.parametrize("extra,words", HOSTILE)
def test_hostile_input_is_one_line_and_exit_2_before_anything_moves(
        bench_dir, tmp_path, capsys, extra, words):
    _hostile_files(tmp_path)
    (tmp_path / "run.csv").write_text("time_s,desired_deg\n0,0\n0.005,0\n")
    args = dict(zip(*[iter(["--port", "emulator:xl330-m288", "--model",
                            str(bench_dir / "fit" / "log_fit.json"), "--desired",
                            str(bench_dir / "pick.csv"), "--method", "direct",
                            "--out", str(tmp_path / "out")])] * 2))
    flags = []
    for i, item in enumerate(extra):
        item = item.replace("{d}", str(tmp_path))
        if item.startswith("--") and item in args and i + 1 < len(extra) and \
                not extra[i + 1].startswith("--"):
            args[item] = None  # replaced by the case's value, which follows
        flags.append(item)
    base = [x for k, v in args.items() if v is not None for x in (k, v)]
    command = ["run", "--protocol", "dynamixel", "--id", "1", "--kp", "400", "--mass-kg", "0.49",
               "--length-m", "0.1", *base, *flags]
    if "--kp" in flags:
        command = command[:command.index("--kp")] + command[command.index("--kp") + 2:]
    assert cli.main(command) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err
    assert "zero" not in captured.out and "servo 1:" not in captured.out, captured.out


def test_emulate_refuses_a_link_that_exists_and_a_protocol_its_servo_does_not_speak(tmp_path):
    (tmp_path / "taken").write_text("x")
    base = ["emulate", "--motor", "xl330-m288", "--ids", "1", "--mass-kg", "0.1",
            "--length-m", "0.1"]
    for extra, words in ((["--protocol", "dynamixel", "--link", tmp_path / "taken"],
                          "exists; leglab makes only a new link"),
                         (["--protocol", "feetech"], "speaks dynamixel, not feetech")):
        done = python_bus(*base, *extra, timeout=60)
        assert done.returncode == 2, done.stderr
        assert len(done.stderr.strip().splitlines()) == 1 and words in done.stderr, done.stderr
    assert (tmp_path / "taken").read_text() == "x"
