"""GripperEnv and GripperVectorEnv: the simulated parallel gripper with both DIGITs, under the
Gymnasium API (reset(seed, options) -> (obs, info); step(action) -> (obs, reward, terminated,
truncated, info)).

One step = one command, then `frames_per_step` sensor frames (1/60 s each by default) of
physics, then both DIGIT images at the last frame. The same environment runs in this process
(backend="inprocess": norm2tex._core, C++ threads) or over a running ROS system
(backend="ros": gripper_sim.launch mode:=synchronous, see ros_backend.py).
"""

import math
import os

import numpy as np

import norm2tex
from norm2tex.blocks import block_mean
from norm2tex.envs import spaces
from norm2tex.envs.commands import (ABSOLUTE, CLOSE, DELTA, DISCRETE_DELTA, KEEP, OPEN,  # noqa
                                    STAY)
from norm2tex.envs.inprocess_backend import InProcessBackend
ACTIONS = ("discrete", "delta", "absolute")
IMAGE_MODES = ("raw", "diff_int16", "diff_float")
FINGERS = ("left", "right")


class _Episode:
    """What one sub-environment knows about its current episode."""

    def __init__(self):
        self.rng = np.random.default_rng()
        self.next_variant = None  # drawn one episode ahead
        self.steps = 0
        self.info = {}


