"""scripts/hold_cube_experiment (norm2tex.rl.hold_cube_experiment): the quick run end to end
with every output, its numbers in range, the same numbers for the same seed; the environments it
needs: a batch with one material per environment, and the empty gripper; its figures
(norm2tex.rl.figures: what each shows, PNGs of their sizes), its encoders (resnet18:
torchvision's, group norm) and its device rule."""

import csv
import json
import math
import os
from dataclasses import replace

import numpy as np

import pytest

torch = pytest.importorskip("torch", reason="PyTorch is not installed (Debian: python3-torch)")

import norm2tex  # noqa: E402
from norm2tex.envs import HoldCubeEnv, HoldCubeVectorEnv, hold_reward  # noqa: E402
from norm2tex.rl import figures  # noqa: E402
from norm2tex.rl import hold_cube_experiment as hce  # noqa: E402
from norm2tex.torch_device import DeviceUnavailable, resolve_device  # noqa: E402

MATERIALS = ["wood", "fabric", "smooth"]


def assert_obs_equal(a, b):
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_each_environment_of_a_batch_runs_its_own_material():
    kwargs = dict(variant=[3, 21], image="diff_int16", downscale=4, force=True)
    batch = HoldCubeVectorEnv(num_envs=3, material=MATERIALS, **kwargs)
    obs, infos = batch.reset(seed=40)
    steps = [batch.step([2, 1, 0])[0] for _ in range(3)]
    for i, m in enumerate(MATERIALS):
        config = norm2tex.MaterialConfig.load(norm2tex.material_config(m))
        assert infos[i]["material"] == m
        assert infos[i]["friction"] == pytest.approx(config.friction)
        assert infos[i]["beta_mm"] == pytest.approx(config.beta_mm)
        # Its images are that material's texture: what an environment of that material alone
        # renders for the same seed and actions, bit for bit.
        single = HoldCubeEnv(material=m, **kwargs)
        first, info = single.reset(seed=40 + i)
        assert info["variant"] == infos[i]["variant"]
        assert_obs_equal(first, {k: v[i] for k, v in obs.items()})
        for t in range(3):
            o = single.step([2, 1, 0][i])[0]
            assert_obs_equal(o, {k: v[i] for k, v in steps[t].items()})
        single.close()
    # The three frictions differ, and so do the images (textures) of the same grasp.
    assert len({info["friction"] for info in infos}) == 3
    batch.close()
    # Textureless: every material's beta is 0, its friction stays the material's.
    flat = HoldCubeVectorEnv(num_envs=3, material=MATERIALS, beta_mm=0.0, **kwargs)
    _, infos = flat.reset(seed=40)
    assert [i["beta_mm"] for i in infos] == [0.0, 0.0, 0.0]
    assert infos[1]["friction"] == pytest.approx(0.6)
    flat.close()
    with pytest.raises(ValueError, match="materials for"):
        HoldCubeVectorEnv(num_envs=2, material=MATERIALS)


def test_the_empty_gripper_holds_nothing_and_never_drops():
    env = HoldCubeVectorEnv(num_envs=2, empty=True, image="diff_int16", downscale=4,
                            max_episode_steps=6)
    obs, infos = env.reset(seed=1)
    assert all(i["dropped"] for i in infos)  # the cube lies on the floor
    assert np.all(obs["force"] == 0.0)
    assert np.all((obs["opening"] >= 0.45) & (obs["opening"] <= 0.55))
    # Nothing touches the gels: the frames are the background (up to the sensor's noise).
    assert np.abs(obs["digit_left"]).mean() < 3.0
    for t in range(6):
        obs, rewards, terminated, truncated, infos = env.step([2, 2])
        assert not terminated.any()
        for i in range(2):  # the paper's reward of the opening, as with the cube
            last = infos[i]["final_observation"] if truncated[i] else {"opening": obs["opening"][i]}
            assert rewards[i] == pytest.approx(hold_reward(last["opening"][0]), abs=1e-5)
    assert truncated.all()
    env.close()
    # The same task with the cube: opening wide drops it and ends the episode.
    held = HoldCubeVectorEnv(num_envs=1, image="diff_int16", downscale=4)
    obs, infos = held.reset(seed=1)
    assert not infos[0]["dropped"] and obs["force"].min() > 1.0
    held.close()


