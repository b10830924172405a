"""norm2tex._core against the C++ tools and analytic expectations (pytest).

Needs the devel (or install) space's environment: `import norm2tex` must find the compiled
module. NORM2TEX_TOOLS_DIR (default: beside the devel space's lib/norm2tex) holds norm2tex_render.
"""

import json
import math
import os
import statistics
import subprocess
import tempfile

import numpy as np
import pytest

import norm2tex

TOOLS_DIR = os.environ.get("NORM2TEX_TOOLS_DIR", "")
POSE_TEXT = "0.001 -0.002 0.015 0.05 -0.03 0.4"  # x y z roll pitch yaw: metres, radians
PRESS_MM = 1.0


def pose_matrix(x, y, z, roll, pitch, yaw):
    """The CLI's --pose: R = Rz(yaw) Ry(pitch) Rx(roll), as 4x4."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    m[:3, 3] = (x, y, z)
    return m


def read_png(path):
    """An 8-bit PNG as (rows, cols, 3) bgr: through the package's own renderer-free reader."""
    from PIL import Image

    rgb = np.asarray(Image.open(path).convert("RGB"))
    return np.ascontiguousarray(rgb[..., ::-1])


@pytest.fixture(scope="module")
def sensor():
    return norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))


@pytest.fixture(scope="module")
def cube():
    return norm2tex.load_object_mesh("box:30x30x30")["mesh"]


def test_render_equals_the_cli_frame_bit_for_bit(sensor, cube, tmp_path):
    tool = os.path.join(TOOLS_DIR, "norm2tex_render")
    if not os.path.exists(tool):
        pytest.skip("norm2tex_render not found in NORM2TEX_TOOLS_DIR=%r" % TOOLS_DIR)
    out = str(tmp_path / "cli.png")
    depth_out = str(tmp_path / "cli_depth.tiff")
    subprocess.run([tool, "--mesh", "box:30x30x30", "--pose", POSE_TEXT, "--press-mm",
                    str(PRESS_MM), "--material", "wood", "--seed", "7", "--sensor",
                    norm2tex.config_path("digit.yaml"), "-o", out, "--depth-out", depth_out],
                   check=True, capture_output=True)
    atlas, mesh, beta_mm, _ = norm2tex.material_texture(norm2tex.material_config("wood"), cube,
                                                         variant=0, seed=7)
    renderer = norm2tex.TactileRenderer(sensor)
    assert renderer.set_object(mesh, atlas, beta_mm) == ""
    values = [float(v) for v in POSE_TEXT.split()]
    values[2] -= PRESS_MM * 1e-3
    frame = renderer.render(pose_matrix(*values), noise_seed=7)
    assert frame.textured
    assert frame.image.shape == (320, 240, 3) and frame.image.dtype == np.uint8
    assert frame.depth.dtype == np.float32 and frame.contact_mask.dtype == np.uint8
    cli = read_png(out)
    assert np.count_nonzero(frame.contact_mask) > 1000  # a real press, not an empty frame
    np.testing.assert_array_equal(frame.image, cli)


def test_quaternion_pose_equals_the_matrix(sensor, cube):
    renderer = norm2tex.TactileRenderer(sensor)
    renderer.set_object(cube)
    m = pose_matrix(0.0, 0.0, 0.0145, 0.0, 0.0, math.pi / 2)
    a = renderer.render(m).image
    b = renderer.render(((0.0, 0.0, 0.0145), (0.0, 0.0, math.sin(math.pi / 4),
                                               math.cos(math.pi / 4)))).image
    # The quaternion's matrix may differ from the product of axis rotations in the last bit.
    assert np.mean(a != b) < 1e-3


def test_a_ball_press_matches_hertz_geometry(sensor):
    ball = norm2tex.load_object_mesh("sphere:10")["mesh"]
    renderer = norm2tex.TactileRenderer(sensor)
    renderer.set_object(ball)
    px_mm2 = sensor.mm_per_pixel**2
    for press_mm in (0.3, 0.6, 1.0):
        frame = renderer.render(pose_matrix(0.0, 0.0, 0.010 - press_mm * 1e-3, 0, 0, 0))
        area_mm2 = np.count_nonzero(frame.contact_mask) * px_mm2
        # A sphere of radius R cut at depth d: a disc of radius sqrt(2 R d - d^2).
        expected = math.pi * (2 * 10.0 * press_mm - press_mm**2)
        assert area_mm2 == pytest.approx(expected, rel=0.05)
        # The gel's deepest point is the press itself (the smoothing keeps the contact core).
        assert float(frame.depth.max()) == pytest.approx(press_mm * 1e-3, rel=0.03)


