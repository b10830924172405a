"""The Norm2Tex paper's closed-loop experiment: hold a cube with the largest opening that does not
let it fall, learned by three policies that differ only in what they see.

  blind        the opening command alone (an MLP)
  textureless  the opening and both DIGIT images of the same simulator with beta 0 (no texture:
               the paper's "Taxim" condition)
  norm2tex     the opening and both textured DIGIT images

Each policy is trained with PPO (norm2tex.rl.ppo) on HoldCubeVectorEnv episodes of wood, fabric
and smooth mixed in every batch (environment i holds materials[i % 3]), on texture variants
0-19, seed `seed`. Then each is evaluated, greedily (the most probable action), on every
material and on an empty gripper (HoldCubeVectorEnv(empty=True)) over `eval_episodes`
episodes of the held-out variants 20-23 and held-out seeds. The physical drop threshold of each
material (norm2tex.envs.drop_threshold) is measured alongside.

The images are background-subtracted (image="diff_float") and averaged down `downscale` x
`downscale` (4: 80 x 60 pixels); one CNN ("cnn": three strided convolutions, or "resnet18":
torchvision's, randomly initialised, group norm) is applied to both, and its two feature vectors
are concatenated with the opening. The opening enters every policy as (opening - 0.6) / 0.05.

Budget (the default ExperimentConfig): 150 000 environment steps per policy (6 environments x
128 steps per update, 195 updates). On the project's 2-core VM: blind 312 steps/s, textureless
195, norm2tex 167 (every condition renders both sensors; the CNN's forward and backward passes
make the difference), about 40 minutes for the whole run with the evaluations (docs/python.md).
At 30 000 steps no policy learned to hold the cube. quick_config(): a smoke run of under a
minute that writes every output.

Also measured per material: the oracle (threshold_oracle: open up to the material's threshold
and stay), evaluated on the same episodes -- the return a policy that holds the cube earns.

Outputs of run(config, out_dir) (also returned as a dict):
  results.json            every number: config, thresholds, oracle, per policy its training
                          log, per material (and "empty") its evaluation and material_spread
  results.csv             the same numbers, one per row: policy, material, metric, step, value
  training_<policy>.csv   the training log (update, steps, steps_per_s, mean_return, ...)
  opening_vs_step.png     the paper's figure: opening vs step, a panel per policy, a curve per
                          material (mean +- std over episodes), each threshold a dashed line
  training_curves.png     mean training return vs environment steps, one curve per policy
  policy_<policy>.pt      the trained weights (state_dict)
The figures are drawn with matplotlib (norm2tex.rl.figures).

Deterministic: the same config gives the same results.json on the same machine (torch's CPU
kernels with a fixed thread count; timings are only in the training CSVs).
"""

import csv
import json
import math
import os
import time
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import torch
from torch import nn

from norm2tex.envs import HoldCubeVectorEnv, drop_threshold
from norm2tex.envs.hold_cube import HORIZON
from norm2tex.resnet import resnet18
from norm2tex.rl import figures, ppo
from norm2tex.torch_device import resolve_device

CONDITIONS = ("blind", "textureless", "norm2tex")
MATERIALS = ("wood", "fabric", "smooth")
EMPTY = "empty"
ENCODERS = ("cnn", "resnet18")
ALGOS = ("ppo", "sb3")
OPENING_CENTRE, OPENING_SCALE = 0.6, 0.05
# diff_float images are (frame - background) / 255: a press moves pixels by a few tens of levels.
IMAGE_GAIN = 4.0
FEATURES = 64


@dataclass
class ExperimentConfig:
    """Everything a run depends on (all of it is written to results.json)."""

    total_steps: int = 150_000         # environment steps per policy
    num_envs: int = 6                  # training environments (materials[i % len(materials)])
    rollout_steps: int = 128           # per environment and update
    update_epochs: int = 4
    minibatches: int = 4
    learning_rate: float = 2.5e-4
    entropy_coef: float = 0.01
    horizon: int = HORIZON             # steps per episode (the paper: 128)
    downscale: int = 4
    encoder: str = "cnn"               # "cnn" or "resnet18" (torchvision's, random weights)
    algo: str = "ppo"                  # "ppo" (norm2tex.rl.ppo) or "sb3" (stable_baselines3)
    materials: tuple = MATERIALS
    conditions: tuple = CONDITIONS
    train_variants: tuple = tuple(range(0, 20))
    eval_variants: tuple = tuple(range(20, 24))
    eval_episodes: int = 50            # per policy and material (and the empty gripper)
    eval_envs: int = 10
    eval_empty: bool = True
    seed: int = 0                      # training; torch
    eval_seed: int = 1_000_000         # evaluation episodes: seeds eval_seed, eval_seed + 1, ...
    # drop_threshold's openings (None: its default, 0.45-0.70 in steps of 0.0025).
    threshold_openings: tuple = None
    threads: int = 0                   # the simulator's C++ threads (0: every core)
    device: str = None                 # None or "auto": cuda if available, else cpu
    extra: dict = field(default_factory=dict)