def _check_outputs(out, results, config):
    for name in ["results.json", "results.csv", "opening_vs_step.png", "training_curves.png"] + [
            "training_%s.csv" % c for c in config.conditions] + [
            "policy_%s.pt" % c for c in config.conditions]:
        assert os.path.getsize(os.path.join(out, name)) > 0, name
    with open(os.path.join(out, "results.json")) as f:
        assert json.load(f) == results
    thresholds = results["thresholds"]
    assert list(thresholds) == list(config.materials)
    for t in thresholds.values():
        assert isinstance(t, float) and 0.45 <= t <= 0.7
    # The compliant drive: a higher friction holds at a wider opening.
    friction = {m: norm2tex.MaterialConfig.load(norm2tex.material_config(m)).friction
                for m in thresholds}
    by_friction = sorted(thresholds, key=lambda m: friction[m])
    assert [thresholds[m] for m in by_friction] == sorted(thresholds.values())
    assert len(set(thresholds.values())) == len(thresholds), thresholds
    assert list(results["policies"]) == list(config.conditions)
    rows = list(csv.DictReader(open(os.path.join(out, "results.csv"))))
    for p, entry in results["policies"].items():
        assert entry["training"] and entry["training"][-1]["steps"] > 0
        assert list(entry["evaluation"]) == list(config.materials) + (
            ["empty"] if config.eval_empty else [])
        for m, ev in entry["evaluation"].items():
            assert set(ev) == {"episodes", "opening_mean", "opening_std", "held_fraction",
                               "final_opening_mean", "final_opening_std", "drop_rate",
                               "return_mean", "return_std"}
            assert ev["episodes"] == config.eval_episodes
            for k in ("opening_mean", "opening_std", "held_fraction"):
                assert len(ev[k]) == config.horizon + 1
            values = ev["opening_mean"] + ev["opening_std"] + ev["held_fraction"] + [
                ev[k] for k in ("final_opening_mean", "final_opening_std", "drop_rate",
                                "return_mean", "return_std")]
            assert all(isinstance(v, float) and math.isfinite(v) for v in values), (p, m)
            assert 0.0 <= ev["drop_rate"] <= 1.0
            assert all(0.0 <= v <= 1.0 for v in ev["opening_mean"] + ev["held_fraction"])
            assert 0.0 <= ev["final_opening_mean"] <= 1.0
            assert 0.0 <= ev["return_mean"] <= config.horizon
            if m == "empty":
                assert ev["drop_rate"] == 0.0
            # Every number of the JSON is a row of the CSV.
            mine = {(r["metric"], r["step"]): float(r["value"]) for r in rows
                    if r["policy"] == p and r["material"] == m}
            assert mine[("drop_rate", "")] == ev["drop_rate"]
            assert mine[("opening_mean", str(config.horizon))] == ev["opening_mean"][-1]
            assert len(mine) == 6 + 3 * (config.horizon + 1)
    for m, t in thresholds.items():
        assert [float(r["value"]) for r in rows
                if r["metric"] == "drop_threshold" and r["material"] == m] == [t]
        # The oracle opens up to the material's threshold and no further.
        oracle = results["oracle"][m]
        assert oracle["episodes"] == config.eval_episodes
        assert max(oracle["opening_mean"][1:]) <= t + 1e-6, (m, t, oracle["opening_mean"])
        assert [float(r["value"]) for r in rows if r["policy"] == "oracle" and
                r["material"] == m and r["metric"] == "return_mean"] == [oracle["return_mean"]]
    for p, entry in results["policies"].items():
        spread = entry["material_spread"]
        finals = [entry["evaluation"][m]["final_opening_mean"] for m in config.materials]
        assert spread["range"] == max(finals) - min(finals)
        assert spread["ci95"][0] <= spread["range"] <= spread["ci95"][1]
    table = hce.results_table(results)
    assert table.count("\n") == len(config.materials) + 2 + (1 if config.eval_empty else 0)
    assert_png(os.path.join(out, "opening_vs_step.png"),
               figures.openings_size_px(len(config.conditions)))
    assert_png(os.path.join(out, "training_curves.png"), figures.TRAINING_SIZE_PX)