def test_a_shear_load_moves_the_gel_and_its_markers_from_python(sensor):
    marked = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    marked.markers_enabled = True
    ball = norm2tex.load_object_mesh("sphere:6")["mesh"]
    renderer = norm2tex.TactileRenderer(marked)
    renderer.set_object(ball)
    pose = pose_matrix(0.0, 0.0, 0.006 - 1e-3, 0, 0, 0)
    pressed = renderer.render(pose, normal_force_n=3.0)
    assert pressed.shear is None and pressed.slip_fraction is None
    assert pressed.markers is not None
    np.testing.assert_array_equal(pressed.markers["current_px"], pressed.markers["rest_px"])
    pushed = renderer.render(pose, normal_force_n=3.0, shear=norm2tex.ShearLoad((1.0, 0.0)))
    assert pushed.shear.shape == (320, 240, 2) and pushed.shear.dtype == np.float32
    centre = pushed.shear[160, 120]
    assert centre[0] > 1e-5 and abs(centre[1]) < 0.05 * centre[0]  # metres, along the push
    moved = pushed.markers["displacement_mm"]
    assert moved.shape == (63, 2) and moved[:, 0].max() > 0.05 and moved[:, 0].min() >= 0.0
    np.testing.assert_allclose(pushed.markers["current_px"] - pushed.markers["rest_px"],
                               moved / marked.mm_per_pixel, atol=1e-3)
    assert 0.0 < pushed.slip_fraction < 1.0
    sliding = renderer.render(pose, normal_force_n=3.0, shear=norm2tex.ShearLoad((4.0, 0.0), 0.0, 1.0))
    assert sliding.slip_fraction == 1.0  # 4 N beyond mu P = 3 N
    # Without markers a shear load leaves the DIGIT frame as it was.
    plain = norm2tex.TactileRenderer(sensor)
    plain.set_object(ball)
    np.testing.assert_array_equal(plain.render(pose, normal_force_n=3.0).image,
                                  plain.render(pose, normal_force_n=3.0,
                                               shear=norm2tex.ShearLoad((1.0, 0.5), 1e-3)).image)
    with pytest.raises(norm2tex.Error, match="finite"):
        renderer.render(pose, shear=norm2tex.ShearLoad((float("nan"), 0.0)))


def test_a_gelsight_mini_press_is_landscape_and_equals_the_cli_frame(tmp_path):
    """The second sensor from Python: its yaml's size, grid and gel, the press under the ball,
    and the very frame norm2tex_render --sensor draws."""
    mini = norm2tex.SensorModel.load(norm2tex.config_path("gelsight_mini.yaml"))
    assert (mini.rows, mini.cols) == (240, 320)
    assert mini.markers_enabled and mini.shear_modulus_mpa == pytest.approx(0.145)
    renderer = norm2tex.TactileRenderer(mini)
    renderer.set_object(norm2tex.load_object_mesh("sphere:4")["mesh"])
    frame = renderer.render(pose_matrix(0.002, -0.001, 0.004 - 1e-3, 0, 0, 0), noise_seed=3)
    assert frame.image.shape == (240, 320, 3) and frame.depth.shape == (240, 320)
    rows, cols = np.nonzero(frame.contact_mask)
    assert cols.mean() == pytest.approx(159.5 + 2.0 / mini.mm_per_pixel, abs=1.5)
    assert rows.mean() == pytest.approx(119.5 - 1.0 / mini.mm_per_pixel, abs=1.5)
    assert frame.markers["rest_px"].shape == (63, 2)  # 7 x 9
    tool = os.path.join(TOOLS_DIR, "norm2tex_render")
    if not os.path.exists(tool):
        pytest.skip("norm2tex_render not found in NORM2TEX_TOOLS_DIR=%r" % TOOLS_DIR)
    out = str(tmp_path / "mini.png")
    subprocess.run([tool, "--mesh", "sphere:4", "--pose", "0.002 -0.001 0.004 0 0 0",
                    "--press-mm", "1", "--seed", "3", "--sensor",
                    norm2tex.config_path("gelsight_mini.yaml"), "-o", out],
                   check=True, capture_output=True)
    np.testing.assert_array_equal(frame.image, read_png(out))


