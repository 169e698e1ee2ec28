"""Tests of leglab.envs.LegTrackingEnv: its spaces, episodes, seeding and scoring.

The expected values are derived apart from the env: the joint limits from Plant.robot, the
episode's plant readings from Plant.run on the same requests and seed, the foot error from
Robot.foot_mm and Walk.foot_mm.
"""

import numpy as np
import pytest

import leglab
from leglab.envs import SEED_MAX, LegTrackingEnv

CONFIG = leglab.config_path("track.yaml")


def run_episode(env, actions=None, seed=None):
    """Runs one episode (zero actions unless `actions`, one row a tick); returns the
    observations (reset's first), the rewards, the truncated flags and the infos."""
    obs, _ = env.reset(seed=seed)
    observations, rewards, truncated, infos = [obs], [], [], []
    for t in range(env.episode_ticks):
        action = np.zeros(3) if actions is None else actions[t]
        obs, reward, term, trunc, info = env.step(action)
        assert term is False
        observations.append(obs)
        rewards.append(reward)
        truncated.append(trunc)
        infos.append(info)
    return np.array(observations), np.array(rewards), truncated, infos


def plant_run(overrides, seed, requests, start):
    """The readings of a fresh plant of `overrides` with `seed`, at rest at `start`, under
    `requests` (Plant.run)."""
    plant = leglab.Plant(CONFIG, {**overrides, "seed": seed})
    plant.reset(start)
    return plant.run(requests)


def test_spaces_have_the_documented_shapes_and_bounds():
    """Action bounds are the robot's limits (request) or +-their span (offset); the observation
    is 3 * (history + preview) long, unbounded where measured, within the limits where desired."""
    limits = leglab.Plant(CONFIG).robot.limits_deg
    request = LegTrackingEnv(history=3, preview=2, action="request")
    assert request.action_space.shape == (3,)
    assert request.action_space.dtype == np.float64
    np.testing.assert_array_equal(request.action_space.low, limits[:, 0])
    np.testing.assert_array_equal(request.action_space.high, limits[:, 1])
    assert request.observation_space.shape == (3 * (3 + 2),)
    # Measured part unbounded, desired part within the limits.
    assert np.all(np.isinf(request.observation_space.low[:9]))
    np.testing.assert_array_equal(request.observation_space.low[9:], np.tile(limits[:, 0], 2))
    np.testing.assert_array_equal(request.observation_space.high[9:], np.tile(limits[:, 1], 2))

    offset = LegTrackingEnv(action="offset")
    span = limits[:, 1] - limits[:, 0]
    np.testing.assert_array_equal(offset.action_space.high, span)
    np.testing.assert_array_equal(offset.action_space.low, -span)
    assert offset.observation_space.shape == (3 * (4 + 4),)

    offset.reset(seed=2)
    for _ in range(50):
        assert offset.action_space.contains(offset.action_space.sample())
    assert not offset.action_space.contains(np.zeros(2))
    assert not offset.action_space.contains(np.array([0.0, np.nan, 0.0]))
    assert not offset.action_space.contains(span + 1.0)


def test_an_episode_is_steps_times_the_period_and_truncates_at_its_end():
    """steps * T ticks (T from leglab.Walk), truncated only on the last, then no more steps."""
    env = LegTrackingEnv(steps=2)
    assert env.period == leglab.Walk(CONFIG).period
    assert env.episode_ticks == 2 * env.period
    _, rewards, truncated, infos = run_episode(env, seed=1)
    assert len(rewards) == 2 * env.period
    assert truncated == [False] * (2 * env.period - 1) + [True]
    assert [info["tick"] for info in infos] == list(range(2 * env.period))
    with pytest.raises(RuntimeError):
        env.step(np.zeros(3))


def test_step_before_reset_is_an_error():
    """step() before any reset() is a RuntimeError."""
    with pytest.raises(RuntimeError):
        LegTrackingEnv().step(np.zeros(3))


def test_the_same_seed_gives_identical_episodes_and_another_seed_differs():
    """Bit-for-bit repeats of one seed, in one env and in a second; another seed's noise
    differs."""
    env = LegTrackingEnv(steps=1, action="offset")
    obs_a, rewards_a, _, _ = run_episode(env, seed=11)
    obs_b, rewards_b, _, _ = run_episode(env, seed=11)
    assert np.array_equal(obs_a, obs_b)
    assert np.array_equal(rewards_a, rewards_b)
    # A second env of the same arguments too.
    obs_c, rewards_c, _, _ = run_episode(LegTrackingEnv(steps=1, action="offset"), seed=11)
    assert np.array_equal(obs_a, obs_c)
    assert np.array_equal(rewards_a, rewards_c)
    obs_d, rewards_d, _, _ = run_episode(env, seed=12)
    assert not np.array_equal(obs_a, obs_d)
    assert not np.array_equal(rewards_a, rewards_d)


