"""norm2tex.HandSim, TactileHand and norm2tex.envs.HandEnv: any hand from its URDF with DIGITs, from
Python (pytest), against TACTO's WSG-50 and Allegro (test/fixtures/robots)."""

import os

import numpy as np
import pytest

import norm2tex
from norm2tex.envs import HandEnv

ROBOTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "robots")
# The WSG-50 upside down over the floor, its gel centres 15 mm above it: a 30 mm cube resting
# on the floor between its fingers is grasped by closing them.
WSG_TOP = os.path.join(ROBOTS, "wsg50", "wsg50_top_grasp.yaml")
ALLEGRO = os.path.join(ROBOTS, "allegro_hand_description", "allegro_hand.yaml")
CUBE_ON_FLOOR = [0.0, 0.0, 0.015]
WSG_JOINTS = ["base_joint_gripper_left", "base_joint_gripper_right"]


def wsg_env(**kwargs):
    args = dict(object="box:30x30x30", object_pose=CUBE_ON_FLOOR, material=None, frames_per_step=10)
    args.update(kwargs)
    return HandEnv(WSG_TOP, **args)


def test_hand_sim_bindings_command_joints_and_report_contacts():
    config = norm2tex.HandSimConfig(norm2tex.HandConfig.load(WSG_TOP))
    config.object.mesh = "box:30x30x30"
    config.object_pose = ([0.0, 0.0, 0.015], [0.0, 0.0, 0.0, 1.0])
    sim = norm2tex.HandSim(config)
    assert sim.actuated_joints == WSG_JOINTS
    assert sim.sensor_names == ["digit_left", "digit_right"]
    np.testing.assert_allclose(sim.joint_positions(), [-0.040, 0.040])
    lower, upper = sim.joint_limits()
    np.testing.assert_allclose(lower, [-0.055, 0.0027])
    np.testing.assert_allclose(upper, [-0.0027, 0.055])
    # Clamped to the URDF's limits and named; refused with the reason, nothing changed.
    assert sim.set_joint_targets({"base_joint_gripper_left": -0.2}) == ["base_joint_gripper_left"]
    np.testing.assert_allclose(sim.joint_targets(), [-0.055, 0.040])
    with pytest.raises(norm2tex.Error, match="unknown joint 'thumb'"):
        sim.set_joint_targets(["thumb"], [0.0])
    with pytest.raises(norm2tex.Error, match="not finite"):
        sim.set_joint_targets(WSG_JOINTS, [float("nan"), 0.0])
    with pytest.raises(norm2tex.Error, match="not after the previous point"):
        sim.set_trajectory(WSG_JOINTS, [0.5, 0.5], [[-0.04, 0.04], [-0.03, 0.03]])
    np.testing.assert_allclose(sim.joint_targets(), [-0.055, 0.040])
    # A trajectory, ending on its target (the drives move at most 20 mm/s).
    sim.set_trajectory(WSG_JOINTS, [0.5], [[-0.032, 0.032]])
    sim.step(1500)
    np.testing.assert_allclose(sim.joint_positions(), [-0.032, 0.032], atol=1e-7)
    assert not sim.contact("digit_left")["in_contact"]
    # Closed on the cube: both gels pressed, the force each drive's effort (10 N).
    sim.set_opening(0.0)
    sim.step(1500)
    for name in sim.sensor_names:
        c = sim.contact(name)
        assert c["in_contact"], name
        assert c["normal_force_n"] == pytest.approx(10.0, rel=0.05)
        gel = sim.gel_in_world(name)
        np.testing.assert_allclose(np.linalg.inv(gel) @ sim.object_in_world(), c["object_in_gel"],
                                   atol=1e-9)
    assert sim.contact(0)["normal_force_n"] == sim.contact("digit_left")["normal_force_n"]
    with pytest.raises(KeyError, match="digit_middle"):
        sim.contact("digit_middle")
    with pytest.raises(IndexError, match=r"\[0, 1\]"):
        sim.contact(2)
    # Reset: joints back, the object at rest where it was put.
    sim.reset(np.array([[1, 0, 0, 0], [0, 1, 0, 0.5], [0, 0, 1, 0.015], [0, 0, 0, 1.0]]))
    np.testing.assert_allclose(sim.joint_positions(), [-0.040, 0.040])
    np.testing.assert_allclose(sim.object_in_world()[:3, 3], [0.0, 0.5, 0.015], atol=1e-9)