def assert_png(path, size):
    from PIL import Image

    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n", path
    with Image.open(path) as image:
        image.load()  # decodes every row: a truncated file fails here
        assert image.format == "PNG" and image.size == tuple(size), (path, image.size)


def test_quick_run_writes_every_output(tmp_path):
    config = hce.quick_config()
    log = []
    results = hce.run(config, str(tmp_path), log=log.append)
    _check_outputs(str(tmp_path), results, config)
    assert any("steps/s" in line for line in log)
    with open(tmp_path / "training_norm2tex.csv") as f:
        records = list(csv.DictReader(f))
    assert len(records) == config.total_steps // (config.num_envs * config.rollout_steps)
    assert float(records[-1]["steps_per_s"]) > 0


def test_the_same_seed_gives_the_same_json(tmp_path):
    # A smaller run than --quick (one image policy, one material, no empty gripper), twice.
    config = replace(hce.quick_config(), conditions=("norm2tex",), materials=("wood",),
                     eval_empty=False, eval_episodes=2, eval_envs=2,
                     threshold_openings=(0.615, 0.6175))
    a = hce.run(config, str(tmp_path / "a"), log=lambda line: None)
    b = hce.run(config, str(tmp_path / "b"), log=lambda line: None)
    assert open(tmp_path / "a" / "results.json").read() == open(
        tmp_path / "b" / "results.json").read()
    assert a == b
    # The comparison can fail: the run trained and evaluated (the quick run's test checks how).
    assert a["policies"]["norm2tex"]["evaluation"]["wood"]["episodes"] == 2


@pytest.mark.parametrize("encoder", hce.ENCODERS)
def test_the_encoders_take_both_images_and_the_opening(encoder):
    if encoder == "resnet18":
        pytest.importorskip("torchvision",
                            reason="torchvision is not installed (Debian: python3-torchvision)")
    obs = {"opening": torch.full((5, 1), 0.6),
           "digit_left": torch.randn(5, 80, 60, 3) * 0.1,
           "digit_right": torch.randn(5, 80, 60, 3) * 0.1}
    policy = hce.make_policy("norm2tex", (80, 60, 3), encoder)
    action, logprob, entropy, value = policy.get_action_and_value(obs)
    assert action.shape == (5,) and value.shape == (5,)
    # The right image changes the features (shared network, both images used).
    changed = dict(obs, digit_right=obs["digit_right"] + 0.5)
    assert not torch.allclose(policy.encoder(obs), policy.encoder(changed))


def test_resnet18_encoder_is_torchvisions_with_group_norm():
    torchvision = pytest.importorskip(
        "torchvision", reason="torchvision is not installed (Debian: python3-torchvision)")
    net = hce.ResNet18((80, 60, 3))
    assert type(net.net) is torchvision.models.ResNet
    norms = [m for m in net.modules() if isinstance(m, (torch.nn.BatchNorm2d, torch.nn.GroupNorm))]
    # Stem, 8 blocks x 2, 3 projections: all group norm (PPO acts on one state at a time).
    assert len(norms) == 20 and all(isinstance(m, torch.nn.GroupNorm) for m in norms)
    assert net(torch.zeros(3, 3, 80, 60)).shape == (3, hce.FEATURES)
    # The same network is the same at batch 1 and inside a batch (batch norm would not be).
    net.train()
    x = torch.randn(4, 3, 80, 60)
    assert torch.allclose(net(x[:1]), net(x)[:1], atol=1e-5)


def test_the_blind_encoder_ignores_the_images():
    obs = {"opening": torch.full((5, 1), 0.6),
           "digit_left": torch.randn(5, 80, 60, 3) * 0.1,
           "digit_right": torch.randn(5, 80, 60, 3) * 0.1}
    blind = hce.make_policy("blind", None)
    changed = dict(obs, digit_left=obs["digit_left"] + 0.5)
    assert torch.equal(blind.encoder(obs), blind.encoder(changed))
    with pytest.raises(ValueError, match="encoder"):
        hce.make_policy("norm2tex", (80, 60, 3), "vgg")


