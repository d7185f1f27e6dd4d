"""A sweep of every public function, constructor and method of ontime, ontime.domains and ontime.env,
enumerated from the modules (a new one without a call in sweep_calls fails the coverage test). Each
parameter of a call that works is given, in turn, each of BAD_VALUES: None, text (empty, a word,
100,000 characters), bytes, an object, NaN, +-inf, negative numbers, zero, huge numbers (2^31 - 1,
2^63, +-2^64, 1e300), a fraction, a bool, empty and huge lists, a dict and numpy values. Every call
either works or raises OnTime's own error (UsageError, InputError): no crash, and never pybind11's
TypeError listing signatures, Python's TypeError, a ValueError or a RuntimeError.

Beyond not failing:
- a value of another kind than the parameter takes (a fraction or a bool for a whole number, a
  number for a bool or a str, None for a parameter whose default is not None, ...) is refused,
  never converted (`horizon=1.5` truncated to 1, `exact=None` read as False);
- a UsageError about a value names its parameter;
- a list given as a numpy array works as the list does;
- an argument too many and an unknown keyword are UsageErrors.
"""

import inspect
import math
import os
import re
import time
from collections.abc import Mapping

import numpy as np
import pytest

import ontime
import ontime.domains
import ontime.env
from conftest import PAPER_INSTANCES, SOURCE_DIR

HUGE_TEXT = "x" * 100_000
HUGE_LIST = ["x"] * 100_000
BAD_VALUES = [None, "x", "", HUGE_TEXT, b"x", object(), math.nan, math.inf, -math.inf, -1, -1.5, 0, 2**31 - 1, 2**63,
              2**64, -2**64, 1e300, 1.5, True, [], HUGE_LIST, {}, np.array([1.0, math.nan]), np.float64(math.nan),
              np.int64(-1)]

# Numbers of units of work (episodes, trials, records, steps of a chain, iterations of a search): a
# huge one asks for a computation that long, which the function starts as asked. Given 2^31 - 1
# and 2^63 they would run for days; every other value is swept.
WORK_COUNTS = {"episodes", "trials", "attempts", "steps", "sequences", "iterations"}
HUGE_COUNTS = [2**31 - 1, 2**63]

# Public callables that no call here sweeps, each with its reason.
EXCLUDED = {
    "World": "the caller's interface: OnTime calls the methods of the caller's subclass",
    "World.begin_episode": "the caller's interface: a subclass defines it and OnTime calls it",
    "World.step": "the caller's interface: a subclass defines it and OnTime calls it",
    "World.statistics": "the caller's interface: a subclass defines it and OnTime calls it",
    "Error": "an exception: OnTime raises it",
    "InputError": "an exception: OnTime raises it",
    "UsageError": "an exception: OnTime raises it",
    "ResourceLimitError": "an exception: OnTime raises it",
}

# Classes whose objects OnTime's functions return and callers do not make: calling the class with
# any argument is a UsageError.
MADE_BY_ONTIME = ["Action", "Allocator", "ChainFit", "ConditionalTimeModel", "Decision", "Distribution",
                  "ExogenousChain", "Problem", "State", "domains.Domain"]

LOG = ("{\"action\": \"a\", \"planning_seconds\": 2, \"found\": false, \"world\": \"t\", \"features\": [0]}\n"
       "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, \"world\": \"t\", "
       "\"features\": [1]}\n")
QUEUE = {"deadline": 3, "step_seconds": 1.0,
         "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.7, 0.3], [0.2, 0.8]]}},
         "actions": {"wait": {"planning": {"pmf": {"1": 1.0}},
                              "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}},
                                                                           "long": {"pmf": {"5": 1.0}}}}}},
         "skeletons": [["wait"]]}
TWO_ACTIONS = {"deadline": 4, "step_seconds": 1.0,
               "actions": {"a": {"planning": {"pmf": {"1": 0.5, "2": 0.25}}, "execution": {"pmf": {"0": 1.0}}},
                           "b": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}}},
               "skeletons": [["a"], ["b"]]}

# a is found in 1 step and runs 2, b 2 steps later and runs 1: a robot acting while planning
# (SPEC §10) starts a while b is planned.
TWO_MOVES = {"deadline": 5, "step_seconds": 1.0,
             "actions": {"a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
                         "b": {"planning": {"pmf": {"2": 1.0}}, "execution": {"pmf": {"1": 1.0}}}},
             "skeletons": [["a", "b"]]}


class Call:
    """A call that works: `target(*args, **kwargs)`, or with fresh=True `target()(*args, **kwargs)`
    (a method of an object made anew for each call, e.g. a session waiting for its report)."""

    def __init__(self, name, target, /, *args, fresh=False, answers_any=False, **kwargs):
        self.name = name
        self.target = target
        self.args = args
        self.kwargs = kwargs
        self.fresh = fresh
        self.answers_any = answers_any  # a membership test: every value has an answer, True or False
        self.none_default = set()

    def allowing_none(self, *names):
        """Parameters that take None although the signature does not say (passed on through **options)."""
        self.none_default.update(names)
        return self

    def function(self):
        return self.target() if self.fresh else self.target

    def __call__(self, args, kwargs):
        return self.function()(*args, **kwargs)