def test_contacts_carry_the_twist_that_holds_a_cube_gripped_off_its_centre():
    # The built-in parallel gripper holds the 30 mm cube 4 mm off its centre along world x: its
    # weight m g dx turns it about the grip axis (world y), and only the gels' twist holds it
    # (the core's GelTwistMoment test, here through the bindings' contact dicts).
    scene = norm2tex.SceneConfig.load(norm2tex.scene_config("cube"))
    config = norm2tex.HandSimConfig(norm2tex.config_path("hands", "parallel_gripper.yaml"), scene)
    dx = 0.004
    config.object_pose = ([dx, 0.0, 0.2], [0.0, 0.0, 0.0, 1.0])
    sim = norm2tex.HandSim(config)
    sim.reset_object(config.object_pose, False)
    sim.set_opening(0.0)
    sim.step(1500)
    sim.set_object_gravity(True)
    sim.step(1000)
    weight_moment = scene.object.mass_kg * scene.physics.gravity_m_s2 * dx
    about_grip_axis = []
    for name in sim.sensor_names:
        c = sim.contact(name)
        assert c["in_contact"], name
        assert c["pressure_centre_m"].shape == (2,)
        # The pads are smaller than the cube's faces: the gels press about their own centres.
        assert np.abs(c["pressure_centre_m"]).max() < 2e-3, (name, c["pressure_centre_m"])
        about_grip_axis.append(c["twist_moment_nm"] * sim.gel_in_world(name)[1, 2])
    for twist in about_grip_axis:
        assert twist == pytest.approx(0.5 * weight_moment, rel=0.2)
    assert sum(about_grip_axis) == pytest.approx(weight_moment, rel=0.05)


def test_tactile_hand_renders_one_image_per_digit_of_the_allegro():
    config = norm2tex.HandSimConfig(ALLEGRO)
    config.object.mesh = "sphere:10"
    config.object_pose = ([0.5, 0.0, 0.01], [0.0, 0.0, 0.0, 1.0])  # out of reach
    options = norm2tex.TactileHandOptions()
    options.noise_seed = -1
    hand = norm2tex.TactileHand(config, norm2tex.SensorModel(), options)
    assert hand.sensor_names == ["digit_index", "digit_middle", "digit_ring", "digit_thumb"]
    hand.step(3)
    images = hand.images()
    assert list(images) == hand.sensor_names
    for i, name in enumerate(hand.sensor_names):
        assert images[name].shape == (320, 240, 3) and images[name].dtype == np.uint8
        # Untouched, without noise: the background exactly.
        np.testing.assert_array_equal(hand.frame(i), hand.background(name))
        # A copy, the caller's to keep.
        images[name][:] = 0
        assert hand.frame(name).any()
    assert hand.frame_index * hand.ticks_per_frame == hand.sim.ticks
    with pytest.raises(norm2tex.Error, match=r"step frames = 0"):
        hand.step(0)


def test_spaces_are_the_hands():
    env = wsg_env()
    assert env.actuated_joints == WSG_JOINTS
    assert set(env.observation_space.keys()) == {"digit_left", "digit_right", "joint_positions"}
    assert env.observation_space["digit_left"].shape == (320, 240, 3)
    assert env.observation_space["digit_left"].dtype == np.uint8
    np.testing.assert_allclose(env.action_space.low, [-0.055, 0.0027], rtol=1e-6)
    np.testing.assert_allclose(env.action_space.high, [-0.0027, 0.055], rtol=1e-6)
    assert env.action_space.dtype == np.float32
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs), {k: (v.dtype, v.shape) for k, v in obs.items()}
    np.testing.assert_allclose(obs["joint_positions"], [-0.040, 0.040], rtol=1e-6)
    for _ in range(3):
        action = env.action_space.sample()
        obs, reward, terminated, truncated, info = env.step(action)
        assert env.observation_space.contains(obs)
        assert reward == 0.0 and not terminated
    delta = wsg_env(action="delta", max_delta=0.002)
    np.testing.assert_allclose(delta.action_space.high, [0.002, 0.002], rtol=1e-6)
    # The Allegro: 16 joints, four images.
    allegro = HandEnv(ALLEGRO, object="sphere:10", object_pose=[0.5, 0, 0.01], material=None)
    assert allegro.action_space.shape == (16,)
    assert [k for k in allegro.observation_space.keys() if k.startswith("digit_")] == [
        "digit_index", "digit_middle", "digit_ring", "digit_thumb"]
    obs, _ = allegro.reset(seed=0)
    assert allegro.observation_space.contains(obs)


