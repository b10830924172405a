"""roslaunch for the tests that start one: a free port for its master and a stop that always ends
the launch, its nodes and master included (they run in the launch's own process group).

Not a test module (pytest collects test_*.py only); the tests import it from this folder.
"""

import contextlib
import os
import signal
import subprocess
import tempfile

import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def free_port(script=None):
    """A TCP port nobody listens on, from the package's free_port script (the source tree's,
    or `script`, e.g. an install space's)."""
    script = script or os.path.join(REPO, "scripts", "free_port")
    out = subprocess.run([script], capture_output=True, text=True, check=True).stdout
    return int(out)


def digit_yaml(**settings):
    """The shipped DIGIT with SensorModel attributes changed (e.g. markers_enabled=True), saved
    to a new temporary directory for a launch's sensor:= and the in-process side to share."""
    import norm2tex

    model = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    for name, value in settings.items():
        setattr(model, name, value)
    path = os.path.join(tempfile.mkdtemp(prefix="norm2tex_test_sensor_"), "digit.yaml")
    model.save(path)
    return path


def start(args, env, log):
    """`roslaunch args...` in a process group of its own, output to the open file `log`."""
    return subprocess.Popen(["roslaunch"] + list(args), env=env, stdout=log,
                            stderr=subprocess.STDOUT, start_new_session=True)


def stop(launch, timeout_s=30):
    """Ends a launch started with start_new_session: Ctrl-C to its group, as a user would, and
    SIGKILL to the group if it has not ended within timeout_s. Returns its exit code."""
    if launch.poll() is None:
        os.killpg(launch.pid, signal.SIGINT)
        try:
            launch.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            os.killpg(launch.pid, signal.SIGKILL)
            launch.communicate()
    return launch.returncode


@contextlib.contextmanager
def system(args, prefix):
    """`roslaunch -p PORT args...` on a master of its own (a free port, ROS_HOME in a new
    temporary folder named with `prefix`), with this process's ROS environment pointed at it.
    Yields (launch, log: its output, an open file); stops it after."""
    home = tempfile.mkdtemp(prefix=prefix)
    port = free_port()
    uri = "http://localhost:%d" % port
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost",
               ROS_HOME=os.path.join(home, "ros_home"))
    with open(os.path.join(home, "roslaunch.log"), "w+") as log:
        launch = start(["-p", str(port)] + list(args), env, log)
        os.environ.update(ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        try:
            yield launch, log
        finally:
            stop(launch, timeout_s=20)


def joined(make, log):
    """make() (a backend joining the launch); when it raises, the launch's output last printed
    first: why the system is not there."""
    try:
        return make()
    except Exception:
        log.seek(0)
        print(log.read()[-4000:])
        raise


def assert_same_gripper_state(a, b, where):
    """Two gripper backends' state() equal: the measured values exactly, the flags, the frames."""
    for key in ("opening", "commanded_opening", "normal_force_n", "penetration_m"):
        np.testing.assert_array_equal(a[key], b[key], err_msg="%s %s" % (where, key))
    for key in ("in_contact", "dropped", "frame"):
        assert np.array_equal(a[key], b[key]), (where, key, a[key], b[key])
