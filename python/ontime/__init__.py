"""OnTime: deadline-aware effort allocation for task and motion planning.

A robot has candidate plan skeletons (sequences of abstract actions); each action must be refined
by a motion planner whose planning and execution times are uncertain. OnTime decides, step by
step, which skeleton gets the planner's next slice of effort, so that some skeleton is refined and
executed before a deadline.

    import ontime
    problem = ontime.load_problem("data/instances/paper/instance1.json")
    print(ontime.solve(problem)["optimal_success_probability"])
    print(ontime.evaluate(problem, "dp-rerun", episodes=10_000, seed=1, exact=True))
    session = ontime.Session(ontime.make_allocator(problem, "dp-rerun"))

The C++ core does the work (`ontime._ontime`); this layer adds the conversions between Python data
and the library's formats. docs/python.md describes the whole API.
"""

from __future__ import annotations

import json
import operator
import os
import sys
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

from ._ontime import (  # noqa: F401  (re-exported)
    NEVER,
    Action,
    ActionAttempt,
    Allocator,
    ChainFit,
    ConcurrentSession,
    ConditionalTimeModel,
    Decision,
    Distribution,
    EndedAttempt,
    Error,
    ExogenousChain,
    InputError,
    LiveSession,
    ManualClock,
    Mdp,
    OnlineBelief,
    PlanningPosterior,
    Problem,
    ResourceLimitError,
    Session,
    State,
    Status,
    UsageError,
    adapt,
    allocators,
    conditional_model_kinds,
    evaluate,
    fit_strength,
    histogram_csv,
    load_chain,
    load_conditional_model,
    load_problem,
    make_allocator,
    read_planner_log,
    reduce_knapsack,
    run_episodes,
    sample_log,
    score,
    solve,
    study,
    table,
    train_ppo,
)
from . import _ontime
from ._arguments import name_wrong_arguments as _name_wrong_arguments

__version__ = "0.1.0"

__all__ = [
    "NEVER", "Action", "ActionAttempt", "Allocator", "ChainFit", "ConcurrentSession", "ConditionalTimeModel", "Decision", "Distribution", "EndedAttempt", "Error", "ExogenousChain", "InputError", "LiveSession",
    "ManualClock", "Mdp", "OnlineBelief", "PlanningPosterior", "Problem",
    "ResourceLimitError", "Session", "State", "Status", "UsageError", "World", "allocators", "conditional_model_kinds",
    "evaluate", "fit", "fit_chain", "fit_conditional", "histogram_csv", "load_chain", "load_conditional_model", "load_problem", "make_allocator", "read_planner_log", "reduce_knapsack", "run_episodes", "sample_log", "score", "adapt", "fit_strength",
    "solve", "study", "table", "train_ppo",
    "write_planner_log",
]

PathLike = Union[str, "os.PathLike[str]"]


class World:
    """The world an episode happens in, implemented in Python: what a step of effort reveals.

    Subclass it around your own planner and pass it (or its class, to get one per thread) to
    ontime.run_episodes, which runs any allocator against it with the library's episode runner.

    begin_episode(seed) starts an episode whose randomness comes from `seed` alone.
    step(action, spent) spends one step of effort on the action with index `action` (into
    Problem.actions; its parent action is already refined in this episode) which has had `spent`
    steps so far in this attempt, and returns None (no motion yet) or the refined motion's execution
    time in steps (an int >= 0; ontime.NEVER or math.inf when it cannot be executed); with
    backtracking (docs/spec.md §7), ("backtrack", culprit) when the attempt gives up blaming the
    earlier action with index `culprit`.
    statistics() may return counters (name -> number) summed over the run.
    """

    def begin_episode(self, seed: int) -> None:
        raise NotImplementedError

    def step(self, action: int, spent: int) -> Optional[int]:
        raise NotImplementedError

    def statistics(self) -> Mapping[str, float]:
        return {}


def _distribution_entry(value: Any) -> Any:
    """A PMF or CDF given as a sequence or numpy array becomes the instance format's {step: p}."""
    if isinstance(value, Mapping):
        return {str(step): float(p) for step, p in value.items()}
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return {str(step): float(p) for step, p in enumerate(value) if p != 0}
    return value


def _instance_data(data: Mapping[str, Any]) -> Any:
    """The instance format with distributions given as arrays converted, everything else as is."""
    out = dict(data)
    actions = out.get("actions")
    if isinstance(actions, Mapping):
        converted = {}
        for action_id, action in actions.items():
            if isinstance(action, Mapping):
                action = dict(action)
                for which in ("planning", "execution"):
                    law = action.get(which)
                    if isinstance(law, Mapping):
                        action[which] = {key: (_distribution_entry(value) if key in ("pmf", "cdf") else value)
                                         for key, value in law.items()}
            converted[action_id] = action
        out["actions"] = converted
    return out


# Problem dicts and planner records are a few levels deep; json.dumps recurses once per level and
# would end in RecursionError long before the C++ reader's own limits, so deeper input is refused
# first, without recursion.
MAX_NESTING = 256