class Tiny(ontime.World):
    """A world in which every motion is found at once and takes no time to execute."""

    def begin_episode(self, seed):
        pass

    def step(self, action, spent):
        return 0


def sweep_calls(tmp_path):
    """The calls that work, one or more per public callable (the name before a space)."""
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    two = ontime.Problem.from_dict(TWO_ACTIONS)
    queue = ontime.Problem.from_dict(QUEUE)
    log = tmp_path / "log.jsonl"
    log.write_text(LOG)
    model = ontime.fit_conditional(str(log), step=1.0, kind="pooled")
    model.save(str(tmp_path / "model.json"))
    chain_log = tmp_path / "queue.jsonl"
    chain_log.write_text("{\"sequence\": \"s\", \"step\": 0, \"state\": 0}\n{\"sequence\": \"s\", \"step\": 1, "
                         "\"state\": 1}\n")
    fitted_chain = ontime.fit_chain([[0, 1, 1, 0]], kind="birth-death", capacity=2)
    chain = fitted_chain.chain
    chain.save(str(tmp_path / "chain.json"))
    mdp = ontime.Mdp(problem)
    start = mdp.start()
    law = problem.actions[0].planning
    sampled = tmp_path / "paper.jsonl"
    ontime.sample_log(problem, str(sampled), attempts=20, seed=1)
    knapsack = {"capacity": 2, "items": [{"weight": 1, "value": 1}, {"weight": 1, "value": 2}]}
    records = [{"action": "a", "planning_seconds": 1.0, "found": True, "execution_seconds": 1.0, "features": [1.0]}]

    def session(instance=two, choose=True, **options):
        made = ontime.Session(ontime.make_allocator(instance, "round-robin"), **options)
        if choose:
            made.choose()
        return made

    def live(instance=two, choose=True):
        made = ontime.LiveSession(instance, "dp-rerun", clock=ontime.ManualClock())
        if choose:
            made.choose()
        return made

    grasps = ontime.load_problem(SOURCE_DIR / "data" / "instances" / "backtracking" / "grasp-and-place.json")

    def backtracking(made, clock=None):
        """`made` (round-robin on grasp-and-place) at place(A,R1), whose attempt may blame pick(A)."""
        for report in ("refined", "not yet", "not yet"):
            made.choose()
            if report == "not yet":
                made.report_not_yet()
            elif clock is None:
                made.report_refined(1)
            else:
                made.report_refined_seconds(grasps.step_seconds)
            if clock is not None:
                clock.advance(grasps.step_seconds)
        made.choose()
        return made

    def live_backtracking():
        clock = ontime.ManualClock()
        return backtracking(ontime.LiveSession(grasps, "round-robin", clock=clock), clock)

    def posterior(**options):
        return ontime.PlanningPosterior(law, 10, 1.0, **options)

    moves = ontime.Problem.from_dict(TWO_MOVES)
    no_backtrack = ontime.Distribution.from_pmf([0.0, 0.0])

    def concurrent(refined=False, started=False, pending=False):
        """A session of the caller's moves on TWO_MOVES: a refined, started, or a step awaiting its report."""
        made = ontime.ConcurrentSession(moves)
        if refined or started:
            made.decide(refine=0)
            made.report_refined(2)
        if started:
            made.decide(start="a")
        if pending:
            made.decide(refine=0)
        return made

    def concurrent_backtracking():
        """The caller's moves on grasp-and-place: pick(A) refined, a step on place(A,R1) awaiting its report."""
        made = ontime.ConcurrentSession(grasps)
        made.decide(refine=0)
        made.report_refined(1)
        made.decide(refine=0)
        return made

    def belief():
        return ontime.OnlineBelief(two, 2.0)

    def environment(reset=True, act=None):
        made = ontime.env.EffortAllocationEnv(moves if act else two, seed=1, act=act)
        if reset:
            made.reset(seed=1)
        return made

    attempts = session(choose=False)
    attempts.choose()
    attempts.report_not_yet()
    out = [
        # ontime: functions
        Call("allocators", ontime.allocators),
        Call("conditional_model_kinds", ontime.conditional_model_kinds),
        Call("solve", ontime.solve, problem, max_states=100_000, threads=1, method="layered", tolerance=0.0,
             max_memory_mib=64, max_disk_mib=64, scratch=str(tmp_path), policy=str(tmp_path / "policy.jsonl"),
             policy_layers=1, gap=0.0),
        Call("solve search", ontime.solve, problem, method="search", gap=0.5),
        Call("solve concurrent", ontime.solve, two, method="memoised", act="concurrent"),
        Call("solve concurrent search", ontime.solve, two, method="search", act="concurrent", gap=0.01),
        Call("evaluate", ontime.evaluate, problem, "dp-rerun", episodes=20, seed=1, threads=1, exact=False,
             regret=False, belief=problem, progress=lambda done, total: None),
        Call("evaluate with parameters", ontime.evaluate, two, "mcts", episodes=2, threads=1, iterations=10),
        Call("evaluate concurrent", ontime.evaluate, moves, "dp-rerun", act="concurrent", episodes=5, seed=1,
             threads=1, exact=True, belief=moves),
        Call("adapt", ontime.adapt, problem, problem, "dp-rerun", strength=10.0, episodes=2, sequences=2, seed=1,
             threads=1, exact=False),
        Call("run_episodes", ontime.run_episodes, two, Tiny(), "dp-rerun", episodes=3, seed=1, threads=1,
             iterations=10, seconds=1.0, progress=lambda done, total: None),
        Call("run_episodes factory", ontime.run_episodes, two, Tiny, ontime.make_allocator(two, "dp-rerun"),
             episodes=3, threads=2),
        Call("table", ontime.table, [problem], solvers=["dp-rerun"], exact=False, episodes=10, seed=1, threads=1,
             format="json", progress=lambda done, total: None),
        Call("study", ontime.study, "compute-time", [two], episodes=2, seed=1, threads=1, searcher="mcts",
             reference="dp-rerun", progress=lambda done, total: None),
        Call("study anytime", ontime.study, "anytime", [two], episodes=2, threads=1, log10_multipliers=[0.0, 0.5]),
        Call("train_ppo", ontime.train_ppo, two, str(tmp_path / "policy.json"), episodes=2, seed=1,
             progress=lambda done, total: None),
        Call("train_ppo concurrent", ontime.train_ppo, two, str(tmp_path / "policy-concurrent.json"), episodes=2,
             seed=1, progress=lambda done, total: None, act="concurrent"),
        Call("score", ontime.score, problem, [str(sampled)], horizon=0, floor=1e-6, skip_unknown=True),
        Call("fit_strength", ontime.fit_strength, model, [str(log)], strengths=[1.0, 2.0]),
        Call("fit_conditional", ontime.fit_conditional, str(log), step=1.0, kind="hazard", horizon=0, ridge=1e-3,
             bins=0, feature_names=["x"]),
        Call("fit_conditional boosted", ontime.fit_conditional, records * 4, step=1.0, kind="boosted", trees=2,
             depth=2, learning_rate=0.3, min_child_weight=1.0, aft_distribution="normal", aft_scale=1.0),
        Call("fit", ontime.fit, records, step=1.0, deadline=5, skeletons=[["a"]], laplace=0.0, name="n",
             description="d"),
        Call("fit_chain", ontime.fit_chain, [[0, 1, 1, 0]], kind="birth-death", name="q", prior=0.0, capacity=3),
        Call("fit_chain log", ontime.fit_chain, str(chain_log), states=["0", "1"], prior=1.0),
        Call("load_problem", ontime.load_problem, str(PAPER_INSTANCES[0])),
        Call("load_chain", ontime.load_chain, str(tmp_path / "chain.json")),
        Call("load_conditional_model", ontime.load_conditional_model, str(tmp_path / "model.json")),
        Call("read_planner_log", ontime.read_planner_log, str(log)),
        Call("write_planner_log", ontime.write_planner_log, records, str(tmp_path / "written.jsonl")),
        Call("sample_log", ontime.sample_log, problem, str(tmp_path / "sampled.jsonl"), attempts=5, seed=1,
             cutoff=3),
        Call("histogram_csv", ontime.histogram_csv, problem),
        Call("make_allocator", ontime.make_allocator, mdp, "mcts", iterations=10),
        Call("reduce_knapsack", ontime.reduce_knapsack, knapsack, name="k"),
        # ontime: classes
        Call("ActionAttempt", ontime.ActionAttempt, 2, True),
        Call("Allocator.begin_episode", ontime.make_allocator(mdp, "dp-rerun").begin_episode, 1),
        Call("Allocator.choose", ontime.make_allocator(mdp, "mcts", iterations=5).choose, start, iterations=5,
             seconds=0.01),
        Call("Allocator.statistics", ontime.make_allocator(mdp, "dp-rerun").statistics),
        Call("ConditionalTimeModel.predict", model.predict, [1.0]),
        Call("ConditionalTimeModel.predict rows", model.predict, [[1.0], [2.0]]),
        Call("ConditionalTimeModel.to_json", model.to_json),
        Call("ConditionalTimeModel.save", model.save, str(tmp_path / "saved-model.json")),
        Call("Distribution.from_pmf", ontime.Distribution.from_pmf, [0.5, 0.5]),
        Call("Distribution.from_cdf", ontime.Distribution.from_cdf, [0.5, 1.0]),
        Call("Distribution.cdf", law.cdf, 2),
        Call("Distribution.survival", law.survival, 2),
        Call("Distribution.hazard", law.hazard, 2),
        Call("Distribution.mean_finite", law.mean_finite),
        Call("Distribution.quantile", law.quantile, 0.5),
        Call("ExogenousChain.distribution", chain.distribution, 2, from_state="1"),
        Call("ExogenousChain.to_json", chain.to_json),
        Call("ExogenousChain.save", chain.save, str(tmp_path / "saved-chain.json")),
        Call("LiveSession", ontime.LiveSession, two, "mcts", seed=1, clock=ontime.ManualClock(), decision_share=0.5,
             iterations=10),
        Call("LiveSession.choose", lambda: live(choose=False).choose, fresh=True),
        Call("LiveSession.report_not_yet", lambda: live().report_not_yet, fresh=True),
        Call("LiveSession.report_not_yet chains", lambda: live(queue).report_not_yet, fresh=True,
             chains={"queue": "long"}),
        Call("LiveSession.report_refined_seconds", lambda: live().report_refined_seconds, fresh=True,
             execution_seconds=1.0),
        Call("LiveSession.report_refined_seconds chains", lambda: live(queue).report_refined_seconds, 1.0, fresh=True,
             chains={"queue": "short"}),
        Call("LiveSession.report_backtrack", lambda: live_backtracking().report_backtrack, "pick(A)", fresh=True),
        Call("LiveSession.charge_outside", lambda: live().charge_outside, 1.0, fresh=True),
        Call("LiveSession.add_skeleton", lambda: live(choose=False).add_skeleton, fresh=True, action_ids=["c"],
             new_actions=ontime.Problem.from_dict({**TWO_ACTIONS, "actions": {"c": TWO_ACTIONS["actions"]["a"]},
                                                   "skeletons": [["c"]]}).actions, reward=1.0, reward_per_step=0.0),
        Call("LiveSession.retire_skeleton", lambda: live(choose=False).retire_skeleton, 1, fresh=True),
        Call("LiveSession.revise_distributions", lambda: live(choose=False).revise_distributions, two, fresh=True),
        Call("ManualClock", ontime.ManualClock, 1.0),
        Call("ManualClock.advance", ontime.ManualClock().advance, 1.0),
        Call("Mdp", ontime.Mdp, problem),
        Call("Mdp.start", mdp.start),
        Call("Mdp.next_action", mdp.next_action, start, 1),
        Call("Mdp.useful_choices", mdp.useful_choices, start),
        Call("Mdp.can_succeed", mdp.can_succeed, start, 1),
        Call("OnlineBelief", ontime.OnlineBelief, problem, 10.0),
        Call("OnlineBelief.observe", lambda: belief().observe, fresh=True, action_id="a", effort=2, found=True),
        Call("OnlineBelief.observe episode", lambda: belief().observe, fresh=True, problem=two,
             attempts=attempts.attempts),
        Call("OnlineBelief.believed", belief().believed),
        Call("OnlineBelief.believed_for", belief().believed_for, two),
        Call("OnlineBelief.planning", belief().planning, "a"),
        Call("PlanningPosterior", ontime.PlanningPosterior, law, 10, 1.0),
        Call("PlanningPosterior backtrack", ontime.PlanningPosterior, law, 10, 1.0, backtrack=no_backtrack),
        Call("PlanningPosterior.observe_backtrack", lambda: posterior(backtrack=no_backtrack).observe_backtrack, 2,
             fresh=True),
        Call("PlanningPosterior.backtrack_mean", posterior(backtrack=no_backtrack).backtrack_mean),
        Call("PlanningPosterior.predictive_backtrack", posterior(backtrack=no_backtrack).predictive_backtrack, 2),
        Call("EndedAttempt", ontime.EndedAttempt, 2, found=False, backtracked=True),
        Call("OnlineBelief.backtrack", ontime.OnlineBelief(grasps, 2.0).backtrack, "place(A,R1)"),
        Call("ConcurrentSession", ontime.ConcurrentSession, moves, "dp-rerun", seed=1),
        Call("ConcurrentSession.choose", lambda: ontime.ConcurrentSession(moves, "dp-rerun").choose, fresh=True),
        Call("ConcurrentSession.decide", lambda: concurrent().decide, fresh=True, refine=0),
        Call("ConcurrentSession.decide start", lambda: concurrent(refined=True).decide, fresh=True, start="a"),
        Call("ConcurrentSession.report_not_yet", lambda: concurrent(pending=True).report_not_yet, fresh=True),
        Call("ConcurrentSession.report_refined", lambda: concurrent(pending=True).report_refined, 2, fresh=True),
        Call("ConcurrentSession.report_backtrack", lambda: concurrent_backtracking().report_backtrack, "pick(A)",
             fresh=True),
        Call("ConcurrentSession.report_execution_finished",
             lambda: concurrent(started=True).report_execution_finished, "a", fresh=True),
        Call("PlanningPosterior.observe_found", lambda: posterior().observe_found, 2, fresh=True),
        Call("PlanningPosterior.observe_cut_off", lambda: posterior().observe_cut_off, 2, fresh=True),
        Call("PlanningPosterior.mean", posterior().mean),
        Call("PlanningPosterior.predictive_found", posterior().predictive_found, 2),
        Call("PlanningPosterior.predictive_cut_off", posterior().predictive_cut_off, 2),
        Call("Problem.from_json", ontime.Problem.from_json, problem.to_json(), source="s"),
        Call("Problem.from_dict", ontime.Problem.from_dict, problem.to_dict(), "s"),
        Call("Problem.to_json", problem.to_json),
        Call("Problem.to_dict", problem.to_dict),
        Call("Problem.save", problem.save, str(tmp_path / "saved-problem.json")),
        Call("Problem.with_acting", problem.with_acting, "concurrent"),
        Call("Problem.find_action", problem.find_action, "a"),
        Call("Session", ontime.Session, ontime.make_allocator(two, "mcts"), seed=1, iterations=10, seconds=1.0),
        Call("Session.choose", lambda: session(choose=False).choose, fresh=True),
        Call("Session.choose budget", lambda: session(choose=False).choose, fresh=True, iterations=10, seconds=1.0),
        Call("Session.report_not_yet", lambda: session().report_not_yet, fresh=True),
        Call("Session.report_not_yet chains", lambda: session(queue).report_not_yet, fresh=True,
             chains={"queue": "long"}),
        Call("Session.report_refined", lambda: session().report_refined, 1, fresh=True),
        Call("Session.report_refined chains", lambda: session(queue).report_refined, 1, fresh=True,
             chains={"queue": "short"}),
        Call("Session.report_backtrack", lambda: backtracking(session(grasps, choose=False)).report_backtrack,
             "pick(A)", fresh=True),
        Call("Status", ontime.Status, 1),
        # ontime.env
        Call("env.EffortAllocationEnv", ontime.env.EffortAllocationEnv, two, seed=1),
        Call("env.EffortAllocationEnv.reset", lambda: environment(reset=False).reset, fresh=True, seed=1,
             options={}),
        Call("env.EffortAllocationEnv.step", lambda: environment().step, 0, fresh=True),
        Call("env.EffortAllocationEnv concurrent", ontime.env.EffortAllocationEnv, moves, seed=1, act="concurrent"),
        Call("env.EffortAllocationEnv.step concurrent", lambda: environment(act="concurrent").step, 0, fresh=True),
        Call("env.EffortAllocationEnv.action_of", lambda: environment(act="concurrent").action_of,
             {"start": None, "skeleton": 0}, fresh=True),
        Call("env.EffortAllocationEnv.action_masks", environment().action_masks),
        Call("env.EffortAllocationEnv.render", environment().render),
        Call("env.EffortAllocationEnv.close", environment().close),
        Call("env.Box", ontime.env.Box, 0.0, 1.0, (2,), dtype=np.float32, seed=1),
        Call("env.Box.seed", ontime.env.Box(0.0, 1.0, (2,)).seed, 1),
        Call("env.Box.sample", ontime.env.Box(0.0, 1.0, (2,)).sample),
        Call("env.Box.contains", ontime.env.Box(0.0, 1.0, (2,)).contains, [0.5, 0.5], answers_any=True),
        Call("env.Discrete", ontime.env.Discrete, 3, seed=1),
        Call("env.Discrete.seed", ontime.env.Discrete(3).seed, 1),
        Call("env.Discrete.sample", ontime.env.Discrete(3).sample, mask=[1, 0, 1]),
        Call("env.Discrete.contains", ontime.env.Discrete(3).contains, 1, answers_any=True),
    ]
    if ontime.domains.available:
        domains = ontime.domains
        world = tmp_path / "world.json"
        domains.generate_world(str(world), rows=1, cols=2, skeletons=1)
        navigation = domains.load("navigation", str(world))
        instance = tmp_path / "world-instance.json"
        domains.collect_and_fit(navigation, str(tmp_path / "world.jsonl"), str(instance), trials=2, threads=1)
        featured = domains.collect(navigation, trials=2, threads=1, features=True)
        world_model = ontime.fit_conditional(featured, step=navigation.defaults["step_seconds"], kind="pooled",
                                             domain="navigation")
        action = navigation.skeletons[0][0]
        out += [
            Call("domains.names", domains.names),
            Call("domains.load", domains.load, "navigation", str(world)),
            Call("domains.feature_names", domains.feature_names, "navigation"),
            Call("domains.features", domains.features, navigation, action),
            Call("domains.collect", domains.collect, navigation, trials=1, seed=1, threads=1, effort="checks",
                 checks_per_second=1000.0, step_seconds=3.0, budget_steps=5, every_action=False, features=True,
                 progress=lambda done, total: None),
            # A collection whose files could not be written leaves its checkpoint: each call starts afresh.
            Call("domains.collect_and_fit", lambda: (remove(tmp_path / "c.checkpoint"), domains.collect_and_fit)[1],
                 navigation, str(tmp_path / "c.jsonl"), fresh=True,
                 instance=str(tmp_path / "c.json"), trials=1, seed=1, threads=1, effort="checks",
                 checks_per_second=1000.0,
                 step_seconds=3.0, deadline=10, budget_steps=5, laplace=0.0, every_action=False, features=False,
                 log_format="jsonl", checkpoint=str(tmp_path / "c.checkpoint"), resume=False,
                 progress=lambda done, total: None),
            Call("domains.run", domains.run, navigation, str(instance), "dp-rerun", episodes=1, seed=1, threads=1,
                 effort="checks", checks_per_second=1000.0, independent_starts=False, exact=False, live=False,
                 decision_share=0.5, belief=str(instance), progress=lambda done, total: None),
            Call("domains.tamp", domains.tamp, navigation, str(instance), "dp-rerun", 30.0, episodes=1, seed=1,
                 threads=1, effort="checks", task_seconds=0.5, arrival_period=2, max_skeletons=2,
                 decision_share=0.5, clock="model", decision_seconds=0.01, iteration_seconds=0.001,
                 picture_episode=0, sequences=1, progress=lambda done, total: None),
            Call("domains.tamp concurrent", domains.tamp, navigation, str(instance), "dp-rerun", 30.0, episodes=1,
                 threads=1, clock="model", max_skeletons=2, act="concurrent"),
            Call("domains.run concurrent live", domains.run, navigation, str(instance), "dp-rerun", episodes=1,
                 seed=1, threads=1, live=True, act="concurrent", belief=str(instance)),
            Call("domains.tamp adapting", domains.tamp, navigation, str(instance), "dp-rerun", 30.0, episodes=1,
                 threads=1, clock="model", adapt_strength=5.0, sequences=2),
            Call("domains.map_data", domains.map_data, navigation, seed=1),
            Call("domains.predict", domains.predict, navigation, world_model, deadline=10, library=False, name="p",
                 threads=1),
            Call("domains.generate_world", domains.generate_world, str(tmp_path / "building.json"), rows=1, cols=2,
                 room_size=4.0, door_density=0.8, narrow_doors=0.2, narrow_min=0.76, narrow_max=0.86, wide_min=1.0,
                 wide_max=1.2, empty_rooms=0.2, cluttered_rooms=0.2, min_boxes=1, max_boxes=2, skeletons=1, seed=1,
                 name="b").allowing_none("name"),
            Call("domains.generate_world kitchen", domains.generate_world, str(tmp_path / "kitchen.json"),
                 domain="manipulation", tables=1, regions=1, region_min=0.2, region_max=0.3, targets=1,
                 min_objects=2, max_objects=3, min_clutter=0, max_clutter=1, classes=["cup", "box"], seed=1,
                 name="k").allowing_none("name"),
        ]
    return out


