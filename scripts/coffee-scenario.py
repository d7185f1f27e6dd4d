#!/usr/bin/python3
"""The coffee scenario: when does watching the coffee queue pay? (docs/spec.md §8, §9)

A robot must reach the meeting room before the deadline. Going through the coffee room, where it
queues for a coffee, is worth 1.0; going around it, without one, 0.7. The queue's length is an
exogenous chain fitted to simulated observations, and the way around passes a door that locks.
The study sweeps the queue's length when the robot starts, from empty to full, and compares
exactly the chain-aware optimum (`optimal`) with the baseline that plans on the chain's mean
occupancy and follows that plan blind to the queue (`averaged`), with the paper's heuristic
reading the queue at every step (`dp-rerun`, SPEC §9's rule), and with two chain-blind
heuristics.

What the script computes, every step an `ontime` command or standard-library Python, every random
choice drawn from `--seed`:

1. `ontime generate-world`: an office of `--rows` x `--cols` rooms (default 3 x 3) whose doors
   are all wide (`--narrow-doors`, default 0: the share of narrow doors).
2. Rooms and skeletons, chosen from the doors: the start is the world's start room, the meeting
   room its goal room (opposite corners). The coffee room lies on a shortest room path, is neither
   of them and can be avoided; among such rooms, the one whose avoidance costs the fewest extra
   moves, then the one nearest the middle of the path, then the one with the most room paths
   through it (at most two moves longer than the shortest), then the first in the world's order
   (`--coffee-room` names it instead). Skeletons are simple room paths of at most four moves more
   than the shortest, shortest first (ties in the order of the rooms' numbers): `--through` of
   them through the coffee room (default 2), `--around` avoiding it (default 1). A move reached
   after other moves than before is an action of its own, named as the task planner names it
   (`move(R7,R8)#2`), so that the skeletons form the prefix tree docs/formats.md requires.
   `coffee-world.json` is the world with these skeletons (moves only).
3. `ontime collect` along them with the real motion planner (`--trials` attempts per move, the
   deterministic checks unit) fits each move's planning and execution PMFs (`moves.json`). The
   step is `--step` seconds (default 6 s). The deadline (`--deadline` sets it) is the world's
   (5 steps of 3 s per move of a shortest path, at least 22 steps of 3 s), converted to the step
   and rounded up, plus the mean wait for a coffee of a robot arriving at a random moment, rounded
   up: (E[q] + 1) / service steps, E[q] the mean length of the stationary queue (the given arrival
   and service rates and capacity), i.e. the services of the people ahead plus one's own.
4. A coffee queue simulated as a birth-death process, one transition per step: a customer arrives
   with probability `--arrival` (default 0.1: about one a minute at 6 s a step; not when the queue
   holds `--capacity`, default 8), otherwise one is served with probability `--service` (default
   0.12: about 50 s a coffee; not when it is empty); `--days` days of `--day-steps` steps, each
   day starting empty, logged in the observation format of docs/formats.md (`queue.jsonl`) and
   fitted by `ontime fit-chain --kind birth-death` (`queue-chain.json`). Its stationary
   distribution is computed here from the fitted transitions by power iteration.
5. One instance per start of the queue, `coffee-start-K.json` for K = 0 .. capacity (`--starts`
   chooses some): the fitted moves; an action `coffee` right after the move into the coffee room
   of each through skeleton (planning: found in its first step; execution, drawn when it starts:
   in queue state q, the q services ahead plus one's own, each a geometric number of steps with
   the fitted service probability, so a negative binomial PMF, listed up to the deadline, the rest
   "never"); the fitted chain as `queue`, starting at K; on each around skeleton, the door where
   it leaves the through skeletons' doors (its first door no through skeleton crosses; if every
   door is crossed, its first move outside the through skeletons' prefix tree) locks: that move
   cannot start after step `--lock-step` (default: half the deadline, rounded down); rewards
   `--through-value` 1.0 and `--around-value` 0.7, each falling by `--per-step` per step
   (default 0).
6. Per start: `ontime solve` (the memoised exact solver: the optimum, its states and time) and
   `ontime evaluate --exact` of `optimal`, `averaged`, `averaged --horizon H` (`--long-horizon`,
   default 10000: the chain's occupancy averaged over H steps from the start, about the long-run
   mix a log of past waits gives; left out with a note when the command line does not know
   `--horizon`), `dp-rerun`, `first-found` and `round-robin`: each policy's exact expected reward and success
   probability. `optimal` re-solves inside `evaluate`; its exact reward is checked against the
   solve's at every start. The sweep evaluates exactly only (`--episodes 1`, the least the command
   accepts); at the fitted chain's start (the empty queue of the morning) each allocator is also
   sampled over `--episodes` episodes (default 10,000) as a check of the exact values. The row
   "random moment" averages each allocator's exact values over the starts, weighted by the fitted
   chain's stationary distribution (only when every start is swept).

Writes `sweep.csv` (start, allocator, exact reward and success), `solves.csv` (start, states,
seconds of the solve), `mc-check.csv` and `comparison.md` (the settings, the reward table with the
gain of `optimal` over `averaged`, the success table and the sampled check); prints the tables
and the total time. Progress lines (start, allocator, seconds) go to standard error. The same
options give the same files, byte for byte, but for measured times (`solves.csv`, `solve-K.json`).

    /usr/bin/python3 scripts/coffee-scenario.py --out /tmp/coffee-sweep
"""

