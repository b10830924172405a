"""RosBackend against InProcessBackend: the same seeds, offsets, commands and texture variants
give the same gripper states and images over a running gripper_sim.launch (synchronous, noise
off, texture_from_frame, the texture's conformity on: the gels' forces reach the renderers) as
in-process; and RosBackend's refusals carry contact_sim's reasons.

Starts its own master on a free port (scripts/free_port). Run (with the workspace sourced):
    /usr/bin/python3 -m pytest -q test/python/test_ros_backend.py
"""
import time

import numpy as np
import pytest

import ros_launch

LAUNCH_SEED = 3  # the launch's seed:=, the in-process backend's seed

# Pixels could differ where the ROS renderer's pose went through TF (the object's pose in the gel
# frame composed from four transforms sent as messages, instead of computed directly): rounding
# of the order of 1e-17 m. Measured over this test's frames (88 images, pytest -s prints it): no
# pixel differs, so the images must be equal bit for bit (and the depths, and the states exactly).
MAX_DIFFERING_PIXEL_FRACTION = 0.0
MAX_PIXEL_DIFFERENCE = 0


@pytest.fixture(scope="module")
def sensor_yaml():
    """The default DIGIT with the texture's conformity on and its marker grid drawn: both sides
    must then pass the gels' normal forces, tangential forces and twists to their renderers
    (contact_sim in SimFrame) to agree."""
    return ros_launch.digit_yaml(conformity_enabled=True, markers_enabled=True)


@pytest.fixture(scope="module")
def ros_system(sensor_yaml):
    """gripper_sim.launch mode:=synchronous on a master of its own; this process's rospy on it."""
    with ros_launch.system(
            ["norm2tex", "gripper_sim.launch", "mode:=synchronous", "noise_seed:=-1",
             "texture_from_frame:=true", "seed:=%d" % LAUNCH_SEED, "sensor:=" + sensor_yaml],
            "norm2tex_ros_backend_test_") as system:
        yield system


@pytest.fixture(scope="module")
def backends(ros_system, sensor_yaml):
    from norm2tex.envs.inprocess_backend import InProcessBackend
    from norm2tex.envs.ros_backend import RosBackend

    ros = ros_launch.joined(lambda: RosBackend(service_timeout_s=40.0, depth=True, markers=True),
                            ros_system[1])
    inproc = InProcessBackend(seed=LAUNCH_SEED, noise_seed=None, noise_per_episode=False,
                              sensor=sensor_yaml)
    yield ros, inproc
    ros.close()
    inproc.close()


def _commands():
    """~30 steps: the paper's deltas, absolute commands, a multi-frame step, a drop."""
    from norm2tex.envs.commands import ABSOLUTE, DELTA, KEEP

    c = [(DELTA, -0.005, 1)] * 4 + [(KEEP, 0.0, 1)] * 3
    c += [(ABSOLUTE, 0.5, 1), (DELTA, 0.005, 2), (DELTA, 0.005, 1)]
    c += [(ABSOLUTE, 0.47, 1)] + [(DELTA, 0.01, 1)] * 6 + [(KEEP, 0.0, 3)]
    c += [(DELTA, -0.005, 1)] * 4
    c += [(ABSOLUTE, 0.9, 1)] + [(KEEP, 0.0, 1)] * 4 + [(KEEP, 0.0, 6)] * 5  # opens: the cube drops
    return c