def remove(path):
    if path.exists():
        path.unlink()


def public_callables():
    """The qualified names of every public function, class and method of ontime, ontime.domains and
    ontime.env ("solve", "Problem", "Problem.from_json", "domains.load", "env.Box.sample")."""
    names = set()
    for prefix, module in (("", ontime), ("domains.", ontime.domains), ("env.", ontime.env)):
        # Everything public that the module defines (or the extension's part behind it) is in __all__.
        own = {module.__name__, module.__name__.replace("ontime", "ontime._ontime", 1)}
        for name, value in vars(module).items():
            if not name.startswith("_") and callable(value) and getattr(value, "__module__", "") in own:
                assert name in module.__all__, f"{prefix}{name} is public but not in {module.__name__}.__all__"
        for name in module.__all__:
            value = getattr(module, name)
            if isinstance(value, type):
                names.add(prefix + name)
                for attribute, member in vars(value).items():
                    if not attribute.startswith("_") and (isinstance(member, (staticmethod, classmethod)) or (
                            callable(member) and not isinstance(member, (type, value)))):
                        names.add(f"{prefix}{name}.{attribute}")
            elif callable(value):
                names.add(prefix + name)
    return names


def test_the_sweep_covers_every_public_callable(tmp_path):
    public = public_callables()
    swept = {call.name.split(" ")[0] for call in sweep_calls(tmp_path)}
    listed = swept | set(EXCLUDED) | set(MADE_BY_ONTIME)
    assert not public - listed, f"public callables without a call in the sweep: {sorted(public - listed)}"
    assert not listed - public, f"calls of callables that are not public: {sorted(listed - public)}"
    assert not swept & (set(EXCLUDED) | set(MADE_BY_ONTIME))