def _check_nesting(value: Any, source: str) -> None:
    """Raises InputError when dicts and lists inside `value` nest deeper than MAX_NESTING."""
    stack = [(value, 0, "")]
    while stack:
        item, depth, place = stack.pop()
        if isinstance(item, Mapping):
            children = ((f"{place}.{key}" if place else str(key), child) for key, child in item.items())
        elif isinstance(item, (list, tuple)):
            children = ((f"{place}[{index}]", child) for index, child in enumerate(item))
        else:
            continue
        if depth >= MAX_NESTING:
            shown = place if len(place) <= 80 else place[:77] + "..."
            raise InputError(f"{source}: {shown or 'top level'}: nested more than {MAX_NESTING} levels deep "
                             f"(the limit of dicts and lists given to ontime)")
        stack.extend((child, depth + 1, child_place) for child_place, child in children)


def _problem_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Problem:
    """An instance from a dict in the instance format (SPEC §5); PMFs and CDFs may be sequences or
    numpy arrays indexed by step. Raises InputError naming the place and the rule, as for a file."""
    if not isinstance(data, Mapping):
        raise InputError(f"{source}: the instance must be a JSON object (a dict), got {type(data).__name__}")
    _check_nesting(data, source)
    try:
        text = json.dumps(_instance_data(data), allow_nan=True)
    except (TypeError, ValueError) as error:
        raise InputError(f"{source}: the instance cannot be written as JSON: {error}") from None
    return Problem.from_json(text, source)


def _problem_to_dict(self: Problem) -> dict:
    """The instance as a dict in the instance format (PMF form): Problem.from_dict reads it back."""
    return json.loads(self.to_json())


Problem.from_dict = staticmethod(_problem_from_dict)
Problem.to_dict = _problem_to_dict