def test_sb3_is_refused_clearly_when_missing(tmp_path):
    try:
        import stable_baselines3  # noqa: F401
        pytest.skip("stable_baselines3 is installed")
    except ImportError:
        pass
    with pytest.raises(RuntimeError, match="stable_baselines3"):
        hce.run(replace(hce.quick_config(), algo="sb3"), str(tmp_path), log=lambda line: None)


def synthetic_results(horizon=8):
    """A results dict as run() returns it, with known numbers (no training)."""
    steps = horizon + 1
    evaluation = {m: {"opening_mean": [0.5 + 0.01 * k] * steps, "opening_std": [0.02] * steps,
                      "drop_rate": 0.25 * k}
                  for k, m in enumerate(["wood", "fabric", "smooth", "empty"])}
    training = [{"steps": 48 * (u + 1), "mean_return": 4.0 + u} for u in range(3)]
    return {"thresholds": {"wood": 0.5725, "fabric": 0.585, "smooth": 0.5475},
            "policies": {p: {"evaluation": evaluation, "training": training}
                         for p in ("blind", "textureless", "norm2tex")}}


def test_the_opening_figure_shows_the_data():
    config = replace(hce.quick_config(), horizon=8, eval_episodes=7)
    fig = figures.openings_figure(synthetic_results(), config)
    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["blind", "textureless", "norm2tex"]
    assert axes[0].get_ylabel() == "opening" and all(ax.get_xlabel() == "step" for ax in axes)
    for ax in axes:
        assert ax.get_xlim() == (0, 8)
        assert [t.get_text() for t in ax.get_legend().get_texts()] == [
            "wood  drop 0%", "fabric  drop 25%", "smooth  drop 50%", "empty  drop 75%"]
        curves = [line for line in ax.get_lines() if line.get_linestyle() == "-"]
        assert [list(line.get_ydata()) for line in curves][1] == [0.51] * 9
        # The +- std band of every material: from mean - std to mean + std.
        assert len(ax.collections) == 4
        band = ax.collections[1].get_paths()[0].vertices[:, 1]
        assert min(band) == pytest.approx(0.49) and max(band) == pytest.approx(0.53)
        dashed = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
        assert sorted(line.get_ydata()[0] for line in dashed) == [0.5475, 0.5725, 0.585]
    assert any("over 7 held-out episodes" in t.get_text() for t in fig.texts)


def test_the_training_figure_shows_the_data():
    config = replace(hce.quick_config(), total_steps=144)
    ax = figures.training_figure(synthetic_results(), config).axes[0]
    assert ax.get_title() == "PPO training: mean episode return"
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("environment steps", "return")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "blind", "textureless", "norm2tex"]
    assert list(ax.get_lines()[0].get_xdata()) == [48, 96, 144]
    assert list(ax.get_lines()[0].get_ydata()) == [4.0, 5.0, 6.0]


def test_the_figures_are_pngs_of_their_size(tmp_path):
    results, config = synthetic_results(), replace(hce.quick_config(), horizon=8)
    figures.plot_openings(str(tmp_path / "o.png"), results, config)
    figures.plot_training(str(tmp_path / "t.png"), results, config)
    assert figures.openings_size_px(3) == (1420, 480)
    assert_png(str(tmp_path / "o.png"), (1420, 480))
    assert_png(str(tmp_path / "t.png"), figures.TRAINING_SIZE_PX)


def test_a_device_that_is_not_there_stops_the_run_before_it_starts(tmp_path):
    assert hce.resolve_device is resolve_device  # the package's one rule
    if torch.cuda.is_available():
        pytest.skip("PyTorch sees a GPU here")
    with pytest.raises(DeviceUnavailable, match="'cuda' was asked for"):
        hce.run(replace(hce.quick_config(), device="cuda"), str(tmp_path / "out"),
                log=lambda line: None)
    assert not (tmp_path / "out").exists()
