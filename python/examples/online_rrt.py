"""An online session driving a small pure-Python planner on the clock.

A point robot in a 10 m x 10 m room must reach the goal through one of two routes: through a narrow
gap in a wall (short, hard to plan) or around the wall's open end (long, easy). Each abstract move is
refined by a numpy RRT that is resumed slice by slice: one step of effort is STEP seconds of wall
clock. The time distributions come from the planner itself: a few timed trials per move, written as
planner-log records and fitted (ontime.fit). Then an OnTime session decides, before every slice,
which move gets it, and the episode ends when a route is refined and executable before the deadline.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/online_rrt.py [--seed N]

Prints the success the fitted model lets dp-rerun expect, every decision, and the outcome (wall-clock times vary run to run).
"""

import argparse
import time

import numpy as np

import ontime

STEP = 0.01      # seconds of planning effort per step
DEADLINE = 40    # steps: planning and execution together
SPEED = 2.0      # metres per step when executing
WALLS = [(4.8, 0.0, 5.2, 4.6), (4.8, 4.9, 5.2, 8.0)]  # rectangles (x0, y0, x1, y1); gap at y 4.6..4.9
POINTS = {"S": (1.0, 2.0), "G": (9.0, 2.0), "P": (5.0, 9.0), "Q": (4.0, 4.75)}
SKELETONS = [["move(S,Q)", "move(Q,G)"], ["move(S,P)", "move(P,G)"]]


def free(points):
    x, y = points[..., 0], points[..., 1]
    inside = np.zeros(x.shape, dtype=bool)
    for x0, y0, x1, y1 in WALLS:
        inside |= (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    return ~inside & (x >= 0) & (x <= 10) & (y >= 0) & (y <= 10)


def segment_free(a, b):
    samples = np.linspace(0.0, 1.0, max(2, int(np.linalg.norm(b - a) / 0.02)))[:, None]
    return bool(free(a + samples * (b - a)).all())


class Rrt:
    """An RRT from `start` to `goal` that can be resumed: advance(seconds) grows the same tree."""

    def __init__(self, start, goal, seed):
        self.rng = np.random.default_rng(seed)
        self.nodes = np.array([start], dtype=float)
        self.parents = [-1]
        self.goal = np.asarray(goal, dtype=float)
        self.path = None

    def advance(self, seconds):
        until = time.perf_counter() + seconds
        while self.path is None and time.perf_counter() < until:
            target = self.goal if self.rng.random() < 0.1 else self.rng.uniform(0, 10, 2)
            nearest = int(np.argmin(((self.nodes - target) ** 2).sum(axis=1)))
            direction = target - self.nodes[nearest]
            length = np.linalg.norm(direction)
            new = target if length < 0.4 else self.nodes[nearest] + direction * (0.4 / length)
            if not segment_free(self.nodes[nearest], new):
                continue
            self.nodes = np.vstack([self.nodes, new])
            self.parents.append(nearest)
            if np.linalg.norm(new - self.goal) < 1e-9 or (
                    np.linalg.norm(new - self.goal) < 0.4 and segment_free(new, self.goal)):
                self.path = self.trace(len(self.nodes) - 1) + [self.goal]
        return self.path is not None

    def trace(self, index):
        path = []
        while index >= 0:
            path.append(self.nodes[index])
            index = self.parents[index]
        return path[::-1]

    def execution_steps(self):
        length = sum(np.linalg.norm(b - a) for a, b in zip(self.path, self.path[1:]))
        return int(np.ceil(length / SPEED))


def endpoints(action):
    a, b = action[len("move("):-1].split(",")
    return POINTS[a], POINTS[b]


def collect(trials, seed):
    """Timed trials of every move, as planner-log records (cut off after DEADLINE steps)."""
    records = []
    for index, action in enumerate(sorted({a for s in SKELETONS for a in s})):
        for trial in range(trials):
            planner = Rrt(*endpoints(action), seed=seed * 1000 + index * 100 + trial)
            started = time.perf_counter()
            found = planner.advance(DEADLINE * STEP)
            spent = time.perf_counter() - started
            record = {"action": action, "planning_seconds": min(spent, DEADLINE * STEP), "found": found}
            if found:
                record["execution_seconds"] = planner.execution_steps() * STEP
            records.append(record)
    return records


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--trials", type=int, default=8)
    args = parser.parse_args()

    problem = ontime.fit(collect(args.trials, args.seed), step=STEP, deadline=DEADLINE, skeletons=SKELETONS,
                         name="two-routes", laplace=0.1)
    expected = ontime.evaluate(problem, "dp-rerun", episodes=1000, exact=True)["exact_success_probability"]
    print(f"model: {problem.skeleton_count} skeletons, deadline {DEADLINE} steps of {STEP} s; "
          f"dp-rerun expects success {expected:.3f}")

    session = ontime.Session(ontime.make_allocator(problem, "dp-rerun"), seed=args.seed)
    planners = {}
    clock = time.perf_counter()
    while session.status == ontime.Status.running:
        decision = session.choose()
        if decision.action < 0:
            session.report_not_yet()
            continue
        action = decision.action_id
        if action not in planners:  # a refinement starts where the move before it ended
            planners[action] = Rrt(*endpoints(action), seed=args.seed + decision.action)
        planner = planners[action]
        if planner.advance(STEP):
            steps = planner.execution_steps()
            print(f"step {session.steps_used:2d}: {action} refined, executes in {steps} steps")
            session.report_refined(steps)
        else:
            session.report_not_yet()
    seconds = time.perf_counter() - clock
    if session.status == ontime.Status.success:
        route = " -> ".join(problem.skeletons[session.solution])
        print(f"success: {route} refined after {session.steps_used} steps ({seconds:.2f} s of planning)")
    else:
        print(f"failure: no route refined in time ({session.steps_used} steps, {seconds:.2f} s)")


if __name__ == "__main__":
    main()
