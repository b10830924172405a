from norm2tex.envs.spaces import Box, Dict, Discrete  # noqa: F401
