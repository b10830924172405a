"""What the ROS backends share (RosBackend: the gripper of gripper_sim.launch; HandRosBackend: any
hand of hand_sim.launch): joining the master, waiting for a synchronous simulator's services and
calling them over persistent connections, and keeping each image topic's latest message so that
a step can wait for the images of the frame its call returned (with a deadline, never a sleep).
"""

import threading
import time

import numpy as np

import norm2tex


def frame_seconds(frame_rate, physics_rate):
    """A sensor frame's simulated seconds: whole physics ticks a frame, as the simulators round
    them (contact_sim, hand_sim and the core's TactileGripper, TactileHand)."""
    ticks = max(1, int(round(physics_rate / frame_rate)))
    return ticks * (1.0 / (ticks * frame_rate))


def bgr8(msg, topic):
    """(rows, cols, 3) uint8, a copy of a bgr8 sensor_msgs/Image's pixels."""
    if msg.encoding != "bgr8":
        raise norm2tex.Error("%s is %s, not bgr8" % (topic, msg.encoding))
    rows = np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)
    return rows[:, : msg.width * 3].reshape(msg.height, msg.width, 3).copy()


class RosClient:
    """A synchronous simulator node of a running launch, from this process (a rospy node:
    ``rospy.init_node(anonymous=True, disable_signals=True)`` unless it already is one).

    who: the name errors begin with; node: the simulator ("contact_sim", "hand_sim"); launch: its
    launch file; start: the roslaunch line an error suggests; namespace: the launch's ``ns``.
    Waits service_timeout_s wall seconds in all for the master, the services and the publishers
    (a system still starting: the renderers bake their textures first), frame_timeout_s for a
    frame's images once the call that made it returned.
    """

    def __init__(self, who, node, launch, start, namespace, service_timeout_s, frame_timeout_s,
                 node_name):
        import rosgraph
        import rospy

        self._rospy = rospy
        self._who, self._node, self._launch, self.START = who, node, launch, start
        self.frame_timeout_s = float(frame_timeout_s)
        self._service_timeout_s = float(service_timeout_s)
        self._deadline = time.monotonic() + self._service_timeout_s
        self._ns = "/" + namespace.strip("/") + "/" if namespace.strip("/") else "/"
        self._proxies = {}
        self._subscribers = []
        # The latest message of each topic; waiters wake on every arrival.
        self._cond = threading.Condition()
        self._latest = {}
        while not rosgraph.is_master_online():
            if time.monotonic() > self._deadline:
                raise self.error("no ROS master at %s within %.0f s; %s"
                                 % (rosgraph.get_master_uri(), service_timeout_s, start))
            time.sleep(0.1)
        if not rospy.core.is_initialized():
            rospy.init_node(node_name, anonymous=True, disable_signals=True)

    def error(self, message):
        return norm2tex.Error("%s: %s" % (self._who, message))

    def param(self, name, default=None):
        """The parameter `name` of the launch (relative to its namespace)."""
        return self._rospy.get_param(self._ns + name, default)

    def topic(self, name):
        return self._ns + name

    def _connect(self, services):
        """Waits for the simulator's `services` ({name: type}), checks that it runs
        synchronously, and opens persistent connections to them."""
        node = self._ns + self._node + "/"
        for name in services:
            try:
                self._rospy.wait_for_service(node + name,
                                             timeout=max(self._deadline - time.monotonic(), 0.01))
            except self._rospy.ROSException:
                mode = self.param(self._node + "/mode")
                why = (" (%s runs in mode %s: ~step exists only in synchronous mode)"
                       % (self._node, mode) if mode not in (None, "synchronous") else "")
                raise self.error("service %s did not appear within %.0f s%s; %s" % (
                    node + name, self._service_timeout_s, why, self.START)) from None
        mode = self.param(self._node + "/mode")
        if mode != "synchronous":
            raise self.error("%s runs in mode %r, not synchronous; %s" % (self._node, mode,
                                                                         self.START))
        for name, service in services.items():
            self._proxies[name] = (node + name, service,
                                   self._rospy.ServiceProxy(node + name, service, persistent=True))

    def _check_renderers(self, sensors):
        """Refuses a simulator whose ~step would not wait for the renderers of `sensors`."""
        renderers = self.param(self._node + "/renderers", [])
        missing = [s for s in sensors if s not in renderers]
        if missing:
            raise self.error("%s's ~renderers %s lacks %s: its ~step would not wait for their "
                             "images" % (self._node, renderers, missing))

    def _read_noise_seed(self, renderer):
        """The renderers' noise seed, fixed at launch (noise_seed:=; negative: None): they count
        noise frames from the launch, not from each episode."""
        noise = int(self.param(renderer + "/noise_seed", 0))
        self.noise_seed = None if noise < 0 else noise
        self.noise_per_episode = False

    def _check_noise_seed(self, noise_seed):
        """Refuses a noise seed other than the launch's."""
        wanted = None if noise_seed is None or int(noise_seed) < 0 else int(noise_seed)
        if wanted != self.noise_seed:
            raise self.error("noise seed %s asked, but the renderers were launched with %s; "
                             "relaunch with noise_seed:=%s"
                             % (wanted, self.noise_seed, -1 if wanted is None else wanted))

    def _call(self, name, request):
        """The simulator's service `name` with `request`; its response."""
        full, service, proxy = self._proxies[name]
        try:
            return proxy(request)
        except (self._rospy.ServiceException, OSError):
            # A persistent connection that broke (the simulator restarted): one new try.
            proxy = self._rospy.ServiceProxy(full, service, persistent=True)
            self._proxies[name] = (full, service, proxy)
            try:
                return proxy(request)
            except (self._rospy.ServiceException, OSError) as error:
                raise self.error("%s failed: %s; is %s still running?"
                                 % (full, error, self._launch)) from None

    def _subscribe(self, topics, msg_type=None):
        """Keeps the latest message (a sensor_msgs/Image unless msg_type says otherwise) of each
        topic, once every one is connected (frames published before a subscription is connected
        are not delivered)."""
        if msg_type is None:
            from sensor_msgs.msg import Image as msg_type

        subscribers = [self._rospy.Subscriber(t, msg_type, self._receive, callback_args=t,
                                              queue_size=None, buff_size=1 << 24,
                                              tcp_nodelay=True) for t in topics]
        self._subscribers += subscribers
        for sub in subscribers:
            while sub.get_num_connections() < 1:
                if time.monotonic() > self._deadline:
                    raise self.error("%s has no publisher within %.0f s; are the renderers of "
                                     "this launch running?" % (sub.name, self._service_timeout_s))
                time.sleep(0.01)

    def _renderer_sensor(self, renderer):
        """The sensor yaml a renderer of the launch reads (its ~sensor; default the DIGIT's)."""
        return self.param(renderer + "/sensor", "") or norm2tex.config_path("digit.yaml")

    def _marker_count(self, renderer):
        """How many markers a renderer's sensor has (0: no marker grid); it publishes
        <sensor>/markers with every frame when it has some."""
        model = norm2tex.SensorModel.load(self._renderer_sensor(renderer))
        rows, cols = model.marker_grid
        return rows * cols if model.markers_enabled else 0

    @staticmethod
    def _markers_type():
        from norm2tex.msg import TactileMarkers

        return TactileMarkers

    @staticmethod
    def _displacements(msg):
        """(markers, 2) float32 mm, gel frame: a TactileMarkers message's displacement_mm."""
        return np.array([(d.x, d.y) for d in msg.displacement_mm],
                        dtype=np.float32).reshape(-1, 2)

    def _receive(self, msg, topic):
        with self._cond:
            self._latest[topic] = msg
            self._cond.notify_all()

    def _wait_for(self, topics, stamp, what):
        """Until every topic's latest message has `stamp` (rospy.Time) or is latched (stamp
        None); returns them."""
        deadline = time.monotonic() + self.frame_timeout_s
        with self._cond:
            while True:
                msgs = [self._latest.get(t) for t in topics]
                if all(m is not None and (stamp is None or m.header.stamp == stamp) for m in msgs):
                    return msgs
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    seen = ["%s: %s" % (t, "none" if m is None else m.header.stamp)
                            for t, m in zip(topics, msgs)]
                    raise self.error(
                        "%s of %s not received within frame_timeout_s = %.1f s (latest: %s); are "
                        "the renderers of this launch running?"
                        % (what, "the latched message" if stamp is None else "stamp %s" % stamp,
                           self.frame_timeout_s, ", ".join(seen)))
                self._cond.wait(remaining)

    def close(self):
        """Unsubscribes and closes the service connections (the ROS system keeps running)."""
        for s in self._subscribers:
            s.unregister()
        self._subscribers = []
        for _, _, proxy in self._proxies.values():
            proxy.close()
        self._proxies = {}
