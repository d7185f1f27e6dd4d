"""scripts/tamp-learning.py's paired statistics, on episodes whose outcomes are written by hand."""

import argparse
import importlib.util
import math
import sys

import pytest

from conftest import SOURCE_DIR


@pytest.fixture(scope="module")
def script():
    sys.path.insert(0, str(SOURCE_DIR / "scripts"))  # the script imports heldout.py beside it
    try:
        spec = importlib.util.spec_from_file_location("tamp_learning", SOURCE_DIR / "scripts" / "tamp-learning.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.path.remove(str(SOURCE_DIR / "scripts"))


def test_seeds_are_ranges_and_lists(script):
    assert script.parse_seeds("6001-6003,6007") == [6001, 6002, 6003, 6007]
    assert script.parse_seeds("6005") == [6005]


def test_gap_and_gain_are_paired_episode_by_episode(script):
    # One building, two sequences of two episodes: sequence 0 is episodes 0-1, sequence 1 is 2-3.
    # Without updates the prediction succeeds in episode 2 only; with them also in episode 3 (the
    # first episode of a sequence is the same run either way); the oracle fails episode 2 only.
    args = argparse.Namespace(episodes=2, sequences=2)
    world = {"oracle": "1101", "fixed": {}, "updated": {}}
    for kind in ("hazard", "boosted", "pooled"):
        world["fixed"][kind], world["updated"][kind] = "0010", "0011"
    summary = script.summarise(args, [world], {"hazard": 100, "boosted": 500, "pooled": 10})
    s = summary["hazard"]
    # Gap: oracle less fixed, per episode (1, 1, -1, 1): mean 1/2, sample variance 1, over 4 episodes.
    assert s["gap"] == pytest.approx(0.5)
    assert s["gap_se"] == pytest.approx(math.sqrt(1 / 4))
    assert s["fixed"] == pytest.approx(0.25) and s["oracle"] == pytest.approx(0.75)
    # Gain by episode: episode 1 nothing (0, 0), episode 2 (0, 1) over the two sequences.
    assert s["gain_by_episode"] == pytest.approx([0.0, 0.5])
    first, second = s["windows"]
    assert first["episodes"] == [1, 1] and first["gain"] == 0 and first["closed"] == 0
    assert second["episodes"] == [2, 2]
    assert second["gain"] == pytest.approx(0.5) and second["closed"] == pytest.approx(1.0)
    # Between sequences the gains are 0 and 1: sample variance 1/2, over 2 sequences.
    assert second["gain_se"] == pytest.approx(math.sqrt(0.25))
    assert s["buildings_with_a_gap"] == 1


def test_windows_are_the_first_episode_then_blocks(script):
    assert script.windows(argparse.Namespace(episodes=50)) == [(1, 2), (2, 6), (6, 11), (11, 21), (21, 31), (31, 41),
                                                                (41, 51)]
    assert script.windows(argparse.Namespace(episodes=3)) == [(1, 2), (2, 4)]
