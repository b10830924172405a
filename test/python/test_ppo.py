"""norm2tex.rl.ppo: GAE and the clipped objective against hand computation, and PPO solving
tiny tasks with known answers (and failing them with the advantage's sign flipped)."""

import numpy as np
import pytest

torch = pytest.importorskip("torch", reason="PyTorch is not installed (Debian: python3-torch)")
from torch import nn  # noqa: E402

from norm2tex.rl import ppo  # noqa: E402


class Bandit:
    """N two-armed bandits, one step per episode: arm 1 pays 1, arm 0 pays 0.2."""

    def __init__(self, num_envs=8):
        self.num_envs = num_envs

    def obs(self):
        return {"x": np.zeros((self.num_envs, 1), dtype=np.float32)}

    def reset(self, seed=None):
        return self.obs(), [{}] * self.num_envs

    def step(self, actions):
        rewards = np.where(np.asarray(actions) == 1, 1.0, 0.2)
        done = np.ones(self.num_envs, dtype=bool)
        return self.obs(), rewards, done, np.zeros_like(done), [{}] * self.num_envs


class MoveToTarget:
    """A point on the integers -4..4 starting at a random non-zero position; actions move it
    left / stay / right; reaching 0 pays 1 and ends the episode, every other step costs 0.05;
    truncated after 12 steps. The optimum walks straight to 0."""

    def __init__(self, num_envs=8, seed=0):
        self.num_envs = num_envs
        self.rng = np.random.default_rng(seed)
        self.x = np.zeros(num_envs, dtype=int)
        self.t = np.zeros(num_envs, dtype=int)

    def _draw(self, i):
        self.x[i] = self.rng.choice([-4, -3, -2, -1, 1, 2, 3, 4])
        self.t[i] = 0

    def obs(self):
        return {"x": (self.x[:, None] / 4.0).astype(np.float32)}

    def reset(self, seed=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        for i in range(self.num_envs):
            self._draw(i)
        return self.obs(), [{}] * self.num_envs

    def step(self, actions):
        self.x += np.asarray(actions) - 1
        self.x = np.clip(self.x, -4, 4)
        self.t += 1
        arrived = self.x == 0
        truncated = ~arrived & (self.t >= 12)
        rewards = np.where(arrived, 1.0, -0.05)
        for i in np.flatnonzero(arrived | truncated):
            self._draw(i)
        return self.obs(), rewards, arrived, truncated, [{}] * self.num_envs


def mlp_policy(actions):
    encoder = nn.Sequential(nn.Linear(1, 32), nn.Tanh(), nn.Linear(32, 32), nn.Tanh())

    class Encoder(nn.Module):
        def __init__(self):
            super().__init__()
            self.net = encoder

        def forward(self, obs):
            return self.net(obs["x"].float())

    return ppo.ActorCritic(Encoder(), 32, actions)


def test_gae_equals_the_hand_computation():
    gamma, lam = 0.9, 0.8
    # One environment, 3 steps; the episode ends after step 1 (dones[2] = 1: step 2 starts anew).
    rewards = torch.tensor([[1.0], [2.0], [3.0]])
    values = torch.tensor([[0.5], [1.0], [1.5]])
    dones = torch.tensor([[0.0], [0.0], [1.0]])
    next_value, next_done = torch.tensor([2.0]), torch.tensor([0.0])
    adv, ret = ppo.compute_gae(rewards, values, dones, next_value, next_done, gamma, lam)
    d2 = 3.0 + gamma * 2.0 - 1.5
    d1 = 2.0 + 0.0 - 1.0  # its episode ended: no bootstrap from step 2
    d0 = 1.0 + gamma * 1.0 - 0.5
    a2 = d2
    a1 = d1
    a0 = d0 + gamma * lam * a1
    assert adv[:, 0].tolist() == pytest.approx([a0, a1, a2])
    assert ret[:, 0].tolist() == pytest.approx([a0 + 0.5, a1 + 1.0, a2 + 1.5])


def test_the_clipped_objective_stops_the_gain_beyond_the_clip():
    eps = 0.2
    old = torch.zeros(4)
    advantages = torch.tensor([1.0, 1.0, -1.0, -1.0])
    # Ratios 1.5 (A > 0: clipped), 0.9 (A > 0: inside), 0.5 (A < 0: clipped), 1.1 (inside).
    new = torch.log(torch.tensor([1.5, 0.9, 0.5, 1.1])).requires_grad_()
    zeros = torch.zeros(4)
    loss, _, _, clip_fraction = ppo.ppo_losses(new, old, advantages, zeros, zeros, zeros, zeros,
                                               eps)
    loss.backward()
    assert loss.item() == pytest.approx(-(1.2 + 0.9 - 0.8 - 1.1) / 4)
    # d(-A r)/d(log r) = -A r / 4 inside the clip, 0 where clipped.
    expected = [0.0, -0.9 / 4, 0.0, 1.1 / 4]
    assert new.grad.tolist() == pytest.approx(expected)
    assert clip_fraction.item() == pytest.approx(0.5)


def run(env, actions, steps, monkeypatch=None, flip=False, seed=0):
    if flip:
        original = ppo.compute_gae

        def flipped(*args):
            adv, ret = original(*args)
            return -adv, ret

        monkeypatch.setattr(ppo, "compute_gae", flipped)
    torch.manual_seed(seed)
    policy = mlp_policy(actions)
    config = ppo.PPOConfig(total_steps=steps, rollout_steps=16, learning_rate=3e-3,
                           update_epochs=4, minibatches=4, seed=seed)
    records = ppo.train(env, policy, config, log_every_s=0.0)
    return policy, records


def test_ppo_finds_the_better_arm(monkeypatch):
    policy, records = run(Bandit(), 2, 4096)
    with torch.no_grad():
        probs = torch.softmax(policy.policy(policy.encoder({"x": torch.zeros(1, 1)})), -1)
    assert probs[0, 1].item() > 0.95
    assert records[-1]["mean_return"] > 0.9
    # The same budget with the advantage's sign flipped learns the worse arm: the test can fail.
    policy, _ = run(Bandit(), 2, 4096, monkeypatch, flip=True)
    with torch.no_grad():
        probs = torch.softmax(policy.policy(policy.encoder({"x": torch.zeros(1, 1)})), -1)
    assert probs[0, 1].item() < 0.5


def test_ppo_walks_to_the_target(monkeypatch):
    policy, records = run(MoveToTarget(seed=1), 3, 16384, seed=1)
    # From every start, the greedy action points at 0.
    with torch.no_grad():
        x = torch.tensor([[-4.0], [-2.0], [-1.0], [1.0], [2.0], [4.0]]) / 4.0
        greedy = policy.policy(policy.encoder({"x": x})).argmax(-1).tolist()
    assert greedy == [2, 2, 2, 0, 0, 0]
    # Optimal return: 1 - 0.05 (|x0| - 1), 0.875 on average over the starts.
    assert records[-1]["mean_return"] > 0.8
    _, flipped = run(MoveToTarget(seed=1), 3, 16384, monkeypatch, flip=True, seed=1)
    assert flipped[-1]["mean_return"] < 0.5


def test_ppo_trains_on_the_hold_cube_batch():
    """One update of a blind policy (the opening only) on HoldCubeVectorEnv: the environments'
    dict observations, batched actions and same-step resets work with the trainer."""
    envs = pytest.importorskip("norm2tex.envs")

    class Blind(nn.Module):
        def __init__(self):
            super().__init__()
            self.net = nn.Sequential(nn.Linear(1, 16), nn.Tanh())

        def forward(self, obs):
            return self.net(obs["opening"].float())

    env = envs.HoldCubeVectorEnv(num_envs=2, image="diff_int16", downscale=8, noise=False,
                                 variant=0)
    policy = ppo.ActorCritic(Blind(), 16, 3)
    config = ppo.PPOConfig(total_steps=32, rollout_steps=16, minibatches=2, update_epochs=1)
    before = [p.detach().clone() for p in policy.parameters()]
    records = ppo.train(env, policy, config, log_every_s=0.0)
    env.close()
    assert records[-1]["steps"] == 32
    assert all(np.isfinite(records[-1][k]) for k in ("policy_loss", "value_loss", "entropy"))
    assert any(not torch.equal(a, b) for a, b in zip(before, policy.parameters()))