def quick_config(**overrides):
    """A smoke run of under a minute: 3 updates of 3 environments x 16 steps per policy, 16-step
    episodes, 3 evaluation episodes per material, thresholds searched over 0.50-0.62 in steps of
    0.005."""
    config = ExperimentConfig(
        total_steps=3 * 3 * 16, num_envs=3, rollout_steps=16, update_epochs=2, minibatches=2,
        horizon=16, eval_episodes=3, eval_envs=3,
        threshold_openings=tuple(np.round(np.arange(0.50, 0.62001, 0.005), 4)))
    return replace(config, **overrides)


def use_device(device=None):
    """resolve_device(device) (an unavailable device is an error); on the CPU torch then uses
    every core: the simulator and the networks take turns, so each may have them all."""
    device = resolve_device(device)
    if device == "cpu":
        torch.set_num_threads(os.cpu_count() or 1)
    return device


# --- the networks ------------------------------------------------------------------------------

def opening_input(obs):
    return (obs["opening"].float() - OPENING_CENTRE) / OPENING_SCALE


class BlindEncoder(nn.Module):
    """The blind policy's encoder: an MLP on the opening."""

    features = FEATURES

    def __init__(self):
        super().__init__()
        self.net = nn.Sequential(nn.Linear(1, FEATURES), nn.Tanh(),
                                 nn.Linear(FEATURES, FEATURES), nn.Tanh())

    def forward(self, obs):
        return self.net(opening_input(obs))


class SmallCNN(nn.Module):
    """Three strided convolutions and a linear layer: (B, 3, H, W) -> (B, out)."""

    def __init__(self, image_shape, out=FEATURES):
        super().__init__()
        self.conv = nn.Sequential(
            nn.Conv2d(3, 16, 5, stride=2), nn.ReLU(),
            nn.Conv2d(16, 32, 3, stride=2), nn.ReLU(),
            nn.Conv2d(32, 32, 3, stride=2), nn.ReLU(),
            nn.Flatten())
        with torch.no_grad():
            n = self.conv(torch.zeros((1, 3) + tuple(image_shape[:2]))).shape[1]
        self.fc = nn.Sequential(nn.Linear(n, out), nn.ReLU())

    def forward(self, x):
        return self.fc(self.conv(x))


def _group_norm(channels):
    """Group norm for ResNet18's norm layers: PPO acts with one state at a time and updates on
    minibatches, and batch norm would make the two disagree. (A module-level function, not a
    lambda, so that the policy pickles.)"""
    return nn.GroupNorm(8, channels)


class ResNet18(nn.Module):
    """torchvision's ResNet-18 ([2, 2, 2, 2] basic blocks, 64-512 channels), randomly
    initialised, with group norm instead of batch norm; its global average pooling feeds a
    linear layer and a ReLU to `out` features."""

    def __init__(self, image_shape=None, out=FEATURES):
        super().__init__()
        self.net = resnet18(norm_layer=_group_norm)
        self.net.fc = nn.Sequential(nn.Linear(self.net.fc.in_features, out), nn.ReLU())

    def forward(self, x):
        return self.net(x)


class TactileEncoder(nn.Module):
    """One image network shared by both DIGITs; its two feature vectors and the opening ->
    FEATURES features."""

    features = FEATURES

    def __init__(self, image_shape, encoder="cnn"):
        super().__init__()
        if encoder not in ENCODERS:
            raise ValueError("encoder %r; valid: %s" % (encoder, ", ".join(ENCODERS)))
        self.image_net = SmallCNN(image_shape) if encoder == "cnn" else ResNet18(image_shape)
        self.head = nn.Sequential(nn.Linear(2 * FEATURES + 1, FEATURES), nn.Tanh())

    def forward(self, obs):
        left = obs["digit_left"].float().permute(0, 3, 1, 2)
        right = obs["digit_right"].float().permute(0, 3, 1, 2)
        both = self.image_net(torch.cat([left, right], 0) * IMAGE_GAIN)
        fl, fr = both[:left.shape[0]], both[left.shape[0]:]
        return self.head(torch.cat([fl, fr, opening_input(obs)], 1))