def test_reset_with_the_same_seed_gives_the_same_observations():
    env = wsg_env()
    close = np.array([-0.016, 0.016], dtype=np.float32)

    def rollout(seed):
        obs, info = env.reset(seed=seed)
        out = [obs]
        for _ in range(4):
            out.append(env.step(close)[0])
        return out

    a, b = rollout(5), rollout(5)
    for x, y in zip(a, b):
        assert x.keys() == y.keys()
        for k in x:
            np.testing.assert_array_equal(x[k], y[k], err_msg=k)
    # The object is back at its pose after a reset, whatever the episode before did.
    env.reset(seed=5)
    np.testing.assert_allclose(env.backend.state()["object_in_world"][:3, 3], CUBE_ON_FLOOR,
                               atol=1e-9)


def test_noise_follows_the_seed(tmp_path):
    # A synthetic background: noise drawn on every frame from the episode's seed.
    sensor = str(tmp_path / "synthetic.yaml")
    norm2tex.SensorModel().save(sensor)
    env = wsg_env(sensor=sensor)
    a = env.reset(seed=3)[0]["digit_left"]
    b = env.reset(seed=3)[0]["digit_left"]
    c = env.reset(seed=4)[0]["digit_left"]
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    off = wsg_env(sensor=sensor, noise=False)
    np.testing.assert_array_equal(off.reset(seed=3)[0]["digit_left"],
                                  off.backend.background("digit_left"))


def test_closing_the_wsg_changes_both_images_where_it_presses():
    env = wsg_env()
    obs, info = env.reset(seed=0)
    start = {k: obs[k].astype(np.int16) for k in ("digit_left", "digit_right")}
    # Closing 24 mm at 20 mm/s takes 1.2 s: 9 steps of 10 frames are 1.5 s.
    for _ in range(9):
        obs, reward, terminated, truncated, info = env.step(np.array([-0.016, 0.016], np.float32))
    for name in ("digit_left", "digit_right"):
        c = info["contacts"][name]
        assert c["in_contact"] and c["normal_force_n"] == pytest.approx(10.0, rel=0.05), name
        # Over the whole image: the cube's face covers the pad, pressed ~1 mm; most of the
        # change is the flat press's (a few grey levels), the rest its edges.
        changed = np.abs(obs[name].astype(np.int16) - start[name]).mean()
        assert changed > 3.0, (name, changed)
    # The fingers stopped at the cube (its faces 15 mm from the centre, pressed ~1 mm into the
    # gels whose surfaces lie 16 mm from the joints' origin), short of their targets.
    assert np.all(np.abs(obs["joint_positions"]) > 0.016 + 0.010)
    # Out of reach: closing changes nothing but the noise (none on the captured background).
    far = wsg_env(object_pose=[0.0, 0.5, 0.015])  # to the side (docs/hands.md)
    obs0, _ = far.reset(seed=0)
    for _ in range(9):
        obs, *_ = far.step(np.array([-0.016, 0.016], np.float32))
    for name in ("digit_left", "digit_right"):
        np.testing.assert_array_equal(obs[name], obs0[name])