def test_same_frames_as_in_process(backends):
    ros, inproc = backends
    assert ros.size == 1
    assert ros.frame_seconds == pytest.approx(inproc.frame_seconds, abs=1e-12)
    assert ros.variant_count == inproc.variant_count
    assert ros.beta_mm == inproc.beta_mm
    assert ros.friction == inproc.friction
    assert ros.height_offset_range == pytest.approx(inproc.height_offset_range, abs=0)
    for finger in ("left", "right"):
        assert np.array_equal(ros.background(finger), inproc.background(finger))

    assert ros.marker_count == inproc.marker_count == 9 * 7
    low, high = inproc.height_offset_range
    differing, worst, frames = [], 0, 0
    moved = []  # the largest marker displacement of each frame, mm

    def compare(where):
        nonlocal worst, frames
        a = ros.state()
        ros_launch.assert_same_gripper_state(a, inproc.state(), where)
        for finger in ("left", "right"):
            x = ros.images(finger).astype(np.int16)
            y = inproc.images(finger).astype(np.int16)
            assert x.shape == y.shape == (1, 320, 240, 3)
            d = np.abs(x - y).max(axis=-1)
            differing.append(float(np.mean(d > 0)))
            worst = max(worst, int(d.max()))
            np.testing.assert_array_equal(ros.depths(finger), inproc.depths(finger),
                                          err_msg=f"{where} depth {finger}")
            markers = ros.markers(finger)
            assert markers.shape == (1, 63, 2) and markers.dtype == np.float32
            np.testing.assert_array_equal(markers, inproc.markers(finger),
                                          err_msg=f"{where} markers {finger}")
            moved.append(float(np.abs(markers).max()))
            frames += 1
        return a

    episodes = [(11, low + 0.3 * (high - low), None), (12, None, 2)]
    dropped_seen = False
    pressed_seen = 0
    for seed, offset, variant in episodes:
        start_ros = ros.reset(0, seed, offset, variant)
        start_inp = inproc.reset(0, seed, offset, variant)
        assert start_ros["episode"] == start_inp["episode"]
        assert start_ros["seed"] == start_inp["seed"] == seed
        assert start_ros["height_offset_m"] == start_inp["height_offset_m"]
        assert start_ros["grasp_opening"] == start_inp["grasp_opening"]
        compare("reset seed %d" % seed)
        for k, (mode, value, n) in enumerate(_commands() if variant is None else _commands()[:10]):
            ros.step([mode], [value], n)
            inproc.step([mode], [value], n)
            state = compare("seed %d step %d" % (seed, k))
            dropped_seen |= bool(state["dropped"][0])
            pressed_seen += int(state["in_contact"].all())
    # The measured equivalence, printed for the record (pytest -s) and bounded.
    print("\nRosBackend vs InProcessBackend over %d sensor frames: differing pixels per frame "
          "max %.6f mean %.6f, max difference %d grey levels"
          % (frames, max(differing), float(np.mean(differing)), worst))
    assert dropped_seen, "the script should drop the cube (a state worth comparing)"
    assert pressed_seen >= 20, "the script should hold the cube with both gels"
    # The held cube's weight drags the gels: the markers move (else their equality says little).
    assert max(moved) > 0.01, max(moved)
    # The variant did reach the ROS renderers: the same episode start in variant 0 looks different
    # (and again equal in-process).
    seed, offset, _ = episodes[1]
    ros.reset(0, seed, offset, 2)
    inproc.reset(0, seed, offset, 2)
    textured = ros.images("left")
    ros.reset(0, seed, offset, 0)
    inproc.reset(0, seed, offset, 0)
    assert not np.array_equal(ros.images("left"), textured)
    assert np.array_equal(ros.images("left"), inproc.images("left"))
    assert max(differing) <= MAX_DIFFERING_PIXEL_FRACTION
    assert worst <= MAX_PIXEL_DIFFERENCE


def test_refusals_carry_contact_sims_reasons(backends):
    import norm2tex
    from norm2tex.envs.commands import ABSOLUTE

    ros, inproc = backends
    ros.reset(0, 5)
    before = ros.state()
    low, high = inproc.height_offset_range
    with pytest.raises(norm2tex.Error) as in_process:
        inproc.reset(0, 5, high + 0.01)
    with pytest.raises(norm2tex.Error) as over_ros:
        ros.reset(0, 5, high + 0.01)
    assert str(over_ros.value).startswith("~reset refused: ")
    assert str(in_process.value) in str(over_ros.value)
    with pytest.raises(norm2tex.Error, match=r"~step refused, nothing changed: gripper opening "
                                             r"1\.5 is out of range; valid: \[0, 1\]"):
        ros.step([ABSOLUTE], [1.5])
    after = ros.state()
    for key in before:
        assert np.array_equal(before[key], after[key]), key  # nothing changed
    with pytest.raises(norm2tex.Error, match="noise seed 7 asked.*noise_seed:=7"):
        ros.set_noise_seed(0, 7)
    ros.set_noise_seed(0, None)  # the launch's (noise_seed:=-1)
    with pytest.raises(norm2tex.Error, match="variant"):
        ros.reset(0, 5, None, 100001)


