"""Gymnasium-style environments on leglab's plants.

LegTrackingEnv follows the Gymnasium 1.x API (reset, step, observation_space, action_space,
np_random, close) without importing gymnasium: one env step is one 8 ms tick of a leglab
Plant, and the task is Table 2's, to make the foot follow the desired walk.

    import leglab.envs
    env = leglab.envs.LegTrackingEnv(action="offset")
    obs, info = env.reset(seed=1)
    while True:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break

When gymnasium is installed, importing this module also registers the env as
"leglab/LegTracking-v0" (gymnasium.make("leglab/LegTracking-v0", action="offset")).
"""

from __future__ import annotations

import operator as _operator
import os as _os
from typing import Any, Mapping, Optional, Union

import numpy as _np
import numpy.typing as _npt

import leglab as _leglab

_Vector = _npt.NDArray[_np.float64]

SEED_MAX: int = int(_leglab._leglab._key_range("seed")[1])
"""The largest plant seed: the config key `seed`'s declared range is [0, SEED_MAX]."""

ACTIONS: tuple[str, str] = ("request", "offset")
"""The action kinds of LegTrackingEnv: the requested angles, or offsets from the desired ones."""

# The most walking steps an episode takes and the most ticks of history or preview: bounds
# that keep an episode's arrays far below memory (10,000 steps of the 88-tick walk are 2 hours).
MAX_STEPS: int = 10_000
MAX_WINDOW: int = 10_000


def _shown(value: object) -> str:
    """`value` as a message shows it: its repr when short and on one line, else its type."""
    text = repr(value)
    return text if "\n" not in text and len(text) <= 60 else type(value).__name__


class Box:
    """A box of float64 vectors, low <= x <= high elementwise (gymnasium.spaces.Box's shape).

    `sample()` draws from the generator of the env that owns the box (its np_random), so it
    is reproducible from the env's seed.

    Parameters
    ----------
    low, high : array_like
        The bounds, of one shape (-inf / inf where unbounded).
    rng_owner : object, optional
        An object whose `np_random` attribute is the generator sample() draws from (None: a
        fresh generator).

    Attributes
    ----------
    low, high : numpy.ndarray
        The bounds, float64 arrays of `shape`, read-only.
    shape : tuple of int
        The vectors' shape.
    dtype : numpy.dtype
        numpy.float64.

    Raises
    ------
    ValueError
        `low` and `high` of different shapes, or `low` above `high` somewhere.
    """

    def __init__(self, low: _npt.ArrayLike, high: _npt.ArrayLike,
                 rng_owner: Optional[object] = None) -> None:
        self.low = _np.array(low, dtype=_np.float64)
        self.high = _np.array(high, dtype=_np.float64)
        if self.low.shape != self.high.shape:
            raise ValueError(f"Box: low has shape {self.low.shape}, high {self.high.shape}")
        if _np.any(self.low > self.high):
            raise ValueError("Box: low is above high somewhere")
        self.low.setflags(write=False)
        self.high.setflags(write=False)
        self.shape = self.low.shape
        self.dtype = _np.dtype(_np.float64)
        self._rng_owner = rng_owner
        self._own_rng: Optional[_np.random.Generator] = None

    def _rng(self) -> _np.random.Generator:
        """The generator sample() draws from: the owner's np_random, else the box's own."""
        rng: Optional[_np.random.Generator] = getattr(self._rng_owner, "np_random", None)
        if rng is None:
            if self._own_rng is None:
                self._own_rng = _np.random.default_rng()
            rng = self._own_rng
        return rng

    def sample(self) -> _Vector:
        """A random element of the box.

        Returns
        -------
        numpy.ndarray
            Uniform in each bounded coordinate, standard normal where both bounds are infinite,
            an exponential step inside a one-sided bound (as gymnasium).
        """
        rng = self._rng()
        low, high = self.low, self.high
        bounded = _np.isfinite(low) & _np.isfinite(high)
        x = _np.empty(self.shape)
        x[bounded] = rng.uniform(low[bounded], high[bounded])
        free = ~_np.isfinite(low) & ~_np.isfinite(high)
        x[free] = rng.normal(size=int(free.sum()))
        only_low = _np.isfinite(low) & ~_np.isfinite(high)
        x[only_low] = low[only_low] + rng.exponential(size=int(only_low.sum()))
        only_high = ~_np.isfinite(low) & _np.isfinite(high)
        x[only_high] = high[only_high] - rng.exponential(size=int(only_high.sum()))
        return x

    def contains(self, x: object) -> bool:
        """Whether `x` is in the box.

        Parameters
        ----------
        x : object
            Anything.

        Returns
        -------
        bool
            Whether `x` is a real array of this shape inside the bounds (NaN is not).
        """
        try:
            a = _np.asarray(x)
        except Exception:  # noqa: BLE001  (whatever cannot be an array is not in the box)
            return False
        if a.shape != self.shape or not (_np.issubdtype(a.dtype, _np.floating) or
                                         _np.issubdtype(a.dtype, _np.integer)):
            return False
        return bool(_np.all(a >= self.low) and _np.all(a <= self.high))

    def __contains__(self, x: object) -> bool:
        """`x in box`: contains(x)."""
        return self.contains(x)

    def __repr__(self) -> str:
        """The bounds and shape."""
        return f"Box(low={self.low.tolist()}, high={self.high.tolist()}, shape={self.shape})"