def test_errors_carry_the_cpp_message(sensor, cube):
    with pytest.raises(norm2tex.Error, match="/no/such/mesh.obj"):
        norm2tex.load_object_mesh("/no/such/mesh.obj")
    renderer = norm2tex.TactileRenderer(sensor)
    renderer.set_object(cube)
    nan_pose = np.eye(4)
    nan_pose[0, 3] = float("nan")
    with pytest.raises(norm2tex.Error, match="finite"):
        renderer.render(nan_pose)
    with pytest.raises(ValueError, match="valid: .*wood"):
        norm2tex.material_config("granite")
    with tempfile.NamedTemporaryFile("w", suffix=".yaml") as bad:
        bad.write("material: wood\nbeta_mm: 7\n")
        bad.flush()
        with pytest.raises(norm2tex.Error, match="beta_mm"):
            norm2tex.MaterialConfig.load(bad.name)
    with pytest.raises(ValueError, match="4x4"):
        renderer.render(np.eye(3))
    with pytest.raises(norm2tex.Error, match="no object"):
        norm2tex.TactileRenderer(sensor).render(np.eye(4))
    # The exception type is RuntimeError's, so code catching RuntimeError still works.
    assert issubclass(norm2tex.Error, RuntimeError)


def test_gripper_sim_is_deterministic_and_refuses_bad_offsets(sensor):
    scene = norm2tex.SceneConfig.load(norm2tex.scene_config("cube"))

    def run():
        sim = norm2tex.GripperSim(scene, sensor)
        start = sim.reset(3)
        sim.set_opening(0.6)
        sim.step(200)
        return start, sim.object_in_world(), sim.contact("left")

    a, b = run(), run()
    assert a[0] == b[0]
    np.testing.assert_array_equal(a[1], b[1])
    assert a[2]["normal_force_n"] == b[2]["normal_force_n"] > 0.0
    sim = norm2tex.GripperSim(scene, sensor)
    low, high = sim.height_offset_range
    with pytest.raises(norm2tex.Error, match="offset"):
        sim.reset(0, high + 0.01)
    with pytest.raises(ValueError, match="left, right"):
        sim.contact("middle")


def test_no_leak_over_ten_thousand_renders(sensor, cube):
    renderer = norm2tex.TactileRenderer(sensor)
    atlas, mesh, beta_mm, _ = norm2tex.material_texture(norm2tex.material_config("wood"), cube)
    renderer.set_object(mesh, atlas, beta_mm)
    pose = pose_matrix(0.0, 0.0, 0.0142, 0.1, 0.0, 0.0)

    def rss_kib():
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    for _ in range(200):  # warm: buffers and allocator arenas reach their size
        renderer.render(pose, noise_seed=1)
    before = rss_kib()
    for i in range(10000):
        frame = renderer.render(pose, noise_seed=i)
    after = rss_kib()
    assert frame.image.shape == (320, 240, 3)
    # A leak of one frame's copies (image, depth, mask: ~620 kB) per render would be 6 GB.
    assert after - before < 20 * 1024, "RSS grew by %d KiB over 10 000 renders" % (after - before)


def test_height_atlas_round_trip_and_bake():
    heights = np.linspace(-1, 1, 64 * 32, dtype=np.float32).reshape(32, 64)
    atlas = norm2tex.HeightAtlas(heights)
    np.testing.assert_array_equal(atlas.heights, heights)
    assert atlas.shape == (32, 64)
    # Texel centre (row 0, column 0) is u = 0.5 / 64, v = 1 - 0.5 / 32.
    assert atlas.sample(0.5 / 64, 1 - 0.5 / 32) == pytest.approx(heights[0, 0])
    with pytest.raises(ValueError, match="dtype"):
        norm2tex.HeightAtlas(heights.astype(np.float64))


