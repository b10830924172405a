"""The ROS backend: one simulated gripper with both DIGITs, driven over a running ROS system.

Start the system first, in synchronous mode (simulated time advances only through ~step):

    roslaunch norm2tex gripper_sim.launch mode:=synchronous texture_from_frame:=true

``texture_from_frame:=true`` lets ``reset(..., variant=v)`` change the texture per episode (the
renderers then draw the variant each frame names); without it only the launch's ``variant`` can
be used. The backend is a rospy node in this process (``rospy.init_node(anonymous=True,
disable_signals=True)`` unless this process already is one).

Each ``step`` calls ``/contact_sim/step`` (with the command) and then waits for the images of the
stamp it returns on ``/digit_left/image_raw`` and ``/digit_right/image_raw``: synchronous mode
publishes both before ~step returns, so the images are exactly that frame's (never a stale one;
a deadline, never a sleep). The gripper's state comes with the ~step/~reset response.

It has InProcessBackend's interface for count 1 (see its docstring; ``step_one(0, ...)`` is
``step``); what differs:
  - the noise seed is the launch's (``noise_seed:=``): ``set_noise_seed`` accepts only that one
    (None for a negative one) and raises otherwise. ROS counts noise frames from the launch, not
    from each episode (InProcessBackend's ``noise_per_episode=False``; the attribute
    ``noise_per_episode`` is False).
  - ``depths`` needs ``depth=True`` at construction (the renderers publish depth only to
    subscribers, so the depth of a frame exists only if someone listened when it was rendered).
  - ``markers`` needs ``markers=True`` at construction and renderers whose sensor has a marker
    grid (they publish /digit_*/markers with every frame).
  - ``prefetch_variant`` does nothing: a renderer prepares a new variant at the episode's first
    frame (the first reset with a new variant takes as long as generating it, ~0.5 s).
  - construction starts no episode: call ``reset`` first (the launch's own first episode,
    ``seed:=``, already ran when contact_sim started, as InProcessBackend's construction does).
"""

import numpy as np

import norm2tex
from norm2tex.envs.ros_client import RosClient, bgr8, frame_seconds

from norm2tex.envs.commands import ABSOLUTE, DELTA, KEEP

FINGERS = ("left", "right")


