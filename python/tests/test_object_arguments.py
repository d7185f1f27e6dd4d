"""Object arguments (a model, a domain, a problem, an allocator) given None or an object of another
type raise UsageError naming the parameter and the class it must be: never a crash of the
interpreter (None passed as an empty pointer) nor pybind11's TypeError listing signatures."""

import pytest

import ontime
from conftest import PAPER_INSTANCES, SOURCE_DIR

NAVIGATION = str(SOURCE_DIR / "data" / "domains" / "navigation.json")
LOG = "{\"action\": \"a\", \"planning_seconds\": 1, \"found\": true, \"execution_seconds\": 1, " \
      "\"world\": \"t\", \"features\": [0]}\n"


def refused(call, parameter, cls, got):
    with pytest.raises(ontime.UsageError) as error:
        call()
    assert str(error.value) == f"parameter '{parameter}': must be a {cls} (got {got})"


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    log = tmp_path_factory.mktemp("model") / "log.jsonl"
    log.write_text(LOG)
    return ontime.fit_conditional(str(log), kind="pooled", step=1.0)


def test_fit_strength_names_its_model(tmp_path, model):
    log = tmp_path / "unseen.jsonl"
    log.write_text(LOG)
    refused(lambda: ontime.fit_strength(None, [str(log)]), "model", "ConditionalTimeModel", "None")
    refused(lambda: ontime.fit_strength(str(log), [str(log)]), "model", "ConditionalTimeModel", "a str")
    assert ontime.fit_strength(model, [str(log)], strengths=[1.0])["attempts"] == 1


def test_mdp_and_session_name_their_problem_and_allocator():
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    refused(lambda: ontime.Mdp(None), "problem", "Problem", "None")
    refused(lambda: ontime.Mdp(str(PAPER_INSTANCES[0])), "problem", "Problem", "a str")
    refused(lambda: ontime.Session(None), "allocator", "Allocator", "None")
    refused(lambda: ontime.Session(problem), "allocator", "Allocator", "a Problem")
    assert ontime.Mdp(problem).deadline == problem.deadline


@pytest.mark.skipif(not ontime.domains.available, reason="built without the domains")
def test_every_domain_function_names_its_domain_and_model(model):
    domains = ontime.domains
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    calls = {
        "collect": lambda d: domains.collect(d, trials=1),
        "collect_and_fit": lambda d: domains.collect_and_fit(d, "log.jsonl", "instance.json", trials=1),
        "run": lambda d: domains.run(d, problem, "dp-rerun", episodes=1),
        "tamp": lambda d: domains.tamp(d, problem, "dp-rerun", 10.0, episodes=1),
        "map_data": lambda d: domains.map_data(d, seed=1),
        "features": lambda d: domains.features(d, "a"),
        "predict": lambda d: domains.predict(d, model, deadline=10),
    }
    for name, call in calls.items():
        refused(lambda: call(None), "domain", "Domain", "None")
        refused(lambda: call("navigation"), "domain", "Domain", "a str")
        refused(lambda: call(model), "domain", "Domain", "a ConditionalTimeModel")
    navigation = domains.load("navigation", NAVIGATION)
    refused(lambda: domains.predict(navigation, None, deadline=10), "model", "ConditionalTimeModel", "None")
    refused(lambda: domains.predict(navigation, navigation, deadline=10), "model", "ConditionalTimeModel",
            "a Domain")