def test_calibration_equals_the_cli_on_real_presses(sensor, tmp_path):
    """norm2tex_calibrate's fit from Python, on 15 real DIGIT presses (test/fixtures/digit_s09)."""
    tool = os.path.join(TOOLS_DIR, "norm2tex_calibrate")
    if not os.path.exists(tool):
        pytest.skip("norm2tex_calibrate not found in NORM2TEX_TOOLS_DIR=%r" % TOOLS_DIR)
    fixtures = os.path.join(os.path.dirname(__file__), "..", "fixtures", "digit_s09")
    presses = [os.path.join(fixtures, "frame_%d.jpg" % i) for i in range(0, 30, 2)]
    background = os.path.join(fixtures, "frame_30.jpg")
    yaml_path = str(tmp_path / "cli.yaml")
    json_path = str(tmp_path / "cli.json")
    subprocess.run([tool, "--background", background, "--presses"] + presses +
                   ["--ball-diameter-mm", "6", "--mm-per-pixel", "0.0532", "-o", yaml_path,
                    "--json", json_path],
                   check=True, capture_output=True)
    cli = norm2tex.SensorModel.load(yaml_path)
    fit = norm2tex.calibrate_sensor(
        norm2tex.SensorModel(), [norm2tex.read_image(background)],
        [norm2tex.read_image(p) for p in presses], ball_diameter_mm=6.0, mm_per_pixel=0.0532)
    model = fit["model"]
    assert model.mm_per_pixel == 0.0532
    # The yaml holds the CLI's response at the precision it writes; the fit is the same fit.
    np.testing.assert_allclose(model.shading_response_bgr, cli.shading_response_bgr,
                               rtol=1e-6, atol=1e-6)
    assert fit["training_presses"] + fit["held_out_presses"] == 15
    # It reproduces presses it was not fitted on (the package's documented quality: > 0.8).
    assert fit["variance_explained"] > 0.8
    # The CLI's --json report: strict JSON (no NaN or Infinity), the same fit's figures.
    with open(json_path) as f:
        report = json.load(f, parse_constant=lambda name: pytest.fail("JSON has " + name))
    assert report["held_out"]["variance_explained"] == pytest.approx(fit["variance_explained"])
    assert [p["image"] for p in report["presses"]] == presses
    held_out = [p for p in report["presses"] if p["held_out"]]
    assert len(held_out) == len(fit["held_out_frames"]) == fit["held_out_presses"]
    for key in ("ssim", "contact_ssim", "psnr_db", "mean_abs_diff"):
        median = report["held_out"]["median"][key]
        assert median == statistics.median(p[key] for p in held_out), key
        assert fit["median_" + key] == pytest.approx(median, rel=1e-6), key
        assert [f[key] for f in fit["held_out_frames"]] == pytest.approx(
            [p[key] for p in held_out], rel=1e-6), key
    # The goal on held-out presses, and the press clearly better than no press in the contact.
    assert report["held_out"]["median"]["ssim"] >= 0.90
    assert (report["held_out"]["median"]["contact_ssim"]
            > report["held_out"]["median_bare_background"]["contact_ssim"] + 0.04)
    with pytest.raises(norm2tex.Error, match="press"):
        norm2tex.calibrate_sensor(norm2tex.SensorModel(), [norm2tex.read_image(background)],
                                  [norm2tex.read_image(presses[0])], ball_diameter_mm=6.0)
    with pytest.raises(norm2tex.Error, match="nothing.jpg"):
        norm2tex.read_image(os.path.join(fixtures, "nothing.jpg"))


def test_compare_images_against_closed_forms_and_scikit_image():
    """norm2tex.compare_images: perfect on itself, the closed form of constant images, exact PSNR
    of alternating noise, a clear error for images of different shapes."""
    rng = np.random.default_rng(3)
    a = rng.integers(0, 256, (40, 30, 3), dtype=np.uint8)
    same = norm2tex.compare_images(a, a)
    assert same["ssim"] == pytest.approx(1.0) and same["psnr_db"] == math.inf
    c1 = (0.01 * 255) ** 2
    grey = norm2tex.compare_images(np.full((16, 12), 100, np.uint8), np.full((16, 12), 150, np.uint8))
    assert grey["ssim"] == pytest.approx((2 * 100 * 150 + c1) / (100 ** 2 + 150 ** 2 + c1))
    assert grey["mean_abs_diff"] == pytest.approx(50.0)
    noisy = np.full((20, 30, 3), 128, np.uint8)
    noisy[::2, ::2] += 5
    noisy[1::2, 1::2] += 5
    noisy[::2, 1::2] -= 5
    noisy[1::2, ::2] -= 5
    flat = np.full_like(noisy, 128)
    assert norm2tex.compare_images(flat, noisy)["psnr_db"] == pytest.approx(
        10 * math.log10(255 ** 2 / 25))
    with pytest.raises(norm2tex.Error, match="differ"):
        norm2tex.compare_images(a, a[:, :20])


