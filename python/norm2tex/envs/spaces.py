"""Observation and action spaces: Gymnasium's when it is installed, else small local classes
with the same attributes (shape, dtype, low, high, n, sample(), contains(), seed()).

Gymnasium is not packaged in Debian 12; the environments work the same with either. With
Gymnasium the environments subclass gymnasium.Env and pass its env_checker.
"""

from collections import OrderedDict

import numpy as np

try:  # pragma: no cover - depends on the machine
    import gymnasium as _gymnasium

    HAVE_GYMNASIUM = True
except ImportError:
    _gymnasium = None
    HAVE_GYMNASIUM = False


class Space:
    """The part of gymnasium.spaces.Space the environments and their users rely on."""

    def __init__(self, shape, dtype, seed=None):
        self.shape = None if shape is None else tuple(shape)
        self.dtype = None if dtype is None else np.dtype(dtype)
        self.np_random = np.random.default_rng(seed)

    def seed(self, seed=None):
        self.np_random = np.random.default_rng(seed)
        return [seed]

    def __contains__(self, x):
        return self.contains(x)


class LocalBox(Space):
    """A box in R^n: every element within [low, high] (gymnasium.spaces.Box)."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        super().__init__(shape, dtype, seed)
        self.low = np.full(self.shape, low, dtype=dtype) if np.isscalar(low) else np.asarray(low, dtype)
        self.high = np.full(self.shape, high, dtype=dtype) if np.isscalar(high) else np.asarray(high, dtype)

    def sample(self):
        if np.issubdtype(self.dtype, np.integer):
            return self.np_random.integers(
                self.low.astype(np.int64), self.high.astype(np.int64) + 1, size=self.shape
            ).astype(self.dtype)
        low = np.where(np.isfinite(self.low), self.low, -1e6).astype(np.float64)
        high = np.where(np.isfinite(self.high), self.high, 1e6).astype(np.float64)
        return self.np_random.uniform(low, high, size=self.shape).astype(self.dtype)

    def contains(self, x):
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        return bool(
            np.can_cast(x.dtype, self.dtype)
            and x.shape == self.shape
            and np.all(x >= self.low)
            and np.all(x <= self.high)
        )

    def __repr__(self):
        return "Box(%s, %s, %s, %s)" % (self.low.min(), self.high.max(), self.shape, self.dtype)


class LocalDiscrete(Space):
    """{0, 1, ..., n - 1} (gymnasium.spaces.Discrete)."""

    def __init__(self, n, seed=None):
        super().__init__((), np.int64, seed)
        self.n = int(n)

    def sample(self):
        return int(self.np_random.integers(self.n))

    def contains(self, x):
        if isinstance(x, (int, np.integer)) or (isinstance(x, np.ndarray) and x.shape == ()):
            return 0 <= int(x) < self.n
        return False

    def __repr__(self):
        return "Discrete(%d)" % self.n


class LocalDict(Space):
    """A dict of named spaces (gymnasium.spaces.Dict)."""

    def __init__(self, spaces, seed=None):
        super().__init__(None, None, seed)
        self.spaces = OrderedDict(spaces)

    def seed(self, seed=None):
        for i, space in enumerate(self.spaces.values()):
            space.seed(None if seed is None else seed + i)
        return [seed]

    def sample(self):
        return OrderedDict((k, s.sample()) for k, s in self.spaces.items())

    def contains(self, x):
        return (
            isinstance(x, dict)
            and set(x.keys()) == set(self.spaces.keys())
            and all(self.spaces[k].contains(x[k]) for k in self.spaces)
        )

    def __getitem__(self, key):
        return self.spaces[key]

    def keys(self):
        return self.spaces.keys()

    def __repr__(self):
        return "Dict(%s)" % ", ".join("%s: %r" % kv for kv in self.spaces.items())


if HAVE_GYMNASIUM:  # pragma: no cover - depends on the machine
    Box = _gymnasium.spaces.Box
    Discrete = _gymnasium.spaces.Discrete
    Dict = _gymnasium.spaces.Dict
    EnvBase = _gymnasium.Env
else:
    Box = LocalBox
    Discrete = LocalDiscrete
    Dict = LocalDict

    class EnvBase:
        """gymnasium.Env's shape: what stable-baselines3-style code looks for."""

        metadata = {"render_modes": []}
        render_mode = None
        spec = None
        np_random = None

        def close(self):
            pass

        @property
        def unwrapped(self):
            return self

        def __enter__(self):
            return self

        def __exit__(self, *args):
            self.close()
            return False
