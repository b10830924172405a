"""Proximal Policy Optimization (Schulman et al. 2017), in the shape of CleanRL's single-file
PPO: rollouts from a vector environment, generalized advantage estimation, the clipped surrogate
objective, a value loss and an entropy bonus, minibatch epochs. For discrete actions (the
paper's -0.005 / 0 / +0.005 on the gripper's opening) and dict observations of arrays.

Written for norm2tex.envs' vector environments (reset(seed) -> (obs, infos); step(actions) ->
(obs, rewards, terminated, truncated, infos), obs a dict of arrays with a first axis of N, a
finished environment reset in the same step); any environment with that shape works.
stable-baselines3 is not packaged in Debian; where it is installed it can train the same
environments instead (they follow the Gymnasium API).

The parts that decide whether PPO learns are pure functions with their own tests:
compute_gae (advantages and returns) and ppo_losses (the clipped objective).
"""

import time
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn


@dataclass
class PPOConfig:
    """Defaults: CleanRL's for discrete control, with the paper's 128-step horizon."""

    total_steps: int = 100_000  # environment steps over all environments
    rollout_steps: int = 128  # per environment, per update
    gamma: float = 0.99
    gae_lambda: float = 0.95
    learning_rate: float = 2.5e-4
    anneal_lr: bool = True
    update_epochs: int = 4
    minibatches: int = 4
    clip_coef: float = 0.2
    clip_value: bool = True
    entropy_coef: float = 0.01
    value_coef: float = 0.5
    max_grad_norm: float = 0.5
    normalize_advantages: bool = True
    seed: int = 0


def compute_gae(rewards, values, dones, next_value, next_done, gamma, gae_lambda):
    """Generalized advantage estimation over a rollout of T steps of N environments.

    rewards, values, dones: (T, N) tensors; dones[t] = 1 when the episode ended *before* step t's
    observation (that observation starts a new episode, as in CleanRL); next_value, next_done:
    (N,) for the observation after the rollout. A step that ended its episode does not look past
    it: delta_t = r_t + gamma V(s_t+1) (1 - done_t+1) - V(s_t), A_t = delta_t + gamma lambda
    (1 - done_t+1) A_t+1. Returns (advantages, returns = advantages + values).
    """
    steps = rewards.shape[0]
    advantages = torch.zeros_like(rewards)
    last = torch.zeros_like(next_value)
    for t in reversed(range(steps)):
        if t == steps - 1:
            not_done, following = 1.0 - next_done, next_value
        else:
            not_done, following = 1.0 - dones[t + 1], values[t + 1]
        delta = rewards[t] + gamma * following * not_done - values[t]
        last = delta + gamma * gae_lambda * not_done * last
        advantages[t] = last
    return advantages, advantages + values


def ppo_losses(new_logprob, old_logprob, advantages, new_value, old_value, returns, entropy,
               clip_coef, clip_value=True):
    """The clipped surrogate objective (to minimise: its negative), the value loss and the mean
    entropy. ratio = pi_new / pi_old; the policy loss is max(-A ratio, -A clip(ratio, 1 - eps,
    1 + eps)): no gain from moving the ratio beyond the clip in the advantage's direction.
    Returns (policy_loss, value_loss, entropy, clip_fraction)."""
    ratio = (new_logprob - old_logprob).exp()
    unclipped = -advantages * ratio
    clipped = -advantages * torch.clamp(ratio, 1.0 - clip_coef, 1.0 + clip_coef)
    policy_loss = torch.max(unclipped, clipped).mean()
    if clip_value:
        value_clipped = old_value + torch.clamp(new_value - old_value, -clip_coef, clip_coef)
        value_loss = 0.5 * torch.max((new_value - returns) ** 2,
                                     (value_clipped - returns) ** 2).mean()
    else:
        value_loss = 0.5 * ((new_value - returns) ** 2).mean()
    clip_fraction = ((ratio - 1.0).abs() > clip_coef).float().mean()
    return policy_loss, value_loss, entropy.mean(), clip_fraction


class ActorCritic(nn.Module):
    """A shared encoder (dict of observation tensors -> features), a categorical policy head
    and a value head, initialised as CleanRL does (orthogonal, small policy gain)."""

    def __init__(self, encoder, features, actions):
        super().__init__()
        self.encoder = encoder
        self.policy = nn.Linear(features, actions)
        self.value = nn.Linear(features, 1)
        nn.init.orthogonal_(self.policy.weight, 0.01)
        nn.init.zeros_(self.policy.bias)
        nn.init.orthogonal_(self.value.weight, 1.0)
        nn.init.zeros_(self.value.bias)

    def get_value(self, obs):
        return self.value(self.encoder(obs)).squeeze(-1)

    def get_action_and_value(self, obs, action=None):
        features = self.encoder(obs)
        dist = torch.distributions.Categorical(logits=self.policy(features))
        if action is None:
            action = dist.sample()
        return action, dist.log_prob(action), dist.entropy(), self.value(features).squeeze(-1)


def _to_tensors(obs, device):
    return {k: torch.as_tensor(np.asarray(v), device=device) for k, v in obs.items()}


