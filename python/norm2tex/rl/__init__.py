"""Reinforcement learning on the environments (PyTorch): a small, readable PPO."""
