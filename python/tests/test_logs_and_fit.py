"""Planner logs written from Python, and fitting them, as `ontime fit` does."""

import json

import numpy as np
import pytest

import ontime


def synthetic_records(seed=3, attempts=200):
    rng = np.random.default_rng(seed)
    records = []
    for action, scale in (("go(A,B)", 1.5), ("go(B,C)", 3.0), ("go(A,C)", 6.0)):
        for trial in range(attempts):
            seconds = float(rng.exponential(scale))
            if seconds > 10.0:
                records.append({"action": action, "planning_seconds": 10.0, "found": False, "trial": trial})
            else:
                records.append({"action": action, "planning_seconds": round(seconds, 3), "found": True,
                                "execution_seconds": round(float(rng.uniform(0.5, 2.5)), 3), "trial": trial})
    return records


SKELETONS = [["go(A,B)", "go(B,C)"], ["go(A,C)"]]


def test_a_log_written_from_python_reads_back_and_fits_like_the_cli(tmp_path, cli):
    records = synthetic_records()
    log = tmp_path / "log.jsonl"
    ontime.write_planner_log(records, log)
    assert ontime.read_planner_log(log) == records
    from_records = ontime.fit(records, step=1.0, deadline=12, skeletons=SKELETONS, name="fitted")
    from_file = ontime.fit(log, step=1.0, deadline=12, skeletons=SKELETONS, name="fitted")
    assert from_records.to_json() == from_file.to_json()
    (tmp_path / "skeletons.json").write_text(json.dumps({"skeletons": SKELETONS}))
    cli("fit", log, "--step", 1.0, "--deadline", 12, "--skeletons", tmp_path / "skeletons.json", "-o",
        tmp_path / "fitted.json", "--name", "fitted", "--json")
    assert ontime.load_problem(tmp_path / "fitted.json").to_json() == from_file.to_json()


def test_censored_attempts_leave_mass_on_never():
    problem = ontime.fit(synthetic_records(), step=1.0, deadline=12, skeletons=SKELETONS)
    slow = problem.actions[problem.find_action("go(A,C)")]
    # P(T > 10 s) = exp(-10/6) ~ 0.19 of the attempts are cut off: their mass beyond 10 steps.
    assert slow.planning.survival(10) == pytest.approx(np.exp(-10 / 6), abs=0.07)


def test_a_bad_record_is_named_by_its_line():
    records = synthetic_records()[:5] + [{"action": "go(A,B)", "planning_seconds": -1.0, "found": False}]
    with pytest.raises(ontime.InputError) as raised:
        ontime.fit(records, step=1.0, deadline=12, skeletons=SKELETONS)
    assert str(raised.value).startswith("<records>: line 6")
    with pytest.raises(ontime.InputError, match="skeletons"):
        ontime.fit(synthetic_records(), step=1.0, deadline=12, skeletons=[["go(A,B)", "go(A,B)"]])
    with pytest.raises(ontime.UsageError, match="step"):
        ontime.fit(synthetic_records(), step=0.0, deadline=12, skeletons=SKELETONS)