def test_markers_of_the_wsg_stay_put_under_a_squeeze_on_a_resting_cube(tmp_path):
    """The WSG-50 squeezing the cube that rests on the table: the gels press it (10 N), the
    table carries its weight, so the tangential load is a few mN and the markers move by
    micrometres, on average along that load; observed per sensor. A sensor without markers is
    refused."""
    model = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    model.markers_enabled = True
    marked = str(tmp_path / "marked.yaml")
    model.save(marked)
    env = wsg_env(sensor=marked, markers=True)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    for _ in range(9):
        obs, reward, terminated, truncated, info = env.step(np.array([-0.016, 0.016], np.float32))
    for name in ("digit_left", "digit_right"):
        moved = obs[name + "_markers"]
        assert moved.shape == (63, 2) and moved.dtype == np.float32
        contact = info["contacts"][name]
        assert contact["in_contact"]
        shear = np.asarray(contact["shear_force_n"][:2])
        assert 1e-4 < np.linalg.norm(shear) < 0.1, shear  # N: the table holds the cube
        mean = moved.mean(axis=0)
        assert np.dot(mean, shear) / (np.linalg.norm(mean) * np.linalg.norm(shear)) > 0.95
        assert np.abs(moved).max() < 0.01  # mm
    with pytest.raises(ValueError, match="marker grid"):
        wsg_env(markers=True)


def test_delta_actions_move_from_the_joint_positions():
    env = wsg_env(action="delta", max_delta=0.005, frames_per_step=30)  # 0.5 s: 10 mm possible
    obs, _ = env.reset(seed=0)
    obs, *_ , info = env.step(np.array([0.004, -0.004], np.float32))
    np.testing.assert_allclose(obs["joint_positions"], [-0.036, 0.036], atol=1e-6)
    # Clipped to max_delta, named.
    obs, *_, info = env.step(np.array([0.02, 0.0], np.float32))
    assert info["clipped"] == ["base_joint_gripper_left"]
    np.testing.assert_allclose(obs["joint_positions"], [-0.031, 0.036], atol=1e-6)


def check_bad_actions_are_refused(env):
    """A WSG-50 HandEnv (either backend) refuses bad actions with the reason, nothing moved, and
    clips out-of-range ones, naming them (test_hand_ros_backend.py uses it too)."""
    env.reset(seed=0)
    before = env.backend.state()
    with pytest.raises(ValueError, match=r"action of shape \(3,\); valid: \(2,\)"):
        env.step(np.zeros(3, np.float32))
    with pytest.raises(ValueError, match="action for base_joint_gripper_right is not finite"):
        env.step(np.array([-0.02, np.nan], np.float32))
    with pytest.raises(ValueError, match="not numbers"):
        env.step(["close", "open"])
    after = env.backend.state()
    np.testing.assert_array_equal(after["joint_targets"], before["joint_targets"])
    assert after["frame"] == before["frame"]
    # Out of the Box: clipped to the limits, named.
    obs, _, _, _, info = env.step(np.array([-1.0, 0.03], np.float32))
    assert info["clipped"] == ["base_joint_gripper_left"]
    np.testing.assert_allclose(info["joint_targets"], [-0.055, 0.03], rtol=1e-6)


def test_bad_actions_are_refused_with_a_clear_error():
    env = wsg_env()
    check_bad_actions_are_refused(env)
    with pytest.raises(ValueError, match="action = 'velocity'; valid: position, delta"):
        wsg_env(action="velocity")
    with pytest.raises(ValueError, match="backend = 'gazebo'; valid: inprocess, ros"):
        wsg_env(backend="gazebo")
    with pytest.raises(ValueError, match="reset options"):
        env.reset(options={"height": 1})


def test_reward_callable_and_truncation():
    seen = []

    def reward(obs, info):
        seen.append(info["steps"])
        return sum(c["normal_force_n"] for c in info["contacts"].values())

    env = wsg_env(reward=reward, max_steps=9)
    env.reset(seed=0)
    close = np.array([-0.016, 0.016], np.float32)
    for step in range(1, 10):
        obs, r, terminated, truncated, info = env.step(close)
        assert truncated == (step == 9) and not terminated
    assert seen == list(range(1, 10))
    assert r == pytest.approx(20.0, rel=0.05)  # two gels at 10 N each
