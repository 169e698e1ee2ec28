"""Two policies on LegTrackingEnv: random offsets and zero offsets, one episode each.

leglab.envs.LegTrackingEnv is Table 2's tracking task as a Gymnasium-style environment: one
env step is one 8 ms tick, the reward is minus the foot's distance from the desired walk, cm.
With action="offset" an action is added to the desired angles of the tick, so the "zero
offset" policy is the `direct` controller (request the desired angles), and the random
policy (action_space.sample(): uniform offsets up to each joint's whole range) shows what
an untrained policy does. Both episodes run on the same seed, so the sensor noise is the same.

Run from the repository root after building the package:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/random_policy_env.py
"""

import numpy as np

from leglab.envs import LegTrackingEnv

SEED = 1


def run_episode(env, policy, seed):
    """One episode of `policy` (observation -> action); returns the foot errors, cm."""
    obs, _ = env.reset(seed=seed)
    errors = []
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        errors.append(info["foot_error_cm"])  # = -reward
        if terminated or truncated:
            return np.array(errors)


def main():
    """One episode of each policy on the same seed; prints their foot errors."""
    env = LegTrackingEnv(steps=4, action="offset")
    print(f"{env!r}: {env.episode_ticks} ticks an episode, observation shape "
          f"{env.observation_space.shape}, offsets within +-{env.action_space.high} deg")

    # Reset first: action_space.sample() draws from the env's generator, seeded by reset.
    random_errors = run_episode(env, lambda obs: env.action_space.sample(), SEED)
    zero_errors = run_episode(env, lambda obs: np.zeros(3), SEED)

    for name, errors in (("random offsets", random_errors), ("zero offsets", zero_errors)):
        print(f"{name:>15}: mean foot error {errors.mean():6.2f} cm, max {errors.max():6.2f} cm")
    env.close()


if __name__ == "__main__":
    main()