def signature_parameters(function):
    """[(name, default is None)] of a function's parameters (its object left out), from
    inspect.signature or from the signatures pybind11 writes in the docstring (every overload's);
    a class's are its constructor's."""
    if isinstance(function, type):
        function = function.__init__
    try:
        return [(p.name, p.default is None) for p in inspect.signature(function).parameters.values()
                if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name != "self"]
    except (TypeError, ValueError):
        pass
    out = []
    for match in re.finditer(r"^(?:\d+\. )?\w+\((.*)\)(?: -> .*)?$", function.__doc__ or "", re.MULTILINE):
        depth, part, parts = 0, "", []
        for char in match.group(1) + ",":
            depth += char in "[(" and 1 or (char in "])" and -1 or 0)
            if char == "," and depth == 0:
                parts.append(part.strip())
                part = ""
            else:
                part += char
        for text in parts:
            name, colon, rest = text.partition(":")
            if colon and name != "self" and not name.startswith("*"):
                out.append((name, rest.strip().endswith("= None")))
    return out


def kind(value):
    """The kind of value a parameter takes, for the rule that a value of another kind is refused."""
    if value is None:
        return "None"
    if isinstance(value, (bool, np.bool_)):
        return "bool"
    if isinstance(value, (int, np.integer)):
        return "whole number"
    if isinstance(value, (float, np.floating)):
        return "number"
    if isinstance(value, (str, bytes, os.PathLike)):
        return "text"
    if isinstance(value, Mapping):
        return "dict"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "list"
    return "object"