def _episode_seed(seed: object) -> int:
    """`seed` as the plant's `seed` key takes it: an int in [0, SEED_MAX]; TypeError for what
    is not an integer (bool included), ValueError outside the range."""
    if isinstance(seed, (bool, _np.bool_)):
        raise TypeError(f"seed: expected an integer in [0, {SEED_MAX}], got {_shown(seed)}")
    try:
        value = _operator.index(seed)  # type: ignore[arg-type]
    except TypeError:
        raise TypeError(f"seed: expected an integer in [0, {SEED_MAX}], got "
                        f"{_shown(seed)}") from None
    if not 0 <= value <= SEED_MAX:
        raise ValueError(f"seed: expected an integer in [0, {SEED_MAX}], got {value}")
    return int(value)


class LegTrackingEnv:
    """Table 2's task as an environment: make the foot follow the desired walk, tick by tick.

    One env step is one 8 ms tick of a leglab.Plant. An episode is `steps` walking steps of the
    config's walk (leglab.Walk), T = walk.period ticks each: steps * T env steps, after which
    `truncated` is True (`terminated` is always False: nothing ends the task early). Each
    episode starts on a fresh plant at rest at the walk's first pose (Plant.reset of
    walk.angles_deg[0]).

    Actions (float64, shape (3,): rotator, abductor, knee, deg):
        action="request": the requested angles of this tick. action_space is the joint limits
            (Robot.limits_deg); the plant clamps a request outside them, as the servos do.
        action="offset": added to the desired angles of this tick; the sum is the request.
            action_space is +-(upper - lower limit) per joint. Zero offsets are the `direct`
            controller of `track`.
    An action that is no array raises TypeError, one of the wrong shape or not finite
    ValueError, naming the action.

    Reward: minus the foot error of the tick, cm: the distance of the foot at the measured
    angles (Robot.foot_mm of the reading's `measured`) from the desired foot point of the
    tick (Walk.foot_mm[tick % T]), as `track` scores it, in cm.

    Observation (float64, shape (3 * (history + preview),)), for the tick t about to be run:
        obs[3*k + j], k = 0..history-1: the measured angle of joint j at the end of tick
            t - history + k (oldest first; the ticks before the episode's first are the start
            pose walk.angles_deg[0], noise-free);
        obs[3*history + 3*k + j], k = 0..preview-1: the desired angle of joint j at tick
            t + k (this tick first; the walk repeats, so the preview wraps into the next step).
    observation_space bounds the desired part by the joint limits and leaves the measured
    part unbounded (sensor noise and the sim's soft joint stops can step past a limit).

    Seeding (Gymnasium's convention): the randomness is the plant's sensor noise, fixed by the
    config key `seed`. reset(seed=s) re-seeds the env's generator `np_random` with s and runs
    the episode on a fresh plant with {"seed": s}; reset() without a seed draws the plant's
    seed from np_random (seeded from the OS when no reset was ever given a seed). The same
    seed gives the same episode, bit for bit, and the same first seed gives the same sequence
    of episodes for the same calls. action_space.sample() draws from np_random too, so
    sampling actions moves the seeds later resets draw (reproducibly).

    Parameters
    ----------
    config : str or os.PathLike, optional
        An experiment YAML file; default leglab.config_path("track.yaml"). Its `plant` (sim or
        model), robot, servo, sensor and walk keys apply; the tracking keys (steps,
        controller.*) do not.
    overrides : dict, optional
        Config keys, as the programs' --set ({"plant": "model"}). Not `seed`: the episode's
        seed is reset's.
    steps : int, optional
        Walking steps per episode (1 to MAX_STEPS, 10,000).
    history : int, optional
        Measured ticks in the observation (0 to MAX_WINDOW, 10,000).
    preview : int, optional
        Desired ticks in the observation (0 to MAX_WINDOW); history + preview >= 1.
    action : {"request", "offset"}, optional
        What an action is.

    Attributes
    ----------
    walk : leglab.Walk
        The desired angles and foot path, `period` T.
    robot : leglab.Robot
        limits_deg, foot_mm.
    plant : leglab.Plant or None
        The current episode's plant (None before the first reset).
    period : int
        T, ticks per step.
    episode_ticks : int
        steps * T.
    tick : int
        The ticks run in this episode so far (the next step runs tick `tick`).
    episode_seed : int or None
        The current episode's plant seed (None before the first reset).
    np_random : numpy.random.Generator or None
        The env's generator (None before the first reset or sample).
    action_space, observation_space : Box
        The spaces.

    Raises
    ------
    TypeError
        An argument of the wrong type: `config` not a path, `overrides` not a dict, `steps`,
        `history` or `preview` not an integer (bool is not one), `action` not a str.
    ValueError
        A bad config or key, an argument out of its range, an unknown action, `seed` in
        `overrides`.
    """

    metadata: dict[str, Any] = {"render_modes": []}
    render_mode: Optional[str] = None

    def __init__(self, config: Union[str, _os.PathLike[str], None] = None,
                 overrides: Optional[Mapping[str, Any]] = None, *, steps: int = 4,
                 history: int = 4, preview: int = 4, action: str = "request") -> None:
        """See the class docstring."""
        if config is None:
            config = _leglab.config_path("track.yaml")
        overrides = {} if overrides is None else overrides
        if not isinstance(overrides, dict):
            raise TypeError(
                f"overrides: expected a dict of config keys, got {type(overrides).__name__}")
        if "seed" in overrides:
            raise ValueError("overrides: 'seed' is the episode's: give it to reset(seed=...)")
        for name, value, most in (("steps", steps, MAX_STEPS), ("history", history, MAX_WINDOW),
                                  ("preview", preview, MAX_WINDOW)):
            if isinstance(value, bool) or not isinstance(value, (int, _np.integer)):
                raise TypeError(f"{name}: expected an integer, got {type(value).__name__}")
            if not 0 <= value <= most:
                raise ValueError(f"{name}: expected an integer from 0 to {most}, got {value}")
        steps, history, preview = int(steps), int(history), int(preview)
        if steps < 1:
            raise ValueError(f"steps: expected at least 1, got {steps}")
        if history + preview < 1:
            raise ValueError(
                f"history, preview: expected >= 1 together, got {history}, {preview}")
        if not isinstance(action, str):
            raise TypeError(f"action: expected a str ({', '.join(ACTIONS)}), got "
                            f"{type(action).__name__}")
        if action not in ACTIONS:
            raise ValueError(f"action: expected one of {', '.join(ACTIONS)}, got {_shown(action)}")

        self._config = config
        self._overrides = dict(overrides)
        self.steps = steps
        self.history = history
        self.preview = preview
        self.action = action
        # The walk and a first plant now, so that a bad config fails here, not at reset.
        self.walk = _leglab.Walk(config, self._overrides)
        self.robot = _leglab.Plant(config, self._overrides).robot
        self.period = int(self.walk.period)
        self.episode_ticks = steps * self.period
        self._desired = _np.array(self.walk.angles_deg, dtype=_np.float64)
        self._desired_foot_mm = _np.array(self.walk.foot_mm, dtype=_np.float64)
        self._start_pose = self._desired[0].copy()

        limits = _np.array(self.robot.limits_deg, dtype=_np.float64)
        if action == "request":
            self.action_space = Box(limits[:, 0], limits[:, 1], self)
        else:
            span = limits[:, 1] - limits[:, 0]
            self.action_space = Box(-span, span, self)
        inf = _np.full(3 * history, _np.inf)
        self.observation_space = Box(
            _np.concatenate([-inf, _np.tile(limits[:, 0], preview)]),
            _np.concatenate([inf, _np.tile(limits[:, 1], preview)]), self)

        self.np_random: Optional[_np.random.Generator] = None
        self.plant: Optional[_leglab.Plant] = None
        self.tick = 0
        self.episode_seed: Optional[int] = None
        self._measured = _np.empty((0, 3))
        self._done = True

    def reset(self, seed: Optional[int] = None,
              options: Optional[dict[str, Any]] = None) -> tuple[_Vector, dict[str, Any]]:
        """Starts an episode on a fresh plant at rest at the walk's first pose.

        Parameters
        ----------
        seed : int, optional
            The plant's seed, in [0, SEED_MAX]: re-seeds np_random too. None draws the plant's
            seed from np_random.
        options : dict, optional
            Unused, for the Gymnasium signature.

        Returns
        -------
        observation : numpy.ndarray
            The first observation.
        info : dict
            "tick" (0), "seed" (the plant's) and "start_deg" (the start pose).

        Raises
        ------
        TypeError
            `seed` not an integer (bool is not one), `options` not a dict.
        ValueError
            `seed` outside [0, SEED_MAX].
        """
        if options is not None and not isinstance(options, dict):
            raise TypeError(f"options: expected None or a dict, got {type(options).__name__}")
        if seed is not None:
            episode_seed = _episode_seed(seed)
            self.np_random = _np.random.default_rng(episode_seed)
        else:
            if self.np_random is None:
                self.np_random = _np.random.default_rng()
            episode_seed = int(self.np_random.integers(0, SEED_MAX, endpoint=True))
        self.plant = _leglab.Plant(self._config, {**self._overrides, "seed": episode_seed})
        self.plant.reset(self._start_pose)
        self.episode_seed = episode_seed
        self.tick = 0
        self._done = False
        # The rows before the first tick are the start pose, then one measured row per tick.
        self._measured = _np.empty((self.history + self.episode_ticks, 3))
        self._measured[:self.history] = self._start_pose
        info = {"tick": 0, "seed": episode_seed, "start_deg": self._start_pose.copy()}
        return self._observation(), info

    def step(self, action: _npt.ArrayLike) -> tuple[_Vector, float, bool, bool, dict[str, Any]]:
        """Runs one 8 ms tick with `action` (see the class docstring).

        Parameters
        ----------
        action : array_like
            3 numbers (rotator, abductor, knee), deg: the request, or offsets from the desired
            angles.

        Returns
        -------
        observation : numpy.ndarray
            The next observation.
        reward : float
            Minus the foot error, cm.
        terminated : bool
            False.
        truncated : bool
            True after the episode's last tick.
        info : dict
            "tick" (the tick just run, from 0), "foot_error_cm", "desired_deg", "request_deg"
            (as the servos applied it, clamped), "measured_deg", "true_deg" (the exact angles:
            for scoring, not for a policy), "foot_mm" (at the measured angles) and
            "desired_foot_mm".

        Raises
        ------
        TypeError
            `action` is no array (None, text, a dict, an object).
        ValueError
            Naming the action: a wrong shape, numbers that are not real (bool, complex) or not
            finite.
        RuntimeError
            Before reset() or after the episode's end.
        """
        if self.plant is None:
            raise RuntimeError("LegTrackingEnv.step: call reset() first")
        if self._done:
            raise RuntimeError("LegTrackingEnv.step: the episode has ended; call reset()")
        a = self._check_action(action)
        t = self.tick
        desired = self._desired[t % self.period]
        request = a if self.action == "request" else desired + a
        reading = self.plant.tick(request)
        measured = _np.asarray(reading.measured, dtype=_np.float64)
        self._measured[self.history + t] = measured
        foot_mm = _np.asarray(self.robot.foot_mm(measured))
        desired_foot_mm = self._desired_foot_mm[t % self.period]
        foot_error_cm = float(_np.linalg.norm(foot_mm - desired_foot_mm)) / 10.0
        self.tick = t + 1
        truncated = self.tick >= self.episode_ticks
        self._done = truncated
        info = {
            "tick": t,
            "foot_error_cm": foot_error_cm,
            "desired_deg": desired.copy(),
            "request_deg": _np.asarray(reading.applied, dtype=_np.float64),
            "measured_deg": measured,
            "true_deg": _np.asarray(reading.true, dtype=_np.float64),
            "foot_mm": foot_mm,
            "desired_foot_mm": desired_foot_mm.copy(),
        }
        return self._observation(), -foot_error_cm, False, truncated, info

    def close(self) -> None:
        """Releases the plant. The env can be reset again afterwards."""
        self.plant = None
        self._done = True

    def _check_action(self, action: _npt.ArrayLike) -> _Vector:
        """`action` as a float64 array of shape (3,); TypeError naming the action when it is
        no array, ValueError when it is not real numbers (bool and complex are not), of another
        shape, or not finite."""
        if action is None or isinstance(action, (str, bytes, dict, set)) or (
                not isinstance(action, (_np.ndarray, list, tuple)) and
                _np.asarray(action).dtype.kind == "O"):
            raise TypeError(f"action: expected 3 numbers (rotator, abductor, knee), deg, got "
                            f"{type(action).__name__}")
        try:
            given = _np.asarray(action)
            if given.dtype.kind not in "iuf":
                raise ValueError(f"expected real numbers, got dtype {given.dtype}")
            a = given.astype(_np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"action: expected 3 numbers (rotator, abductor, knee), deg: {e}") \
                from None
        if a.shape != (3,):
            raise ValueError(
                f"action: expected shape (3,) (rotator, abductor, knee), deg, got shape {a.shape}")
        for j, name in enumerate(_leglab.JOINT_NAMES):
            if not _np.isfinite(a[j]):
                raise ValueError(f"action: the {name}'s value is {a[j]}")
        return a

    def _observation(self) -> _Vector:
        """The observation for the tick about to be run (layout: the class docstring)."""
        t = self.tick
        history = self._measured[t:t + self.history].ravel()
        preview = self._desired[_np.arange(t, t + self.preview) % self.period].ravel()
        return _np.concatenate([history, preview])

    def __repr__(self) -> str:
        """The env's arguments and period."""
        return (f"LegTrackingEnv(steps={self.steps}, history={self.history}, "
                f"preview={self.preview}, action={self.action!r}, period={self.period})")


try:
    import gymnasium as _gymnasium

    _gymnasium.register(id="leglab/LegTracking-v0", entry_point="leglab.envs:LegTrackingEnv")
except ImportError:
    pass