def test_unseeded_resets_repeat_the_sequence_of_the_first_seed():
    """reset(seed=5), reset(), reset() gives the same three episodes every time, of three seeds."""
    def sequence():
        """The seeds and episodes of a fresh env's three resets."""
        env = LegTrackingEnv(steps=1, action="offset")
        seeds, episodes = [], []
        for seed in (5, None, None):
            obs, rewards, _, _ = run_episode(env, seed=seed)
            seeds.append(env.episode_seed)
            episodes.append((obs, rewards))
        return seeds, episodes

    seeds_a, episodes_a = sequence()
    seeds_b, episodes_b = sequence()
    assert seeds_a == seeds_b
    assert seeds_a[0] == 5
    assert len(set(seeds_a)) == 3
    assert all(0 <= s <= SEED_MAX for s in seeds_a)
    for (obs_a, rew_a), (obs_b, rew_b) in zip(episodes_a, episodes_b):
        assert np.array_equal(obs_a, obs_b)
        assert np.array_equal(rew_a, rew_b)
    # The episodes of different seeds differ.
    assert not np.array_equal(episodes_a[1][1], episodes_a[2][1])


@pytest.mark.parametrize("overrides", [{}, {"plant": "model"}], ids=["sim", "model"])
def test_zero_offsets_request_the_desired_angles_and_score_as_plant_run(overrides):
    """Zero offsets request the walk's angles; the readings and rewards are those of Plant.run
    on the same requests and seed, scored with Robot.foot_mm and Walk.foot_mm."""
    steps, seed = 2, 7
    env = LegTrackingEnv(overrides=overrides, steps=steps, action="offset")
    _, rewards, _, infos = run_episode(env, seed=seed)

    walk = leglab.Walk(CONFIG, overrides)
    requests = np.tile(walk.angles_deg, (steps, 1))
    np.testing.assert_array_equal(np.array([i["request_deg"] for i in infos]), requests)

    run = plant_run(overrides, seed, requests, walk.angles_deg[0])
    np.testing.assert_array_equal(np.array([i["measured_deg"] for i in infos]), run["measured"])
    np.testing.assert_array_equal(np.array([i["true_deg"] for i in infos]), run["true"])
    feet = walk.robot.foot_mm(run["measured"])
    error_cm = np.linalg.norm(feet - np.tile(walk.foot_mm, (steps, 1)), axis=1) / 10.0
    np.testing.assert_allclose(rewards, -error_cm, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose([i["foot_error_cm"] for i in infos], error_cm, rtol=1e-12,
                               atol=1e-12)
    # The walk is reachable and the servos lag it: the foot is off its path, by centimetres
    # (not metres).
    assert 0.0 < np.mean(error_cm) < 10.0


def test_request_actions_of_the_desired_angles_equal_zero_offsets():
    """Requesting the desired angles is the same episode as zero offsets."""
    offset = LegTrackingEnv(steps=1, action="offset")
    request = LegTrackingEnv(steps=1, action="request")
    obs_o, rew_o, _, _ = run_episode(offset, seed=3)
    obs_r, rew_r, _, _ = run_episode(request, actions=offset._desired, seed=3)
    assert np.array_equal(obs_o, obs_r)
    assert np.array_equal(rew_o, rew_r)


def test_the_observation_is_the_measured_history_then_the_desired_preview():
    """Each observation is Plant.run's measured rows (start pose before the first tick), then
    the walk's next desired rows, cyclic."""
    history, preview, steps, seed = 3, 5, 1, 9
    env = LegTrackingEnv(steps=steps, history=history, preview=preview, action="offset")
    observations, _, _, _ = run_episode(env, seed=seed)
    walk = leglab.Walk(CONFIG)
    T = walk.period
    run = plant_run({}, seed, np.tile(walk.angles_deg, (steps, 1)), walk.angles_deg[0])
    # Rows of measured angles with the start pose before the first tick.
    measured = np.vstack([np.tile(walk.angles_deg[0], (history, 1)), run["measured"]])
    assert observations.shape == (steps * T + 1, 3 * (history + preview))
    for t, obs in enumerate(observations):
        np.testing.assert_array_equal(obs[:3 * history], measured[t:t + history].ravel())
        rows = [(t + k) % T for k in range(preview)]
        np.testing.assert_array_equal(obs[3 * history:], walk.angles_deg[rows].ravel())
        assert env.observation_space.contains(obs)


@pytest.mark.parametrize(
    "action, words",
    [(np.zeros(2), "shape (2,)"), (np.zeros((3, 1)), "shape (3, 1)"),
     ([0.0, float("nan"), 0.0], "abductor"), ([0.0, 0.0, float("inf")], "knee"),
     ([True, False, True], "dtype bool"),
     (np.array([1 + 1j, 0, 0]), "dtype complex128")])
def test_bad_actions_raise_value_error_naming_the_action(action, words):
    """Wrong shapes, NaN, inf and text raise ValueError naming the action (and the joint), and
    run no tick."""
    env = LegTrackingEnv(steps=1, action="offset")
    env.reset(seed=1)
    with pytest.raises(ValueError, match="action") as error:
        env.step(action)
    assert words in str(error.value)
    # The bad action ran no tick.
    assert env.tick == 0
    env.step(np.zeros(3))
    assert env.tick == 1


@pytest.mark.parametrize("seed", [-1, SEED_MAX + 1])
def test_bad_seeds_raise_value_error_naming_the_seed(seed):
    """Negative and too large seeds raise ValueError naming the seed."""
    with pytest.raises(ValueError, match="seed"):
        LegTrackingEnv(steps=1).reset(seed=seed)


# TypeError for a wrong type, as everywhere in the package (these were ValueError before the
# package followed Python's convention; CHANGELOG.md, Changed).
@pytest.mark.parametrize("seed", [1.5, True, "3"])
def test_seeds_of_the_wrong_type_raise_type_error_naming_the_seed(seed):
    """Fractional, boolean and text seeds raise TypeError naming the seed."""
    with pytest.raises(TypeError, match="seed") as error:
        LegTrackingEnv(steps=1).reset(seed=seed)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("action", ["abc", None, {}, object()])
def test_an_action_that_is_no_array_raises_type_error_naming_the_action(action):
    """Text, None, a dict or an object is no action: TypeError naming it, and no tick run."""
    env = LegTrackingEnv(steps=1, action="offset")
    env.reset(seed=1)
    with pytest.raises(TypeError, match="action") as error:
        env.step(action)
    assert "\n" not in str(error.value)
    assert env.tick == 0


def test_arguments_of_the_wrong_type_raise_type_error_naming_them():
    """A bool or text where an integer goes, a list for overrides, a number for action."""
    with pytest.raises(TypeError, match="preview: expected an integer, got bool"):
        LegTrackingEnv(preview=True)
    with pytest.raises(TypeError, match="steps: expected an integer, got str"):
        LegTrackingEnv(steps="4")
    with pytest.raises(TypeError, match="overrides"):
        LegTrackingEnv(overrides=[("plant", "model")])
    with pytest.raises(TypeError, match="action"):
        LegTrackingEnv(action=1)


def test_numpy_integer_seeds_and_the_largest_seed_are_taken():
    """A numpy integer and SEED_MAX (the config key's upper bound) are valid seeds."""
    env = LegTrackingEnv(steps=1)
    env.reset(seed=np.uint64(4))
    assert env.episode_seed == 4
    env.reset(seed=SEED_MAX)
    assert env.episode_seed == SEED_MAX
    # SEED_MAX comes from the seed key's declaration ([0, 9.2e18], docs/configuration.md): the
    # plant takes it as its seed and refuses a larger one (10^6 larger: an override passes
    # through a double, whose neighbours there are 1024 apart).
    assert SEED_MAX == 9_200_000_000_000_000_000
    leglab.Plant(CONFIG, {"seed": SEED_MAX})
    with pytest.raises(ValueError, match="seed"):
        leglab.Plant(CONFIG, {"seed": SEED_MAX + 10**6})


def test_bad_arguments_raise_value_error():
    """Bad constructor arguments and config keys raise ValueError naming them."""
    with pytest.raises(ValueError, match="action"):
        LegTrackingEnv(action="torque")
    with pytest.raises(ValueError, match="steps"):
        LegTrackingEnv(steps=0)
    with pytest.raises(ValueError, match="seed"):
        LegTrackingEnv(overrides={"seed": 3})
    with pytest.raises(ValueError, match="servo.delay_ms"):
        LegTrackingEnv(overrides={"servo.delay_ms": -5})
    # Bounds before any allocation (history=10**9 would ask for 22 GiB).
    with pytest.raises(ValueError, match="history: expected an integer from 0 to 10000"):
        LegTrackingEnv(history=10**9)
    with pytest.raises(ValueError, match="steps: expected an integer from 0 to 10000"):
        LegTrackingEnv(steps=10**6)


def test_the_env_has_gymnasiums_attributes():
    """metadata, render_mode, reset's (obs, info) and close()."""
    env = LegTrackingEnv(steps=1)
    assert env.metadata == {"render_modes": []}
    assert env.render_mode is None
    obs, info = env.reset(seed=1)
    assert obs.dtype == np.float64 and info["tick"] == 0 and info["seed"] == 1
    env.close()
    with pytest.raises(RuntimeError):
        env.step(np.zeros(3))