def test_reset_refuses_an_unknown_texture(backends):
    import rospy
    from norm2tex.srv import Reset, ResetRequest

    reset = rospy.ServiceProxy("/contact_sim/reset", Reset)
    r = reset(ResetRequest(seed=1, height_offset=float("nan"), set_texture=True,
                           material="no_such_material", variant=1))
    assert not r.success
    assert r.message.startswith("~reset refused: ") and "no_such_material" in r.message


def test_no_system_is_a_clear_error(ros_system):
    import norm2tex
    from norm2tex.envs.ros_backend import RosBackend

    with pytest.raises(norm2tex.Error, match="start: roslaunch norm2tex gripper_sim.launch "
                                             "mode:=synchronous"):
        RosBackend(namespace="/nowhere", service_timeout_s=0.5)


def test_the_environment_is_the_same_over_both_backends(backends, sensor_yaml):
    """GripperEnv over ROS and in-process: same seeds and actions, the same observations."""
    from norm2tex.envs import GripperEnv

    over_ros = GripperEnv(backend="ros", noise=False, sensor=sensor_yaml, markers=True,
                          ros_options={"service_timeout_s": 40.0})
    in_process = GripperEnv(noise=False, sensor=sensor_yaml, markers=True)
    assert over_ros.observation_space.keys() == in_process.observation_space.keys()
    assert over_ros.observation_space["markers_left"].shape == (63, 2)
    actions = np.random.default_rng(1).integers(0, 3, size=25)
    for seed in (1, 2):
        a, info_a = over_ros.reset(seed=seed)
        b, info_b = in_process.reset(seed=seed)
        assert info_a["variant"] == info_b["variant"] and info_a["seed"] == info_b["seed"]
        for step, action in enumerate(actions):
            for key in b:
                assert np.array_equal(a[key], b[key]), (seed, step, key)
            a, reward_a, done_a, cut_a, info_a = over_ros.step(int(action))
            b, reward_b, done_b, cut_b, info_b = in_process.step(int(action))
            assert (reward_a, done_a, cut_a) == (reward_b, done_b, cut_b)
            assert info_a["finger_opening"] == info_b["finger_opening"]
    over_ros.close()
    in_process.close()


def test_an_environment_unlike_the_running_system_is_refused(backends):
    from norm2tex.envs import GripperEnv, HoldCubeEnv

    with pytest.raises(ValueError, match="scene hold_cube .*launch with scene:="):
        HoldCubeEnv(backend="ros", ros_options={"service_timeout_s": 40.0})
    with pytest.raises(ValueError, match="material fabric"):
        GripperEnv(backend="ros", material="fabric", ros_options={"service_timeout_s": 40.0})


def test_the_next_variant_is_announced_to_the_renderers(backends):
    """reset(..., next_variant=v): this episode's frames name v as the next texture (the
    renderers prepare it meanwhile); a reset without it announces nothing."""
    import threading

    import rospy
    from norm2tex.msg import SimFrame

    ros, _ = backends
    frames = []
    arrived = threading.Condition()

    def keep(msg):
        with arrived:
            frames.append(msg)
            arrived.notify_all()

    sub = rospy.Subscriber("/contact_sim/frame", SimFrame, keep, queue_size=100)
    deadline = time.monotonic() + 20.0
    while sub.get_num_connections() < 1:
        assert time.monotonic() < deadline, "no connection to /contact_sim/frame"
        time.sleep(0.01)

    def frame_of(episode):
        with arrived:
            ok = arrived.wait_for(lambda: any(f.episode == episode for f in frames),
                                  timeout=max(deadline - time.monotonic(), 0.1))
            assert ok, "no frame of episode %d" % episode
            return [f for f in frames if f.episode == episode][0]

    try:
        start = ros.reset(0, 21, None, 1, next_variant=7)
        frame = frame_of(start["episode"])
        assert (frame.material, frame.variant) == ("wood", 1)
        assert (frame.next_material, frame.next_variant) == ("wood", 7)
        start = ros.reset(0, 22, None, 7)
        frame = frame_of(start["episode"])
        assert (frame.variant, frame.next_material) == (7, "")
    finally:
        sub.unregister()