def test_compare_images_equals_scikit_image():
    """Where scikit-image is installed (it is not a dependency): its SSIM and PSNR, exactly."""
    skimage_metrics = pytest.importorskip("skimage.metrics")
    rng = np.random.default_rng(4)
    a = rng.integers(0, 256, (40, 30, 3), dtype=np.uint8)
    b = np.clip(a.astype(int) + rng.integers(-30, 31, a.shape), 0, 255).astype(np.uint8)
    mask = np.zeros((40, 30), np.uint8)
    mask[10:25, 8:20] = 1  # inside the 5 px border that SSIM's mean leaves out
    measured = norm2tex.compare_images(a, b, mask)
    expected, full = skimage_metrics.structural_similarity(
        a, b, channel_axis=2, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
        data_range=255, full=True)
    assert measured["ssim"] == pytest.approx(expected, abs=1e-12)
    assert measured["ssim_in_mask"] == pytest.approx(full.mean(axis=2)[10:25, 8:20].mean(),
                                                     abs=1e-12)
    assert measured["psnr_db"] == pytest.approx(
        skimage_metrics.peak_signal_noise_ratio(a, b, data_range=255), abs=1e-12)


def test_conformity_from_python_follows_the_force(sensor, cube):
    """With the sensor's conformity on, a harder press of the same pose shows more texture;
    off, the force changes nothing."""
    atlas, mesh, beta_mm, _ = norm2tex.material_texture(norm2tex.material_config("wood"), cube)
    pose = pose_matrix(0.0, 0.0, 0.015 - 0.0008, 0.0, 0.0, 0.0)
    on = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    on.conformity_enabled = True
    textureless = norm2tex.TactileRenderer(on)
    textureless.set_object(mesh)
    flat = textureless.render(pose).image.astype(np.int16)
    rms = []
    for force in (1.0, 20.0):
        renderer = norm2tex.TactileRenderer(on)
        renderer.set_object(mesh, atlas, beta_mm)
        image = renderer.render(pose, normal_force_n=force).image.astype(np.int16)
        rms.append(float(np.sqrt(np.mean((image - flat) ** 2))))
    assert rms[0] < rms[1]
    assert sensor.conformity_enabled, "on by default"
    off_model = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    off_model.conformity_enabled = False
    off = norm2tex.TactileRenderer(off_model)
    off.set_object(mesh, atlas, beta_mm)
    np.testing.assert_array_equal(off.render(pose, normal_force_n=1.0).image,
                                  off.render(pose, normal_force_n=20.0).image)
    with pytest.raises(norm2tex.Error, match="force"):
        off.render(pose, normal_force_n=-1.0)


