"""leglab.servo.learned: the learned rungs (PyTorch) trained at a small size on synthetic
servos whose behaviour is written here, scored as identify scores, reproducibly."""

import subprocess
import sys

import numpy as np
import pytest

from leglab.servo import learned as learned_fit  # torch: imported when a network is trained

torch = pytest.importorskip("torch", reason="PyTorch is not installed (python3-torch)")

SMALL = {"teacher_steps": 100, "teacher_batch": 16, "piece": 16, "steps": 60, "batch": 16,
         "window": 16, "grid_mlp": [(3, 8)], "grid_lstm": [(1, 8)]}


def lag_servo(requests, gain=0.3, start=0.0):
    """A servo written here: one tick of lag, then a first-order approach,
    M(t+1) = M(t) + gain (R(t-1) - M(t))."""
    angles = [start]
    for t in range(len(requests) - 1):
        acting = requests[max(t - 1, 0)]
        angles.append(angles[-1] + gain * (acting - angles[-1]))
    return np.array(angles)


def synthetic_log(seed, ticks=300, off=()):
    rng = np.random.default_rng(seed)
    requests = np.cumsum(rng.normal(0.0, 2.0, ticks))
    driven = np.ones(ticks, dtype=bool)
    for begin, end in off:
        driven[begin:end] = False
    return {"request": requests, "measured": lag_servo(requests), "driven": driven,
            "kp": 400.0, "load_nm": 0.0, "tick_s": 0.005, "row": {}}


def test_the_same_seed_trains_the_same_network_and_the_same_numbers():
    logs = [synthetic_log(1), synthetic_log(2)]
    held_out = synthetic_log(3)
    results = []
    for _ in range(2):
        torch.set_num_threads(1)
        net, scale = learned_fit.train("mlp", 3, 8, logs, SMALL, seed=5)
        mae, predicted = learned_fit.score(net, "mlp", 3, scale, held_out)
        results.append((mae, predicted, [p.detach().numpy().copy() for p in net.parameters()]))
    assert results[0][0] == results[1][0]
    np.testing.assert_array_equal(results[0][1], results[1][1])
    for a, b in zip(results[0][2], results[1][2]):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("form, history", [("mlp", 3), ("lstm", 1)])
def test_a_network_that_outputs_nothing_scores_the_start_angle_held_by_hand(form, history):
    # Torque off over ticks 100..140: two runs, each predicted at its first tick's angle.
    log = synthetic_log(4, off=[(100, 140)])
    net = learned_fit.make_net(form, history, 8).double()
    last = net[-1] if form == "mlp" else net["out"]
    with torch.no_grad():
        last.weight.zero_()
        last.bias.zero_()
    mae, predicted = learned_fit.score(net, form, history, (1.0, 1.0, 1.0), log)
    m = log["measured"]
    expected = np.concatenate([np.abs(m[0:100] - m[0]), np.abs(m[140:] - m[140])]).mean()
    assert mae == pytest.approx(expected, rel=1e-12)
    np.testing.assert_array_equal(predicted[100:140], m[100:140])  # not driven: left as measured


def test_a_run_of_one_driven_tick_is_scored_at_its_measured_angle():
    # Driven ticks 0 and 5 alone, and 10..: the one-tick runs are their own start (error 0).
    log = synthetic_log(6, ticks=40, off=[(1, 5), (6, 10)])
    net = learned_fit.make_net("mlp", 2, 4).double()
    mae, predicted = learned_fit.score(net, "mlp", 2, (1.0, 1.0, 1.0), log)
    assert predicted[0] == log["measured"][0] and predicted[5] == log["measured"][5]
    driven = log["driven"]
    assert mae == pytest.approx(np.abs(predicted[driven] - log["measured"][driven]).mean())
    only_starts = synthetic_log(7, ticks=6, off=[(1, 3), (4, 6)])
    assert learned_fit.score(net, "mlp", 2, (1.0, 1.0, 1.0), only_starts)[0] == 0.0


def test_trained_on_a_lagging_servo_it_predicts_a_log_it_never_saw():
    logs = [synthetic_log(s) for s in (10, 11, 12)]
    held_out = synthetic_log(13)
    direct = np.abs(held_out["request"] - held_out["measured"]).mean()
    torch.set_num_threads(1)
    net, scale = learned_fit.train("mlp", 3, 8, logs, SMALL, seed=1)
    mae, _ = learned_fit.score(net, "mlp", 3, scale, held_out)
    assert mae < 0.5 * direct, (mae, direct)


def test_each_fold_trains_on_every_log_but_the_ones_it_holds_out():
    def row(f, trajectory, kp):
        return {"file": f, "role": "train", "motor": "m", "trajectory": trajectory, "kp": kp}
    rows = [row("a1", "a", 100.0), row("a2", "a", 400.0), row("b1", "b", 100.0),
            row("c1", "c", 400.0)]
    fit = {"cross_validate": "leave_one_trajectory_out", "logs": rows,
           "folds": [{"motor": "m", "held_out": t} for t in "abc"]}
    jobs = learned_fit.model_jobs(fit)
    assert jobs[0] == ("m", None, ["a1", "a2", "b1", "c1"], ["a1", "a2", "b1", "c1"])
    assert jobs[1] == ("m", "a", ["b1", "c1"], ["a1", "a2"])
    assert jobs[3] == ("m", "c", ["a1", "a2", "b1"], ["c1"])
    fit = {"cross_validate": "leave_one_kp_out", "logs": rows,
           "folds": [{"motor": "m", "held_out": "kp 100"}]}
    assert learned_fit.model_jobs(fit)[1] == ("m", "kp 100", ["a2", "c1"], ["a1", "b1"])


def test_the_learning_curve_trains_on_every_subset_of_the_other_groups():
    def row(f, trajectory):
        return {"file": f, "role": "train", "motor": "m", "trajectory": trajectory, "kp": 1.0}
    rows = [row(t + "1", t) for t in "abcd"] + [row("a2", "a")]
    fit = {"cross_validate": "leave_one_trajectory_out", "logs": rows, "folds": []}
    jobs = learned_fit.curve_jobs(fit, "m")
    # 4 held-out groups, each with C(3,1) + C(3,2) + C(3,3) = 7 training sets.
    assert len(jobs) == 28
    held_a = [j for j in jobs if j[1] == "a"]
    assert [sorted(j[2]) for j in held_a] == [["b1"], ["c1"], ["d1"], ["b1", "c1"],
                                              ["b1", "d1"], ["c1", "d1"], ["b1", "c1", "d1"]]
    assert all(j[3] == ["a1", "a2"] for j in held_a)
    with pytest.raises(learned_fit.UserError, match="at least 3"):
        learned_fit.curve_jobs(fit | {"logs": rows[:2]}, "m")


def test_a_folder_identify_did_not_write_is_one_line_exit_2_and_nothing_written(tmp_path):
    (tmp_path / "log_fit.json").write_text("{not json", encoding="utf-8")
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, "-m", "leglab.servo.learned", str(tmp_path),
                             "--out", str(out)], capture_output=True, text=True, check=False)
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "log_fit.json" in result.stderr
    assert not out.exists()
