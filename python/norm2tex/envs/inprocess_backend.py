"""The in-process backend: N simulated grippers with both DIGITs in this process
(norm2tex._core.TactileGripperBatch), stepped on C++ threads with the GIL released."""

import math

import numpy as np

import norm2tex

from norm2tex.envs.commands import ABSOLUTE, DELTA, KEEP  # noqa: F401 (the modes of step)


class InProcessBackend:
    """What an environment needs from a simulator, for `count` grippers.

    Every backend has this interface (RosBackend too, for count 1):
      size, frame_seconds, variant_count
      reset(i, seed, height_offset_m=None, variant=None, next_variant=None)
          -> dict(episode, seed, height_offset_m, grasp_opening); next_variant: the texture
             variant the next episode will use, prepared in the background meanwhile
      set_noise_seed(i, noise_seed)
      step(modes, values, frames=1)      # per gripper: KEEP / ABSOLUTE / DELTA and a value
      step_one(i, mode, value, frames=1)  # gripper i alone (the others stand still)
      images(finger) -> (N, rows, cols, 3) uint8     finger: "left" / "right"
      depths(finger) -> (N, rows, cols) float32 m
      marker_count                      (markers per gel; 0: the sensor has no marker grid)
      markers(finger) -> (N, markers, 2) float32 mm    (RosBackend: with markers=True)
      background(finger) -> (rows, cols, 3) uint8    (no contact, no noise)
      state() -> dict of arrays: opening, commanded_opening (N,), normal_force_n,
                 penetration_m, in_contact (N, 2), dropped (N,), frame (N,)
      height_offset_range -> (low, high) m
      close()

    Parameters are contact_sim's and tactile_renderer's (same names, same defaults), so the same
    choices give the same frames as gripper_sim.launch. `material` may also be a list, one per
    gripper (then friction, beta and texture are each gripper's own: frictions, betas_mm);
    variant_count is then the smallest of the materials'.
    """

    def __init__(
        self,
        count=1,
        scene="cube",
        sensor=None,
        material="wood",
        variant=0,
        beta_mm=None,
        friction=None,
        seed=0,
        noise_seed=0,
        noise_per_episode=True,
        material_seed=0,
        frame_rate_hz=60.0,
        physics_rate_hz=1000.0,
        threads=0,
    ):
        sensor_model = norm2tex.SensorModel.load(sensor or norm2tex.config_path("digit.yaml"))
        scene_config = norm2tex.SceneConfig.load(norm2tex.scene_config(scene))
        options = []
        # One material for all grippers, or a list of one per gripper.
        materials = list(material) if isinstance(material, (list, tuple)) else [material] * count
        if len(materials) != count:
            raise ValueError("%d materials for %d grippers; valid: one, or one per gripper"
                             % (len(materials), count))
        paths = [norm2tex.material_config(m) if m else "" for m in materials]
        counts = [norm2tex.MaterialConfig.load(p).variant_count if p else 1 for p in paths]
        # The variants every gripper's material has (an environment draws from one list).
        self.variant_count = min(c for c, p in zip(counts, paths) if p) if any(paths) else 1
        for material_path in paths:
            o = norm2tex.TactileGripperOptions()
            o.material_config = material_path
            o.variant = int(variant)
            o.material_seed = int(material_seed)
            o.beta_mm = -1.0 if beta_mm is None else float(beta_mm)
            o.friction = -1.0 if friction is None else float(friction)
            o.seed = int(seed)
            o.noise_seed = -1 if noise_seed is None else int(noise_seed)
            o.noise_per_episode = bool(noise_per_episode)
            o.frame_rate_hz = float(frame_rate_hz)
            o.physics_rate_hz = float(physics_rate_hz)
            options.append(o)
        self.batch = norm2tex.TactileGripperBatch(scene_config, sensor_model, options, threads)
        self.marker_count = self.batch.markers("left")["displacement_mm"].shape[1]
        self.size = count
        self.has_materials = [bool(p) for p in paths]
        self.has_material = any(self.has_materials)
        # Noise drawn per episode from a seed the environment gives (set_noise_seed).
        self.noise_per_episode = bool(noise_per_episode)
        self.frame_seconds = self.batch.frame_seconds
        self.height_offset_range = self.batch.sim(0).height_offset_range
        self.beta_mm = self.batch.beta_mm(0)
        self.friction = self.batch.friction(0)
        # Per gripper (they differ when the materials do).
        self.betas_mm = [self.batch.beta_mm(i) for i in range(count)]
        self.frictions = [self.batch.friction(i) for i in range(count)]
        self._backgrounds = {f: self.batch.background(f) for f in ("left", "right")}

    def reset(self, i, seed, height_offset_m=None, variant=None, next_variant=None):
        offset = None if height_offset_m is None or math.isnan(height_offset_m) else height_offset_m
        if not self.has_materials[i]:
            variant = next_variant = None  # no texture to vary
        start = self.batch.reset(i, int(seed), offset, -1 if variant is None else int(variant))
        if next_variant is not None:
            # Generated (for gripper i's material) while this episode runs.
            self.batch.prefetch_variant(int(next_variant), i)
        return start

    def prefetch_variant(self, variant, i=0):
        self.batch.prefetch_variant(int(variant), i)

    def set_noise_seed(self, i, noise_seed):
        self.batch.set_noise_seed(i, -1 if noise_seed is None else int(noise_seed))

    def step(self, modes, values, frames=1):
        self.batch.step(list(modes), [float(v) for v in values], int(frames))

    def step_one(self, i, mode, value, frames=1):
        self.batch.step_one(i, int(mode), float(value), int(frames))

    def images(self, finger):
        return self.batch.images(finger)

    def depths(self, finger):
        return self.batch.depths(finger)

    def markers(self, finger):
        """(N, markers, 2) float32: each marker's displacement on the gel, mm (0 wide: none)."""
        return self.batch.markers(finger)["displacement_mm"]

    def background(self, finger):
        return self._backgrounds[finger]

    def state(self):
        return self.batch.state()

    def close(self):
        self.batch = None
