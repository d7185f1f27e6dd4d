"""Conditional time models from Python: fit_conditional and ontime.domains.predict give the model file
and the instance `ontime fit --conditional` and `ontime predict` write, byte for byte; predictions take
numpy feature arrays; bad input is refused as the command line refuses it."""

import json

import numpy as np
import pytest

import ontime

pytestmark = pytest.mark.skipif(not ontime.domains.available, reason="built without the domains")


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    """Two small buildings with many narrow doors, collected with features, and a third one unseen."""
    folder = tmp_path_factory.mktemp("corpus")
    logs = []
    for seed in (1, 2):
        world = folder / f"b{seed}.json"
        ontime.domains.generate_world(world, rows=2, cols=3, narrow_doors=0.5, seed=seed)
        records = ontime.domains.collect(ontime.domains.load("navigation", world), trials=5, threads=2,
                                         every_action=True, features=True)
        log = folder / f"b{seed}.jsonl"
        ontime.write_planner_log(records, log)
        logs.append(log)
    unseen = folder / "b3.json"
    ontime.domains.generate_world(unseen, rows=2, cols=3, narrow_doors=0.5, seed=3)
    return folder, logs, unseen


def test_records_carry_the_world_and_the_features(corpus):
    folder, logs, _ = corpus
    records = ontime.read_planner_log(logs[0])
    building = ontime.domains.load("navigation", folder / "b1.json")
    assert {record["world"] for record in records} == {"b1"}
    first = records[0]
    assert first["features"] == list(ontime.domains.features(building, first["action"]))
    assert len(first["features"]) == len(ontime.domains.feature_names("navigation")) == 11


def test_fit_and_predict_write_the_clis_files(corpus, cli):
    folder, logs, unseen = corpus
    model_file = folder / "cli-model.json"
    cli("fit", *logs, "--conditional", "hazard", "--domain", "navigation", "--step", 3, "-o", model_file, "--json")
    model = ontime.fit_conditional(logs, step=3.0, kind="hazard", domain="navigation")
    assert model.to_json() == model_file.read_text()
    assert model.feature_names[0] == "door_width"
    assert model.training_worlds == 2

    instance_file = folder / "cli-predicted.json"
    cli("predict", "--domain", "navigation", "--world", unseen, "--model", model_file, "-o", instance_file, "--json")
    loaded = ontime.load_conditional_model(model_file)
    problem = ontime.domains.predict(ontime.domains.load("navigation", unseen), loaded)
    python_file = folder / "python-predicted.json"
    problem.save(python_file)
    assert json.loads(python_file.read_text()) == json.loads(instance_file.read_text())
    one_thread = ontime.domains.predict(ontime.domains.load("navigation", unseen), loaded, threads=1)
    assert one_thread.to_json() == problem.to_json()
    with pytest.raises(ValueError, match="threads"):
        ontime.domains.predict(ontime.domains.load("navigation", unseen), loaded, threads=-1)


def test_predict_takes_numpy_rows_and_records_fit_as_files_do(corpus):
    folder, logs, unseen = corpus
    records = ontime.read_planner_log(logs[0]) + ontime.read_planner_log(logs[1])
    from_records = ontime.fit_conditional(records, step=3.0, domain="navigation")
    from_files = ontime.fit_conditional(logs, step=3.0, domain="navigation")
    assert from_records.to_json() == from_files.to_json()
    building = ontime.domains.load("navigation", unseen)
    actions = [f"move({a},{b})" for a, b in (("R1", "R2"), ("R2", "R1"))]
    rows = np.array([ontime.domains.features(building, action) for action in actions])
    predicted = from_files.predict(rows)
    assert len(predicted) == 2
    planning, execution = from_files.predict(rows[1])
    assert list(planning.pmf) == list(predicted[1][0].pmf)
    assert planning.pmf[0] == 0  # planning takes at least one step
    assert abs(planning.pmf.sum() + planning.never - 1) < 1e-9
    assert abs(execution.pmf.sum() + execution.never - 1) < 1e-9