class GripperVectorEnv(spaces.EnvBase):
    """N gripper environments in one process, stepped together on C++ threads (one Python call
    per batch step). Environment i, reset with seed s + i, gives exactly what a GripperEnv
    reset with that seed gives for the same actions.

    Observations, rewards, terminated and truncated are stacked along a first axis of N; infos
    are a list of N dicts. A finished environment is reset at once (same-step autoreset): its
    row then holds the new episode's first observation, and its info the last one as
    info["final_observation"] (and the final info as info["final_info"]).

    Parameters (every one also of GripperEnv):
      num_envs: N (>= 1).
      material: config/materials/<name>.yaml name or a path; None: no texture, friction 0.5.
        In-process also a list of N, one per environment (each its own friction and texture;
        variants then index every one of them); info["material"] says which.
      variant: an int, or a list of variants drawn from uniformly per episode (the paper uses
        24: variants=range(24)); None = range(the material's variant_count).
      beta_mm: texture depth, mm (None: the material's; 0: the textureless sensor).
      scene: config/scenes/<name>.yaml name or a path (the gripper, the object, the episode);
        a scene whose gripper.hand names a two-finger hand yaml (a WSG-50 with two DIGITs, say)
        runs its episodes on that hand (docs/hands.md).
      sensor: a sensor yaml (default config/digit.yaml).
      friction: Coulomb coefficient (None: the material's).
      noise: image noise on (drawn per episode from its seed) or off. The sensor adds noise on
        a synthetic background (or with noise.on_real_background); the default sensor's
        captured background already carries the real DIGIT's noise and gets none on top.
      action: "discrete" (Discrete(3): 0 close by 0.005, 1 stay, 2 open by 0.005), "delta" (Box
        [-max_delta, max_delta]) or "absolute" (Box [0, 1]): the normalised opening command.
      image: "raw" (uint8 bgr8), "diff_int16" (minus the no-contact frame, int16) or
        "diff_float" (the same / 255, float32).
      downscale: integer factor, images averaged over factor x factor pixels.
      depth: also "depth_left"/"depth_right" (float32 metres, gel deformation).
      force: also "force": normal force of each gel (2,) float32, N.
      markers: also "markers_left"/"markers_right": every marker's displacement on the gel
        (markers, 2) float32, mm (gel frame x, y), carried by the gel's lateral motion under the
        physics' tangential force and twist; needs a sensor with a marker grid (its yaml's
        markers:; over ROS, the launch's sensor:=).
      frames_per_step: sensor frames per step.
      max_episode_steps: truncation (None: never).
      backend: "inprocess" or "ros" (num_envs 1; ros_options are RosBackend's arguments).
      threads: C++ threads (0: the machine's CPUs).
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(
        self,
        num_envs=1,
        material="wood",
        variant=0,
        beta_mm=None,
        scene="cube",
        sensor=None,
        friction=None,
        noise=True,
        action="discrete",
        max_delta=0.05,
        image="raw",
        downscale=1,
        depth=False,
        force=True,
        markers=False,
        frames_per_step=1,
        max_episode_steps=None,
        backend="inprocess",
        ros_options=None,
        threads=0,
        render_mode=None,
    ):
        if num_envs < 1:
            raise ValueError("num_envs = %r; valid: >= 1" % num_envs)
        if action not in ACTIONS:
            raise ValueError("action = %r; valid: %s" % (action, ", ".join(ACTIONS)))
        if image not in IMAGE_MODES:
            raise ValueError("image = %r; valid: %s" % (image, ", ".join(IMAGE_MODES)))
        if int(downscale) != downscale or downscale < 1:
            raise ValueError("downscale = %r; valid: an integer >= 1" % downscale)
        if frames_per_step < 1:
            raise ValueError("frames_per_step = %r; valid: >= 1" % frames_per_step)
        self.num_envs = int(num_envs)
        self.action_kind = action
        self.max_delta = float(max_delta)
        self.image_mode = image
        self.downscale = int(downscale)
        self.with_depth = bool(depth)
        self.with_force = bool(force)
        self.with_markers = bool(markers)
        self.frames_per_step = int(frames_per_step)
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        self.noise = bool(noise)

        variants = variant
        if backend == "inprocess":
            first = variants if isinstance(variants, (int, np.integer)) else 0
            self.backend = InProcessBackend(
                count=self.num_envs,
                scene=scene,
                sensor=sensor,
                material=material,
                variant=first,
                beta_mm=beta_mm,
                friction=friction,
                noise_seed=0 if noise else None,
                noise_per_episode=True,
                threads=threads,
            )
        elif backend == "ros":
            if isinstance(material, (list, tuple)):
                raise ValueError("backend 'ros' runs one material: give a name, not a list")
            if self.num_envs != 1:
                raise ValueError("backend 'ros' drives one running gripper: num_envs must be 1")
            from norm2tex.envs.ros_backend import RosBackend

            self.backend = RosBackend(**dict(ros_options or {}, markers=self.with_markers))
            self._check_ros_system(scene, sensor, material, beta_mm, friction)
        else:
            raise ValueError("backend = %r; valid: inprocess, ros" % backend)
        if variants is None:
            variants = range(self.backend.variant_count)
        self.variants = (
            [int(variants)] if isinstance(variants, (int, np.integer)) else [int(v) for v in variants]
        )
        if not self.variants or min(self.variants) < 0:
            raise ValueError("variant(s) %r; valid: ints >= 0" % (variant,))
        self._episodes = [_Episode() for _ in range(self.num_envs)]
        # Per environment: its material's name (None: no texture), friction and texture depth.
        materials = (list(material) if isinstance(material, (list, tuple))
                     else [material] * self.num_envs)
        self.materials = [os.path.splitext(os.path.basename(m))[0] if m else None
                          for m in materials]
        n = self.num_envs
        self.frictions = [float(f) for f in getattr(self.backend, "frictions",
                                                    [self.backend.friction] * n)]
        self.betas_mm = [float(b) for b in getattr(self.backend, "betas_mm",
                                                   [self.backend.beta_mm] * n)]
        self._backgrounds = {f: self.backend.background(f) for f in FINGERS}

        self.single_observation_space = self._single_observation_space()
        self.single_action_space = self._single_action_space()
        # The batch's spaces: every entry with a first axis of N (actions: one per environment).
        self.observation_space = spaces.Dict(
            {k: self._batched(v) for k, v in self.single_observation_space.spaces.items()}
        )
        self.action_space = self._batched(self.single_action_space)

    def _check_ros_system(self, scene, sensor, material, beta_mm, friction):
        """The running system decides the scene, sensor and material: refuse an environment
        that asks for others (it would silently be another task)."""
        def same(a, b):
            return os.path.realpath(a) == os.path.realpath(b)

        b = self.backend
        wrong = []
        if b.scene and not same(norm2tex.scene_config(scene), b.scene):
            wrong.append("scene %s (the system's: %s; launch with scene:=%s)"
                         % (scene, b.scene, norm2tex.scene_config(scene)))
        if b.mesh:
            wrong.append("the system simulates its own mesh %s" % b.mesh)
        if sensor and b.sensor and not same(sensor, b.sensor):
            wrong.append("sensor %s (the system's: %s)" % (sensor, b.sensor))
        if (material or "none") != b.material:
            wrong.append("material %s (the system's: %s; launch with material:=%s)"
                         % (material, b.material, material or "none"))
        if beta_mm is not None and abs(beta_mm - b.beta_mm) > 1e-12:
            wrong.append("beta_mm %g (the system's: %g)" % (beta_mm, b.beta_mm))
        if friction is not None and abs(friction - b.friction) > 1e-12:
            wrong.append("friction %g (the system's: %g)" % (friction, b.friction))
        if wrong:
            self.backend.close()
            raise ValueError("backend 'ros': the running gripper_sim.launch differs from this "
                             "environment: " + "; ".join(wrong))

    # --- spaces -----------------------------------------------------------------------------
    def _image_shape(self):
        rows, cols = self._backgrounds["left"].shape[:2]
        return (rows // self.downscale, cols // self.downscale, 3)

    def _single_observation_space(self):
        shape = self._image_shape()
        if self.image_mode == "raw":
            image = spaces.Box(0, 255, shape=shape, dtype=np.uint8)
        elif self.image_mode == "diff_int16":
            image = spaces.Box(-255, 255, shape=shape, dtype=np.int16)
        else:
            image = spaces.Box(-1.0, 1.0, shape=shape, dtype=np.float32)
        entries = [
            ("opening", spaces.Box(0.0, 1.0, shape=(1,), dtype=np.float32)),
            ("digit_left", image),
            ("digit_right", spaces.Box(image.low, image.high, shape=shape, dtype=image.dtype)),
        ]
        if self.with_depth:
            depth = (shape[0], shape[1])
            for f in FINGERS:
                entries.append(("depth_" + f, spaces.Box(0.0, 0.01, shape=depth, dtype=np.float32)))
        if self.with_force:
            entries.append(("force", spaces.Box(0.0, np.inf, shape=(2,), dtype=np.float32)))
        if self.with_markers:
            count = self.backend.marker_count
            if count == 0:
                raise ValueError("markers=True needs a sensor with a marker grid (its yaml's "
                                 "markers: enabled: true), e.g. config/gelsight_mini.yaml")
            for f in FINGERS:
                entries.append(("markers_" + f, spaces.Box(-np.inf, np.inf, shape=(count, 2),
                                                           dtype=np.float32)))
        return spaces.Dict(dict(entries))

    def _batched(self, space):
        n = self.num_envs
        if isinstance(space, spaces.Discrete):
            return spaces.Box(0, space.n - 1, shape=(n,), dtype=np.int64)
        return spaces.Box(
            np.broadcast_to(space.low, (n,) + space.shape),
            np.broadcast_to(space.high, (n,) + space.shape),
            shape=(n,) + space.shape,
            dtype=space.dtype,
        )

    def _single_action_space(self):
        if self.action_kind == "discrete":
            return spaces.Discrete(3)
        if self.action_kind == "delta":
            return spaces.Box(-self.max_delta, self.max_delta, shape=(1,), dtype=np.float32)
        return spaces.Box(0.0, 1.0, shape=(1,), dtype=np.float32)

    # --- observations -----------------------------------------------------------------------
    def _image_obs(self, finger):
        images = self.backend.images(finger)
        if self.image_mode == "raw":
            if self.downscale == 1:
                return images
            return np.rint(block_mean(images, self.downscale)).astype(np.uint8)
        if self.downscale == 1:
            out = images.astype(np.int16) - self._backgrounds[finger].astype(np.int16)[None]
        else:
            # The core's block mean: numpy's reshape-mean, bit for bit, at a twentieth of the
            # cost (it was most of a training step's time).
            out = block_mean(images, self.downscale, self._backgrounds[finger])
        if self.image_mode == "diff_int16":
            return np.rint(out).astype(np.int16) if out.dtype != np.int16 else out
        return (out / 255.0).astype(np.float32)

    def _observe(self, state):
        obs = {
            "opening": state["commanded_opening"].astype(np.float32).reshape(-1, 1),
            "digit_left": self._image_obs("left"),
            "digit_right": self._image_obs("right"),
        }
        if self.with_depth:
            for f in FINGERS:
                depths = self.backend.depths(f)  # (N, rows, cols): no channel axis
                obs["depth_" + f] = np.clip(
                    block_mean(depths, self.downscale, axes=(-2, -1)), 0.0, 0.01
                ).astype(np.float32)
        if self.with_force:
            obs["force"] = state["normal_force_n"].astype(np.float32)
        if self.with_markers:
            for f in FINGERS:
                obs["markers_" + f] = self.backend.markers(f)
        return obs

    @staticmethod
    def _row(obs, i):
        return {k: v[i] for k, v in obs.items()}

    # --- the task: GripperEnv has none (reward 0, the episode ends when the object drops) ---
    def _reward(self, state, i):
        return 0.0

    def _terminated(self, state, i):
        """Whether environment i's episode ends at this step: the object dropped."""
        return bool(state["dropped"][i])

    def _after_reset(self, i, rng):
        """Called after the simulator's reset of environment i: returns (mode, value, frames),
        a command environment i alone is stepped with before its first observation, or None."""
        return None

    # --- the API ----------------------------------------------------------------------------
    def _start(self, i, seed=None, options=None):
        episode = self._episodes[i]
        if seed is not None:
            episode.rng = np.random.default_rng(seed)
            episode.next_variant = None
        rng = episode.rng
        options = options or {}
        sim_seed = int(rng.integers(0, 2**31 - 1))
        # The variant was drawn one episode ahead (so that it could be prepared meanwhile).
        drawn = episode.next_variant
        if drawn is None:
            drawn = self.variants[int(rng.integers(len(self.variants)))]
        variant = options.get("variant", drawn)
        episode.next_variant = self.variants[int(rng.integers(len(self.variants)))]
        noise_seed = int(rng.integers(0, 2**31 - 1)) if self.noise else None
        height = options.get("height_offset_m")
        if getattr(self.backend, "noise_per_episode", False):
            self.backend.set_noise_seed(i, noise_seed)
        next_variant = episode.next_variant if len(self.variants) > 1 else None
        start = self.backend.reset(i, sim_seed, height, variant, next_variant)
        command = self._after_reset(i, rng)
        episode.steps = 0
        episode.info = {
            "material": self.materials[i],
            "friction": self.frictions[i],
            "beta_mm": self.betas_mm[i],
            "start_opening": float(command[1]) if command else float("nan"),
            "episode": int(start["episode"]),
            "seed": sim_seed,
            "variant": int(variant),
            "height_offset_m": float(start["height_offset_m"]),
            "grasp_opening": float(start["grasp_opening"]),
        }
        return command

    def _reset_indices(self, indices, seeds, options):
        for i, seed in zip(indices, seeds):
            command = self._start(i, seed, options)
            if command is not None:
                mode, value, frames = command
                self.backend.step_one(i, mode, value, frames)

    def reset(self, seed=None, options=None):
        """Starts an episode in every environment. seed: environment i gets seed + i (None:
        continue each one's random stream). options: {"height_offset_m": m, "variant": k}."""
        seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        if seed is not None:
            self.np_random = np.random.default_rng(seed)
        self._reset_indices(range(self.num_envs), seeds, options)
        state = self.backend.state()
        obs = self._observe(state)
        infos = [self._info(state, i) for i in range(self.num_envs)]
        return obs, infos

    def _info(self, state, i):
        info = dict(self._episodes[i].info)
        info.update(
            {
                "dropped": bool(state["dropped"][i]),
                "finger_opening": float(state["opening"][i]),
                "normal_force_n": state["normal_force_n"][i].copy(),
                "penetration_m": state["penetration_m"][i].copy(),
                "frame": int(state["frame"][i]),
                "steps": self._episodes[i].steps,
            }
        )
        return info

    def _commands(self, actions):
        modes, values = [], []
        for a in actions:
            if self.action_kind == "discrete":
                a = int(np.asarray(a).reshape(()))
                if a not in (CLOSE, STAY, OPEN):
                    raise ValueError("action %r; valid: %d (CLOSE), %d (STAY), %d (OPEN)"
                                     % (a, CLOSE, STAY, OPEN))
                # The paper's step: close or open by DISCRETE_DELTA, or leave the command.
                modes.append(KEEP if a == STAY else DELTA)
                values.append({CLOSE: -DISCRETE_DELTA, STAY: 0.0, OPEN: DISCRETE_DELTA}[a])
            else:
                v = float(np.asarray(a, dtype=np.float64).reshape(-1)[0])
                if not math.isfinite(v):
                    raise ValueError("action %r is not finite" % (a,))
                if self.action_kind == "delta":
                    modes.append(DELTA)
                    values.append(min(max(v, -self.max_delta), self.max_delta))
                else:
                    modes.append(ABSOLUTE)
                    values.append(min(max(v, 0.0), 1.0))
        return modes, values

    def step(self, actions):
        """One command per environment, frames_per_step frames, both images."""
        if len(actions) != self.num_envs:
            raise ValueError("%d actions for %d environments" % (len(actions), self.num_envs))
        modes, values = self._commands(actions)
        self.backend.step(modes, values, self.frames_per_step)
        state = self.backend.state()
        rewards = np.zeros(self.num_envs, dtype=np.float64)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        for i in range(self.num_envs):
            self._episodes[i].steps += 1
            terminated[i] = self._terminated(state, i)
            rewards[i] = 0.0 if terminated[i] else self._reward(state, i)
            truncated[i] = (
                not terminated[i]
                and self.max_episode_steps is not None
                and self._episodes[i].steps >= self.max_episode_steps
            )
        obs = self._observe(state)
        infos = [self._info(state, i) for i in range(self.num_envs)]
        done = [i for i in range(self.num_envs) if terminated[i] or truncated[i]]
        if done and self.num_envs > 1:
            # Copies: the rows of obs are overwritten with the new episodes' below.
            finals = {i: ({k: v[i].copy() for k, v in obs.items()}, infos[i]) for i in done}
            self._reset_indices(done, [None] * len(done), None)
            state = self.backend.state()
            fresh = self._observe(state)
            for i in done:
                for k in obs:
                    obs[k][i] = fresh[k][i]
                infos[i] = self._info(state, i)
                infos[i]["final_observation"], infos[i]["final_info"] = finals[i]
        return obs, rewards, terminated, truncated, infos

    def render(self):
        """Both DIGIT images side by side (rgb, uint8) of environment 0."""
        left = self.backend.images("left")[0][..., ::-1]
        right = self.backend.images("right")[0][..., ::-1]
        return np.concatenate([left, right], axis=1)

    def close(self):
        if getattr(self, "backend", None) is not None:
            self.backend.close()
            self.backend = None