def must_refuse(good, bad, none_default):
    """Whether `bad` is of another kind than `good`, the value of a call that works (a whole number
    for a number, a tuple or a numpy array for a list, None where None is the default are not)."""
    if bad is None and none_default:
        return False
    if good is None or kind(good) == "object":
        return False  # a None or an object (a callback, a world, a problem) given: its kinds are many
    if (kind(good), kind(bad)) == ("number", "whole number"):
        return False
    return kind(good) != kind(bad)


def names_parameter(message, parameter, value):
    """Whether an error message names the parameter (as written, or with spaces or hyphens for its
    underscores) or, for a value of text or a list of texts, quotes it."""
    if any(spelling in message for spelling in {parameter, parameter.replace("_", " "), parameter.replace("_", "-")}):
        return True
    if isinstance(value, (list, tuple)) and value and isinstance(value[0], str):
        value = value[0]
    if isinstance(value, bytes):
        value = value.decode()
    return isinstance(value, str) and (f"'{value[:40]}" in message or message.startswith(value[:40] or "\0"))


def shown(value):
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def test_every_parameter_refuses_bad_values_with_ontimes_errors(tmp_path, monkeypatch):
    failures = []
    started = time.monotonic()
    slow = []
    swept = 0
    calls = sweep_calls(tmp_path)
    for number, call in enumerate(calls):
        # A path given as "x" is written in a folder of the call's own: another call does not read it.
        (tmp_path / f"call-{number}").mkdir()
        monkeypatch.chdir(tmp_path / f"call-{number}")
        call(call.args, call.kwargs)  # the call works as given
        parameters = signature_parameters(call.function())
        none_default = {name for name, is_none in parameters if is_none} | call.none_default
        names = [name for name, _ in parameters]
        variants = []
        for i, good in enumerate(call.args):
            name = names[i] if i < len(names) else f"argument {i + 1}"
            variants += [(name, good, bad, call.args[:i] + (bad,) + call.args[i + 1:], call.kwargs)
                         for bad in BAD_VALUES]
        for key, good in call.kwargs.items():
            variants += [(key, good, bad, call.args, {**call.kwargs, key: bad}) for bad in BAD_VALUES]
        for parameter, good, bad, args, kwargs in variants:
            if parameter in WORK_COUNTS and kind(bad) == "whole number" and bad in HUGE_COUNTS:
                continue
            at = time.monotonic()
            swept += 1
            try:
                call(args, kwargs)
                if must_refuse(good, bad, parameter in none_default) and not call.answers_any:
                    failures.append(f"{call.name}, {parameter}={shown(bad)}: taken for {shown(good)}")
            except ontime.UsageError as error:
                if not names_parameter(str(error), parameter, bad):
                    failures.append(f"{call.name}, {parameter}={shown(bad)}: UsageError not naming "
                                    f"'{parameter}': {str(error)[:160]}")
            except ontime.InputError:
                pass
            except Exception as error:  # noqa: BLE001 -- the point: anything else is a failure
                failures.append(f"{call.name}, {parameter}={shown(bad)}: {type(error).__name__}: "
                                f"{str(error).splitlines()[0][:160] if str(error) else ''}")
            if time.monotonic() - at > 1.0:
                slow.append(f"{call.name}, {parameter}={shown(bad)}: {time.monotonic() - at:.1f} s")
    print(f"sweep: {len({call.name.split(' ')[0] for call in calls})} callables, {len(calls)} calls, {swept} "
          f"variants, {time.monotonic() - started:.1f} s", *slow, sep="\n")
    assert not failures, f"{len(failures)} failures:\n" + "\n".join(failures)


