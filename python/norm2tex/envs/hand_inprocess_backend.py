"""HandEnv's in-process backend: any hand with its DIGITs in this process
(norm2tex._core.TactileHand)."""

import os

import norm2tex


class HandInProcessBackend:
    """What HandEnv needs from a simulator of a hand.

    Every hand backend has this interface (HandRosBackend too):
      sensor_names, actuated_joints
      joint_lower, joint_upper        (the actuated joints' URDF limits; +-inf: continuous)
      frame_seconds, material (its name; None: no texture), friction, beta_mm
      noise_per_episode               (False: the noise is the system's, noise_seed says which)
      set_noise_seed(noise_seed)      # from the next reset on; None: no noise
      reset(object_pose)              # (xyz, quaternion xyzw) of the object in the world
      step(targets, frames=1)         # a target per actuated joint, then `frames` frames
      images() -> {sensor: (rows, cols, 3) uint8 bgr8} of the current frame
      marker_counts                   ({sensor: its markers}; 0: its gel has no marker grid)
      markers() -> {sensor: (markers, 2) float32 mm}   (HandRosBackend: with markers=True)
      background(sensor) -> (rows, cols, 3) uint8 (no contact, no noise)
      state() -> dict(joint_positions, joint_targets: (n,) float64, object_in_world: 4x4,
                      contacts: {sensor: HandSim.contact's dict}, frame: int)
      close()

    Parameters are hand_sim's and tactile_renderer's (same meanings and defaults: HandEnv's
    docstring), so the same choices give the same frames as hand_sim.launch.
    """

    def __init__(self, hand, object=None, scale=1.0, object_pose=None, scene=None, sensor=None,
                 material="wood", variant=0, beta_mm=None, friction=None, noise_seed=0,
                 render_threads=0):
        if scene is not None:
            config = norm2tex.HandSimConfig(
                hand, norm2tex.SceneConfig.load(norm2tex.scene_config(scene)))
        else:
            config = norm2tex.HandSimConfig(hand)
        if object is not None:
            config.object.mesh = str(object)
            config.object.scale = float(scale)
            config.object.name = os.path.splitext(os.path.basename(str(object)))[0]
        if object_pose is not None:
            config.object_pose = object_pose
        options = norm2tex.TactileHandOptions()
        options.material_config = norm2tex.material_config(material) if material else ""
        options.variant = int(variant)
        options.beta_mm = -1.0 if beta_mm is None else float(beta_mm)
        options.friction = -1.0 if friction is None else float(friction)
        options.noise_seed = -1 if noise_seed is None else int(noise_seed)
        options.noise_per_episode = True
        # The sensors render at once, one per core (frames identical to one after another), as
        # hand_sim.launch's renderers, a nodelet each, do.
        options.render_threads = int(render_threads)
        sensor_model = norm2tex.SensorModel.load(sensor or norm2tex.config_path("digit.yaml"))
        self.hand = norm2tex.TactileHand(config, sensor_model, options)
        self.material = os.path.splitext(os.path.basename(material))[0] if material else None
        self.noise_per_episode = True
        sim = self.hand.sim
        self.sensor_names = list(self.hand.sensor_names)
        self.actuated_joints = list(sim.actuated_joints)
        self.joint_lower, self.joint_upper = sim.joint_limits()
        self.frame_seconds = self.hand.frame_seconds
        self.friction = self.hand.friction
        self.beta_mm = self.hand.beta_mm
        self.marker_counts = {name: moved.shape[0] for name, moved in self.hand.markers().items()}

    def set_noise_seed(self, noise_seed):
        self.hand.set_noise_seed(-1 if noise_seed is None else int(noise_seed))

    def reset(self, object_pose):
        self.hand.reset(object_pose)

    def step(self, targets, frames=1):
        self.hand.sim.set_joint_targets(self.actuated_joints, targets)
        self.hand.step(int(frames))

    def images(self):
        return self.hand.images()

    def markers(self):
        """{sensor: (markers, 2) float32 mm}: each marker's displacement on its gel."""
        return self.hand.markers()

    def background(self, sensor):
        return self.hand.background(sensor)

    def state(self):
        sim = self.hand.sim
        return {"joint_positions": sim.joint_positions(self.actuated_joints),
                "joint_targets": sim.joint_targets(self.actuated_joints),
                "object_in_world": sim.object_in_world(),
                "contacts": {name: sim.contact(i) for i, name in enumerate(self.sensor_names)},
                "frame": int(self.hand.frame_index)}

    def close(self):
        self.hand = None
