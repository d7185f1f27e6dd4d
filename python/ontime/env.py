"""A Gymnasium-style environment of the effort-allocation MDP, plan-first or acting while planning.

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

The acting mode (SPEC §10): `act=None` plays the instance's own ("acting" in its file, plan-first
when absent), `act='plan-first'` or `act='concurrent'` reads it in that mode (as `ontime.evaluate`'s
`act`); `env.act` says which.

Plan-first (SPEC §2). Episode: one simulated episode of the problem (a hidden sampled world). Action:
a skeleton index in [0, K). Observation: the normalised MDP state the ppo allocator sees (float32,
1 + 3 K values: CT/D, then per skeleton l_k/A_k, PT_k/D, ET_k/D; with chains or expiry their
features after). info["action_mask"] (also env.action_masks()) marks the useful choices: one per
group of skeletons sharing their next action, among those that can still succeed. `env.state` is
the MDP state (ontime.State).

Acting while planning (act='concurrent', SPEC §10): the robot executes refined actions while the
rest is planned. Episode: one ConcurrentSession episode in a hidden sampled world, carried out as
`ontime.evaluate(problem, solver, act='concurrent')` carries out its allocators' moves. Action: one
of 2 K + 1 moves, laid out as the concurrent ppo actor's outputs: k < K a step in which the planner
refines skeleton k's next action, K + k the start of skeleton k's next action to execute (the robot
begins it now; no time passes), 2 K a step in which the planner idles (the robot executes either
way). Observation: the features the concurrent ppo policy sees (float32, 2 + 6 K values: CT/D, r/D,
then per skeleton 1 when it is live (else 0 for all six), its actions started / length, l_k /
length, PT_k/D, the robot's backlog along it / D and 1 when its next action may start now; with
chains, each chain's state one-hot after). info["action_mask"] marks exactly the state's useful
moves (the moves the exact solver considers, ConcurrentMdp::useful_moves, as the ppo trainer masks
them); a masked-out action is refused (UsageError). After a step in which the planner worked on an
action, info["found"] says whether its motion was found and info["execution_steps"] its execution
time in steps (ontime.NEVER: it cannot be executed), and info["culprit"] the id of the action an
attempt that gave up blamed (SPEC §7; else None); all three are None after a start or an idle step.
`env.state` is a dict of the concurrent state (time, robot_left, started, live, refined, spent,
startable). `env.action_of(move)` is the action of a move as ontime.ConcurrentSession's choose()
returns it, so that a registry allocator's moves can be played (an allocator's move outside the
useful moves has no action to play).

Reward (both modes): on success the executed skeleton's reward at its finish (SPEC §8; 1 when the
instance declares no rewards, as in the paper), 0 otherwise. The episode terminates on success or
failure (deadline passed, or no skeleton can still meet it); it is never truncated.

Seeding: reset(seed=s) restarts the episode count; episode e after it lives in the hidden world of
stream e of s, the world episode e of `ontime.evaluate(..., seed=s)` lives in (in the same mode).
reset() without a seed goes on to the next episode. `env.session_seed` is the seed of the current
episode's session: acting while planning, the runner's (its simulated chains, SPEC §9, are those of
episode e of evaluate), so that ontime.ConcurrentSession(problem, solver, seed=env.session_seed)
told what each step revealed (report_refined, report_not_yet, report_backtrack) makes the same moves
as the runner's allocator in that episode:

    env = EffortAllocationEnv(problem, act="concurrent")
    env.reset(seed=s)
    session = ontime.ConcurrentSession(problem, "optimal", seed=env.session_seed)
    move = session.choose()
    observation, reward, terminated, truncated, info = env.step(env.action_of(move))
    if move["start"] is None:  # a step: tell the session what it revealed
        if info["found"]: session.report_refined(info["execution_steps"])
        elif info["culprit"] is not None: session.report_backtrack(info["culprit"])
        else: session.report_not_yet()
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from typing import Any, Optional, Tuple

import numpy as np

from ._arguments import _shown
from ._arguments import name_wrong_arguments as _name_wrong_arguments
from ._ontime import Problem, UsageError, _ConcurrentEnvironmentCore, _environment_core

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

    def __init__(self, problem: Problem, seed: int = 0, act: Optional[str] = None):
        if act is not None and not isinstance(act, str):
            raise UsageError(f"parameter 'act': must be 'plan-first', 'concurrent' or None (got {_shown(act)})")
        # The problem (a Problem, an Mdp or a path), the seed and the mode checked.
        self._core = _environment_core(problem, seed, act)
        self._concurrent = isinstance(self._core, _ConcurrentEnvironmentCore)
        if self._concurrent:
            self.act = "concurrent"
            self.problem = self._core.problem
            actions = self._core.action_count
        else:
            self.act = "plan-first"
            self.problem = self._core.mdp.problem
            actions = self._core.skeleton_count
        seed = int(seed)
        deadline = self.problem.deadline
        # Every feature lies in [0, (D + 1) / D]: times and efforts at most D, executions and the
        # robot's backlog saturate at D + 1, the rest are shares and flags.
        high = 1.0 + 1.0 / deadline
        if _gym_spaces is not None:
            self.observation_space = _gym_spaces.Box(0.0, high, shape=(self._core.feature_size,), dtype=np.float32,
                                                     seed=seed)
            self.action_space = _gym_spaces.Discrete(actions, seed=seed)
        else:
            self.observation_space = Box(0.0, high, (self._core.feature_size,), np.float32, seed=seed)
            self.action_space = Discrete(actions, seed=seed)
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
        """Plan-first, one step of effort on skeleton `action`; acting while planning, the move
        `action` stands for (see the module). Returns (observation, reward, terminated, truncated,
        info)."""
        if self._concurrent:
            observation, reward, terminated, truncated, found, execution, culprit = self._core.step(action)  # checked
            self._mask = self._core.action_mask()
            return observation, reward, terminated, truncated, {"action_mask": self._mask, "found": found,
                                                                "execution_steps": execution, "culprit": culprit}
        observation, reward, terminated, truncated = self._core.step(action)  # a whole number, checked
        self._mask = self._core.action_mask()
        return observation, reward, terminated, truncated, {"action_mask": self._mask}

    def action_masks(self) -> np.ndarray:
        """The useful choices of the current state as booleans (MaskablePPO's convention)."""
        return self._core.action_mask().astype(bool)

    def action_of(self, move: Mapping) -> int:
        """Acting while planning: the action that plays `move` in the current state, a move as
        ontime.ConcurrentSession's choose() and decide() return it ({'start': an action's id or
        None, 'skeleton': a skeleton index or None, ...}; neither: the planner idles; a step on a
        skeleton is the step of its group, the live skeletons sharing that next action, named by
        the lowest index). UsageError
        in plan-first mode, for a malformed move and for a start of an action no live skeleton
        executes next. The action may still be masked out (a move outside the useful ones)."""
        if not self._concurrent:
            raise UsageError("action_of: moves are those of acting while planning (act='concurrent'); plan-first, "
                             "the action is the skeleton index")
        if not isinstance(move, Mapping):
            raise UsageError(f"parameter 'move': must be a dict as ConcurrentSession.choose() returns "
                             f"(got {_shown(move)})")
        return self._core.action_of(move.get("start"), move.get("skeleton"))

    @property
    def state(self):
        """Plan-first, the MDP state (ontime.State) of the current step; acting while planning, a
        dict of the concurrent state: 'time' (CT), 'robot_left' (r), 'started' (the ids of the
        actions started, in order), per skeleton 'live', 'refined' (l_k) and 'spent' (PT_k; both 0
        once it is dropped), and 'startable' (the ids of the actions the robot may start now)."""
        return self._core.state

    @property
    def session_seed(self) -> int:
        """The seed of the current episode's session (see the module)."""
        return self._core.session_seed

    @property
    def unwrapped(self) -> "EffortAllocationEnv":
        return self

    def render(self) -> None:
        return None

    def close(self) -> None:
        pass


# Arguments that match no parameter raise UsageError naming it (ontime/_arguments.py).
_name_wrong_arguments(sys.modules[__name__])
