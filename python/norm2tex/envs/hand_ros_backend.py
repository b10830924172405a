"""HandEnv's ROS backend: any hand of a running hand_sim.launch, driven over ROS.

Start the system first, in synchronous mode (simulated time advances only through ~step):

    roslaunch norm2tex hand_sim.launch mode:=synchronous hand:=HAND_YAML [noise_seed:=-1]

The backend is a rospy node in this process (``rospy.init_node(anonymous=True,
disable_signals=True)`` unless this process already is one).

Each ``step`` calls ``/hand_sim/step`` with the joints' targets and then waits for the images of
the stamp it returns on every sensor's ``/SENSOR/image_raw``: synchronous mode publishes them
before ~step returns, so the images are exactly that frame's (never a stale one; a deadline,
never a sleep). The hand's state (joints, contacts, object) comes with the ~step and ~reset
responses. Each ``reset`` calls ``/hand_sim/reset`` with the object's pose.

It has HandInProcessBackend's interface (see its docstring); what differs:
  - the noise seed is the launch's (``noise_seed:=``, ``noise_seed`` here; None for a negative
    one), and the renderers count noise frames from the launch, not from each episode
    (``noise_per_episode`` is False; ``set_noise_seed`` accepts only the launch's seed).
  - the material, its variant and texture depth, the friction, the object (scene, mesh, scale),
    the sensor and the rates are the launch's: ``material``, ``variant``, ``beta_mm``,
    ``friction``, ``scene``, ``mesh``, ``scale``, ``sensor`` and ``frame_seconds`` say which.
  - ``frame`` counts hand_sim's frames since it started, and a reset is a frame of its own.
"""

import numpy as np

import norm2tex
from norm2tex.envs.ros_client import RosClient, bgr8, frame_seconds