class RosBackend(RosClient):
    """One gripper of a running ``gripper_sim.launch mode:=synchronous`` (see the module's doc).

    namespace: the launch's ``ns`` ("/" by default).
    service_timeout_s: wall seconds to wait for the master, the parameters and contact_sim's
      services (a system still starting: the renderers bake their textures first).
    frame_timeout_s: wall seconds to wait for a frame's images once ~step or ~reset returned.
    depth: also subscribe to /digit_*/depth (needed by ``depths``).
    markers: also subscribe to /digit_*/markers (needed by ``markers``); refused with the reason
      when the renderers' sensor has no marker grid.
    Raises norm2tex.Error (a RuntimeError) with what to start when the system is not there.
    """

    def __init__(self, namespace="/", service_timeout_s=30.0, frame_timeout_s=10.0, depth=False,
                 node_name="norm2tex_ros_backend", markers=False):
        from norm2tex.msg import GripperCommand
        from norm2tex.srv import Reset, Step

        super().__init__("RosBackend", "contact_sim", "gripper_sim.launch",
                         "start: roslaunch norm2tex gripper_sim.launch mode:=synchronous "
                         "texture_from_frame:=true", namespace, service_timeout_s,
                         frame_timeout_s, node_name)
        self._GripperCommand = GripperCommand
        self._Reset, self._Step = Reset, Step
        self._connect({"reset": Reset, "step": Step})
        self._check_renderers(["digit_" + f for f in FINGERS])

        # The launch's choices, as contact_sim and the renderers read them.
        param = self.param
        self.material = param("contact_sim/material", "wood") or "none"
        self.scene = param("contact_sim/scene", "")
        self.mesh = param("contact_sim/mesh", "")
        self.sensor = param("contact_sim/sensor", "")
        material = None
        if self.material != "none":
            material = norm2tex.MaterialConfig.load(norm2tex.material_config(self.material))
        self.variant_count = material.variant_count if material else 1
        self.variant = int(param("contact_sim/variant", 0))
        friction = float(param("contact_sim/friction", -1.0))
        self.friction = friction if friction >= 0 else (material.friction if material else 0.5)
        beta = float(param("digit_left_renderer/beta", -1.0))
        self.beta_mm = beta if beta >= 0 else (material.beta_mm if material else 0.0)
        self._read_noise_seed("digit_left_renderer")
        self.texture_from_frame = bool(param("digit_left_renderer/texture_from_frame", False))
        self.frame_seconds = frame_seconds(float(param("contact_sim/frame_rate", 60.0)),
                                           float(param("contact_sim/physics_rate", 1000.0)))
        low, high = param("contact_sim/height_offset_range", [float("nan")] * 2)
        self.height_offset_range = (float(low), float(high))
        self.size = 1
        self.has_material = material is not None

        kinds = ("image_raw", "depth") if depth else ("image_raw",)
        self._subscribe([self._topic(f, k) for f in FINGERS for k in kinds + ("background",)])
        self._depth = bool(depth)
        # Each renderer reads its own ~sensor; the left one stands for both (as for the beta).
        # Read only when asked: the yaml is the renderers' file, which a backend on another
        # machine may not have.
        self._markers = bool(markers)
        self.marker_count = self._marker_count("digit_left_renderer") if self._markers else None
        if self._markers:
            if self.marker_count == 0:
                self.close()
                raise self.error("markers=True, but the renderers' sensor (%s) has no marker grid "
                                 "(its yaml's markers: enabled: false); launch with a sensor that "
                                 "has one, e.g. sensor:=$(rospack find norm2tex)/config/"
                                 "gelsight_mini.yaml" % self._renderer_sensor("digit_left_renderer"))
            self._subscribe([self._topic(f, "markers") for f in FINGERS], self._markers_type())
        self._stamp = None  # the frame the backend is at (after a reset or step)
        self._state = None
        self._backgrounds = {}

    def _topic(self, finger, kind):
        return self.topic("digit_%s/%s" % (finger, kind))

    def _frame_msg(self, finger, kind):
        if self._stamp is None:
            raise self.error("no frame yet; call reset() first")
        return self._wait_for([self._topic(finger, kind)], self._stamp,
                              "/digit_%s/%s" % (finger, kind))[0]

    @staticmethod
    def _check_finger(finger):
        if finger not in FINGERS:
            raise ValueError("finger %r; valid: 'left', 'right'" % (finger,))

    # --- the backend interface ------------------------------------------------------------------
    def _take_state(self, r, commanded):
        self._state = {
            "opening": np.array([r.opening], dtype=np.float64),
            "commanded_opening": np.array([commanded], dtype=np.float64),
            "normal_force_n": np.array([list(r.normal_force)], dtype=np.float64),
            "penetration_m": np.array([list(r.penetration)], dtype=np.float64),
            "in_contact": np.array([[bool(c) for c in r.in_contact]], dtype=bool),
            "too_deep": np.array([[bool(c) for c in r.too_deep]], dtype=bool),
            "dropped": np.array([bool(r.dropped)], dtype=bool),
            "frame": np.array([r.frame], dtype=np.int64),
        }

    def reset(self, i, seed, height_offset_m=None, variant=None, next_variant=None):
        """Starts an episode (~reset): seed >= 0, offset [m] within height_offset_range (None:
        drawn with the seed), texture variant (None: keep; another than the launch's needs
        texture_from_frame:=true), and the variant the next episode will use (None: unknown),
        which the renderers then prepare during this one. Returns dict(episode, seed,
        height_offset_m, grasp_opening). Raises norm2tex.Error with contact_sim's message when
        it refuses (nothing changed)."""
        self._check_index(i)
        request = self._Reset._request_class()
        request.seed = int(seed)
        request.height_offset = (float("nan") if height_offset_m is None
                                 else float(height_offset_m))
        if not self.has_material:
            variant = None  # no texture to vary
        if variant is not None and int(variant) != self.variant:
            if not self.texture_from_frame:
                raise self.error("variant %d asked, but the renderers draw only the launch's "
                                 "variant %d; %s" % (int(variant), self.variant, self.START))
            request.set_texture = True
            request.variant = int(variant)
        if self.has_material and self.texture_from_frame and next_variant is not None:
            # Announced in this episode's frames: the renderers prepare it in the background.
            request.set_texture = True
            request.variant = self.variant if variant is None else int(variant)
            request.next_material = self.material
            request.next_variant = int(next_variant)
        r = self._call("reset", request)
        if not r.success:
            raise norm2tex.Error(r.message)
        if request.set_texture:
            self.variant = int(variant)
        self._stamp = r.info.header.stamp
        self._take_state(r, r.grasp_opening)
        return {"episode": int(r.info.episode), "seed": int(r.info.seed),
                "height_offset_m": float(r.info.height_offset),
                "grasp_opening": float(r.grasp_opening)}

    def set_noise_seed(self, i, noise_seed):
        """The renderers' noise seed is fixed at launch (noise_seed:=, negative = None): only that
        one is accepted."""
        self._check_index(i)
        self._check_noise_seed(noise_seed)

    def prefetch_variant(self, variant):
        """Nothing here: reset(..., next_variant=v) announces it to the renderers."""

    def step(self, modes, values, frames=1):
        """One command (KEEP / ABSOLUTE / DELTA and its value) and `frames` sensor frames
        (~step); returns once both images of the last frame are here. Raises norm2tex.Error
        with contact_sim's message when it refuses (nothing moved) or a frame failed."""
        if len(modes) != 1 or len(values) != 1:
            raise self.error("%d modes and %d values for 1 gripper" % (len(modes), len(values)))
        mode, value = int(modes[0]), float(values[0])
        request = self._Step._request_class()
        request.frames = int(frames)
        if mode == ABSOLUTE or mode == DELTA:
            request.set_command = True
            request.command.mode = mode  # the message's own values (norm2tex.envs.commands)
            request.command.opening = value
        elif mode != KEEP:
            raise ValueError("command mode %d; valid: 0 ABSOLUTE, 1 DELTA, 2 KEEP "
                             "(norm2tex.envs.commands)" % mode)
        r = self._call("step", request)
        if not r.success:
            raise norm2tex.Error(r.message)
        if r.missing_images:
            raise self.error("%d images of this step were not rendered (see the renderers' log)"
                             % r.missing_images)
        self._stamp = r.stamp
        self._take_state(r, r.commanded_opening)
        self._wait_for([self._topic(f, "image_raw") for f in FINGERS], self._stamp, "images")

    def step_one(self, i, mode, value, frames=1):
        """Gripper i alone: with one gripper, step()."""
        self._check_index(i)
        self.step([mode], [value], frames)

    def images(self, finger):
        """(1, rows, cols, 3) uint8 bgr8: the sensor's image of the current frame."""
        self._check_finger(finger)
        return bgr8(self._frame_msg(finger, "image_raw"), "/digit_%s/image_raw" % finger)[None]

    def depths(self, finger):
        """(1, rows, cols) float32 gel deformation [m] of the current frame (needs depth=True)."""
        self._check_finger(finger)
        if not self._depth:
            raise self.error("depths need RosBackend(depth=True) (the renderers publish depth "
                             "only to subscribers)")
        msg = self._frame_msg(finger, "depth")
        dtype = np.dtype(np.float32).newbyteorder(">" if msg.is_bigendian else "<")
        rows = np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
        depth = rows[:, : msg.width * 4].copy().view(dtype).astype(np.float32)
        return depth.reshape(1, msg.height, msg.width)

    def markers(self, finger):
        """(1, markers, 2) float32: each marker's displacement on the gel at the current frame,
        mm, gel frame (needs markers=True)."""
        self._check_finger(finger)
        if not self._markers:
            raise self.error("markers need RosBackend(markers=True)")
        return self._displacements(self._frame_msg(finger, "markers"))[None]

    def background(self, finger):
        """(rows, cols, 3) uint8: the sensor's no-contact frame without noise (latched topic)."""
        self._check_finger(finger)
        if finger not in self._backgrounds:
            topic = self._topic(finger, "background")
            self._backgrounds[finger] = bgr8(self._wait_for([topic], None, topic)[0], topic)
        return self._backgrounds[finger]

    def state(self):
        """As InProcessBackend.state(), at the current frame (from the ~step/~reset response)."""
        if self._state is None:
            raise self.error("no frame yet; call reset() first")
        return {k: v.copy() for k, v in self._state.items()}

    @staticmethod
    def _check_index(i):
        if i != 0:
            raise IndexError("gripper %d of a RosBackend of 1" % i)
