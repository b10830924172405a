"""norm2tex.envs.drop_threshold on the hold-the-cube scene: with the scene's compliant drive the
opening that still holds the cube grows with the material's friction, and it is the
environment's own: an episode commanded there lasts the horizon, one a step wider drops
(pytest)."""

import numpy as np
import pytest

import norm2tex
from norm2tex.envs import HoldCubeEnv, drop_threshold
from norm2tex.envs.hold_cube import HORIZON, REWARD_HIGH, REWARD_LOW

MATERIALS = ("smooth", "print3d", "wood", "fabric", "rock")
HEIGHT_OFFSETS = (0.0, 0.0125, 0.025)  # drop_threshold's
# A coarse sweep (0.01 = 0.48 mm of gap) keeps the test short. At the scene's 1 N/mm the fine
# thresholds are 0.5475, 0.5575, 0.5725, 0.585, 0.59 (docs/python.md): on this grid 0.54, 0.55,
# 0.57, 0.58, 0.59, still one apart each.
STEP = 0.01
OPENINGS = np.round(np.arange(REWARD_LOW, REWARD_HIGH + 1e-9, STEP), 4)
FAST = dict(image="diff_int16", downscale=4, threads=2)


def friction(material):
    return norm2tex.MaterialConfig.load(norm2tex.material_config(material)).friction


@pytest.fixture(scope="module")
def thresholds():
    found = {}
    for material in MATERIALS:
        threshold, results = drop_threshold(material, openings=OPENINGS, **FAST)
        assert threshold is not None, "%s drops already at %s" % (material, OPENINGS[0])
        assert results[round(threshold + STEP, 4)], "%s never dropped in the sweep" % material
        found[material] = threshold
    return found


def test_the_threshold_grows_with_friction(thresholds):
    ordered = sorted(MATERIALS, key=friction)
    values = [thresholds[m] for m in ordered]
    frictions = [friction(m) for m in ordered]
    assert len(set(frictions)) == len(frictions)
    # The grip a friction needs, F = m g / (2 mu), sets the drive's deflection F / k: more
    # friction, less force, the fingers sit less far back, a wider command still holds.
    assert all(b > a for a, b in zip(values, values[1:])), dict(zip(ordered, values))
    assert values[-1] - values[0] >= 0.04, dict(zip(ordered, values))
    # Inside the reward's range, short of where the cube touches the undeformed gels (0.625).
    assert all(REWARD_LOW < v < 0.625 for v in values), dict(zip(ordered, values))


@pytest.mark.parametrize("material", ["smooth", "rock"])
def test_the_environment_holds_at_the_threshold_and_drops_a_step_wider(thresholds, material):
    threshold = thresholds[material]
    env = HoldCubeEnv(material=material, action="absolute", noise=False, **FAST)
    try:
        # Commanded at the threshold: held for the whole horizon at every height offset.
        for h in HEIGHT_OFFSETS:
            env.reset(seed=3, options={"height_offset_m": h})
            for step in range(1, HORIZON + 1):
                _, reward, terminated, truncated, info = env.step(np.array([threshold]))
                assert not terminated, "%s dropped at %s, offset %s, step %d" % (
                    material, threshold, h, step)
            assert truncated and not info["dropped"]
            assert reward > 0.0
        # A step wider: dropped (terminated, reward 0) at one of the offsets at least, as
        # drop_threshold found.
        drops = 0
        for h in HEIGHT_OFFSETS:
            env.reset(seed=3, options={"height_offset_m": h})
            for _ in range(HORIZON):
                _, reward, terminated, truncated, info = env.step(np.array([threshold + STEP]))
                if terminated or truncated:
                    break
            if terminated:
                assert info["dropped"] and reward == 0.0 and not truncated
                drops += 1
        assert drops >= 1, "%s held at %s at every offset" % (material, threshold + STEP)
    finally:
        env.close()
