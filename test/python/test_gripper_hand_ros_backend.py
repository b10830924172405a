"""The gripper's episodes on a hand of its own over ROS: gripper_sim.launch with a scene whose
gripper.hand is TACTO's WSG-50 (test/fixtures/robots/wsg50/wsg50_cube_scene.yaml) gives, through
RosBackend, the same states and images as the in-process backend for the same seeds, offsets and
commands; its TF tree places the gels where the hand has them, and /joint_states carries the
hand's own joints.

Starts its own master on a free port (scripts/free_port). Run (with the workspace sourced):
    /usr/bin/python3 -m pytest -q test/python/test_gripper_hand_ros_backend.py
"""
import os
import time

import numpy as np
import pytest

import ros_launch

LAUNCH_SEED = 3
SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "robots",
                     "wsg50", "wsg50_cube_scene.yaml")


@pytest.fixture(scope="module")
def ros_system():
    with ros_launch.system(
            ["norm2tex", "gripper_sim.launch", "mode:=synchronous", "noise_seed:=-1",
             "seed:=%d" % LAUNCH_SEED, "scene:=" + os.path.realpath(SCENE)],
            "norm2tex_gripper_hand_ros_backend_test_") as system:
        yield system


@pytest.fixture(scope="module")
def backends(ros_system):
    from norm2tex.envs.inprocess_backend import InProcessBackend
    from norm2tex.envs.ros_backend import RosBackend

    ros = ros_launch.joined(lambda: RosBackend(service_timeout_s=40.0), ros_system[1])
    inproc = InProcessBackend(scene=SCENE, seed=LAUNCH_SEED, noise_seed=None,
                              noise_per_episode=False)
    yield ros, inproc
    ros.close()
    inproc.close()


def test_same_frames_as_in_process_on_the_wsg50(backends):
    from norm2tex.envs.commands import ABSOLUTE, DELTA, KEEP

    ros, inproc = backends
    assert ros.height_offset_range == pytest.approx(inproc.height_offset_range, abs=0)

    def compare(where):
        a = ros.state()
        ros_launch.assert_same_gripper_state(a, inproc.state(), where)
        for finger in ("left", "right"):
            np.testing.assert_array_equal(ros.images(finger), inproc.images(finger),
                                          err_msg=f"{where} image {finger}")
        return a

    low, high = inproc.height_offset_range
    start_ros = ros.reset(0, 21, low + 0.5 * (high - low))
    start_inp = inproc.reset(0, 21, low + 0.5 * (high - low))
    assert start_ros["grasp_opening"] == start_inp["grasp_opening"]
    state = compare("reset")
    # Held with the WSG-50's 10 N per finger (the scene's 1 mm asks more).
    assert state["in_contact"].all()
    assert state["normal_force_n"][0] == pytest.approx([10.0, 10.0], rel=0.05)
    commands = [(KEEP, 0.0, 2), (DELTA, -0.01, 1), (KEEP, 0.0, 1), (ABSOLUTE, 1.0, 1)]
    commands += [(KEEP, 0.0, 3)] * 4
    for k, (mode, value, n) in enumerate(commands):
        ros.step([mode], [value], n)
        inproc.step([mode], [value], n)
        state = compare("step %d" % k)
    assert state["dropped"][0], "opened wide, the cube should have fallen"


def _wait_until(condition, what, timeout_s=20.0):
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, "no %s within %g s" % (what, timeout_s)
        time.sleep(0.01)


def _matrix(transform):
    """4x4 of a geometry_msgs/Transform (its unit quaternion's rotation matrix)."""
    q, t = transform.rotation, transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = [t.x, t.y, t.z]
    return m


def test_tf_places_the_gels_where_the_hand_has_them(backends):
    import rospy
    from sensor_msgs.msg import JointState
    from tf2_msgs.msg import TFMessage

    import norm2tex
    from norm2tex.envs.commands import KEEP

    ros, _ = backends
    ros.reset(0, 22)
    # The frame's tree as contact_sim sends it: world -> gripper_base -> finger_* on /tf (one
    # message a frame), finger_* -> digit_*_gel on /tf_static (latched).
    static = rospy.wait_for_message("/tf_static", TFMessage, timeout=20.0).transforms
    received, joint_states = [], []
    subscribers = [rospy.Subscriber("/tf", TFMessage, received.append),
                   rospy.Subscriber("/joint_states", JointState, joint_states.append)]
    _wait_until(lambda: all(s.get_num_connections() > 0 for s in subscribers), "connection")
    ros.step([KEEP], [0.0], 1)  # a frame: its /tf and /joint_states messages
    _wait_until(lambda: received and joint_states, "/tf and /joint_states message")
    for subscriber in subscribers:
        subscriber.unregister()
    dynamic = received[-1].transforms
    edges = {(t.header.frame_id, t.child_frame_id): _matrix(t.transform) for t in static + dynamic}
    sim = norm2tex.GripperSim(norm2tex.SceneConfig.load(SCENE),
                              norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml")))
    sim.reset(22)  # the same episode: the fingers where the ROS system has them
    for finger in ("left", "right"):
        gel = (edges[("world", "gripper_base")] @ edges[("gripper_base", "finger_" + finger)]
               @ edges[("finger_" + finger, "digit_%s_gel" % finger)])
        np.testing.assert_allclose(gel, sim.gel_in_world(finger), atol=1e-6, err_msg=finger)
    joints = joint_states[-1]
    assert joints.name == ["base_joint_gripper_left", "base_joint_gripper_right"]
    # The fingers sit symmetric about the hand's centre (closed on the cube).
    assert joints.position[0] == pytest.approx(-joints.position[1], abs=1e-4)