def numpy_block_mean(images, factor, background=None):
    """The reshape-mean the environments used before the core's block_mean (the reference)."""
    x = images if background is None else (
        images.astype(np.int16) - background.astype(np.int16)[None])
    n, rows, cols = x.shape[:3]
    rows, cols = rows // factor * factor, cols // factor * factor
    blocks = x[:, :rows, :cols].reshape((n, rows // factor, factor, cols // factor, factor, 3))
    return blocks.mean(axis=(2, 4), dtype=np.float32)


def test_core_block_mean_equals_numpy_bit_for_bit_and_refuses_bad_input():
    # The binding itself; norm2tex.block_mean (any array) sends bgr8 frames to it
    # (test_block_mean.py).
    core_block_mean = norm2tex._core.block_mean
    rng = np.random.default_rng(3)
    images = rng.integers(0, 256, size=(3, 61, 47, 3), dtype=np.uint8)
    background = rng.integers(0, 256, size=(61, 47, 3), dtype=np.uint8)
    for factor in (1, 2, 3, 4, 5):
        for bg in (None, background):
            expected = numpy_block_mean(images, factor, bg)
            got = core_block_mean(images, factor, bg)
            assert got.dtype == np.float32 and got.shape == expected.shape
            assert np.array_equal(got, expected), (factor, bg is None)
            # One image: the batch's first, without the batch axis.
            assert np.array_equal(core_block_mean(images[0], factor, bg), expected[0])
    # A non-contiguous batch (every other image) is read correctly too.
    assert np.array_equal(core_block_mean(images[::2], 4), numpy_block_mean(images[::2], 4))
    for bad in (dict(images=images.astype(np.int16), factor=2),
                dict(images=images[..., :2], factor=2),
                dict(images=images, factor=0),
                dict(images=images, factor=48),
                dict(images=images, factor=2, background=background[:60])):
        with pytest.raises(ValueError):
            core_block_mean(**bad)


def test_command_modes_are_one_set_of_values():
    # norm2tex.envs.commands, the core's OpeningCommand and the message's constants agree, and a
    # batch step refuses a mode outside them, naming the names.
    from norm2tex.envs import commands

    assert int(norm2tex.OpeningCommand.ABSOLUTE) == commands.ABSOLUTE
    assert int(norm2tex.OpeningCommand.DELTA) == commands.DELTA
    assert int(norm2tex.OpeningCommand.KEEP) == commands.KEEP
    try:
        from norm2tex.msg import GripperCommand
    except ImportError:
        pytest.skip("the generated messages are not on the path")
    assert GripperCommand.ABSOLUTE == commands.ABSOLUTE
    assert GripperCommand.DELTA == commands.DELTA
    assert len({commands.CLOSE, commands.STAY, commands.OPEN}) == 3


def test_a_batch_step_applies_each_mode_as_named(sensor):
    from norm2tex.envs.commands import ABSOLUTE, DELTA, KEEP

    scene = norm2tex.SceneConfig.load(norm2tex.scene_config("cube"))
    options = norm2tex.TactileGripperOptions()
    batch = norm2tex.TactileGripperBatch(scene, sensor, [options] * 3, threads=1)
    before = [batch.sim(i).commanded_opening for i in range(3)]
    batch.step([ABSOLUTE, DELTA, KEEP], [0.25, -0.5, 0.9])
    after = [batch.sim(i).commanded_opening for i in range(3)]
    assert after[0] == pytest.approx(0.25)
    assert after[1] == pytest.approx(max(0.0, before[1] - 0.5))
    assert after[2] == before[2]
    with pytest.raises(ValueError, match="command mode 3; valid: 0 ABSOLUTE, 1 DELTA, 2 KEEP"):
        batch.step([3, KEEP, KEEP], [0.0, 0.0, 0.0])


def test_ridge_contrast_of_a_sinusoid_is_its_band_gain():
    # Vertical ridges 11 px apart, amplitude 10 on every channel: the difference of Gaussians
    # (1.5 and 6 px) passes exp(-(1.5 k)^2 / 2) - exp(-(6 k)^2 / 2) of it, B, G, R in quadrature.
    x = np.arange(320)
    ridges = 100.0 + 10.0 * np.sin(2.0 * math.pi * x / 11.0)
    frame = np.repeat(np.tile(ridges, (240, 1))[:, :, None], 3, axis=2).round().astype(np.uint8)
    background = np.full((240, 320, 3), 100, np.uint8)
    k = 2.0 * math.pi / 11.0
    gain = math.exp(-0.5 * (1.5 * k) ** 2) - math.exp(-0.5 * (6.0 * k) ** 2)
    c = norm2tex.measure_ridge_contrast(frame, background, (120, 88, 80, 65))
    assert c["raw"] == pytest.approx(math.sqrt(3.0) * 10.0 * gain / math.sqrt(2.0), rel=0.04)
    assert c["contrast"] == c["raw"] and c["noise"] == 0.0
    with pytest.raises(norm2tex.Error, match="not inside"):
        norm2tex.measure_ridge_contrast(frame, background, (300, 200, 80, 65))