def test_bad_features_and_models_are_refused(corpus, tmp_path):
    folder, logs, _ = corpus
    model = ontime.fit_conditional(logs, step=3.0, kind="pooled")
    with pytest.raises(ontime.UsageError, match="takes 11 features, got 3"):
        model.predict(np.zeros(3))
    with pytest.raises(ontime.UsageError, match="not a finite number"):
        model.predict(np.full(11, np.nan))
    with pytest.raises(ontime.UsageError, match="other features"):
        ontime.domains.predict(ontime.domains.load("navigation", folder / "b1.json"), model)
    with pytest.raises(ontime.UsageError, match="unknown conditional model kind"):
        ontime.fit_conditional(logs, step=3.0, kind="forest")
    bad = tmp_path / "model.json"
    bad.write_text(model.to_json().replace('"version": 1', '"version": 9'))
    with pytest.raises(ontime.InputError, match="version"):
        ontime.load_conditional_model(bad)
    assert [kind["name"] for kind in ontime.conditional_model_kinds()] == ["pooled", "hazard", "boosted"]


BOOSTED = {"trees": 20, "depth": 2, "learning_rate": 0.5, "min_child_weight": 2.0, "aft_distribution": "extreme",
           "aft_scale": 0.8}


def test_boosted_fits_the_clis_file_and_predicts_its_instance(corpus, cli):
    folder, logs, unseen = corpus
    model_file = folder / "boosted-model.json"
    flags = [item for key, value in BOOSTED.items() for item in ("--" + key.replace("_", "-"), value)]
    summary = cli("fit", *logs, "--conditional", "boosted", "--domain", "navigation", "--step", 3, *flags,
                  "-o", model_file, "--json")
    model = ontime.fit_conditional(logs, step=3.0, kind="boosted", domain="navigation", **BOOSTED)
    assert model.to_json() == model_file.read_text()
    assert model.kind == "boosted"
    parameters = json.loads(model.to_json())["parameters"]
    assert {key: parameters[key] for key in BOOSTED} == BOOSTED
    # The summary leaves XGBoost's trees in the file.
    assert set(summary["parameters"]) == set(parameters) - {"never_booster", "planning_booster", "execution_booster"}

    instance_file = folder / "boosted-predicted.json"
    cli("predict", "--domain", "navigation", "--world", unseen, "--model", model_file, "-o", instance_file, "--json")
    problem = ontime.domains.predict(ontime.domains.load("navigation", unseen), ontime.load_conditional_model(model_file))
    python_file = folder / "boosted-python-predicted.json"
    problem.save(python_file)
    assert json.loads(python_file.read_text()) == json.loads(instance_file.read_text())

    # One row at a time or a 2-D array: the same distributions.
    building = ontime.domains.load("navigation", unseen)
    rows = np.array([ontime.domains.features(building, f"move({a},{b})") for a, b in (("R1", "R2"), ("R2", "R1"))])
    planning, execution = model.predict(rows[1])
    assert list(model.predict(rows)[1][0].pmf) == list(planning.pmf)
    assert abs(planning.pmf.sum() + planning.never - 1) < 1e-9
    assert abs(execution.pmf.sum() + execution.never - 1) < 1e-9


def test_boosted_settings_out_of_range_are_refused(corpus):
    _, logs, _ = corpus
    for bad, rule in ((dict(aft_distribution="weibull"), "normal, logistic or extreme"), (dict(trees=0), "trees"),
                      (dict(learning_rate=0.0), "learning_rate"), (dict(aft_scale=-1.0), "aft_scale")):
        with pytest.raises(ontime.UsageError, match=rule):
            ontime.fit_conditional(logs, step=3.0, kind="boosted", **bad)
    names = [p["name"] for p in ontime.conditional_model_kinds()[2]["parameters"]]
    assert names == list(BOOSTED)