def test_lists_given_as_numpy_arrays_work_as_the_lists_do(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    failures = []
    for call in sweep_calls(tmp_path):
        lists = [(i, value) for i, value in enumerate(call.args)] + list(call.kwargs.items())
        for key, value in lists:
            if not isinstance(value, (list, tuple)) or not value:
                continue
            array = np.array(value)
            if array.dtype.kind not in "fiuUb":
                continue  # lists of dicts, of objects, of rows of different lengths
            args = tuple(array if i == key else v for i, v in enumerate(call.args))
            kwargs = {k: (array if k == key else v) for k, v in call.kwargs.items()}
            try:
                call(args, kwargs)
            except Exception as error:  # noqa: BLE001
                failures.append(f"{call.name}, {key} as a numpy array: {type(error).__name__}: {error}")
    assert not failures, "\n".join(failures)


def test_an_argument_too_many_or_an_unknown_keyword_is_a_usage_error(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    failures = []
    for call in sweep_calls(tmp_path):
        signature = signature_parameters(call.function())
        extra = call.args + tuple(object() for _ in range(len(signature) + 1 - len(call.args)))
        for label, args, kwargs in (("an argument too many", extra, call.kwargs),
                                    ("an unknown keyword", call.args, {**call.kwargs, "no_such_parameter": 1})):
            try:
                call(args, kwargs)
                failures.append(f"{call.name}, {label}: taken")
            except ontime.UsageError:
                pass
            except Exception as error:  # noqa: BLE001
                failures.append(f"{call.name}, {label}: {type(error).__name__}: {str(error)[:160]}")
    assert not failures, "\n".join(failures)


def test_classes_that_ontime_makes_refuse_to_be_called():
    for name in MADE_BY_ONTIME:
        cls = ontime.domains.Domain if name == "domains.Domain" else getattr(ontime, name)
        for args in ((), (None,), ("x",), (1,)):
            with pytest.raises(ontime.UsageError, match=rf"^ontime\.{cls.__name__} objects are not made by calling"):
                cls(*args)


def test_what_the_sweep_found_is_refused_or_works(tmp_path):
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    two = ontime.Problem.from_dict(TWO_ACTIONS)
    mdp = ontime.Mdp(problem)
    start = mdp.start()
    # A status is one of its values (pybind11's constructor took any int: Status.???).
    assert ontime.Status(2) == ontime.Status.failure
    with pytest.raises(ontime.UsageError, match=r"^parameter 'value': must be a whole number from 0 to 2 \(got 7\)$"):
        ontime.Status(7)
    # A skeleton index or a state beyond the MDP's tables (read out of bounds before).
    with pytest.raises(ontime.UsageError, match=r"^parameter 'skeleton': must be a whole number from 0 to 3 "):
        mdp.next_action(start, 4)
    with pytest.raises(ontime.UsageError, match=r"^parameter 'state': a state of the MDP of another problem"):
        mdp.can_succeed(ontime.Mdp(two).start(), 0)
    with pytest.raises(ontime.UsageError, match=r"^parameter 'state': a state of the MDP of another problem"):
        ontime.make_allocator(mdp, "dp-rerun").choose(ontime.Mdp(two).start())
    assert mdp.next_action(ontime.Mdp(ontime.load_problem(PAPER_INSTANCES[0])).start(), 0) == mdp.next_action(start, 0)
    # A state compared with another object is not equal to it (a TypeError before).
    assert start != 3 and start is not None and start == mdp.start()
    # A numpy array of instances: each item held while it is read (a crash, later, before).
    path = tmp_path / "two.json"
    two.save(path)
    for instances in (np.array([str(path)]), [str(path)]):
        assert ontime.study("compute-time", instances, episodes=1, threads=1).startswith("instance,")
    # A World's class is a factory, one world per thread (it was taken for one World object).
    assert ontime.run_episodes(two, Tiny, "dp-rerun", episodes=4, threads=2)["successes"] == 4
    # Bools are bools: None or 0.5 were read as False and True.
    for value in (None, 0.5, 1):
        with pytest.raises(ontime.UsageError, match=r"^parameter 'exact': must be a bool \(True or False\)"):
            ontime.evaluate(problem, "dp-rerun", episodes=1, exact=value)
    # Outputs that cannot be written are UsageErrors naming the file (RuntimeError before).
    with pytest.raises(ontime.UsageError, match=r"cannot create a staging directory: No such file or directory$"):
        ontime.train_ppo(two, str(tmp_path / "missing" / "policy.json"), episodes=1)


def test_a_boosted_fit_with_a_huge_step_counts_each_found_motion_as_one_step():
    # Found by the sweep: with a step of 1e9 s a motion found after 1 s rounded to 0 steps, and the
    # boosted fit ended in an internal error. Rounded as `fit` rounds it, it is one step.
    records = [{"action": "a", "planning_seconds": 1.0, "found": True, "execution_seconds": 1.0,
                "features": [1.0]}] * 4
    model = ontime.fit_conditional(records, step=1e9, kind="boosted", trees=2, depth=2)
    assert model.horizon == 1


def test_a_refused_type_names_the_parameter_and_what_it_must_be(tmp_path):
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    law = problem.actions[0].planning
    cases = [
        (lambda: ontime.score(problem, [], floor="x"),
         "parameter 'floor': must be a finite number from 0.0 to 1.0 (got a str)"),
        (lambda: ontime.fit_strength(None, []), "parameter 'model': must be a ConditionalTimeModel (got None)"),
        (lambda: ontime.fit_conditional([], step=1.0, kind=None), "parameter 'kind': must be a str (got None)"),
        (lambda: ontime.fit_conditional([], step=1.0, horizon=1.5),
         "parameter 'horizon': must be a whole number from 0 to 10000 (got 1.5)"),
        (lambda: ontime.PlanningPosterior(law, 10, 1.0).observe_found(2**40),
         "parameter 'steps': must be a whole number from 1 to 2147483647 (got 1099511627776)"),
        (lambda: ontime.evaluate(problem), "parameter 'solver' is missing"),
        (lambda: ontime.evaluate(problem, None), "parameter 'solver': must be a str (got None)"),
        (lambda: ontime.table(None), "parameter 'instances': must be a list (got None)"),
        (lambda: ontime.fit([], step=None, deadline=3, skeletons=[["a"]]),
         "parameter 'step': must be a finite number >= 0.0 (got None)"),
    ]
    if ontime.domains.available:
        cases.append((lambda: ontime.domains.generate_world(str(tmp_path / "w.json"), domain="manipulation",
                                                            classes="cup"),
                      "parameter 'classes': must be a list whose items are each a str (got a str)"))
    for call, message in cases:
        with pytest.raises(ontime.UsageError) as error:
            call()
        assert str(error.value) == message


def test_numpy_arrays_are_taken_wherever_a_list_is(tmp_path):
    records = [{"action": "a", "planning_seconds": 1.0 + i % 3, "found": i % 2 == 0,
                "features": np.array([float(i % 3), 2.0])} for i in range(6)]
    for record in records[::2]:
        record["execution_seconds"] = np.float64(1.5)
    model = ontime.fit_conditional(records, step=1.0, kind="pooled")
    plain = ontime.fit_conditional([{**r, "features": r["features"].tolist()} for r in records], step=1.0,
                                   kind="pooled")
    assert model.to_json() == plain.to_json()
    assert model.feature_names == ["f1", "f2"]
    numpy_laws = model.predict(np.array([1.0, 2.0]))
    list_laws = plain.predict([1.0, 2.0])
    assert [law.pmf.tolist() for law in numpy_laws] == [law.pmf.tolist() for law in list_laws]
