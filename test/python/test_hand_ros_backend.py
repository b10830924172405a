"""HandEnv over ROS against HandEnv in-process: TACTO's WSG-50 (test/fixtures/robots) over a
30 mm cube on the floor, run by hand_sim.launch (synchronous, noise off) and in this process. The
same seeds, object poses and actions give the same observations, contacts and joints; bad
actions are refused the same way on both, and hand_sim's refusals carry the core's reasons.

Starts its own master on a free port (scripts/free_port). Run (with the workspace sourced):
    /usr/bin/python3 -m pytest -q test/python/test_hand_ros_backend.py
"""
import os

import numpy as np
import pytest

import ros_launch
from test_hand_env import check_bad_actions_are_refused

ROBOTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "robots")
# Upside down over the floor, its gel centres 15 mm above it: closing grasps the cube.
WSG_TOP = os.path.realpath(os.path.join(ROBOTS, "wsg50", "wsg50_top_grasp.yaml"))
ALLEGRO = os.path.join(ROBOTS, "allegro_hand_description", "allegro_hand.yaml")
CUBE_ON_FLOOR = [0.0, 0.0, 0.015]
CLOSE = np.array([-0.016, 0.016], np.float32)

# Both backends run the same physics on the same inputs (targets, and object poses as the same
# quaternion), and hand_sim's renderers draw the pose TF composes along the hand's links where
# the core computes it directly: rounding of the order of 1e-17 m. Measured over this test's
# frames (pytest -s prints it): no pixel differs, so the images must be equal bit for bit, as
# the joints, the contact forces and penetrations. Poses that pass through a quaternion on the
# way (object_in_world, object_in_gel) agree to 1e-12.
MAX_DIFFERING_PIXEL_FRACTION = 0.0
MAX_PIXEL_DIFFERENCE = 0
POSE_TOLERANCE = 1e-12


@pytest.fixture(scope="module")
def sensor_yaml():
    """The default DIGIT with its marker grid drawn: both sides render the gels' lateral motion
    from the physics' tangential forces and twists."""
    return ros_launch.digit_yaml(markers_enabled=True)


@pytest.fixture(scope="module")
def ros_system(sensor_yaml):
    """hand_sim.launch mode:=synchronous with the WSG-50 on a master of its own; this process's
    rospy on it."""
    with ros_launch.system(["norm2tex", "hand_sim.launch", "mode:=synchronous",
                            "hand:=" + WSG_TOP, "noise_seed:=-1", "sensor:=" + sensor_yaml],
                           "norm2tex_hand_ros_backend_test_") as system:
        yield system


def wsg(**kwargs):
    from norm2tex.envs import HandEnv

    args = dict(object_pose=CUBE_ON_FLOOR, noise=False, frames_per_step=10)
    if kwargs.get("backend") == "ros":
        args["ros_options"] = {"service_timeout_s": 60.0}
    args.update(kwargs)
    return HandEnv(WSG_TOP, **args)


@pytest.fixture(scope="module")
def envs(ros_system, sensor_yaml):
    over_ros = ros_launch.joined(lambda: wsg(backend="ros", sensor=sensor_yaml, markers=True),
                                 ros_system[1])
    in_process = wsg(sensor=sensor_yaml, markers=True)
    yield over_ros, in_process
    over_ros.close()
    in_process.close()


def _actions():
    """~25 steps of 10 frames: close on the cube (one value beyond its joint's limit, clipped),
    hold, open part way, close again."""
    a = [CLOSE] * 8 + [np.array([-0.1, 0.016], np.float32)] * 2  # -0.1: below -0.055, clipped
    a += [np.array([-0.035, 0.035], np.float32)] * 5 + [CLOSE] * 6
    return a + [np.array([-0.02, 0.025], np.float32)] * 4


