"""Long calls release the GIL and stop on Ctrl-C without leaving files; no references leak."""

import gc
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import tracemalloc

import pytest

import ontime
from conftest import PAPER_INSTANCES, SOURCE_DIR


def test_evaluate_releases_the_gil():
    # While one thread evaluates, this thread keeps running Python code: with the GIL held through
    # the call it could not run at all until the call returned.
    problem = ontime.load_problem(PAPER_INSTANCES[2])
    worker = threading.Thread(target=ontime.evaluate, args=(problem, "dp-rerun"),
                              kwargs={"episodes": 400_000, "threads": 1})
    worker.start()
    ticks = 0
    started = time.perf_counter()
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    elapsed = time.perf_counter() - started
    worker.join()
    assert elapsed > 0.05
    assert ticks > 0.2 * elapsed / 0.001


def test_two_threads_evaluating_at_once_run_at_the_same_time():
    # Each call reports its progress from inside the computation. With the GIL held through a call
    # the second could not begin before the first returned, so all of one call's reports would come
    # before the other's (one switch); released, the two calls run at once and their reports
    # interleave. Whatever the load on the machine, this shows the order, not a speed.
    problem = ontime.load_problem(PAPER_INSTANCES[2])
    order = []

    def one(name):
        ontime.evaluate(problem, "dp-rerun", episodes=300_000, threads=1,
                        progress=lambda done, total: order.append(name))

    pool = [threading.Thread(target=one, args=(name,)) for name in "ab"]
    for thread in pool:
        thread.start()
    for thread in pool:
        thread.join()
    switches = sum(1 for first, second in zip(order, order[1:]) if first != second)
    assert order.count("a") >= 2 and order.count("b") >= 2, order
    assert switches >= 3, order


def run_and_interrupt(code, after_seconds):
    """Runs `code` in a fresh interpreter, sends SIGINT once it printed 'started', returns its output."""
    env = dict(os.environ)
    child = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
    assert child.stdout.readline().strip() == "started"
    time.sleep(after_seconds)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=60)
    return child.returncode, out, err, time.perf_counter() - sent


@pytest.mark.parametrize("call", [
    "ontime.evaluate(problem, 'dp-rerun', episodes=10**10, threads=2)",
    "ontime.evaluate(problem, 'mcts', episodes=10**9, iterations=100000)",
    "ontime.run_episodes(problem, lambda: Slow(), 'dp', episodes=10**9, threads=2)",
    "ontime.fit_chain([[0, 1, 1, 0]], kind='birth-death', capacity=2).chain.distribution(2**62)",
])
def test_ctrl_c_stops_a_long_call_with_keyboard_interrupt(call):
    code = f"""
        import ontime, sys, time
        problem = ontime.load_problem({str(PAPER_INSTANCES[0])!r})
        class Slow(ontime.World):
            def begin_episode(self, seed): pass
            def step(self, action, spent):
                time.sleep(0.001)
                return None
        print("started", flush=True)
        try:
            {call}
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
        print("finished")
    """
    code_, out, err, seconds = run_and_interrupt(code, 0.5)
    assert code_ == 0, err
    assert out.strip() == "interrupted"
    assert seconds < 10


def test_an_interrupted_training_writes_no_policy(tmp_path):
    policy = tmp_path / "policy.json"
    code = f"""
        import ontime, sys
        print("started", flush=True)
        try:
            ontime.train_ppo({str(PAPER_INSTANCES[0])!r}, {str(policy)!r}, episodes=10**8)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
    """
    code_, out, err, _ = run_and_interrupt(code, 1.0)
    assert code_ == 0, err
    assert out.strip() == "interrupted"
    assert not policy.exists()
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_solve_raises_keyboard_interrupt():
    instance = SOURCE_DIR / "data" / "instances" / "navigation.json"
    code = f"""
        import ontime, sys
        print("started", flush=True)
        try:
            ontime.solve({str(instance)!r})
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
        print("finished")
    """
    code_, out, err, seconds = run_and_interrupt(code, 1.0)
    assert code_ == 0, err
    assert out.strip() == "interrupted"
    assert seconds < 10


def test_a_training_run_writes_a_policy_the_ppo_allocator_reads(tmp_path):
    policy = tmp_path / "policy.json"
    curve = ontime.train_ppo(PAPER_INSTANCES[0], policy, episodes=3000, seed=2)
    assert curve and curve[-1]["episodes"] >= 3000
    result = ontime.evaluate(str(PAPER_INSTANCES[0]), "ppo", episodes=1000, exact=True, policy=policy)
    assert 0.0 < result["exact_success_probability"] <= 0.942 + 1e-9


def test_no_references_leak_over_100000_session_steps():
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    allocator = ontime.make_allocator(problem, "dp-rerun")

    def steps(count):
        done = 0
        episode = 0
        while done < count:
            session = ontime.Session(allocator, seed=episode)
            episode += 1
            while session.status == ontime.Status.running and done < count:
                decision = session.choose()
                _ = decision.action_id, session.state
                if (done + decision.skeleton) % 3 == 0:
                    session.report_refined(1)
                else:
                    session.report_not_yet()
                done += 1

    steps(2_000)  # warm-up: caches, interned strings
    gc.collect()
    references = (sys.getrefcount(problem), sys.getrefcount(allocator))
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    steps(100_000)
    gc.collect()
    after = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    assert (sys.getrefcount(problem), sys.getrefcount(allocator)) == references
    assert after - before < 64 * 1024, after - before
