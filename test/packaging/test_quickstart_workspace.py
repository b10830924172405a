#!/usr/bin/env python3
"""The quick-start workspace without a file system loop (scripts/link_package, which
scripts/quickstart runs).

The default workspace, <repo>/.catkin_ws, lies inside the package it links. Linked by one symlink,
the package held its own workspace, which led back to the package: rosrun searches the package
with `find -L` and printed "find: File system loop detected" on every call.

  - in the workspace this suite runs from, `rosrun norm2tex norm2tex_texgen --help` prints its
    usage and nothing about a loop (a real check of the quick-start workspace when the suite runs
    there, as `scripts/quickstart test` and .ci/run do by default);
  - a workspace inside a package (a scratch package with the real package.xml and a program):
    rosrun runs the program, with no loop on stderr; reruns follow entries added to and removed
    from the package; a workspace outside a package gets a plain symlink; an old quick-start
    symlink is replaced; a directory that is not the script's own is refused, untouched.

Usage: test_quickstart_workspace.py REPO_ROOT   (default: two folders up). Stdlib only.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
LINK_PACKAGE = os.path.join(REPO, "scripts", "link_package")
LOOP = "File system loop"


def link_package(package, workspace):
    return subprocess.run([LINK_PACKAGE, package, workspace], capture_output=True, text=True,
                          timeout=60)


class ThisWorkspace(unittest.TestCase):
    @unittest.skipIf(not os.environ.get("ROS_PACKAGE_PATH"), "no sourced workspace")
    def test_rosrun_prints_no_file_system_loop(self):
        run = subprocess.run(["rosrun", "norm2tex", "norm2tex_texgen", "--help"],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        self.assertIn("usage", run.stdout.lower())
        self.assertNotIn(LOOP, run.stderr)


class WorkspaceInsideThePackage(unittest.TestCase):
    def setUp(self):
        self.dir = os.path.realpath(tempfile.mkdtemp(prefix="norm2tex_link_test_"))
        self.package = os.path.join(self.dir, "repo")
        os.makedirs(os.path.join(self.package, "scripts"))
        shutil.copy(os.path.join(REPO, "package.xml"), self.package)
        program = os.path.join(self.package, "scripts", "hello")
        with open(program, "w") as f:
            f.write('#!/bin/sh\necho "hello $*"\n')
        os.chmod(program, 0o755)
        self.workspace = os.path.join(self.package, ".catkin_ws")
        self.link = os.path.join(self.workspace, "src", "norm2tex")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def rosrun(self, *args):
        # Only this workspace: rospack finds the package through it, catkin_find finds nothing.
        env = {"PATH": "/usr/bin:/bin", "HOME": self.dir, "ROS_HOME": os.path.join(self.dir, "ros"),
               "ROS_PACKAGE_PATH": os.path.join(self.workspace, "src")}
        return subprocess.run(["rosrun", "norm2tex"] + list(args), capture_output=True,
                              text=True, timeout=60, env=env)

    def assert_linked(self):
        run = link_package(self.package, self.workspace)
        self.assertEqual(run.returncode, 0, run.stderr)

    def test_rosrun_runs_the_program_without_a_loop(self):
        self.assert_linked()
        run = self.rosrun("hello", "--help")
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        self.assertEqual(run.stdout.strip(), "hello --help")
        self.assertNotIn(LOOP, run.stderr)
        self.assertEqual(run.stderr, "")
        # A directory of links to all but the package's entry that holds the workspace.
        self.assertFalse(os.path.islink(self.link))
        self.assertEqual(sorted(os.listdir(self.link)), ["package.xml", "scripts"])

    def test_an_old_quick_start_symlink_is_replaced(self):
        os.makedirs(os.path.dirname(self.link))
        os.symlink(self.package, self.link)
        self.assertIn(LOOP, self.rosrun("hello").stderr)  # what the symlink did
        self.assert_linked()
        run = self.rosrun("hello")
        self.assertEqual(run.stdout.strip(), "hello")
        self.assertNotIn(LOOP, run.stderr)

    def test_reruns_follow_the_package(self):
        self.assert_linked()
        os.makedirs(os.path.join(self.package, "launch"))
        with open(os.path.join(self.package, ".clang-format"), "w") as f:
            f.write("BasedOnStyle: Google\n")
        self.assert_linked()
        self.assertEqual(sorted(os.listdir(self.link)),
                         [".clang-format", "launch", "package.xml", "scripts"])
        os.rmdir(os.path.join(self.package, "launch"))
        self.assert_linked()
        self.assertEqual(sorted(os.listdir(self.link)), [".clang-format", "package.xml", "scripts"])
        self.assertEqual(os.path.realpath(os.path.join(self.link, "scripts")),
                         os.path.join(self.package, "scripts"))

    def test_a_workspace_outside_the_package_gets_a_symlink(self):
        outside = os.path.join(self.dir, "ws")
        run = link_package(self.package, outside)
        self.assertEqual(run.returncode, 0, run.stderr)
        link = os.path.join(outside, "src", "norm2tex")
        self.assertTrue(os.path.islink(link))
        self.assertEqual(os.path.realpath(link), self.package)

    def test_a_directory_not_its_own_is_refused_untouched(self):
        os.makedirs(self.link)
        mine = os.path.join(self.link, "notes.txt")
        with open(mine, "w") as f:
            f.write("mine\n")
        run = link_package(self.package, self.workspace)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn(self.link, run.stderr)
        self.assertEqual(os.listdir(self.link), ["notes.txt"])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
