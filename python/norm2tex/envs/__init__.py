"""Gymnasium-style environments over the simulated gripper with two DIGITs (GripperEnv,
HoldCubeEnv) and over any hand with DIGITs from its URDF (HandEnv).

    from norm2tex.envs import HoldCubeEnv
    env = HoldCubeEnv()
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

With Gymnasium installed the environments are gymnasium.Env subclasses with gymnasium's
spaces; without it (Debian 12 does not package it) they use the local spaces of
norm2tex.envs.spaces, with the same attributes.
"""

from norm2tex.envs.gripper_env import GripperEnv, GripperVectorEnv  # noqa: F401
from norm2tex.envs.hand_env import HandEnv  # noqa: F401
from norm2tex.envs.hold_cube import (  # noqa: F401
    HoldCubeEnv,
    HoldCubeVectorEnv,
    drop_threshold,
    hold_reward,
)
from norm2tex.envs.spaces import HAVE_GYMNASIUM  # noqa: F401