def make_policy(condition, image_shape, encoder="cnn"):
    """The ActorCritic of a condition (the same heads and PPO for all three)."""
    if condition == "blind":
        enc = BlindEncoder()
    elif condition in ("textureless", "norm2tex"):
        enc = TactileEncoder(image_shape, encoder)
    else:
        raise ValueError("condition %r; valid: %s" % (condition, ", ".join(CONDITIONS)))
    return ppo.ActorCritic(enc, FEATURES, 3)


def make_env(condition, config, materials, variants, num_envs, empty=False):
    """HoldCubeVectorEnv for a condition: environment i holds materials[i % len(materials)];
    textureless renders with beta 0; images diff_float, downscaled; no force reading."""
    per_env = [materials[i % len(materials)] for i in range(num_envs)]
    return HoldCubeVectorEnv(
        num_envs=num_envs, material=per_env, variant=list(variants),
        beta_mm=0.0 if condition == "textureless" else None, image="diff_float",
        downscale=config.downscale, force=False, max_episode_steps=config.horizon,
        threads=config.threads, empty=empty)


# --- training ----------------------------------------------------------------------------------

def _ppo_config(config):
    return ppo.PPOConfig(
        total_steps=config.total_steps, rollout_steps=config.rollout_steps,
        learning_rate=config.learning_rate, update_epochs=config.update_epochs,
        minibatches=config.minibatches, entropy_coef=config.entropy_coef, seed=config.seed)


def train_condition(condition, config, log=print):
    """Trains one policy with norm2tex.rl.ppo; returns (act, records, policy). act(obs) ->
    greedy actions for a batch of observations. log(record) per update."""
    device = use_device(config.device)
    env = make_env(condition, config, config.materials, config.train_variants, config.num_envs)
    try:
        torch.manual_seed(config.seed)
        policy = make_policy(condition, env.single_observation_space["digit_left"].shape,
                             config.encoder).to(device)
        records = ppo.train(env, policy, _ppo_config(config), log=log, log_every_s=0.0,
                            device=device)
    finally:
        env.close()
    policy.eval()

    def act(obs):
        with torch.no_grad():
            t = {k: torch.as_tensor(np.asarray(v), device=device) for k, v in obs.items()}
            return policy.policy(policy.encoder(t)).argmax(-1).cpu().numpy()

    return act, records, policy


def require_sb3():
    """Raises RuntimeError unless stable_baselines3 and gymnasium are importable."""
    try:
        import gymnasium  # noqa: F401
        import stable_baselines3  # noqa: F401
    except ImportError as e:
        raise RuntimeError("--algo sb3 needs stable_baselines3 and gymnasium (%s); the default "
                           "--algo ppo needs neither" % e) from e