def train(env, policy, config, log=None, log_every_s=1.0, device="cpu"):
    """Trains `policy` (an ActorCritic) with PPO on the vector environment `env` (num_envs N).

    log(record) is called at most every log_every_s seconds and after the last update with a
    dict: update, steps, steps_per_s, mean_return and mean_length of the episodes finished since
    the last record (NaN if none), policy_loss, value_loss, entropy, clip_fraction. Returns the
    list of records. Deterministic for a seed on one machine (torch's CPU kernels).
    """
    torch.manual_seed(config.seed)
    n = env.num_envs
    t_steps = config.rollout_steps
    batch = t_steps * n
    minibatch = batch // config.minibatches
    updates = max(1, config.total_steps // batch)
    optimizer = torch.optim.Adam(policy.parameters(), lr=config.learning_rate, eps=1e-5)

    obs, _ = env.reset(seed=config.seed)
    next_obs = _to_tensors(obs, device)
    next_done = torch.zeros(n, device=device)
    store_obs = {k: torch.zeros((t_steps,) + v.shape, dtype=v.dtype, device=device)
                 for k, v in next_obs.items()}
    actions = torch.zeros((t_steps, n), dtype=torch.long, device=device)
    logprobs = torch.zeros((t_steps, n), device=device)
    rewards = torch.zeros((t_steps, n), device=device)
    dones = torch.zeros((t_steps, n), device=device)
    values = torch.zeros((t_steps, n), device=device)

    episode_return = np.zeros(n)
    episode_length = np.zeros(n, dtype=int)
    finished_returns, finished_lengths = [], []
    records = []
    start = last_log = time.monotonic()
    steps = 0
    for update in range(1, updates + 1):
        if config.anneal_lr:
            optimizer.param_groups[0]["lr"] = config.learning_rate * (
                1.0 - (update - 1.0) / updates)
        for t in range(t_steps):
            for k in store_obs:
                store_obs[k][t] = next_obs[k]
            dones[t] = next_done
            with torch.no_grad():
                action, logprob, _, value = policy.get_action_and_value(next_obs)
            actions[t], logprobs[t], values[t] = action, logprob, value
            obs, reward, terminated, truncated, _ = env.step(action.cpu().numpy())
            done = np.logical_or(terminated, truncated)
            rewards[t] = torch.as_tensor(reward, dtype=torch.float32, device=device)
            # A truncated episode is cut, not ended: its last state's value would be the right
            # bootstrap; like CleanRL, treat it as ended (the horizon is part of the task here).
            next_obs = _to_tensors(obs, device)
            next_done = torch.as_tensor(done, dtype=torch.float32, device=device)
            episode_return += reward
            episode_length += 1
            for i in np.flatnonzero(done):
                finished_returns.append(episode_return[i])
                finished_lengths.append(episode_length[i])
                episode_return[i], episode_length[i] = 0.0, 0
            steps += n

        with torch.no_grad():
            next_value = policy.get_value(next_obs)
        advantages, returns = compute_gae(rewards, values, dones, next_value, next_done,
                                          config.gamma, config.gae_lambda)

        flat_obs = {k: v.reshape((batch,) + v.shape[2:]) for k, v in store_obs.items()}
        flat = dict(actions=actions.reshape(-1), logprobs=logprobs.reshape(-1),
                    advantages=advantages.reshape(-1), returns=returns.reshape(-1),
                    values=values.reshape(-1))
        generator = torch.Generator().manual_seed(config.seed * 100003 + update)
        for _ in range(config.update_epochs):
            order = torch.randperm(batch, generator=generator)
            for begin in range(0, batch, minibatch):
                idx = order[begin:begin + minibatch]
                _, new_logprob, entropy, new_value = policy.get_action_and_value(
                    {k: v[idx] for k, v in flat_obs.items()}, flat["actions"][idx])
                adv = flat["advantages"][idx]
                if config.normalize_advantages and adv.numel() > 1:
                    adv = (adv - adv.mean()) / (adv.std() + 1e-8)
                policy_loss, value_loss, entropy_mean, clip_fraction = ppo_losses(
                    new_logprob, flat["logprobs"][idx], adv, new_value, flat["values"][idx],
                    flat["returns"][idx], entropy, config.clip_coef, config.clip_value)
                loss = (policy_loss - config.entropy_coef * entropy_mean
                        + config.value_coef * value_loss)
                optimizer.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(policy.parameters(), config.max_grad_norm)
                optimizer.step()

        now = time.monotonic()
        if now - last_log >= log_every_s or update == updates:
            record = dict(
                update=update, steps=steps, steps_per_s=steps / max(now - start, 1e-9),
                mean_return=float(np.mean(finished_returns)) if finished_returns else float("nan"),
                mean_length=float(np.mean(finished_lengths)) if finished_lengths else float("nan"),
                policy_loss=float(policy_loss), value_loss=float(value_loss),
                entropy=float(entropy_mean), clip_fraction=float(clip_fraction))
            records.append(record)
            if log is not None:
                log(record)
            finished_returns, finished_lengths = [], []
            last_log = now
    return records