def _matrix(pose):
    """A geometry_msgs/Pose as a 4x4."""
    x, y, z, w = pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w
    out = np.eye(4)
    out[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    out[:3, 3] = pose.position.x, pose.position.y, pose.position.z
    return out


class HandRosBackend(RosClient):
    """The hand of a running ``hand_sim.launch mode:=synchronous`` (see the module's doc).

    namespace: the launch's namespace ("/" by default).
    service_timeout_s: wall seconds to wait for the master, the parameters, hand_sim's services
      and the renderers (a system still starting: the renderers bake their textures first).
    frame_timeout_s: wall seconds to wait for a frame's images once ~step or ~reset returned.
    markers: also subscribe to every sensor's markers (needed by ``markers``); refused with the
      reason when a sensor's renderer has no marker grid.
    Raises norm2tex.Error (a RuntimeError) with what to start when the system is not there.
    """

    def __init__(self, namespace="/", service_timeout_s=30.0, frame_timeout_s=10.0,
                 node_name="norm2tex_hand_ros_backend", markers=False):
        from norm2tex.srv import HandReset, HandStep

        super().__init__("HandRosBackend", "hand_sim", "hand_sim.launch",
                         "start: roslaunch norm2tex hand_sim.launch mode:=synchronous "
                         "hand:=HAND_YAML", namespace, service_timeout_s, frame_timeout_s,
                         node_name)
        self._HandReset, self._HandStep = HandReset, HandStep
        param = self.param
        self._connect({"reset": HandReset, "step": HandStep})
        # hand_sim sets ~sensors before it offers its services.
        self.sensor_names = list(param("hand_sim/sensors"))
        self._check_renderers(self.sensor_names)

        # The launch's choices, as hand_sim and the renderers read them.
        self.hand = param("hand_sim/hand")
        self.scene = param("hand_sim/scene", "")
        self.mesh = param("hand_sim/mesh", "")
        self.scale = float(param("hand_sim/scale", 1.0))
        self.sensor = param("hand_sim/sensor", "")
        name = param("hand_sim/material", "wood")
        self.material = None if name in ("", "none") else name
        material = None
        if self.material:
            material = norm2tex.MaterialConfig.load(norm2tex.material_config(self.material))
        friction = float(param("hand_sim/friction", -1.0))
        self.friction = friction if friction >= 0 else (material.friction if material else 0.5)
        renderer = self.sensor_names[0] + "_renderer"  # every sensor's has the launch's
        self.variant = int(param(renderer + "/variant", 0))
        beta = float(param(renderer + "/beta", -1.0))
        self.beta_mm = (beta if beta >= 0 else material.beta_mm) if material else 0.0
        self._read_noise_seed(renderer)
        self.frame_seconds = frame_seconds(float(param("hand_sim/frame_rate", 60.0)),
                                           float(param("hand_sim/physics_rate", 1000.0)))
        # The joints and their URDF limits, from the hand yaml as hand_sim reads it.
        description = norm2tex.HandSim(norm2tex.HandSimConfig(self.hand))
        self.actuated_joints = list(description.actuated_joints)
        self.joint_lower, self.joint_upper = description.joint_limits()

        self._images = [self.topic(s + "/image_raw") for s in self.sensor_names]
        self._subscribe(self._images + [self.topic(s + "/background") for s in self.sensor_names])
        # Each sensor's renderer reads its own ~sensor (a mount's sensor_yaml, or the launch's);
        # read only when asked (the renderers' files; a backend elsewhere may not have them).
        self.marker_counts = None
        self._markers = [self.topic(s + "/markers") for s in self.sensor_names] if markers else None
        if markers:
            self.marker_counts = {s: self._marker_count(s + "_renderer") for s in self.sensor_names}
            bare = [s for s in self.sensor_names if self.marker_counts[s] == 0]
            if bare:
                self.close()
                raise self.error("markers=True, but the sensor of %s (%s) has no marker grid "
                                 "(its yaml's markers: enabled: false); launch with a sensor that "
                                 "has one, e.g. sensor:=$(rospack find norm2tex)/config/"
                                 "gelsight_mini.yaml" % (bare[0],
                                                         self._renderer_sensor(bare[0] + "_renderer")))
            self._subscribe(self._markers, self._markers_type())
        # The frame the backend is at (after a reset or step): its stamp, number and state.
        self._stamp = self._frame = self._state = None
        self._backgrounds = {}

    def _take(self, response):
        """The response's frame is the backend's; raises with hand_sim's reason when it refused
        or a frame failed, and waits for every sensor's image of that frame."""
        if not response.success:
            raise norm2tex.Error(response.message)
        if getattr(response, "missing_images", 0):
            raise self.error("%d images of this step were not rendered (see the renderers' log)"
                             % response.missing_images)
        self._stamp, self._frame, self._state = response.stamp, int(response.frame), response.state
        self._wait_for(self._images, self._stamp, "images")

    # --- the backend interface ------------------------------------------------------------------
    def set_noise_seed(self, noise_seed):
        """The renderers' noise seed is fixed at launch (noise_seed:=, negative = None): only
        that one is accepted."""
        self._check_noise_seed(noise_seed)

    def reset(self, object_pose):
        """~reset: the hand at its initial joint positions, the object at rest at object_pose
        ((xyz, quaternion xyzw) in the world). Raises norm2tex.Error with hand_sim's reason when
        it refuses (nothing changed)."""
        request = self._HandReset._request_class()
        request.set_object_pose = True
        xyz, q = object_pose
        p = request.object_pose
        p.position.x, p.position.y, p.position.z = (float(v) for v in xyz)
        p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = (float(v) for v in q)
        self._take(self._call("reset", request))

    def step(self, targets, frames=1):
        """~step: the actuated joints' targets, then `frames` sensor frames; returns once every
        sensor's image of the last frame is here. Raises norm2tex.Error with hand_sim's reason
        when it refuses (nothing moved) or a frame failed. The hand's root stays where the hand
        yaml puts it, as in-process (the request's ``set_base_pose`` is false; a client moving
        the root sends ``base_pose`` in its ~step request, ordered with the frames)."""
        request = self._HandStep._request_class()
        request.frames = int(frames)
        request.targets.name = self.actuated_joints
        request.targets.position = [float(v) for v in targets]
        self._take(self._call("step", request))

    def images(self):
        """{sensor: (rows, cols, 3) uint8 bgr8}: every sensor's image of the current frame."""
        if self._stamp is None:
            raise self.error("no frame yet; call reset() first")
        msgs = self._wait_for(self._images, self._stamp, "images")
        return {name: bgr8(m, t) for name, m, t in zip(self.sensor_names, msgs, self._images)}

    def markers(self):
        """{sensor: (markers, 2) float32 mm, gel frame}: each marker's displacement at the
        current frame (needs markers=True)."""
        if self._markers is None:
            raise self.error("markers need HandRosBackend(markers=True)")
        if self._stamp is None:
            raise self.error("no frame yet; call reset() first")
        msgs = self._wait_for(self._markers, self._stamp, "markers")
        return {name: self._displacements(m) for name, m in zip(self.sensor_names, msgs)}

    def background(self, sensor):
        """(rows, cols, 3) uint8: the sensor's no-contact frame without noise (latched topic)."""
        if sensor not in self._backgrounds:
            if sensor not in self.sensor_names:
                raise KeyError("sensor %r; the hand's: %s" % (sensor, ", ".join(self.sensor_names)))
            topic = self.topic(sensor + "/background")
            self._backgrounds[sensor] = bgr8(self._wait_for([topic], None, topic)[0], topic)
        return self._backgrounds[sensor]

    def state(self):
        """As HandInProcessBackend.state(), at the current frame (from the ~step/~reset
        response)."""
        s = self._state
        if s is None:
            raise self.error("no frame yet; call reset() first")
        contacts = {
            name: {"in_contact": bool(s.in_contact[i]),
                   "normal_force_n": float(s.normal_force[i]),
                   "shear_force_n": np.array([s.shear_force[i].x, s.shear_force[i].y,
                                              s.shear_force[i].z]),
                   "pressure_centre_m": np.array([s.pressure_centre[i].x,
                                                  s.pressure_centre[i].y]),
                   "twist_moment_nm": float(s.twist_moment[i]),
                   "penetration_m": float(s.penetration[i]),
                   "too_deep": bool(s.too_deep[i]),
                   "object_in_gel": _matrix(s.object_in_gel[i])}
            for i, name in enumerate(s.sensors)}
        return {"joint_positions": np.array(s.joint_positions, dtype=np.float64),
                "joint_targets": np.array(s.joint_targets, dtype=np.float64),
                "object_in_world": _matrix(s.object_in_world), "contacts": contacts,
                "frame": self._frame}