def _json_value(value: Any) -> Any:
    """numpy arrays and scalars (features) as lists and numbers; anything else is no JSON value."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"a {type(value).__name__} is not a JSON value")


def _iterable(value: Any, parameter: str, what: str) -> Iterable[Any]:
    """`value` when it can be iterated (and is no str), else UsageError naming the parameter."""
    if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__iter__"):
        raise UsageError(f"parameter '{parameter}': must be {what} (got "
                         f"{'None' if value is None else 'a ' + type(value).__name__})")
    return value


def _records_text(records: Iterable[Mapping[str, Any]], parameter: str = "records") -> str:
    lines = []
    for number, record in enumerate(_iterable(records, parameter, "a list of records (dicts)"), start=1):
        _check_nesting(record, f"<records>: record {number}")
        try:
            if not isinstance(record, Mapping):
                lines.append(json.dumps(record, default=_json_value)
                             if isinstance(record, (list, str, int, float)) else "null")
            else:
                lines.append(json.dumps(dict(record), allow_nan=True, default=_json_value))
        except (TypeError, ValueError) as error:
            raise InputError(f"<records>: record {number}: cannot be written as JSON: {error}") from None
    return "".join(line + "\n" for line in lines)


def write_planner_log(records: Iterable[Mapping[str, Any]], path: PathLike) -> None:
    """Writes planner-log records (dicts with action, planning_seconds, found, execution_seconds when
    found) as a log file (JSON Lines, docs/formats.md), atomically. Every record is checked by the
    rules of a log file; InputError names the record as `<records>, line N`."""
    _ontime._save_planner_log(_records_text(records), "<records>", path)


def fit(records_or_path: Union[PathLike, Iterable[Mapping[str, Any]]], *, step: float, deadline: int,
        skeletons: Union[PathLike, Sequence[Sequence[str]]], laplace: float = 0.0, name: str = "fitted",
        description: str = "") -> Problem:
    """Learns an instance from a planner log, as `ontime fit` does: each action's planning- and
    execution-time distributions by maximum likelihood (Kaplan-Meier for attempts cut off), in steps
    of `step` seconds, with deadline `deadline` steps.

    records_or_path: a log file or its records (dicts); skeletons: a JSON file with a `skeletons`
    member (an instance or world file will do) or the skeletons as lists of action ids.
    """
    # Files are read by the library's own readers (limits, encodings, places in messages), records
    # and skeleton lists given in Python are read as the text of such files.
    log_is_path = isinstance(records_or_path, (str, os.PathLike))
    log = os.fspath(records_or_path) if log_is_path else _records_text(records_or_path, "records_or_path")
    skeletons_is_path = isinstance(skeletons, (str, os.PathLike))
    skeleton_data = (os.fspath(skeletons) if skeletons_is_path else json.dumps(
        {"skeletons": [list(_iterable(s, "skeletons", "a list of action ids"))
                       for s in _iterable(skeletons, "skeletons", "a path or a list of skeletons")]},
        default=_json_value))
    # Numbers as given: the extension checks and names them (a float for a whole number is refused,
    # never truncated).
    return _ontime._fit(log, log_is_path, skeleton_data, skeletons_is_path, step, deadline, laplace, name,
                        description)


def fit_conditional(records_or_paths: Union[PathLike, Sequence[PathLike], Iterable[Mapping[str, Any]]], *,
                    step: float, kind: str = "hazard", domain: Optional[str] = None,
                    feature_names: Optional[Sequence[str]] = None, horizon: int = 0, ridge: float = 1e-3,
                    bins: int = 0, trees: int = 100, depth: int = 3, learning_rate: float = 0.3,
                    min_child_weight: float = 1.0, aft_distribution: str = "normal",
                    aft_scale: float = 1.0) -> "ConditionalTimeModel":
    """A conditional time model (docs/learning.md), as `ontime fit --conditional KIND` fits it: from one or
    more planner logs (paths), or from records (dicts), whose every record carries `features` (`collect
    --features`). Times in steps of `step` seconds; `horizon` steps predicted (0: the longest planning time
    of the data). Feature names: the domain's (`domain="navigation"`), or `feature_names`, or f1, f2, ....
    kind "pooled" ignores the features (Kaplan-Meier over every record); "hazard" is the discrete-time
    hazard model with a cure fraction (`ridge`, `bins`); "boosted" is XGBoost's gradient-boosted trees, a
    cure fraction and an accelerated failure time fitted together to the censored times (`trees`, `depth`,
    `learning_rate`, `min_child_weight`, `aft_distribution`, `aft_scale`): conditional_model_kinds()."""
    if domain is not None and feature_names is not None:
        raise UsageError("give domain or feature_names, not both")
    names = list(_iterable(feature_names, "feature_names", "a list of names")) if feature_names is not None else []
    if domain is not None:
        from . import domains as _domains_module
        if not _domains_module.available:
            raise UsageError("domain= needs the domains build (ONTIME_BUILD_DOMAINS)")
        names = list(_domains_module.feature_names(domain))
    if isinstance(records_or_paths, (str, os.PathLike)):
        logs, are_paths = [os.fspath(records_or_paths)], True
    else:
        items = list(_iterable(records_or_paths, "records_or_paths", "a path, a list of paths or a list of records"))
        are_paths = bool(items) and all(isinstance(item, (str, os.PathLike)) for item in items)
        logs = [os.fspath(item) for item in items] if are_paths else [_records_text(items, "records_or_paths")]
    # Numbers as given: the extension checks and names them (horizon=1.5 is refused, not truncated).
    return _ontime._fit_conditional(logs, are_paths, step, kind, names, horizon, ridge, bins, trees, depth,
                                    learning_rate, min_child_weight, aft_distribution, aft_scale)


def fit_chain(logs_or_sequences: Union[PathLike, Sequence[PathLike], Sequence[Sequence[Union[int, str]]]], *,
              kind: str = "markov", name: str = "chain", prior: float = 0.0,
              states: Optional[Sequence[Union[int, str]]] = None, capacity: int = 0) -> "ChainFit":
    """An exogenous chain (docs/learning.md, "Exogenous chains"), as `ontime fit-chain` fits it: from one or
    more observation logs (paths; JSON lines of sequence, step, state), or from sequences of states observed at
    consecutive steps (each a list of names or whole numbers, e.g. a queue's lengths). kind "markov" frees every
    transition probability (`prior` pseudo-transitions per entry; `states` in that order); "birth-death" is a
    queue of `capacity` (0: the longest observed) with one arrival and one service probability per step."""
    if isinstance(logs_or_sequences, (str, os.PathLike)):
        logs, sequences = [os.fspath(logs_or_sequences)], []
    else:
        items = list(_iterable(logs_or_sequences, "logs_or_sequences", "a path, a list of paths or of sequences"))
        if not items:
            raise UsageError("parameter 'logs_or_sequences': give at least one log or sequence")
        if all(isinstance(item, (str, os.PathLike)) for item in items):
            logs, sequences = [os.fspath(item) for item in items], []
        else:
            what = "a list of paths or of sequences of states"
            logs, sequences = [], [[_state_name(state, "logs_or_sequences")
                                    for state in _iterable(sequence, "logs_or_sequences", what)] for sequence in items]
    listed = [_state_name(state, "states") for state in _iterable(states, "states", "a list of states")] \
        if states is not None else []
    if len(set(listed)) != len(listed):
        twice = next(state for number, state in enumerate(listed) if state in listed[:number])
        raise UsageError(f"parameter 'states': state '{twice}' is listed twice")
    return _ontime._fit_chain(logs, sequences, kind, name, prior, listed, capacity)


def _state_name(state: Union[int, str], parameter: str) -> str:
    """A state's name: a str as it is, a whole number >= 0 (int, numpy integer) as its digits."""
    if isinstance(state, str):
        return state
    if isinstance(state, bool) or not hasattr(state, "__index__") or operator.index(state) < 0:
        raise UsageError(f"parameter '{parameter}': a state is a name (str) or a whole number >= 0 (got {state!r})")
    return str(operator.index(state))


# Arguments of the wrong type raise UsageError naming the parameter (ontime/_arguments.py): the
# functions of this module and the extension's own, which the functions above call.
_name_wrong_arguments(_ontime)
_name_wrong_arguments(sys.modules[__name__])

from . import env  # noqa: E402,F401  (ontime.env.EffortAllocationEnv)
from . import domains  # noqa: E402,F401  (ontime.domains, when built)
