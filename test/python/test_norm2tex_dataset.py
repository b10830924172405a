"""norm2tex_dataset against a real recording: record_dataset.launch on a master of its own,
norm2tex_export, then both datasets through a torch DataLoader: shapes, labels, counts, the
same pixels both ways, and clear errors for bad input.

Usage (catkin passes these): test_norm2tex_dataset.py NORM2TEX_EXPORT_EXECUTABLE
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

try:
    import torch
    from norm2tex_dataset import BagDataset, ExportedDataset
except ImportError as missing:  # PyTorch is the user's own install where rosdep has no key
    torch = None
    TORCH_MISSING = "PyTorch is not installed (pip install torch): %s" % missing

EXPORT = sys.argv[1] if len(sys.argv) > 1 else "norm2tex_export"


def _free_port():
    # scripts/free_port: below the kernel's ephemeral range, so roslaunch's own server cannot
    # be handed the same port before its master binds it.
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                          "free_port")
    return int(subprocess.run([script], capture_output=True, text=True, check=True).stdout)


@unittest.skipIf(torch is None, TORCH_MISSING if torch is None else "")
class LabelParsingTest(unittest.TestCase):
    def test_64_bit_labels_keep_every_digit(self):
        # A seed and a stamp above 2**53: read through a float they came back changed
        # (7566867672928951314 -> ...296).
        root = tempfile.mkdtemp(prefix="norm2tex_labels_test_")
        try:
            with open(os.path.join(root, "labels.csv"), "w") as f:
                f.write("raw,diff,depth,material,variant,sensor,stamp,seed,beta\n")
                f.write("a.png,b.png,,wood,3,digit_left,1795672061300976827,"
                        "7566867672928951314,0.035\n")
                f.write("a.png,b.png,,wood,3.0,digit_left,1e3,1,0.035\n")
            rows = ExportedDataset(root, return_labels=True).rows
            self.assertEqual(rows[0]["seed"], 7566867672928951314)
            self.assertEqual(rows[0]["stamp"], 1795672061300976827)
            self.assertEqual(rows[0]["variant"], 3)
            self.assertAlmostEqual(rows[0]["beta"], 0.035)
            self.assertEqual((rows[1]["variant"], rows[1]["stamp"]), (3, 1000))
        finally:
            shutil.rmtree(root, ignore_errors=True)


@unittest.skipIf(torch is None, TORCH_MISSING if torch is None else "")
class ShearFieldTest(unittest.TestCase):
    def test_the_shear_field_loads_in_millimetres_channels_first(self):
        # As norm2tex_export writes it (the tactile_markers rostest checks its bytes against
        # numpy.save's layout): (rows, cols, 2) float32 metres per frame, named in labels.csv.
        root = tempfile.mkdtemp(prefix="norm2tex_shear_test_")
        try:
            field = np.zeros((4, 3, 2), np.float32)
            field[1, 2] = (2.5e-4, -1e-4)
            os.makedirs(os.path.join(root, "shear", "wood"))
            np.save(os.path.join(root, "shear", "wood", "a.npy"), field)
            with open(os.path.join(root, "labels.csv"), "w") as f:
                f.write("raw,diff,depth,material,variant,sensor,stamp,markers,shear\n")
                f.write("a.png,b.png,,wood,0,digit_left,1,,shear/wood/a.npy\n")
            tensor, label = ExportedDataset(root, image="shear")[0]
            self.assertEqual(tuple(tensor.shape), (2, 4, 3))
            self.assertEqual(tensor.dtype, torch.float32)
            self.assertAlmostEqual(float(tensor[0, 1, 2]), 0.25, places=6)
            self.assertAlmostEqual(float(tensor[1, 1, 2]), -0.1, places=6)
            self.assertEqual(float(tensor.abs().sum()), float(tensor[:, 1, 2].abs().sum()))
            with open(os.path.join(root, "labels.csv"), "a") as f:
                f.write("a.png,b.png,,wood,0,digit_left,2,,\n")
            with self.assertRaisesRegex(ValueError, "without the shear field.*record_shear"):
                ExportedDataset(root, image="shear")
        finally:
            shutil.rmtree(root, ignore_errors=True)


@unittest.skipIf(torch is None, TORCH_MISSING if torch is None else "")
class DatasetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="norm2tex_python_test_")
        cls.out = os.path.join(cls.dir, "bags")
        port = _free_port()
        env = dict(os.environ, ROS_HOME=os.path.join(cls.dir, "ros_home"),
                   ROS_MASTER_URI=f"http://localhost:{port}")
        # 20 frames: wood and fabric, one variant each, presses of 5 frames.
        run = subprocess.run(
            ["timeout", "300", "roslaunch", "-p", str(port), "norm2tex", "record_dataset.launch",
             "material:=wood,fabric", "variants:=1", "samples:=10", "slides:=4", "seed:=5",
             f"out:={cls.out}"], env=env, capture_output=True, text=True)
        assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
        cls.bags = sorted(os.path.join(cls.out, f) for f in os.listdir(cls.out)
                          if f.endswith(".bag"))
        cls.export = os.path.join(cls.dir, "export")
        run = subprocess.run([EXPORT] + cls.bags + ["-o", cls.export], capture_output=True,
                             text=True)
        assert run.returncode == 0, run.stdout + run.stderr
        cls.export_stderr = run.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_progress_in_a_log_is_whole_lines(self):
        # stderr is a pipe here, as in a log or Slurm's output: no carriage returns (they made one
        # enormous line), each report a line of its own.
        self.assertIn("norm2tex_export: ", self.export_stderr)
        self.assertNotIn("\r", self.export_stderr)

    def test_exported_frames_load_in_batches_with_their_labels(self):
        data = ExportedDataset(self.export)
        self.assertEqual(len(data), 20)
        self.assertEqual(data.classes, ["fabric", "wood"])
        loader = torch.utils.data.DataLoader(data, batch_size=8, shuffle=True, num_workers=2)
        seen = {0: 0, 1: 0}
        for images, targets in loader:
            self.assertEqual(images.dtype, torch.float32)
            self.assertEqual(tuple(images.shape[1:]), (3, 320, 240))
            for t in targets.tolist():
                seen[t] += 1
        self.assertEqual(seen, {0: 10, 1: 10})
        # diff images: noise around 0 away from the contact, large inside it.
        image, labels = ExportedDataset(self.export, return_labels=True)[0]
        self.assertEqual(labels["scenario"], "probe")
        self.assertEqual(labels["in_contact"], 1)
        self.assertIn(labels["material"], ("wood", "fabric"))
        # The probe presses straight in: nothing slips or twists; a DIGIT has no markers.
        self.assertEqual(labels["slip_fraction"], 0.0)
        self.assertEqual(labels["twist_moment"], 0.0)
        self.assertEqual(labels["markers"], "")
        depth, _ = ExportedDataset(self.export, image="depth")[0]
        self.assertEqual(tuple(depth.shape), (1, 320, 240))
        self.assertAlmostEqual(depth.max().item(), labels["press_depth"] * 1000.0, delta=0.01)
        # Pixels that differ from the background by more than 8 grey levels (4 noise sigmas):
        # none where the gel is untouched, many where it is pressed (shading, texture, rim).
        strong = image.abs().mean(0) > 8
        self.assertLess(strong[depth[0] == 0].float().mean().item(), 0.001)
        self.assertGreater(strong[depth[0] > 0].float().mean().item(), 0.05)

    def test_filters_hold_out_materials_and_variants(self):
        self.assertEqual(len(ExportedDataset(self.export, materials=["wood"])), 10)
        self.assertEqual(len(ExportedDataset(self.export, variants=[1])), 0)
        self.assertEqual(len(ExportedDataset(self.export, sensors=["digit_right"])), 0)

    def test_bags_give_the_same_frames_as_the_export(self):
        exported = ExportedDataset(self.export, image="raw", return_labels=True)
        by_stamp = {labels["stamp"]: image for image, labels in exported}
        bag_frames = list(BagDataset(self.bags, image="raw", return_labels=True))
        self.assertEqual(len(bag_frames), 20)
        for image, labels in bag_frames:
            self.assertTrue(torch.equal(image, by_stamp[labels["stamp"]]), labels["stamp"])
        # diff straight from the bag = the exported diff wherever the export did not clamp.
        exported_diff = {l["stamp"]: i for i, l in ExportedDataset(self.export, return_labels=True)}
        loader = torch.utils.data.DataLoader(BagDataset(self.bags, return_labels=True),
                                             batch_size=5)
        count = 0
        for images, labels in loader:
            for image, stamp in zip(images, labels["stamp"].tolist()):
                expected = exported_diff[stamp]
                inside = (image > -128) & (image < 127)
                self.assertTrue(torch.equal(image[inside], expected[inside]))
                count += 1
        self.assertEqual(count, 20)
        classes = BagDataset(self.bags).classes
        self.assertEqual(classes, ["fabric", "wood"])

    def test_bad_input_is_named(self):
        not_a_bag = os.path.join(self.dir, "not_a.bag")
        with open(not_a_bag, "w") as f:
            f.write("not a bag")
        with self.assertRaisesRegex(ValueError, "not_a.bag"):
            BagDataset([not_a_bag])
        with self.assertRaisesRegex(FileNotFoundError, "labels.csv"):
            ExportedDataset(self.dir)
        with self.assertRaisesRegex(ValueError, "diff, raw, depth or shear"):
            ExportedDataset(self.export, image="rgb")


class ExportCliTest(unittest.TestCase):
    def test_help_prints_the_usage_and_succeeds(self):
        for flag in ("--help", "-h"):
            run = subprocess.run([EXPORT, flag], capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
            self.assertIn("usage: norm2tex_export BAG", run.stdout)
            self.assertNotIn("unknown option", run.stdout + run.stderr)
        # A mistake is still one: the usage on stderr, exit 2.
        run = subprocess.run([EXPORT, "--no-such-option"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 2, run.stdout + run.stderr)
        self.assertIn("usage: norm2tex_export", run.stderr)


if __name__ == "__main__":
    unittest.main()