def train_condition_sb3(condition, config, log=print):
    """The same task and networks trained by stable_baselines3's PPO (one HoldCubeEnv per
    training environment). Raises RuntimeError when stable_baselines3 is not importable."""
    require_sb3()
    import gymnasium
    from stable_baselines3 import PPO
    from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from norm2tex.envs import HoldCubeEnv

    keys = ("opening",) if condition == "blind" else ("opening", "digit_left", "digit_right")

    class Only(gymnasium.ObservationWrapper):
        def __init__(self, env):
            super().__init__(env)
            self.observation_space = gymnasium.spaces.Dict(
                {k: env.observation_space[k] for k in keys})

        def observation(self, obs):
            return {k: obs[k] for k in keys}

    def factory(i):
        def make():
            return Only(HoldCubeEnv(
                material=config.materials[i % len(config.materials)],
                variant=list(config.train_variants),
                beta_mm=0.0 if condition == "textureless" else None, image="diff_float",
                downscale=config.downscale, force=False, max_episode_steps=config.horizon,
                threads=config.threads))
        return make

    venv = DummyVecEnv([factory(i) for i in range(config.num_envs)])
    image_shape = venv.observation_space["opening"].shape
    if condition != "blind":
        image_shape = venv.observation_space["digit_left"].shape

    class Extractor(BaseFeaturesExtractor):
        def __init__(self, observation_space):
            super().__init__(observation_space, FEATURES)
            self.encoder = make_policy(condition, image_shape, config.encoder).encoder

        def forward(self, obs):
            return self.encoder(obs)

    device = use_device(config.device)
    model = PPO("MultiInputPolicy", venv, n_steps=config.rollout_steps,
                batch_size=config.rollout_steps * config.num_envs // config.minibatches,
                n_epochs=config.update_epochs, learning_rate=config.learning_rate,
                ent_coef=config.entropy_coef, seed=config.seed, device=device,
                policy_kwargs=dict(features_extractor_class=Extractor, net_arch=[]))
    start = time.monotonic()
    model.learn(total_timesteps=config.total_steps)
    venv.close()
    records = [dict(update=0, steps=config.total_steps,
                    steps_per_s=config.total_steps / max(time.monotonic() - start, 1e-9),
                    mean_return=float("nan"), mean_length=float("nan"))]
    if log:
        log(records[0])

    def act(obs):
        actions, _ = model.predict({k: np.asarray(obs[k]) for k in keys}, deterministic=True)
        return np.asarray(actions)

    return act, records, model.policy


# --- evaluation --------------------------------------------------------------------------------

def evaluate(act, condition, material, config):
    """Runs `config.eval_episodes` episodes of `config.horizon` steps with act (greedy) on the
    held-out variants and seeds; material EMPTY: the empty gripper. Returns a dict of numbers:
    opening_mean / opening_std / held_fraction per step (0 = the first observation, after the
    grasp), final_opening_mean / _std, drop_rate, return_mean / _std, episodes. After a drop an
    episode keeps the opening that dropped the cube (the curve ends where the cube fell)."""
    empty = material == EMPTY
    n = max(1, min(config.eval_envs, config.eval_episodes))
    env = make_env(condition, config, [config.materials[0] if empty else material],
                   config.eval_variants, n, empty=empty)
    horizon = config.horizon
    openings, returns, drops, held = [], [], [], []
    try:
        for first in range(0, config.eval_episodes, n):
            obs, _ = env.reset(seed=config.eval_seed + first)
            traj = np.zeros((n, horizon + 1))
            traj[:, 0] = obs["opening"][:, 0]
            ret = np.zeros(n)
            dropped = np.zeros(n, dtype=bool)
            running = np.ones(n, dtype=bool)
            holding = np.ones((n, horizon + 1), dtype=bool)  # the cube not dropped by step t
            for t in range(1, horizon + 1):
                obs, reward, terminated, truncated, infos = env.step(act(obs))
                for i in range(n):
                    if not running[i]:
                        traj[i, t] = traj[i, t - 1]
                        holding[i, t] = holding[i, t - 1]
                        continue
                    done = terminated[i] or truncated[i]
                    last = infos[i].get("final_observation") if done else None
                    traj[i, t] = (last if last is not None else
                                  {"opening": obs["opening"][i]})["opening"][0]
                    ret[i] += reward[i]
                    dropped[i] = bool(terminated[i])
                    holding[i, t] = not dropped[i]
                    running[i] = not done
            take = min(n, config.eval_episodes - first)
            openings.append(traj[:take])
            returns.append(ret[:take])
            drops.append(dropped[:take])
            held.append(holding[:take])
    finally:
        env.close()
    openings = np.concatenate(openings)
    returns = np.concatenate(returns)
    drops = np.concatenate(drops)
    held = np.concatenate(held)
    return dict(
        episodes=int(len(returns)),
        opening_mean=openings.mean(0).tolist(),
        opening_std=openings.std(0).tolist(),
        held_fraction=held.mean(0).tolist(),
        final_opening_mean=float(openings[:, -1].mean()),
        final_opening_std=float(openings[:, -1].std()),
        drop_rate=float(drops.mean()),
        return_mean=float(returns.mean()),
        return_std=float(returns.std()),
    )