class GripperEnv(spaces.EnvBase):
    """The simulated gripper with both DIGITs, one environment (see GripperVectorEnv for every
    parameter; here without num_envs). Observation: a dict of "opening" (the normalised
    opening command, (1,) float32), "digit_left" and "digit_right" (images), optionally depth,
    and "force". Reward 0; terminated when the object drops out of the gripper."""

    metadata = GripperVectorEnv.metadata
    _vector_class = GripperVectorEnv

    def __init__(self, **kwargs):
        self._vector = self._vector_class(num_envs=1, **kwargs)
        self.observation_space = self._vector.single_observation_space
        self.action_space = self._vector.single_action_space
        self.render_mode = self._vector.render_mode

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.np_random = np.random.default_rng(seed)
        obs, infos = self._vector.reset(seed=seed, options=options)
        return GripperVectorEnv._row(obs, 0), infos[0]

    def step(self, action):
        obs, rewards, terminated, truncated, infos = self._vector.step([action])
        return (
            GripperVectorEnv._row(obs, 0),
            float(rewards[0]),
            bool(terminated[0]),
            bool(truncated[0]),
            infos[0],
        )

    def render(self):
        return self._vector.render()

    def close(self):
        self._vector.close()

    @property
    def backend(self):
        return self._vector.backend
