"""The install space on its own: what `catkin_make install` puts in install/ runs the README's
commands with nothing of the source tree or the devel space in reach.

The build's install scripts (what `catkin_make install` runs) install under a temporary DESTDIR
(catkin's setup.bash finds its own folder, so an install space works wherever it is); then, in an
environment made only from that install space's setup.bash:
  - `rospack find norm2tex` is the install space, and every program README names is there;
  - `rosrun norm2tex norm2tex_texgen` writes a material from the installed config;
  - `roslaunch norm2tex gripper_sim.launch` publishes DIGIT images (320x240 bgr8) of both fingers;
  - `rosrun norm2tex record_dataset` records a complete dataset.

Usage: test_install_space.py REPO_ROOT CATKIN_BUILD_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.abspath(sys.argv[1])
BUILD = os.path.abspath(sys.argv[2])
sys.path.insert(0, os.path.join(REPO, "test", "python"))
import ros_launch  # noqa: E402  (the tests' roslaunch stop, from the source tree's test folder)

# The programs README names, as `rosrun norm2tex NAME`.
PROGRAMS = [
    "contact_sim", "tactile_renderer", "probe_sim", "dataset_recorder", "nodelet_group",
    "norm2tex_bake", "norm2tex_texgen", "norm2tex_render", "norm2tex_calibrate", "norm2tex_match_texture",
    "norm2tex_export",
    "norm2tex_grasp_demo", "norm2tex_gripper_sweep", "norm2tex_make_demo_normal_map",
    "norm2tex_ros_bench", "norm2tex_wake_bench", "norm2tex_launch_check",
    "record_dataset", "free_port", "merge_dataset", "train_material_classifier", "texture_contrast",
    "ros_benchmark", "latency_trace", "env_benchmark", "hold_cube_experiment",
    "slurm/submit_dataset", "slurm/record_dataset.sbatch",
]


def run(cmd, env, timeout, **kwargs):
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, **kwargs)


class InstallSpace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="norm2tex_install_test_")
        with open(os.path.join(BUILD, "CMakeCache.txt")) as f:
            configured = re.search(r"(?m)^CMAKE_INSTALL_PREFIX:PATH=(.*)$", f.read()).group(1)
        # catkin's workspace files (setup.bash, _setup_util.py) are installed to the configured
        # prefix by absolute path, so the install goes under DESTDIR rather than to a new prefix.
        cls.prefix = os.path.join(cls.dir, "destdir") + configured
        installed = subprocess.run(
            ["cmake", "-P", "cmake_install.cmake"], cwd=BUILD, capture_output=True, text=True,
            timeout=600, env=dict(os.environ, DESTDIR=os.path.join(cls.dir, "destdir")))
        assert installed.returncode == 0, installed.stdout[-2000:] + installed.stderr[-2000:]
        # Only the install space: a fresh environment, nothing inherited from the devel space.
        base = {"PATH": "/usr/bin:/bin", "HOME": cls.dir, "LANG": "C.UTF-8",
                "ROS_HOME": os.path.join(cls.dir, "ros_home"), "ROS_HOSTNAME": "localhost"}
        dump = run(["bash", "-c", 'set +eu; source "$1/setup.bash"; env -0', "bash", cls.prefix],
                   base, 60)
        assert dump.returncode == 0, dump.stderr
        cls.env = dict(item.split("=", 1) for item in dump.stdout.split("\0") if "=" in item)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def free_port(self):
        return int(run([os.path.join(self.prefix, "lib", "norm2tex", "free_port")], self.env,
                       30).stdout)

    def wait_for_master(self, env, launch, deadline_s=60.0):
        """Until the launch's master answers (rostopic would give up at once without one)."""
        deadline = time.monotonic() + deadline_s
        while time.monotonic() < deadline:
            if launch.poll() is not None:
                self.fail("roslaunch ended (exit %d): %s" % (launch.returncode,
                                                            launch.stdout.read()[-3000:]))
            if run(["rostopic", "list"], env, 30).returncode == 0:
                return
            time.sleep(0.2)
        self.fail("no master on %s within %.0f s" % (env["ROS_MASTER_URI"], deadline_s))

    def test_the_environment_is_the_install_space_alone(self):
        found = run(["rospack", "find", "norm2tex"], self.env, 60)
        self.assertEqual(found.stdout.strip(), os.path.join(self.prefix, "share", "norm2tex"),
                         found.stderr)
        workspace = os.path.dirname(BUILD)  # holds the devel space
        for name in ("ROS_PACKAGE_PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "CMAKE_PREFIX_PATH",
                     "PATH"):
            for entry in filter(None, self.env.get(name, "").split(":")):
                if entry.startswith(self.dir + os.sep):
                    continue  # the install space under test
                self.assertFalse(entry.startswith((REPO + os.sep, workspace + os.sep)),
                                 "%s has %s" % (name, entry))

    def test_every_program_readme_names_is_installed(self):
        missing = [p for p in PROGRAMS
                   if not os.access(os.path.join(self.prefix, "lib", "norm2tex", p), os.X_OK)]
        self.assertEqual(missing, [])
        for name in ("launch/gripper_sim.launch", "launch/record_dataset.launch",
                     "config/digit.yaml", "rviz/norm2tex.rviz", "nodelet_plugins.xml"):
            self.assertTrue(os.path.isfile(os.path.join(self.prefix, "share", "norm2tex", name)),
                            name)
        # The Python scripts run whichever python3 comes first on PATH (a venv's, a conda's).
        for name in ("free_port", "merge_dataset", "train_material_classifier"):
            with open(os.path.join(self.prefix, "lib", "norm2tex", name)) as f:
                self.assertEqual(f.readline().strip(), "#!/usr/bin/env python3", name)

    def test_a_tool_uses_the_installed_config(self):
        out = os.path.join(self.dir, "wood.png")
        made = run(["rosrun", "norm2tex", "norm2tex_texgen", "--material", "wood", "--size", "64",
                    "-o", out], self.env, 120)
        self.assertEqual(made.returncode, 0, made.stdout + made.stderr)
        self.assertTrue(os.path.getsize(out) > 0)

    def test_the_python_module_runs_from_the_install_space(self):
        # norm2tex._core, norm2tex.envs and catkin's generated messages share one package.
        script = (
            "import norm2tex, norm2tex.envs\n"
            "from norm2tex.msg import TactileContact\n"
            "from norm2tex.srv import Step\n"
            "print(norm2tex.__file__)\n"
            "print(norm2tex._core.__file__)\n"
            "print(norm2tex.config_dir())\n"
            "env = norm2tex.envs.HoldCubeEnv(noise=False)\n"
            "obs, info = env.reset(seed=1)\n"
            "print(obs['digit_left'].shape, obs['digit_left'].dtype)\n"
        )
        ran = run(["/usr/bin/python3", "-c", script], self.env, 300)
        self.assertEqual(ran.returncode, 0, ran.stdout + ran.stderr)
        lines = ran.stdout.split("\n")
        for path in lines[:3]:
            self.assertTrue(path.startswith(self.prefix + os.sep), ran.stdout)
        self.assertEqual(lines[2], os.path.join(self.prefix, "share", "norm2tex", "config"))
        self.assertEqual(lines[3], "(320, 240, 3) uint8")

    def test_gripper_sim_launch_publishes_images_of_both_fingers(self):
        port = self.free_port()
        env = dict(self.env, ROS_MASTER_URI="http://localhost:%d" % port)
        launch = subprocess.Popen(["roslaunch", "-p", str(port), "norm2tex", "gripper_sim.launch"],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  text=True, start_new_session=True)
        try:
            self.wait_for_master(env, launch)
            for side in ("left", "right"):
                # rostopic waits for the first message itself; the timeout is only a deadline.
                echo = run(["rostopic", "echo", "-n", "1", "--noarr",
                            "/digit_%s/image_raw" % side], env, 120)
                self.assertEqual(echo.returncode, 0, echo.stdout + echo.stderr)
                self.assertRegex(echo.stdout, r"height: 320\b")
                self.assertRegex(echo.stdout, r"width: 240\b")
                self.assertRegex(echo.stdout, r"encoding: \"?bgr8")
        finally:
            ros_launch.stop(launch)

    def test_record_dataset_records_a_complete_dataset(self):
        out = os.path.join(self.dir, "dataset")
        rec = run(["rosrun", "norm2tex", "record_dataset", out, "material:=wood", "variants:=1",
                   "samples:=10", "slides:=4"], self.env, 300)
        self.assertEqual(rec.returncode, 0, rec.stdout[-3000:] + rec.stderr[-3000:])
        with open(os.path.join(out, "norm2tex_shard0.yaml")) as f:
            manifest = f.read()
        self.assertRegex(manifest, r"(?m)^complete: true$")
        images = re.search(r"(?m)^images: (\d+)$", manifest)
        self.assertIsNotNone(images, manifest)
        self.assertEqual(int(images.group(1)), 10, manifest)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
