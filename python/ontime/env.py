"""A Gymnasium-style environment of the effort-allocation MDP.

    env = ontime.env.EffortAllocationEnv(ontime.load_problem("data/instances/paper/instance1.json"), seed=1)
    observation, info = env.reset(seed=1)
    while True:
        action = policy(observation, info["action_mask"])
        observation, reward, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break

It follows Gymnasium's Env API (reset/step signatures, spaces, seeding) without requiring gymnasium:
when gymnasium is importable, `observation_space` and `action_space` are gymnasium.spaces objects,
otherwise small equivalents with the same attributes and methods (shape, dtype, n, sample, contains,
seed). Debian 12 packages no gymnasium.

Episode: one simulated episode of the problem (a hidden sampled world). Action: a skeleton index in
[0, K). Observation: the normalised MDP state the ppo allocator sees (float32, 1 + 3 K values: CT/D,
then per skeleton l_k/A_k, PT_k/D, ET_k/D). Reward: on success the executed skeleton's reward at its
finish (SPEC §8; 1 when the instance declares no rewards, as in the paper), 0 otherwise.
The episode terminates on success or failure (deadline passed, or no skeleton can still meet it); it
is never truncated. info["action_mask"] (also env.action_masks()) marks the useful choices: one per
group of skeletons sharing their next action, among those that can still succeed.

Seeding: reset(seed=s) restarts the episode count; episode e after it lives in the hidden world of
stream e of s, the world episode e of `ontime.evaluate(..., seed=s)` lives in. reset() without a
seed goes on to the next episode.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from typing import Any, Optional, Tuple

import numpy as np

from ._arguments import _shown
from ._arguments import name_wrong_arguments as _name_wrong_arguments
from ._ontime import Problem, UsageError, _EnvironmentCore

__all__ = ["Box", "Discrete", "EffortAllocationEnv"]

# The most values a Box holds: its bounds are arrays of its shape.
MAX_BOX_VALUES = 1 << 24


def _whole(value: Any, parameter: str, minimum: int, maximum: Optional[int] = None) -> int:
    """`value` as an int when it is a whole number (an int or a numpy integer) in range, else
    UsageError naming the parameter; a float is refused, never truncated."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < minimum or \
            (maximum is not None and value > maximum):
        rule = f"from {minimum} to {maximum}" if maximum is not None else f">= {minimum}"
        raise UsageError(f"parameter '{parameter}': must be a whole number {rule} (got {_shown(value)})")
    return int(value)


def _seed(seed: Any) -> Optional[int]:
    """A seed: None or a whole number from 0 to 2^64 - 1, as the library's seeds are."""
    return None if seed is None else _whole(seed, "seed", 0, 2**64 - 1)

try:  # Gymnasium's spaces when it is installed; it is never required.
    from gymnasium import spaces as _gym_spaces  # type: ignore
except ImportError:  # pragma: no cover - depends on the machine
    _gym_spaces = None


class Box:
    """A box of real vectors, as gymnasium.spaces.Box (low, high, shape, dtype, sample, contains, seed)."""

    def __init__(self, low: float, high: float, shape: Tuple[int, ...], dtype=np.float32, seed: Optional[int] = None):
        if isinstance(shape, (str, bytes, Mapping)) or not hasattr(shape, "__iter__"):
            raise UsageError(f"parameter 'shape': must be a tuple of whole numbers >= 0 (got {_shown(shape)})")
        self.shape = tuple(_whole(side, "shape", 0) for side in shape)
        if int(np.prod(self.shape, dtype=object)) > MAX_BOX_VALUES:
            raise UsageError(f"parameter 'shape': must hold at most {MAX_BOX_VALUES} values (got {self.shape})")
        try:
            self.dtype = np.dtype(dtype)
        except (TypeError, ValueError):
            self.dtype = None
        if self.dtype is None or self.dtype.kind not in "fiu":
            raise UsageError(f"parameter 'dtype': must be a numpy dtype of numbers (got {_shown(dtype)})")
        limits = np.finfo(self.dtype) if self.dtype.kind == "f" else np.iinfo(self.dtype)
        bounds = []
        for name, value in (("low", low), ("high", high)):
            number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
            if not number or not (math.isfinite(value) if isinstance(value, (float, np.floating)) else True) or \
                    not limits.min <= value <= limits.max:
                raise UsageError(f"parameter '{name}': must be a finite number that a {self.dtype} holds "
                                 f"(got {_shown(value)})")
            bounds.append(value)
        if bounds[0] > bounds[1]:
            raise UsageError(f"parameter 'low': must not exceed high ({_shown(high)}) (got {_shown(low)})")
        self.low = np.full(self.shape, low, dtype=self.dtype)
        self.high = np.full(self.shape, high, dtype=self.dtype)
        self._rng = np.random.default_rng(_seed(seed))

    def seed(self, seed: Optional[int] = None) -> list:
        self._rng = np.random.default_rng(_seed(seed))
        return [seed]

    def sample(self) -> np.ndarray:
        return self._rng.uniform(self.low, self.high).astype(self.dtype)

    def contains(self, x: Any) -> bool:
        try:
            x = np.asarray(x)
        except (TypeError, ValueError):  # e.g. lists of different lengths
            return False
        return (x.shape == self.shape and np.can_cast(x.dtype, self.dtype)
                and bool(np.all(x >= self.low)) and bool(np.all(x <= self.high)))

    def __contains__(self, x: Any) -> bool:
        return self.contains(x)

    def __repr__(self) -> str:
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


