"""HandEnv: any hand from its URDF with a DIGIT on any of its links (a hand yaml, docs/hands.md),
under the Gymnasium API (reset(seed, options) -> (obs, info); step(action) -> (obs, reward,
terminated, truncated, info)).

One step = one joint command, then `frames_per_step` sensor frames (1/60 s each by default) of
physics, then every DIGIT's image at the last frame. In-process only for now
(norm2tex._core.TactileHand); the ROS backend (hand_sim.launch) is to come.
"""

import math
import os

import numpy as np

import norm2tex
from norm2tex.envs import spaces

ACTIONS = ("position", "delta")
JOINTS_KEY = "joint_positions"


def _pose(value, what):
    """A 4x4 pose from [x, y, z], [x, y, z, roll, pitch, yaw] (m, rad; URDF's rpy) or a 4x4."""
    a = np.asarray(value, dtype=np.float64)
    if a.shape == (4, 4):
        return a
    if a.shape in ((3,), (6,)) and np.all(np.isfinite(a)):
        roll, pitch, yaw = a[3:] if a.shape == (6,) else (0.0, 0.0, 0.0)
        cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                                  math.sin(pitch), math.cos(yaw), math.sin(yaw))
        out = np.eye(4)
        # R = Rz(yaw) Ry(pitch) Rx(roll), as poseFromXyzRpy.
        out[:3, :3] = [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
        out[:3, 3] = a[:3]
        return out
    raise ValueError("%s = %r; valid: [x, y, z], [x, y, z, roll, pitch, yaw] (finite, m and rad) "
                     "or a 4x4 matrix" % (what, value))


class HandEnv(spaces.EnvBase):
    """A hand with its DIGITs and an object, one environment.

    Observation: a dict with one image per sensor, keyed by the sensor's name in the hand yaml
    ((rows, cols, 3) uint8 bgr8), and "joint_positions": the actuated joints' positions
    ((n,) float32, rad or m, in the order of `actuated_joints`).

    Action: one value per actuated joint (float32, the order of `actuated_joints`):
      "position": the joints' targets, a Box over their URDF limits (a continuous joint's:
        [-pi, pi]);
      "delta": added to the joints' current positions, a Box of [-max_delta, max_delta] per
        joint (max_delta: a number, one per joint, or None: a tenth of each joint's range).
    Values outside the Box are clipped (info["clipped"] names the joints); an action of another
    shape, or with a value that is not a finite number, raises ValueError and moves nothing.

    Reward: 0, or reward(obs, info) when a callable is given. Never terminated; truncated after
    max_steps steps (None: never).

    Parameters:
      hand: a hand yaml (docs/hands.md) or a norm2tex.HandConfig.
      object: a mesh file or a primitive ("box:30x30x30", "sphere:10", mm); None: the scene's,
        or a 30 mm cube.
      scale: mesh file units to metres.
      object_pose: where reset() puts the object at rest: [x, y, z], [x, y, z, roll, pitch,
        yaw] (m, rad) or a 4x4 (reset's options["object_pose"] overrides it for one episode).
      scene: a config/scenes name or path whose object, physics and gel law to use (None: the
        defaults).
      sensor: a sensor yaml (default config/digit.yaml; a sensor's own in the hand yaml wins).
      material: config/materials name or path (texture and friction); None: no texture.
      variant, beta_mm, friction: the material's variant, texture depth (mm; None: the
        material's) and Coulomb friction (None: the material's).
      noise: image noise on (its seed drawn from reset's seed) or off. The default sensor's
        captured background carries the real DIGIT's noise and gets none on top.
      frames_per_step: sensor frames per step.
      max_steps: truncation (None: never).
      backend: "inprocess" (the only one for now).
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(
        self,
        hand,
        object=None,
        scale=1.0,
        object_pose=(0.0, 0.0, 0.1),
        scene=None,
        sensor=None,
        material="wood",
        variant=0,
        beta_mm=None,
        friction=None,
        noise=True,
        action="position",
        max_delta=None,
        frames_per_step=1,
        max_steps=None,
        reward=None,
        backend="inprocess",
        render_mode=None,
    ):
        if action not in ACTIONS:
            raise ValueError("action = %r; valid: %s" % (action, ", ".join(ACTIONS)))
        if int(frames_per_step) != frames_per_step or frames_per_step < 1:
            raise ValueError("frames_per_step = %r; valid: an integer >= 1" % (frames_per_step,))
        if max_steps is not None and (int(max_steps) != max_steps or max_steps < 1):
            raise ValueError("max_steps = %r; valid: an integer >= 1, or None" % (max_steps,))
        if reward is not None and not callable(reward):
            raise ValueError("reward = %r; valid: None or a callable reward(obs, info)" % (reward,))
        if backend != "inprocess":
            raise ValueError("backend = %r; valid: inprocess (HandEnv has no ROS backend yet)"
                             % (backend,))
        self.action_kind = action
        self.frames_per_step = int(frames_per_step)
        self.max_steps = None if max_steps is None else int(max_steps)
        self.reward_fn = reward
        self.render_mode = render_mode
        self.noise = bool(noise)
        self.object_pose = _pose(object_pose, "object_pose")

        if scene is not None:
            config = norm2tex.HandSimConfig(hand, norm2tex.SceneConfig.load(norm2tex.scene_config(scene)))
        else:
            config = norm2tex.HandSimConfig(hand)
        if object is not None:
            config.object.mesh = str(object)
            config.object.scale = float(scale)
            config.object.name = os.path.splitext(os.path.basename(str(object)))[0]
        config.object_pose = self.object_pose
        options = norm2tex.TactileHandOptions()
        options.material_config = norm2tex.material_config(material) if material else ""
        options.variant = int(variant)
        options.beta_mm = -1.0 if beta_mm is None else float(beta_mm)
        options.friction = -1.0 if friction is None else float(friction)
        options.noise_seed = 0 if self.noise else -1
        options.noise_per_episode = True
        sensor_model = norm2tex.SensorModel.load(sensor or norm2tex.config_path("digit.yaml"))
        self.hand = norm2tex.TactileHand(config, sensor_model, options)
        self.material = os.path.splitext(os.path.basename(material))[0] if material else None

        sim = self.hand.sim
        self.sensor_names = list(self.hand.sensor_names)
        if JOINTS_KEY in self.sensor_names:
            raise ValueError("a sensor is named %r, the observation's key for the joints; rename "
                             "it in the hand yaml" % JOINTS_KEY)
        self.actuated_joints = list(sim.actuated_joints)
        if not self.actuated_joints:
            raise ValueError("the hand has no actuated joint to command")
        lower, upper = sim.joint_limits()
        continuous = ~np.isfinite(lower) | ~np.isfinite(upper)
        self.joint_lower = np.where(continuous, -math.pi, lower)
        self.joint_upper = np.where(continuous, math.pi, upper)
        n = len(self.actuated_joints)
        if action == "delta":
            if max_delta is None:
                max_delta = 0.1 * (self.joint_upper - self.joint_lower)
            max_delta = np.broadcast_to(np.asarray(max_delta, dtype=np.float64), (n,)).copy()
            if not np.all(np.isfinite(max_delta)) or np.any(max_delta <= 0):
                raise ValueError("max_delta = %r; valid: > 0, one number or one per joint (%d)"
                                 % (max_delta, n))
            self.max_delta = max_delta
            self.action_space = spaces.Box(-max_delta.astype(np.float32), max_delta.astype(np.float32),
                                           shape=(n,), dtype=np.float32)
        else:
            self.max_delta = None
            self.action_space = spaces.Box(self.joint_lower.astype(np.float32),
                                           self.joint_upper.astype(np.float32), shape=(n,),
                                           dtype=np.float32)
        entries = [(name, spaces.Box(0, 255, shape=self.hand.background(name).shape, dtype=np.uint8))
                   for name in self.sensor_names]
        # Joint positions stay within the URDF limits (the drives clamp); a float32's rounding
        # is allowed for.
        entries.append((JOINTS_KEY, spaces.Box((self.joint_lower - 1e-6).astype(np.float32),
                                               (self.joint_upper + 1e-6).astype(np.float32),
                                               shape=(n,), dtype=np.float32)))
        self.observation_space = spaces.Dict(dict(entries))
        self._rng = np.random.default_rng()
        self._steps = 0
        self._episode_info = {}

    # --- observations -----------------------------------------------------------------------
    def _observe(self):
        obs = {name: self.hand.frame(i) for i, name in enumerate(self.sensor_names)}
        obs[JOINTS_KEY] = self.hand.sim.joint_positions(self.actuated_joints).astype(np.float32)
        return obs

    def _info(self, clipped=()):
        sim = self.hand.sim
        info = dict(self._episode_info)
        info.update(
            {
                "contacts": {name: sim.contact(i) for i, name in enumerate(self.sensor_names)},
                "object_in_world": sim.object_in_world(),
                "joint_targets": sim.joint_targets(self.actuated_joints),
                "clipped": list(clipped),
                "frame": int(self.hand.frame_index),
                "steps": self._steps,
            }
        )
        return info

    # --- the API ----------------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Puts the hand at its initial joint positions and the object at rest at object_pose
        (options: {"object_pose": pose} for this episode). seed: the episode's noise seed is
        drawn from it (None: continue the random stream)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
            self.np_random = np.random.default_rng(seed)
        options = options or {}
        unknown = set(options) - {"object_pose"}
        if unknown:
            raise ValueError("reset options %s; valid: object_pose" % sorted(unknown))
        pose = _pose(options["object_pose"], "object_pose") if "object_pose" in options else self.object_pose
        noise_seed = int(self._rng.integers(0, 2**31 - 1)) if self.noise else -1
        self.hand.set_noise_seed(noise_seed)
        self.hand.reset(pose)
        self._steps = 0
        self._episode_info = {"material": self.material, "noise_seed": noise_seed,
                              "friction": float(self.hand.friction),
                              "beta_mm": float(self.hand.beta_mm)}
        return self._observe(), self._info()

    def _targets(self, action):
        try:
            a = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError("action %r is not numbers; valid: %d values, one per joint of %s"
                             % (action, len(self.actuated_joints), self.actuated_joints)) from None
        n = len(self.actuated_joints)
        if a.shape != (n,):
            raise ValueError("action of shape %s; valid: (%d,), one value per joint of %s"
                             % (a.shape, n, self.actuated_joints))
        bad = [j for j, v in zip(self.actuated_joints, a) if not math.isfinite(v)]
        if bad:
            raise ValueError("action for %s is not finite" % ", ".join(bad))
        low = self.action_space.low.astype(np.float64)
        high = self.action_space.high.astype(np.float64)
        clipped = [j for j, v, lo, hi in zip(self.actuated_joints, a, low, high) if v < lo or v > hi]
        a = np.clip(a, low, high)
        if self.action_kind == "delta":
            a = np.clip(self.hand.sim.joint_positions(self.actuated_joints) + a,
                        self.joint_lower, self.joint_upper)
        return a, clipped

    def step(self, action):
        """Sets the joints' targets from the action, advances frames_per_step frames, renders
        every sensor."""
        targets, clipped = self._targets(action)
        self.hand.sim.set_joint_targets(self.actuated_joints, targets)
        self.hand.step(self.frames_per_step)
        self._steps += 1
        obs = self._observe()
        info = self._info(clipped)
        reward = 0.0 if self.reward_fn is None else float(self.reward_fn(obs, info))
        truncated = self.max_steps is not None and self._steps >= self.max_steps
        return obs, reward, False, bool(truncated), info

    def render(self):
        """Every DIGIT's image side by side (rgb, uint8)."""
        return np.concatenate([self.hand.frame(i)[..., ::-1] for i in range(len(self.sensor_names))],
                              axis=1)

    def close(self):
        self.hand = None