def threshold_oracle(threshold):
    """The reference a policy is measured against: knowing the material's drop threshold, open
    while the next step stays at or below it, close when above it (an episode may start there),
    else stay. Acts on a batch of observations, as a trained policy's act does."""
    step = 0.005

    def act(obs):
        opening = np.asarray(obs["opening"], dtype=np.float64)[:, 0]
        return np.where(opening + step <= threshold + 1e-6, 2,
                        np.where(opening > threshold + 1e-6, 0, 1))
    return act


def material_spread(evaluation, materials):
    """How differently a policy holds the materials: the range of its mean final openings over
    `materials` (max - min) and a 95 % confidence interval of that difference, from the two
    extreme materials' episode spreads (normal approximation: +- 1.96 sqrt(s1^2/n1 + s2^2/n2)).
    Also each material's mean final opening with its own 95 % half-width. A policy that holds
    every material alike has a range whose interval includes 0."""
    means = {m: evaluation[m]["final_opening_mean"] for m in materials}
    half = {m: 1.96 * evaluation[m]["final_opening_std"] / math.sqrt(evaluation[m]["episodes"])
            for m in materials}
    hi = max(materials, key=lambda m: means[m])
    lo = min(materials, key=lambda m: means[m])
    spread = means[hi] - means[lo]
    h = 1.96 * math.sqrt(sum(evaluation[m]["final_opening_std"] ** 2 / evaluation[m]["episodes"]
                             for m in (hi, lo)))
    return {"range": spread, "ci95": [spread - h, spread + h], "widest": hi, "narrowest": lo,
            "final_opening_ci95_half": half}


def results_table(results):
    """The README's table (markdown) of a results dict: per material its drop threshold, what
    holding it at the threshold earns (the oracle's return) and, per policy, the mean final
    opening (+- its 95 % half-width), drop rate and mean return; then each policy's range of
    final openings across the materials with its interval."""
    config = results.get("config", {})
    policies = [p for p in config.get("conditions", results["policies"])
                if p in results["policies"]]
    materials = [m for m in config.get("materials", results["thresholds"])
                 if m in results["thresholds"]]
    oracle = results.get("oracle", {})
    head = "| material | drop threshold | oracle's return | " + " | ".join(
        "%s: final opening, drop rate, return" % p for p in policies) + " |"
    lines = [head, "|" + "---|" * (3 + len(policies))]
    spreads = {p: material_spread(results["policies"][p]["evaluation"], materials)
               for p in policies}
    for m in materials + ([EMPTY] if all(EMPTY in results["policies"][p]["evaluation"]
                                          for p in policies) else []):
        t = results["thresholds"].get(m)
        cells = []
        for p in policies:
            ev = results["policies"][p]["evaluation"][m]
            half = 1.96 * ev["final_opening_std"] / math.sqrt(ev["episodes"])
            cells.append("%.4f ± %.4f, %.0f %%, %.2f" % (
                ev["final_opening_mean"], half, 100 * ev["drop_rate"], ev["return_mean"]))
        lines.append("| %s | %s | %s | %s |" % (
            m, "%.4f" % t if t is not None else "–",
            "%.2f" % oracle[m]["return_mean"] if m in oracle else "–", " | ".join(cells)))
    lines.append("| range across %s | %.4f | | %s |" % (
        ", ".join(materials),
        max(results["thresholds"][m] for m in materials) -
        min(results["thresholds"][m] for m in materials),
        " | ".join("%.4f (95 %% CI %.4f to %.4f)" % (s["range"], *s["ci95"])
                   for s in spreads.values())))
    return "\n".join(lines)


# --- outputs -----------------------------------------------------------------------------------

def _finite_or_none(x):
    return x if isinstance(x, (int, str)) or (x is not None and math.isfinite(x)) else None


def _clean(obj):
    """NaN -> None, tuples -> lists, numpy scalars -> Python (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return _finite_or_none(float(obj))
    if isinstance(obj, (np.integer,)):
        return int(obj)
    return obj


TRAINING_FIELDS = ("update", "steps", "steps_per_s", "mean_return", "mean_length",
                   "policy_loss", "value_loss", "entropy", "clip_fraction")


def write_training_csv(path, records):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(TRAINING_FIELDS)
        for r in records:
            w.writerow([r.get(k, "") for k in TRAINING_FIELDS])


def write_results_csv(path, results):
    """Every number of results.json: policy, material, metric, step ('' for scalars), value."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(("policy", "material", "metric", "step", "value"))
        for m, t in results["thresholds"].items():
            w.writerow(("", m, "drop_threshold", "", "" if t is None else repr(t)))
        evaluations = [("oracle", results.get("oracle", {}))] + [
            (p, entry["evaluation"]) for p, entry in results["policies"].items()]
        for p, entry in results["policies"].items():
            for r in entry["training"]:
                for k in ("mean_return", "mean_length"):
                    v = r.get(k)
                    w.writerow((p, "", "train_" + k, r["steps"], "" if v is None else repr(v)))
        for p, evaluation in evaluations:
            for m, ev in evaluation.items():
                for k, v in ev.items():
                    if isinstance(v, list):
                        for s, x in enumerate(v):
                            w.writerow((p, m, k, s, repr(x)))
                    else:
                        w.writerow((p, m, k, "", repr(v)))