class Discrete:
    """The integers 0..n-1, as gymnasium.spaces.Discrete (n, shape, dtype, sample, contains, seed)."""

    def __init__(self, n: int, seed: Optional[int] = None):
        self.n = _whole(n, "n", 1)
        self.shape: Tuple[int, ...] = ()
        self.dtype = np.dtype(np.int64)
        self.start = 0
        self._rng = np.random.default_rng(_seed(seed))

    def seed(self, seed: Optional[int] = None) -> list:
        self._rng = np.random.default_rng(_seed(seed))
        return [seed]

    def sample(self, mask: Optional[np.ndarray] = None) -> int:
        """A value drawn uniformly, among those whose entry of `mask` (n values 0 or 1) is 1 when it
        is given (0 when none is)."""
        if mask is not None:
            try:
                values = np.asarray(mask)
            except (TypeError, ValueError):
                values = None
            if values is None or values.shape != (self.n,) or values.dtype.kind not in "biu" or \
                    not np.isin(values, (0, 1)).all():
                raise UsageError(f"parameter 'mask': must be an array of {self.n} values 0 or 1 (got {_shown(mask)})")
            allowed = np.flatnonzero(values)
            return int(self._rng.choice(allowed)) if allowed.size else 0
        return int(self._rng.integers(self.n))

    def contains(self, x: Any) -> bool:
        if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
            return 0 <= int(x) < self.n
        if isinstance(x, np.ndarray) and x.shape == () and np.issubdtype(x.dtype, np.integer):
            return 0 <= int(x) < self.n
        return False

    def __contains__(self, x: Any) -> bool:
        return self.contains(x)

    def __repr__(self) -> str:
        return f"Discrete({self.n})"


class EffortAllocationEnv:
    """The effort-allocation MDP of `problem` as a Gymnasium-style environment (see the module)."""

    metadata = {"render_modes": []}
    render_mode = None
    spec = None

    def __init__(self, problem: Problem, seed: int = 0):
        self._core = _EnvironmentCore(problem, seed)  # the problem (a Problem, an Mdp or a path) and seed checked
        self.problem = self._core.mdp.problem
        seed = int(seed)
        skeletons = self._core.skeleton_count
        deadline = self.problem.deadline
        high = 1.0 + 1.0 / deadline  # ET_k saturates at D + 1
        if _gym_spaces is not None:
            self.observation_space = _gym_spaces.Box(0.0, high, shape=(self._core.feature_size,), dtype=np.float32,
                                                     seed=seed)
            self.action_space = _gym_spaces.Discrete(skeletons, seed=seed)
        else:
            self.observation_space = Box(0.0, high, (self._core.feature_size,), np.float32, seed=seed)
            self.action_space = Discrete(skeletons, seed=seed)
        self._mask = None

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        """Starts an episode; returns (observation, info)."""
        if options is not None and not isinstance(options, Mapping):
            raise UsageError(f"parameter 'options': must be a dict or None (got {_shown(options)})")
        observation = self._core.reset(seed)  # the seed checked
        if seed is not None:
            self.action_space.seed(int(seed))
        self._mask = self._core.action_mask()
        return observation, {"action_mask": self._mask}

    def step(self, action):
        """One step of effort on skeleton `action`; returns (observation, reward, terminated,
        truncated, info)."""
        observation, reward, terminated, truncated = self._core.step(action)  # a whole number, checked
        self._mask = self._core.action_mask()
        return observation, reward, terminated, truncated, {"action_mask": self._mask}

    def action_masks(self) -> np.ndarray:
        """The useful choices of the current state as booleans (MaskablePPO's convention)."""
        return self._core.action_mask().astype(bool)

    @property
    def state(self):
        """The MDP state (ontime.State) of the current step."""
        return self._core.state

    @property
    def unwrapped(self) -> "EffortAllocationEnv":
        return self

    def render(self) -> None:
        return None

    def close(self) -> None:
        pass


# Arguments that match no parameter raise UsageError naming it (ontime/_arguments.py).
_name_wrong_arguments(sys.modules[__name__])
