"""HandEnv: any hand from its URDF with a DIGIT on any of its links (a hand yaml, docs/hands.md),
under the Gymnasium API (reset(seed, options) -> (obs, info); step(action) -> (obs, reward,
terminated, truncated, info)).

One step = one joint command, then `frames_per_step` sensor frames (1/60 s each by default) of
physics, then every DIGIT's image at the last frame. The same environment runs in this process
(backend="inprocess": norm2tex._core.TactileHand) or over a running ROS system (backend="ros":
hand_sim.launch mode:=synchronous, see hand_ros_backend.py).
"""

import math
import os

import numpy as np

import norm2tex
from norm2tex.envs import spaces
from norm2tex.envs.hand_inprocess_backend import HandInProcessBackend
from norm2tex.envs.ros_client import frame_seconds

ACTIONS = ("position", "delta")
JOINTS_KEY = "joint_positions"


def _quaternion(r):
    """The unit quaternion (x, y, z, w) of a rotation matrix."""
    t = np.trace(r)
    if t > 0:
        s = 2.0 * math.sqrt(t + 1.0)
        q = ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4)
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = (s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s)
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = ((r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = ((r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4, (r[1, 0] - r[0, 1]) / s)
    q = np.array(q)
    return q / np.linalg.norm(q)


def _pose(value, what):
    """(xyz, quaternion xyzw) from [x, y, z], [x, y, z, roll, pitch, yaw] (m, rad; URDF's rpy) or
    a 4x4 rigid transform. Both backends are given this quaternion (hand_sim in a
    geometry_msgs/Pose) and make the same rotation matrix of it: the same episodes."""
    a = np.asarray(value, dtype=np.float64)
    if a.shape in ((3,), (6,)) and np.all(np.isfinite(a)):
        roll, pitch, yaw = a[3:] / 2 if a.shape == (6,) else (0.0, 0.0, 0.0)
        cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                                  math.sin(pitch), math.cos(yaw), math.sin(yaw))
        # q = qz(yaw) qy(pitch) qx(roll), as URDF's rpy.
        return a[:3].copy(), np.array([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                                       cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy])
    if a.shape == (4, 4) and np.all(np.isfinite(a)):
        r = a[:3, :3]
        if (np.array_equal(a[3], [0.0, 0.0, 0.0, 1.0])
                and np.allclose(r.T @ r, np.eye(3), rtol=0, atol=1e-6) and np.linalg.det(r) > 0):
            return a[:3, 3].copy(), _quaternion(r)
    raise ValueError("%s = %r; valid: [x, y, z], [x, y, z, roll, pitch, yaw] (finite, m and rad) "
                     "or a 4x4 rigid transform" % (what, value))


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
      hand: a hand yaml (docs/hands.md) or a norm2tex.HandConfig (in-process).
      object: a mesh file or a primitive ("box:30x30x30", "sphere:10", mm); None: the scene's,
        or a 30 mm cube.
      scale: mesh file units to metres.
      object_pose: where reset() puts the object at rest: [x, y, z], [x, y, z, roll, pitch,
        yaw] (m, rad) or a 4x4 (reset's options["object_pose"] overrides it for one episode).
      scene: a config/scenes name or path whose object, physics and gel law to use (None: the
        defaults, config/scenes/cube.yaml's).
      sensor: a sensor yaml (default config/digit.yaml; a sensor's own in the hand yaml wins).
      material: config/materials name or path (texture and friction); None: no texture.
      variant, beta_mm, friction: the material's variant, texture depth (mm; None: the
        material's) and Coulomb friction (None: the material's).
      noise: image noise on (its seed drawn from reset's seed) or off. The default sensor's
        captured background carries the real DIGIT's noise and gets none on top.
      markers: also "<sensor>_markers" for every sensor: its markers' displacement on the gel,
        (markers, 2) float32 mm (gel frame); needs sensors with a marker grid (over ROS, the
        launch's).
      frames_per_step: sensor frames per step.
      max_steps: truncation (None: never).
      backend: "inprocess", or "ros": a running hand_sim.launch mode:=synchronous
        (hand_ros_backend.py; ros_options are HandRosBackend's arguments). The system must run
        this environment's hand, object, sensor, material and rates (else ValueError naming
        what differs and the launch argument that sets it); every reset puts the object at
        object_pose; its image noise is the launch's (noise_seed:=), which must be off for
        noise=False.
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
        markers=False,
        frames_per_step=1,
        max_steps=None,
        reward=None,
        backend="inprocess",
        ros_options=None,
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
        if backend not in ("inprocess", "ros"):
            raise ValueError("backend = %r; valid: inprocess, ros" % (backend,))
        self.with_markers = bool(markers)
        self.action_kind = action
        self.frames_per_step = int(frames_per_step)
        self.max_steps = None if max_steps is None else int(max_steps)
        self.reward_fn = reward
        self.render_mode = render_mode
        self.noise = bool(noise)
        self.object_pose = _pose(object_pose, "object_pose")

        if backend == "inprocess":
            self.backend = HandInProcessBackend(
                hand, object, scale, self.object_pose, scene, sensor, material, variant, beta_mm,
                friction, noise_seed=0 if self.noise else None)
        else:
            from norm2tex.envs.hand_ros_backend import HandRosBackend

            self.backend = HandRosBackend(**dict(ros_options or {}, markers=bool(markers)))
            self._check_ros_system(hand, object, scale, scene, sensor, material, variant,
                                   beta_mm, friction)
        b = self.backend
        self.material = b.material
        self.sensor_names = list(b.sensor_names)
        if JOINTS_KEY in self.sensor_names:
            raise ValueError("a sensor is named %r, the observation's key for the joints; rename "
                             "it in the hand yaml" % JOINTS_KEY)
        self.actuated_joints = list(b.actuated_joints)
        if not self.actuated_joints:
            raise ValueError("the hand has no actuated joint to command")
        lower, upper = np.asarray(b.joint_lower), np.asarray(b.joint_upper)
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
        entries = [(name, spaces.Box(0, 255, shape=b.background(name).shape, dtype=np.uint8))
                   for name in self.sensor_names]
        # Joint positions stay within the URDF limits (the drives clamp); a float32's rounding
        # is allowed for.
        entries.append((JOINTS_KEY, spaces.Box((self.joint_lower - 1e-6).astype(np.float32),
                                               (self.joint_upper + 1e-6).astype(np.float32),
                                               shape=(n,), dtype=np.float32)))
        if self.with_markers:
            for name in self.sensor_names:
                count = b.marker_counts[name]
                if count == 0:
                    b.close()
                    raise ValueError("markers=True: sensor %s has no marker grid (its yaml's "
                                     "markers: enabled: true)" % name)
                entries.append((name + "_markers", spaces.Box(-np.inf, np.inf, shape=(count, 2),
                                                              dtype=np.float32)))
        self.observation_space = spaces.Dict(dict(entries))
        self._rng = np.random.default_rng()
        self._steps = 0
        self._episode_info = {}
        self._state = None

    def _check_ros_system(self, hand, object, scale, scene, sensor, material, variant, beta_mm,
                          friction):
        """The running system decides the hand, the object, the sensor, the material, the noise
        and the rates: refuse an environment that asks for others (it would silently be another
        task)."""
        def same(a, b):
            return os.path.realpath(a) == os.path.realpath(b)

        b = self.backend
        wrong = []
        if not isinstance(hand, (str, os.PathLike)) or not same(hand, b.hand):
            wrong.append("hand %s (the system's: %s; launch with hand:=, the yaml's path)"
                         % (hand, b.hand))
        scene_path = norm2tex.scene_config(scene or "cube")
        if not same(scene_path, b.scene):
            wrong.append("scene %s (the system's: %s; launch with scene:=%s)"
                         % (scene, b.scene, scene_path))
        if (object or b.mesh) and not (object and b.mesh and same(str(object), b.mesh)
                                       and float(scale) == b.scale):
            wrong.append("object %s scale %g (the system's: %s scale %g; launch with mesh:=%s "
                         "scale:=%g)" % (object or "of the scene", scale, b.mesh or "the scene's",
                                         b.scale, object or "''", scale))
        sensor_path = sensor or norm2tex.config_path("digit.yaml")
        if not same(sensor_path, b.sensor):
            wrong.append("sensor %s (the system's: %s; launch with sensor:=%s)"
                         % (sensor_path, b.sensor, sensor_path))
        if (material is None) != (b.material is None) or (
                material and not same(norm2tex.material_config(material),
                                      norm2tex.material_config(b.material))):
            wrong.append("material %s (the system's: %s; launch with material:=%s)"
                         % (material, b.material, material or "none"))
        if material and int(variant) != b.variant:
            wrong.append("variant %d (the system's renderers draw %d)" % (variant, b.variant))
        if beta_mm is not None and abs(beta_mm - b.beta_mm) > 1e-12:
            wrong.append("beta_mm %g (the system's: %g)" % (beta_mm, b.beta_mm))
        if friction is not None and abs(friction - b.friction) > 1e-12:
            wrong.append("friction %g (the system's: %g; launch with friction:=%g)"
                         % (friction, b.friction, friction))
        if self.noise != (b.noise_seed is not None):
            launched = -1 if b.noise_seed is None else b.noise_seed
            wrong.append("noise %s (the system's renderers: noise_seed %d; launch with "
                         "noise_seed:=%d)" % (self.noise, launched, 0 if self.noise else -1))
        if abs(b.frame_seconds - frame_seconds(60.0, 1000.0)) > 1e-12:
            wrong.append("frames of %g s (the environment's: 1/60 s of 17 physics ticks; launch "
                         "with rate:=60 physics_rate:=1000)" % b.frame_seconds)
        if wrong:
            b.close()
            raise ValueError("backend 'ros': the running hand_sim.launch differs from this "
                             "environment: " + "; ".join(wrong))

    # --- observations -----------------------------------------------------------------------
    def _observe(self):
        images = self.backend.images()
        obs = {name: images[name] for name in self.sensor_names}
        obs[JOINTS_KEY] = self._state["joint_positions"].astype(np.float32)
        if self.with_markers:
            for name, moved in self.backend.markers().items():
                obs[name + "_markers"] = moved
        return obs

    def _info(self, clipped=()):
        info = dict(self._episode_info)
        info.update(
            {
                "contacts": self._state["contacts"],
                "object_in_world": self._state["object_in_world"],
                "joint_targets": self._state["joint_targets"],
                "clipped": list(clipped),
                "frame": self._state["frame"],
                "steps": self._steps,
            }
        )
        return info

    # --- the API ----------------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Puts the hand at its initial joint positions and the object at rest at object_pose
        (options: {"object_pose": pose} for this episode). seed: the episode's noise seed is
        drawn from it (None: continue the random stream; over ROS the noise is the launch's)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
            self.np_random = np.random.default_rng(seed)
        options = options or {}
        unknown = set(options) - {"object_pose"}
        if unknown:
            raise ValueError("reset options %s; valid: object_pose" % sorted(unknown))
        pose = _pose(options["object_pose"], "object_pose") if "object_pose" in options else self.object_pose
        noise_seed = int(self._rng.integers(0, 2**31 - 1)) if self.noise else None
        if self.backend.noise_per_episode:
            self.backend.set_noise_seed(noise_seed)
        else:
            noise_seed = self.backend.noise_seed  # the system's
        self.backend.reset(pose)
        self._state = self.backend.state()
        self._steps = 0
        self._episode_info = {"material": self.material,
                              "noise_seed": -1 if noise_seed is None else noise_seed,
                              "friction": float(self.backend.friction),
                              "beta_mm": float(self.backend.beta_mm)}
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
            a = np.clip(self._state["joint_positions"] + a, self.joint_lower, self.joint_upper)
        return a, clipped

    def step(self, action):
        """Sets the joints' targets from the action, advances frames_per_step frames, renders
        every sensor."""
        if self._state is None:
            raise RuntimeError("step() before reset(); call reset() first")
        targets, clipped = self._targets(action)
        self.backend.step(targets, self.frames_per_step)
        self._state = self.backend.state()
        self._steps += 1
        obs = self._observe()
        info = self._info(clipped)
        reward = 0.0 if self.reward_fn is None else float(self.reward_fn(obs, info))
        truncated = self.max_steps is not None and self._steps >= self.max_steps
        return obs, reward, False, bool(truncated), info

    def render(self):
        """Every DIGIT's image side by side (rgb, uint8)."""
        images = self.backend.images()
        return np.concatenate([images[name][..., ::-1] for name in self.sensor_names], axis=1)

    def close(self):
        if getattr(self, "backend", None) is not None:
            self.backend.close()
            self.backend = None