def test_same_episodes_over_both_backends(envs):
    over_ros, in_process = envs
    assert over_ros.actuated_joints == in_process.actuated_joints
    assert over_ros.sensor_names == in_process.sensor_names == ["digit_left", "digit_right"]
    assert over_ros.observation_space.keys() == in_process.observation_space.keys()
    for x, y in ((over_ros.action_space, in_process.action_space),
                 (over_ros.observation_space["joint_positions"],
                  in_process.observation_space["joint_positions"])):
        assert np.array_equal(x.low, y.low) and np.array_equal(x.high, y.high)
    for name in over_ros.sensor_names:
        assert np.array_equal(over_ros.backend.background(name),
                              in_process.backend.background(name))

    differing, worst, frames, pressed = [], 0, 0, 0
    moved = []  # the largest marker displacement of each frame, mm

    def compare(a, b, info_a, info_b, where):
        nonlocal worst, frames, pressed
        assert a.keys() == b.keys()
        np.testing.assert_array_equal(a["joint_positions"], b["joint_positions"],
                                      err_msg=where)
        np.testing.assert_array_equal(info_a["joint_targets"], info_b["joint_targets"],
                                      err_msg=where)
        assert info_a["clipped"] == info_b["clipped"], where
        np.testing.assert_allclose(info_a["object_in_world"], info_b["object_in_world"], rtol=0,
                                   atol=POSE_TOLERANCE, err_msg=where)
        for name in over_ros.sensor_names:
            x, y = info_a["contacts"][name], info_b["contacts"][name]
            assert x.keys() == y.keys()
            for key in ("in_contact", "normal_force_n", "penetration_m", "too_deep",
                        "twist_moment_nm"):
                assert x[key] == y[key], (where, name, key, x[key], y[key])
            np.testing.assert_array_equal(x["shear_force_n"], y["shear_force_n"], err_msg=where)
            np.testing.assert_array_equal(x["pressure_centre_m"], y["pressure_centre_m"],
                                          err_msg=where)
            np.testing.assert_allclose(x["object_in_gel"], y["object_in_gel"], rtol=0,
                                       atol=POSE_TOLERANCE, err_msg=where)
            assert a[name].shape == b[name].shape == (320, 240, 3), where
            d = np.abs(a[name].astype(np.int16) - b[name].astype(np.int16)).max(axis=-1)
            differing.append(float(np.mean(d > 0)))
            worst = max(worst, int(d.max()))
            frames += 1
            markers = a[name + "_markers"]
            assert markers.shape == (63, 2) and markers.dtype == np.float32, where
            np.testing.assert_array_equal(markers, b[name + "_markers"], err_msg=where)
            moved.append(float(np.abs(markers).max()))
        pressed += all(info_a["contacts"][n]["in_contact"] for n in over_ros.sensor_names)

    # The cube where it lies, then turned by 0.3 rad and shifted (a pose through a quaternion).
    for seed, options in ((1, None), (2, {"object_pose": [0.002, 0.001, 0.015, 0.0, 0.0, 0.3]})):
        a, info_a = over_ros.reset(seed=seed, options=options)
        b, info_b = in_process.reset(seed=seed, options=options)
        assert info_a.keys() == info_b.keys()
        for key in ("material", "noise_seed", "friction", "beta_mm", "steps"):
            assert info_a[key] == info_b[key], key
        compare(a, b, info_a, info_b, "reset seed %d" % seed)
        for k, action in enumerate(_actions()):
            a, reward_a, done_a, cut_a, info_a = over_ros.step(action)
            b, reward_b, done_b, cut_b, info_b = in_process.step(action)
            assert (reward_a, done_a, cut_a) == (reward_b, done_b, cut_b)
            compare(a, b, info_a, info_b, "seed %d step %d" % (seed, k))
    print("\nHandEnv over ROS vs in-process over %d sensor frames: differing pixels per frame max "
          "%.6f mean %.6f, max difference %d grey levels"
          % (frames, max(differing), float(np.mean(differing)), worst))
    assert pressed >= 20, "the actions should hold the cube with both gels (a state worth comparing)"
    # Closing on the cube drags the gels' surfaces: the markers move (else equality says little).
    assert max(moved) > 0.01, max(moved)
    assert max(differing) <= MAX_DIFFERING_PIXEL_FRACTION
    assert worst <= MAX_PIXEL_DIFFERENCE


def test_bad_actions_are_refused_the_same_on_both(envs):
    import norm2tex

    for env in envs:
        check_bad_actions_are_refused(env)

    # Past the environment, the simulators refuse with the same reasons, nothing changed.
    over_ros, in_process = envs
    before = over_ros.backend.state()
    for targets in ([float("nan"), 0.03], [0.03]):
        with pytest.raises(norm2tex.Error) as in_core:
            in_process.backend.step(targets)
        with pytest.raises(norm2tex.Error) as over_ros_error:
            over_ros.backend.step(targets)
        assert str(over_ros_error.value).startswith("~step refused, nothing changed: ")
        assert str(in_core.value) in str(over_ros_error.value)
    after = over_ros.backend.state()
    np.testing.assert_array_equal(after["joint_targets"], before["joint_targets"])
    assert after["frame"] == before["frame"]


def test_an_environment_unlike_the_running_system_is_refused(envs):
    from norm2tex.envs import HandEnv

    with pytest.raises(ValueError, match="hand .*allegro_hand.yaml.*launch with hand:="):
        HandEnv(ALLEGRO, backend="ros", noise=False, ros_options={"service_timeout_s": 60.0})
    with pytest.raises(ValueError, match="material fabric .*launch with material:=fabric"):
        wsg(backend="ros", material="fabric")
    with pytest.raises(ValueError, match="noise True .*launch with noise_seed:=0"):
        wsg(backend="ros", noise=True)
    with pytest.raises(ValueError, match="object sphere:10 .*launch with mesh:=sphere:10"):
        wsg(backend="ros", object="sphere:10")


def test_markers_of_a_sensor_without_a_grid_are_refused(envs):
    """A renderer whose ~sensor has no marker grid publishes no markers: asking for them names
    the sensor and what to launch instead (the backend reads each renderer's ~sensor, here
    pointed at the plain DIGIT for the time of the test)."""
    import norm2tex
    import rospy
    from norm2tex.envs.hand_ros_backend import HandRosBackend

    param = "/digit_right_renderer/sensor"
    launched = rospy.get_param(param)
    rospy.set_param(param, norm2tex.config_path("digit.yaml"))
    try:
        with pytest.raises(norm2tex.Error, match="digit_right .*has no marker grid.*gelsight_mini"):
            HandRosBackend(service_timeout_s=40.0, markers=True)
    finally:
        rospy.set_param(param, launched)


def test_no_system_is_a_clear_error(ros_system):
    import norm2tex
    from norm2tex.envs.hand_ros_backend import HandRosBackend

    with pytest.raises(norm2tex.Error, match="start: roslaunch norm2tex hand_sim.launch "
                                             "mode:=synchronous hand:="):
        HandRosBackend(namespace="/nowhere", service_timeout_s=0.5)