# --- the experiment ----------------------------------------------------------------------------

def run(config=None, out_dir="hold_cube_experiment", log=print):
    """Trains, evaluates and measures as the module docstring says; writes every output to
    out_dir and returns the results dict (what results.json holds)."""
    config = config or ExperimentConfig()
    if config.algo not in ALGOS:
        raise ValueError("algo %r; valid: %s" % (config.algo, ", ".join(ALGOS)))
    if config.encoder not in ENCODERS:
        raise ValueError("encoder %r; valid: %s" % (config.encoder, ", ".join(ENCODERS)))
    if config.algo == "sb3":
        require_sb3()
    device = use_device(config.device)  # first: a missing GPU stops the run before any work
    os.makedirs(out_dir, exist_ok=True)
    log("hold_cube_experiment: device %s, %d torch threads, %s" % (
        device, torch.get_num_threads(), json.dumps(_clean(asdict(config)))))

    results = {"config": _clean(asdict(config)), "thresholds": {}, "policies": {}}
    for m in config.materials:
        kwargs = {}
        if config.threshold_openings is not None:
            kwargs["openings"] = list(config.threshold_openings)
        threshold, _ = drop_threshold(m, threads=config.threads, **kwargs)
        results["thresholds"][m] = threshold
        log("drop threshold %s: %s" % (m, threshold))

    # What holding each material at its threshold earns on the same episodes: the ceiling a
    # policy's return is read against.
    results["oracle"] = {}
    for m in config.materials:
        if results["thresholds"][m] is None:
            continue
        ev = evaluate(threshold_oracle(results["thresholds"][m]), "blind", m, config)
        results["oracle"][m] = ev
        log("oracle      on %-6s: final opening %.4f, drop rate %.2f, return %.2f" % (
            m, ev["final_opening_mean"], ev["drop_rate"], ev["return_mean"]))

    trainer = train_condition if config.algo == "ppo" else train_condition_sb3
    for condition in config.conditions:
        def progress(r, condition=condition):
            log("%-11s update %4d  steps %7d  %6.1f steps/s  return %7.3f  length %6.1f" % (
                condition, r["update"], r["steps"], r["steps_per_s"], r["mean_return"],
                r["mean_length"]))

        act, records, policy = trainer(condition, config, log=progress)
        write_training_csv(os.path.join(out_dir, "training_%s.csv" % condition), records)
        torch.save(policy.state_dict(), os.path.join(out_dir, "policy_%s.pt" % condition))
        entry = {"training": [{k: r.get(k) for k in ("update", "steps", "mean_return",
                                                     "mean_length")} for r in records],
                 "evaluation": {}}
        for m in list(config.materials) + ([EMPTY] if config.eval_empty else []):
            ev = evaluate(act, condition, m, config)
            entry["evaluation"][m] = ev
            log("%-11s on %-6s: final opening %.4f +- %.4f, drop rate %.2f, return %.2f" % (
                condition, m, ev["final_opening_mean"], ev["final_opening_std"],
                ev["drop_rate"], ev["return_mean"]))
        entry["material_spread"] = material_spread(entry["evaluation"], config.materials)
        results["policies"][condition] = entry

    results = _clean(results)
    with open(os.path.join(out_dir, "results.json"), "w") as f:
        json.dump(results, f, indent=1, sort_keys=True)
    write_results_csv(os.path.join(out_dir, "results.csv"), results)
    figures.plot_openings(os.path.join(out_dir, "opening_vs_step.png"), results, config)
    figures.plot_training(os.path.join(out_dir, "training_curves.png"), results, config)
    log("wrote %s" % out_dir)
    return results
