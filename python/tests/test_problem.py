"""Problems in and out: files, dicts, numpy distributions, and errors named as the CLI names them."""

import json

import numpy as np
import pytest

import ontime
from conftest import PAPER_INSTANCES, SOURCE_DIR


def small_instance(**changes):
    data = {
        "name": "small",
        "deadline": 6,
        "actions": {
            "a": {"planning": {"pmf": {"1": 0.5, "2": 0.5}}, "execution": {"pmf": {"1": 1.0}}},
            "b": {"planning": {"pmf": {"2": 1.0}}, "execution": {"pmf": {"2": 0.5, "3": 0.5}}},
            "c": {"planning": {"pmf": {"3": 0.4}}, "execution": {"pmf": {"1": 1.0}}},
        },
        "skeletons": [["a", "b"], ["c"]],
    }
    data.update(changes)
    return data


def test_a_loaded_instance_has_its_file_contents():
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    assert problem.name == "paper-instance-1"
    assert problem.deadline == 14
    assert problem.skeleton_count == 4
    assert problem.skeletons[0] == ["a1_1", "a1_2", "a1_3"]
    a11 = problem.actions[problem.find_action("a1_1")]
    np.testing.assert_allclose(a11.planning.pmf, [0, 0, 0.2, 0.6, 0.2])
    assert a11.planning.never == pytest.approx(0.0)
    assert a11.planning.min_step == 2 and a11.planning.max_step == 4
    assert a11.planning.hazard(2) == pytest.approx(0.6 / 0.8)


@pytest.mark.parametrize("path", PAPER_INSTANCES)
def test_dict_round_trip_gives_the_same_instance(path):
    problem = ontime.load_problem(path)
    again = ontime.Problem.from_dict(problem.to_dict())
    assert again.to_json() == problem.to_json()
    assert again.to_dict() == problem.to_dict()
    assert problem.to_dict()["skeletons"] == json.loads(path.read_text())["skeletons"]


def test_distributions_may_be_given_as_numpy_arrays():
    data = small_instance()
    data["actions"]["a"]["planning"] = {"pmf": np.array([0.0, 0.5, 0.5])}
    data["actions"]["c"]["planning"] = {"cdf": [0.0, 0.0, 0.0, 0.4]}
    from_arrays = ontime.Problem.from_dict(data)
    from_text = ontime.Problem.from_dict(small_instance())
    assert from_arrays.to_json() == from_text.to_json()
    c = from_arrays.actions[from_arrays.find_action("c")]
    assert c.planning.never == pytest.approx(0.6)
    assert ontime.Distribution.from_pmf(np.array([0, 0.25, 0.75])) == ontime.Distribution.from_cdf([0, 0.25, 1.0])


def test_a_bad_dict_names_the_place_and_the_rule():
    data = small_instance()
    data["actions"]["a"]["planning"] = {"pmf": {"0": 0.5, "1": 0.5}}
    with pytest.raises(ontime.InputError) as raised:
        ontime.Problem.from_dict(data)
    assert raised.value.source == "<dict>"
    assert raised.value.place == 'actions.a.planning.pmf."0"'
    assert "step 0" in raised.value.rule or "0" in raised.value.rule
    assert str(raised.value).startswith('<dict>: actions.a.planning.pmf."0": ')
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, ontime.Error)


BAD_FILES = sorted((SOURCE_DIR / "tests" / "data" / "bad").glob("*.json"))


@pytest.mark.parametrize("path", BAD_FILES[:12], ids=lambda p: p.name)
def test_a_bad_file_raises_the_message_the_cli_prints(path, cli):
    done = cli("solve", path, expect_json=False)
    assert done.returncode == 2
    with pytest.raises(ontime.InputError) as raised:
        ontime.load_problem(path)
    # The CLI prints one line ending with the same message.
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].endswith(f"error: {raised.value}")


def test_save_writes_a_file_load_reads_back(tmp_path):
    problem = ontime.Problem.from_dict(small_instance())
    problem.save(tmp_path / "small.json")
    assert ontime.load_problem(tmp_path / "small.json").to_json() == problem.to_json()


def test_a_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(ontime.InputError) as raised:
        ontime.load_problem(tmp_path / "missing.json")
    assert "missing.json" in str(raised.value)