def test_the_online_update_follows_the_beta_stacy_algebra():
    # Prior p(1) = 1/2, p(2) = 1/4 worth 2 attempts; found at 2 gives hazards 1/3 and 3/4.
    posterior = ontime.PlanningPosterior(ontime.Distribution.from_pmf([0.0, 0.5, 0.25]), 2, 2.0)
    assert posterior.predictive_found(2) == pytest.approx(0.25)
    posterior.observe_found(2)
    mean = posterior.mean()
    assert list(mean.pmf[1:3]) == pytest.approx([1 / 3, 1 / 2])
    assert mean.never == pytest.approx(1 / 6)
    assert posterior.observations == 1
    with pytest.raises(ontime.UsageError):
        ontime.PlanningPosterior(mean, 2, 0.0)


def test_the_kitchen_family_fits_and_predicts(tmp_path, cli):
    """Generated kitchens collected with features, a pooled model over them, the instance of a kitchen
    none of them is: the same from Python as from the command line."""
    logs = []
    for seed in (1, 2, 3):
        ontime.domains.generate_world(tmp_path / f"k{seed}.json", domain="manipulation", targets=1, min_objects=2,
                                      max_objects=3, min_clutter=1, max_clutter=1, seed=seed)
    for seed in (1, 2):
        kitchen = ontime.domains.load("manipulation", tmp_path / f"k{seed}.json")
        records = ontime.domains.collect(kitchen, trials=2, threads=2, budget_steps=3, features=True)
        assert records[0]["features"] == list(ontime.domains.features(kitchen, records[0]["action"]))
        log = tmp_path / f"k{seed}.jsonl"
        ontime.write_planner_log(records, log)
        logs.append(log)
    assert ontime.domains.feature_names("manipulation")[0] == "is_place"
    model = ontime.fit_conditional(logs, step=7.0, kind="pooled", domain="manipulation")
    model_file = tmp_path / "model.json"
    cli("fit", *logs, "--conditional", "pooled", "--domain", "manipulation", "--step", 7, "-o", model_file, "--json")
    assert model.to_json() == model_file.read_text()
    unseen = ontime.domains.load("manipulation", tmp_path / "k3.json")
    problem = ontime.domains.predict(unseen, model)
    assert len(problem.skeletons) == len(unseen.skeletons)
    with pytest.raises(ontime.UsageError, match="is not move\\+pick"):
        ontime.domains.features(unseen, "move+pick(nothing)")


def test_a_model_file_whose_numbers_are_not_finite_or_overflow_is_an_input_error(corpus, tmp_path):
    # A number that is not finite is refused where the reader meets it; finite numbers can still
    # overflow where they meet features (a scale of 1e-320 makes door_width's standard score
    # infinite, a coefficient of 0 makes it NaN), and the prediction names the file and its
    # parameters (it used to raise "a probability is not a number (NaN)", naming neither).
    folder, logs, unseen = corpus
    data = json.loads(ontime.fit_conditional(logs, step=3.0, kind="hazard", domain="navigation").to_json())
    data["parameters"]["hazard"][0] = 12345.5
    marked = json.dumps(data, indent=2)
    for number in ("1e999", "-1e999", "NaN", "Infinity"):
        path = tmp_path / f"{number}.json"
        path.write_text(marked.replace("12345.5", number))
        with pytest.raises(ontime.InputError) as error:
            ontime.load_conditional_model(path)
        assert error.value.source == str(path) and error.value.place.startswith("line "), str(error.value)
    data["parameters"]["hazard"] = [0.0] * len(data["parameters"]["hazard"])
    data["parameters"]["scale"][0] = 1e-320
    path = tmp_path / "overflow.json"
    path.write_text(json.dumps(data))
    overflowing = ontime.load_conditional_model(path)
    far = np.array(data["parameters"]["mean"]) + 1.0
    for predict in (lambda: overflowing.predict(far), lambda: overflowing.predict(np.array([far, far])),
                    lambda: ontime.domains.predict(ontime.domains.load("navigation", unseen), overflowing)):
        with pytest.raises(ontime.InputError) as error:
            predict()
        assert (error.value.source, error.value.place) == (str(path), "parameters")
        assert error.value.rule.startswith("the model's numbers overflow for some features: ")