import argparse
import csv
import json
import math
import os
import random
import re
import subprocess
import sys
import time
from collections import deque

PROGRAM = "coffee-scenario"
REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MOVE = re.compile(r"^move\(([^,()]+),([^,()]+)\)(#\d+)?$")
PATH_SLACK = 4  # room paths considered: at most this many moves longer than the shortest
RANDOM_MOMENT = "random moment"


class Parser(argparse.ArgumentParser):
    """Bad usage is one line on standard error and exit code 2."""

    def error(self, message):
        usage_error(message)


def usage_error(message):
    print(f"{PROGRAM}: usage error: {message}", file=sys.stderr)
    sys.exit(2)


def note(message):
    print(f"{PROGRAM}: {message}", file=sys.stderr, flush=True)


def fail(message):
    print(f"{PROGRAM}: {message}", file=sys.stderr)
    sys.exit(1)


def run(args, command):
    """Runs `ontime COMMAND...` and returns its standard output; stops the script if it fails."""
    full = [args.ontime, "--quiet", *map(str, command)]
    done = subprocess.run(full, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        fail(f"{' '.join(full)} failed ({done.returncode}): {done.stderr.strip()}")
    return done.stdout


def read_json(path):
    with open(path, encoding="utf-8") as text:
        return json.load(text)


def write_json(path, data):
    with open(path, "w", encoding="utf-8") as out:
        json.dump(data, out, indent=1)
        out.write("\n")


def room_order(room):
    digits = re.sub(r"\D", "", room)
    return (int(digits) if digits else 0, room)


# Rooms and skeletons ----------------------------------------------------------------------------

def neighbours(world):
    graph = {room: set() for room in world["rooms"]}
    for door in world["doors"]:
        a, b = door["rooms"]
        graph[a].add(b)
        graph[b].add(a)
    return {room: sorted(rooms, key=room_order) for room, rooms in graph.items()}


def distances(graph, source, avoid=None):
    """Moves from `source` to every room reachable without entering `avoid`."""
    seen = {source: 0}
    queue = deque([source])
    while queue:
        room = queue.popleft()
        for other in graph[room]:
            if other != avoid and other not in seen:
                seen[other] = seen[room] + 1
                queue.append(other)
    return seen


def simple_paths(graph, start, goal, longest):
    """Every simple room path from start to goal of at most `longest` moves, shortest first."""
    to_goal = distances(graph, goal)
    paths, path = [], [start]

    def extend(room):
        if room == goal:
            paths.append(list(path))
            return
        for other in graph[room]:
            if other not in path and len(path) + to_goal.get(other, math.inf) <= longest:
                path.append(other)
                extend(other)
                path.pop()

    extend(start)
    return sorted(paths, key=lambda p: (len(p), [room_order(r) for r in p]))


def choose_coffee_room(graph, start, goal, paths):
    """The coffee room (the order is in the header), or None when no room qualifies."""
    from_start, to_goal = distances(graph, start), distances(graph, goal)
    shortest = from_start[goal]
    best = None
    for room in sorted(graph, key=room_order):
        on_shortest = from_start.get(room, math.inf) + to_goal.get(room, math.inf) == shortest
        around = distances(graph, start, avoid=room).get(goal)
        if room in (start, goal) or not on_shortest or around is None:
            continue
        through = sum(1 for p in paths if room in p and len(p) - 1 <= shortest + 2)
        middle = abs(from_start[room] - to_goal[room])
        key = (around - shortest, middle, -through, room_order(room))
        if best is None or key < best[0]:
            best = (key, room)
    return None if best is None else best[1]


def name_skeletons(token_skeletons):
    """Action ids of skeletons of tokens ((FROM, TO) for a move, or "coffee"): a token reached
    after other tokens than before is an action of its own, `NAME#k`, k counting the prefixes it
    was reached after; the skeletons then form a prefix tree."""
    ids, counts, named = {}, {}, []
    for tokens in token_skeletons:
        skeleton = []
        for i, token in enumerate(tokens):
            key = tuple(tokens[: i + 1])
            if key not in ids:
                base = token if isinstance(token, str) else f"move({token[0]},{token[1]})"
                counts[base] = counts.get(base, 0) + 1
                ids[key] = base if counts[base] == 1 else f"{base}#{counts[base]}"
            skeleton.append(ids[key])
        named.append(skeleton)
    return named


def door_of(action):
    """The rooms a move's door joins, or None for an action that is not a move."""
    match = MOVE.match(action)
    return None if match is None else frozenset((match.group(1), match.group(2)))


def plan_skeletons(args, world):
    graph = neighbours(world)
    start, goal = world["start"]["room"], world["goal_room"]
    shortest = distances(graph, start)[goal]
    paths = simple_paths(graph, start, goal, shortest + PATH_SLACK)
    coffee_room = args.coffee_room or choose_coffee_room(graph, start, goal, paths)
    if coffee_room is None:
        fail(f"no room on a shortest path from {start} to {goal} can be avoided; "
             "try another --seed")
    if coffee_room not in graph or coffee_room in (start, goal):
        usage_error(f"--coffee-room {coffee_room}: not a room of the world other than {start} "
                    f"and {goal}")
    through = [p for p in paths if coffee_room in p][: args.through]
    around = [p for p in paths if coffee_room not in p][: args.around]
    if not through or not around:
        fail(f"no room path of at most {shortest + PATH_SLACK} moves goes "
             f"{'through' if not through else 'around'} {coffee_room}")
    if len(through) < args.through or len(around) < args.around:
        note(f"only {len(through)} paths through and {len(around)} around {coffee_room} of at "
             f"most {shortest + PATH_SLACK} moves")
    tokens = []
    for path in through + around:
        moves = []
        for a, b in zip(path, path[1:]):
            moves.append((a, b))
            if b == coffee_room:
                moves.append("coffee")
        tokens.append(moves)
    return {"start": start, "meeting": goal, "coffee_room": coffee_room,
            "skeletons": name_skeletons(tokens), "through": len(through)}


def locked_moves(plan):
    """Per around skeleton, the move through its first door no through skeleton crosses (else its
    first action outside the through skeletons' prefix tree)."""
    through = plan["skeletons"][: plan["through"]]
    through_doors = {door_of(a) for s in through for a in s} - {None}
    through_ids = {a for s in through for a in s}
    locked = []
    for skeleton in plan["skeletons"][plan["through"]:]:
        chosen = next((a for a in skeleton if door_of(a) not in through_doors), None)
        locked.append(chosen or next(a for a in skeleton if a not in through_ids))
    return locked


# The queue --------------------------------------------------------------------------------------

def stationary_mean_wait(arrival, service, capacity):
    """Steps of the wait for a coffee behind the stationary queue: (E[q] + 1) / service."""
    weights = [(arrival / service) ** n for n in range(capacity + 1)]
    mean_queue = sum(n * w for n, w in enumerate(weights)) / sum(weights)
    return (mean_queue + 1) / service


def simulate_queue(path, args):
    draw = random.Random(args.seed)
    with open(path, "w", encoding="utf-8") as log:
        for day in range(1, args.days + 1):
            length = 0
            for step in range(args.day_steps):
                record = {"sequence": f"day{day}", "step": step, "state": length}
                log.write(json.dumps(record) + "\n")
                u = draw.random()
                arrives = args.arrival if length < args.capacity else 0.0
                if u < arrives:
                    length += 1
                elif length > 0 and u < arrives + args.service:
                    length -= 1


def wait_pmf(ahead, service, deadline):
    """PMF of the sum of `ahead` + 1 geometric service times (success probability `service`, at
    least one step each), over steps 1..deadline; the mass beyond is left as "never"."""
    served = ahead + 1
    pmf = {}
    for steps in range(served, deadline + 1):
        probability = (math.comb(steps - 1, ahead) * service ** served
                       * (1.0 - service) ** (steps - served))
        if probability > 0.0:
            pmf[str(steps)] = probability
    return {"pmf": pmf}



def stationary_distribution(transitions, tolerance=1e-15, rounds=1_000_000):
    """The stationary distribution of a chain's transition matrix, by power iteration."""
    size = len(transitions)
    share = [1.0 / size] * size
    for _ in range(rounds):
        following = [sum(share[i] * transitions[i][j] for i in range(size)) for j in range(size)]
        total = sum(following)
        following = [x / total for x in following]
        if max(abs(a - b) for a, b in zip(share, following)) < tolerance:
            return following
        share = following
    return share


# The study --------------------------------------------------------------------------------------

def parse_arguments():
    parser = Parser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder (created if missing)")
    parser.add_argument("--ontime", default=os.path.join(REPOSITORY, "build", "ontime"),
                        help="the ontime binary (default: build/ontime of this repository)")
    parser.add_argument("--seed", type=int, default=1, help="seed of every random choice")
    parser.add_argument("--rows", type=int, default=3, help="rooms along y")
    parser.add_argument("--cols", type=int, default=3, help="rooms along x")
    parser.add_argument("--narrow-doors", type=float, default=0.0,
                        help="share of the building's doors that are narrow (default 0: all wide)")
    parser.add_argument("--coffee-room", help="the coffee room (default: chosen from the doors)")
    parser.add_argument("--through", type=int, default=2, help="skeletons through the coffee room")
    parser.add_argument("--around", type=int, default=1, help="skeletons around the coffee room")
    parser.add_argument("--trials", type=int, default=150, help="attempts per move collected")
    parser.add_argument("--threads", type=int, default=1,
                        help="threads of collect and evaluate (0: one per hardware thread)")
    parser.add_argument("--step", type=float, default=6.0, help="seconds of effort per step")
    parser.add_argument("--deadline", type=int, default=0,
                        help="deadline in steps (0: the world's plus the mean wait for a coffee)")
    parser.add_argument("--arrival", type=float, default=0.1,
                        help="queue: probability of an arrival per step")
    parser.add_argument("--service", type=float, default=0.12,
                        help="queue: probability of a service per step")
    parser.add_argument("--capacity", type=int, default=8, help="queue: most people in line")
    parser.add_argument("--days", type=int, default=5, help="queue: days observed")
    parser.add_argument("--day-steps", type=int, default=1000, help="queue: steps observed a day")
    parser.add_argument("--starts", help="queue lengths at step 0 swept, comma-separated "
                        "(default: every one, 0 to the capacity)")
    parser.add_argument("--lock-step", type=int, help="the locking door cannot be passed after "
                        "this step (default: half the deadline)")
    parser.add_argument("--through-value", type=float, default=1.0, help="reward with a coffee")
    parser.add_argument("--around-value", type=float, default=0.7, help="reward without one")
    parser.add_argument("--per-step", type=float, default=0.0, help="fall of the rewards per step")
    parser.add_argument("--long-horizon", type=int, default=10_000,
                        help="steps of the second averaged column (averaged --horizon; 0: none)")
    parser.add_argument("--max-states", type=int, default=10_000_000,
                        help="cap on the states of the exact solve and exact evaluations")
    parser.add_argument("--episodes", type=int, default=10_000,
                        help="episodes of the sampled check at the fitted chain's start")
    args = parser.parse_args()

    if not (os.path.isfile(args.ontime) and os.access(args.ontime, os.X_OK)):
        usage_error(f"--ontime: no executable at {args.ontime}")
    checks = [
        (args.seed >= 0, "--seed must be at least 0"),
        (1 <= args.rows <= 50 and 1 <= args.cols <= 50 and args.rows * args.cols >= 3,
         "--rows and --cols must be 1 to 50, with at least 3 rooms"),
        (0.0 <= args.narrow_doors <= 1.0, "--narrow-doors must lie in [0, 1]"),
        (args.through >= 1 and args.around >= 1 and args.through + args.around <= 16,
         "--through and --around must be at least 1, and at most 16 together"),
        (args.trials >= 1, "--trials must be at least 1"),
        (0 <= args.threads <= 1024, "--threads must be 0 to 1024"),
        (0.0 < args.step <= 1e6, "--step must be a positive number of seconds"),
        (0 <= args.deadline <= 10_000, "--deadline must be 0 to 10000"),
        (0.0 < args.arrival < 1.0 and 0.0 < args.service < 1.0,
         "--arrival and --service must lie in (0, 1)"),
        (args.arrival + args.service <= 1.0, "--arrival plus --service must be at most 1"),
        (1 <= args.capacity <= 4095, "--capacity must be 1 to 4095"),
        (args.days >= 1 and args.day_steps >= 2,
         "--days must be at least 1, --day-steps at least 2"),
        (args.lock_step is None or args.lock_step >= 0, "--lock-step must be at least 0"),
        (0.0 <= args.through_value <= 1.0 and 0.0 <= args.around_value <= 1.0,
         "--through-value and --around-value must lie in [0, 1]"),
        (args.per_step >= 0.0, "--per-step must be at least 0"),
        (0 <= args.long_horizon <= 1_000_000, "--long-horizon must be 0 to 1000000"),
        (args.max_states >= 1, "--max-states must be at least 1"),
        (args.episodes >= 1, "--episodes must be at least 1"),
    ]
    for ok, message in checks:
        if not ok:
            usage_error(message)
    if args.starts is None:
        args.starts = list(range(args.capacity + 1))
    else:
        starts = [s.strip() for s in args.starts.split(",") if s.strip()]
        if not starts or not all(s.isdigit() and int(s) <= args.capacity for s in starts):
            usage_error(f"--starts must list queue lengths from 0 to {args.capacity}")
        args.starts = sorted({int(s) for s in starts})
    return args


def check_against_deadline(args, deadline):
    """The options that depend on the deadline; sets the default lock step."""
    if args.lock_step is None:
        args.lock_step = deadline // 2
    if args.lock_step > deadline:
        usage_error(f"--lock-step {args.lock_step}: past the deadline ({deadline} steps)")
    if min(args.through_value, args.around_value) - args.per_step * deadline < 0.0:
        usage_error(f"--per-step {args.per_step:g}: a reward would fall below 0 by the deadline "
                    f"({deadline} steps)")


def coffee_instance(args, plan, moves, chain, service, lock_step, start):
    deadline = moves["deadline"]
    through, count = plan["through"], len(plan["skeletons"])
    values = [args.through_value] * through + [args.around_value] * (count - through)
    actions = dict(moves["actions"])
    waits = {state: wait_pmf(int(state), service, deadline) for state in chain["states"]}
    for skeleton in plan["skeletons"]:
        for action in skeleton:
            if action.split("#")[0] == "coffee":
                actions[action] = {"planning": {"pmf": {"1": 1.0}},
                                   "execution": {"chain": "queue", "by_state": waits}}
    locked = locked_moves(plan)
    for action in locked:
        actions[action] = dict(actions[action], expires={"after": lock_step})
    doors = sorted({"-".join(sorted(door_of(a), key=room_order)) for a in locked})
    description = (
        f"To the meeting in {plan['meeting']} from {plan['start']}: through the coffee room "
        f"{plan['coffee_room']} (worth {args.through_value:g}), where the wait depends on the "
        f"queue's length (chain 'queue', fitted to simulated observations, {start} in line at "
        f"step 0), or around it (worth {args.around_value:g}) through the "
        f"door{'s' if len(doors) > 1 else ''} {', '.join(doors)}, locked after step {lock_step} "
        f"(SPEC §8, §9). Building {args.rows} x {args.cols}, seed {args.seed}, "
        f"{args.trials} attempts per move.")
    rewards = [v if args.per_step == 0.0 else {"value": v, "per_step": args.per_step}
               for v in values]
    return {
        "name": f"coffee-start-{start}",
        "description": description,
        "deadline": deadline,
        "step_seconds": moves.get("step_seconds", 1.0),
        "chains": {"queue": {"states": chain["states"],
                             "start": str(start),
                             "transitions": chain["transitions"]}},
        "actions": actions,
        "skeletons": plan["skeletons"],
        "rewards": rewards,
    }, values, locked


def allocator_columns(args):
    """(label, solver arguments) of the compared allocators, in the tables' order."""
    columns = [("optimal", ["optimal"]), ("averaged", ["averaged"])]
    if args.long_horizon:
        columns.append((f"averaged --horizon {args.long_horizon}",
                        ["averaged", "--horizon", str(args.long_horizon)]))
    columns += [("dp-rerun", ["dp-rerun"]), ("first-found", ["first-found"]),
                ("round-robin", ["round-robin"])]
    return columns


def evaluate(args, instance, solver, episodes):
    """Exact (and, with more than one episode, sampled) evaluation of one allocator; None (with a
    note) when the command line refuses the allocator or one of its options."""
    command = [args.ontime, "--quiet", "evaluate", instance, "--solver", *solver, "--exact",
               "--episodes", str(episodes), "--seed", str(args.seed), "--threads",
               str(args.threads), "--max-states", str(args.max_states), "--no-timing", "--json"]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    refused = any(text in done.stderr for text in
                  ("unknown solver", "does not take", "were not expected", "was not expected"))
    if done.returncode == 2 and refused:
        note(f"{' '.join(solver)} left out: {done.stderr.strip()}")
        return None
    if done.returncode != 0:
        fail(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip()}")
    result = json.loads(done.stdout)
    # With every reward 1 the command reports success only: the reward is the success.
    return {
        "exact_expected_reward": result.get("exact_expected_reward",
                                            result["exact_success_probability"]),
        "exact_success_probability": result["exact_success_probability"],
        "mean_reward": result.get("mean_reward", result["success_rate"]),
        "reward_ci95": result.get("reward_ci95", result["ci95"]),
        "success_rate": result["success_rate"],
        "success_ci95": result["ci95"],
        "episodes": result["episodes"],
    }


def skeleton_rooms(plan, skeleton):
    """A skeleton as its rooms, the coffee marked: `R1 R2 R5+coffee R8 R9`."""
    rooms = [plan["start"]]
    for action in skeleton:
        match = MOVE.match(action)
        if match is not None:
            rooms.append(match.group(2))
        else:
            rooms[-1] += "+coffee"
    return " → ".join(rooms)


def settings_paragraph(args, plan, deadline, deadline_rule, values, locked, fitted, stationary,
                       step_seconds):
    mean_queue = sum(n * p for n, p in enumerate(stationary))
    skeletons = "; ".join(f"{skeleton_rooms(plan, s)} (worth {v:g})"
                          for s, v in zip(plan["skeletons"], values))
    doors = ", ".join(f"{a} ({'-'.join(sorted(door_of(a), key=room_order))})"
                      if door_of(a) else a for a in locked)
    per_step = (f", each falling by {args.per_step:g} per step" if args.per_step else "")
    return (
        f"Coffee scenario: an office of {args.rows} x {args.cols} rooms (`generate-world` seed "
        f"{args.seed}, share of narrow doors {args.narrow_doors:g}); start {plan['start']}, coffee "
        f"room {plan['coffee_room']}, meeting room {plan['meeting']}. Skeletons "
        f"({plan['through']} through the coffee room, {len(values) - plan['through']} around it): "
        f"{skeletons}{per_step}. Moves fitted from {args.trials} motion-planner attempts each. "
        f"The way around is closed after step {args.lock_step}: {doors}. Steps of "
        f"{step_seconds:g} s; deadline {deadline} steps ({deadline * step_seconds:g} s: "
        f"{deadline_rule}). Queue: simulated with arrival {args.arrival:g} and service "
        f"{args.service:g} per step, capacity {args.capacity}, {args.days} days of "
        f"{args.day_steps} steps each starting empty; fitted birth-death chain: arrival "
        f"{fitted['arrival']:.4f}, service {fitted['service']:.4f} per step; its stationary mean "
        f"length {mean_queue:.3f}. The coffee takes the services of the people ahead plus one's "
        f"own, each geometric with the fitted service probability. Values are exact "
        f"(`ontime evaluate --exact`); `optimal` watches the queue, `averaged` plans with the "
        f"queue replaced by its mean occupancy over the deadline from the start and follows that "
        f"plan blind to the queue, `averaged --horizon {args.long_horizon}` the same with the "
        f"occupancy averaged over {args.long_horizon} steps (about the long-run mix of a log of "
        f"past waits). The row \"{RANDOM_MOMENT}\" weights the starts by the fitted chain's "
        f"stationary distribution (column π).")


def write_outputs(args, labels, starts, results, stationary, paragraph, mc_rows, default_start):
    with open(os.path.join(args.out, "sweep.csv"), "w", encoding="utf-8", newline="") as out:
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(["start", "allocator", "exact_expected_reward",
                         "exact_success_probability"])
        for start in starts:
            for label in labels:
                row = results[start][label]
                writer.writerow([start, label, repr(row["exact_expected_reward"]),
                                 repr(row["exact_success_probability"])])
        if RANDOM_MOMENT in results:
            for label in labels:
                row = results[RANDOM_MOMENT][label]
                writer.writerow([RANDOM_MOMENT, label, repr(row["exact_expected_reward"]),
                                 repr(row["exact_success_probability"])])
    with open(os.path.join(args.out, "mc-check.csv"), "w", encoding="utf-8", newline="") as out:
        fields = ["start", "allocator", "exact_expected_reward", "mean_reward", "reward_ci95",
                  "exact_success_probability", "success_rate", "success_ci95", "episodes"]
        writer = csv.DictWriter(out, fieldnames=fields, lineterminator="\n")
        writer.writeheader()
        writer.writerows(mc_rows)

    keys = list(starts) + ([RANDOM_MOMENT] if RANDOM_MOMENT in results else [])

    def share(key):
        return "1" if key == RANDOM_MOMENT else f"{stationary[key]:.4f}"

    def name(key):
        return f"**{key}**" if key == RANDOM_MOMENT else str(key)

    lines = [paragraph, "", "Exact expected reward by the queue's length at step 0:", "",
             "| start | π | " + " | ".join(f"`{l}`" for l in labels)
             + " | gain of optimal over averaged (reward) | (success probability) |",
             "|---" * (len(labels) + 4) + "|"]
    for key in keys:
        row = results[key]
        gain = row["optimal"]["exact_expected_reward"] - row["averaged"]["exact_expected_reward"]
        gain_success = (row["optimal"]["exact_success_probability"]
                        - row["averaged"]["exact_success_probability"])
        lines.append(f"| {name(key)} | {share(key)} | "
                     + " | ".join(f"{row[l]['exact_expected_reward']:.4f}" for l in labels)
                     + f" | {gain:+.4f} | {gain_success:+.4f} |")
    lines += ["", "Exact success probability (on time by either way):", "",
              "| start | " + " | ".join(f"`{l}`" for l in labels) + " |",
              "|---" * (len(labels) + 1) + "|"]
    for key in keys:
        lines.append(f"| {name(key)} | "
                     + " | ".join(f"{results[key][l]['exact_success_probability']:.4f}"
                                  for l in labels) + " |")
    if mc_rows:
        lines += ["", f"Sampled check at start {default_start} ({mc_rows[0]['episodes']} episodes, "
                  "95% half-widths):", "",
                  "| allocator | exact reward | sampled mean reward | exact success | "
                  "success rate |", "|---|---|---|---|---|"]
        for row in mc_rows:
            lines.append(f"| `{row['allocator']}` | {row['exact_expected_reward']:.4f} | "
                         f"{row['mean_reward']:.4f} ± {row['reward_ci95']:.4f} | "
                         f"{row['exact_success_probability']:.4f} | {row['success_rate']:.4f} ± "
                         f"{row['success_ci95']:.4f} |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "comparison.md"), "w", encoding="utf-8") as out:
        out.write(text)
    return text


def main():
    began = time.monotonic()
    args = parse_arguments()
    os.makedirs(args.out, exist_ok=True)

    def path(name):
        return os.path.join(args.out, name)

    note(f"1/6 an office of {args.rows} x {args.cols} rooms (seed {args.seed}, share of narrow "
         f"doors {args.narrow_doors:g})")
    run(args, ["generate-world", "--rows", args.rows, "--cols", args.cols, "--seed", args.seed,
               "--narrow-doors", args.narrow_doors, "-o", path("world.json")])
    world = read_json(path("world.json"))

    plan = plan_skeletons(args, world)
    world["skeletons"] = [[a for a in s if a.split("#")[0] != "coffee"] for s in plan["skeletons"]]
    world["description"] += (f" Coffee scenario: start {plan['start']}, coffee room "
                             f"{plan['coffee_room']}, meeting room {plan['meeting']}.")
    write_json(path("coffee-world.json"), world)
    note(f"2/6 start {plan['start']}, coffee room {plan['coffee_room']}, meeting room "
         f"{plan['meeting']}: {plan['through']} skeletons through, "
         f"{len(plan['skeletons']) - plan['through']} around")

    deadline = args.deadline
    if deadline:
        deadline_rule = "given"
    else:
        world_seconds = world["collection"]["deadline"] * world["collection"]["step_seconds"]
        wait = stationary_mean_wait(args.arrival, args.service, args.capacity)
        walk = math.ceil(world_seconds / args.step - 1e-9)
        deadline = min(walk + math.ceil(wait), 10_000)
        deadline_rule = (f"the world's {world_seconds:g} s, {walk} steps, plus the mean wait for "
                         f"a coffee behind the stationary queue, {wait:.2f} steps rounded up to "
                         f"{math.ceil(wait)}")
    check_against_deadline(args, deadline)
    note(f"3/6 collecting {args.trials} attempts per move, steps of {args.step:g} s, deadline "
         f"{deadline} steps")
    started = time.monotonic()
    run(args, ["collect", "--domain", "navigation", "--world", path("coffee-world.json"),
               "--trials", args.trials, "--seed", args.seed, "--threads", args.threads,
               "--step", args.step, "--deadline", deadline,
               "--log", path("moves.jsonl"), "-o", path("moves.json")])
    collect_seconds = time.monotonic() - started
    moves = read_json(path("moves.json"))

    note(f"4/6 the queue: {args.days} days of {args.day_steps} steps, a birth-death chain fitted")
    simulate_queue(path("queue.jsonl"), args)
    fitted = json.loads(run(args, ["fit-chain", "--kind", "birth-death",
                                   "--capacity", args.capacity, "--name", "queue",
                                   "-o", path("queue-chain.json"), path("queue.jsonl"), "--json"]))
    chain = read_json(path("queue-chain.json"))
    if chain["states"] != [str(n) for n in range(args.capacity + 1)]:
        fail(f"the fitted queue's states are {chain['states']}, not 0 to {args.capacity}")
    stationary = stationary_distribution(chain["transitions"])
    default_start = int(chain["start"])

    columns = allocator_columns(args)
    results, solves, mc_rows, largest_gap = {}, [], [], 0.0
    values = locked = None
    for n, start in enumerate(args.starts):
        instance, values, locked = coffee_instance(args, plan, moves, chain, fitted["service"],
                                                   args.lock_step, start)
        name = path(f"coffee-start-{start}.json")
        write_json(name, instance)
        note(f"5/6 start {start} ({n + 1} of {len(args.starts)}): solving exactly")
        started = time.monotonic()
        solved = json.loads(run(args, ["solve", name, "--max-states", args.max_states, "--json"]))
        seconds = time.monotonic() - started
        write_json(path(f"solve-{start}.json"), solved)
        solves.append({"start": start, "states": solved.get("states"),
                       "seconds": round(seconds, 1)})
        note(f"    start {start}: solve {seconds:.1f} s, {solved.get('states')} states, optimum "
             f"{solved['optimal_expected_reward']:.6f}")
        results[start] = {}
        for label, solver in list(columns):
            episodes = args.episodes if start == default_start else 1
            started = time.monotonic()
            row = evaluate(args, name, solver, episodes)
            if row is None:
                columns.remove((label, solver))
                continue
            note(f"6/6 start {start}: {label}: {time.monotonic() - started:.1f} s (exact"
                 f"{f', {episodes} episodes' if episodes > 1 else ''})")
            results[start][label] = row
            if start == default_start:
                mc_rows.append({"start": start, "allocator": label,
                                **{k: row[k] for k in ("exact_expected_reward", "mean_reward",
                                                       "reward_ci95", "exact_success_probability",
                                                       "success_rate", "success_ci95",
                                                       "episodes")}})
        gap = abs(results[start]["optimal"]["exact_expected_reward"]
                  - solved["optimal_expected_reward"])
        largest_gap = max(largest_gap, gap)
        if gap > 1e-9:
            evaluated = results[start]["optimal"]["exact_expected_reward"]
            note(f"start {start}: evaluate optimal {evaluated!r} differs from solve "
                 f"{solved['optimal_expected_reward']!r}")
    labels = [label for label, _ in columns]
    for start in args.starts:  # a column dropped part way is dropped everywhere
        results[start] = {label: results[start][label] for label in labels}
    mc_rows = [row for row in mc_rows if row["allocator"] in labels]
    if args.starts == list(range(args.capacity + 1)):
        results[RANDOM_MOMENT] = {
            label: {key: sum(stationary[s] * results[s][label][key] for s in args.starts)
                    for key in ("exact_expected_reward", "exact_success_probability")}
            for label in labels}

    paragraph = settings_paragraph(args, plan, deadline, deadline_rule, values, locked, fitted,
                                   stationary, moves.get("step_seconds", args.step))
    text = write_outputs(args, labels, args.starts, results, stationary, paragraph, mc_rows,
                         default_start)
    with open(path("solves.csv"), "w", encoding="utf-8", newline="") as out:
        writer = csv.DictWriter(out, fieldnames=["start", "states", "seconds"],
                                lineterminator="\n")
        writer.writeheader()
        writer.writerows(solves)

    print(f"collect {collect_seconds:.1f} s")
    print("solves (start: states, seconds): " + "; ".join(
        f"{s['start']}: {s['states']}, {s['seconds']:.1f}" for s in solves))
    print(f"optimal: evaluate --exact and solve differ by at most {largest_gap:.2e}")
    print()
    print(text)
    print(f"files in {args.out}:")
    for name in sorted(os.listdir(args.out)):
        print(f"  {name:<22} {os.path.getsize(path(name)):>9} bytes")
    print(f"total time {time.monotonic() - began:.1f} s")


if __name__ == "__main__":
    main()
