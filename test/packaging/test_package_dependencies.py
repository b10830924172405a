"""package.xml against rosdep's rules and against the code.

Every dependency key must resolve where README says the package installs: Ubuntu 20.04 (focal,
ROS Noetic, through rosdep) and Debian 11/12/13. rosdep's rules are plain data; the ones this
package uses are copied into test/fixtures/rosdep/ with their source, and resolved here the way
rosdep resolves them (an OS entry is a package list, or a map from release to list where an
explicit null means "not available" and '*' is the default). The ROS packages resolve through
Noetic's release (ros-noetic-<name>).

Also: every ROS package the C++ code includes or find_package(catkin COMPONENTS) names is
declared, and every system key's Debian package is in scripts/debian-packages.txt, which is
what scripts/quickstart installs.

Usage: test_package_dependencies.py REPO_ROOT (stdlib + PyYAML, which catkin itself needs).
"""
import os
import re
import shutil
import subprocess
import sys
import unittest
import xml.etree.ElementTree as ET

import yaml

REPO = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
FIXTURES = os.path.join(REPO, "test", "fixtures", "rosdep")

# Where the package says it installs: (rosdep OS name, release codename).
PLATFORMS = [("ubuntu", "focal"), ("debian", "bullseye"), ("debian", "bookworm"), ("debian", "trixie")]

# Keys the Debian list need not name, with why: rosdep's boost is libboost-all-dev, while the code
# needs only boost/make_shared.hpp (roscpp's message pointers), which libroscpp-dev brings, and
# Boost.Program_options, which has a key of its own (libboost-program-options-dev).
NOT_LISTED_FOR_DEBIAN = {"boost"}


class UnresolvableKey(Exception):
    pass


def load_yaml(name):
    with open(os.path.join(FIXTURES, name)) as f:
        return yaml.safe_load(f)


def package_dependencies(path):
    """{key: [tags]} of every dependency declared in a format-2 package.xml."""
    root = ET.parse(path).getroot()
    deps = {}
    for elem in root:
        if elem.tag.endswith("depend"):
            deps.setdefault(elem.text.strip(), []).append(elem.tag)
    return deps


def resolve(key, os_name, release, rules, ros_packages):
    """The system packages rosdep installs for `key` on (os_name, release), as rosdep does."""
    if key in ros_packages:
        if os_name == "ubuntu":
            return ["ros-noetic-" + key.replace("_", "-")]
        # Debian's own ROS 1 has no rosdep release; scripts/debian-packages.txt covers it.
        return ["(Debian's ROS 1 package for %s)" % key]
    if key not in rules:
        raise UnresolvableKey("key '%s' is in no rule of test/fixtures/rosdep: copy its rule from "
                              "rosdistro, or it does not exist" % key)
    rule = rules[key]
    if os_name not in rule:
        raise UnresolvableKey("key '%s' has no rule for %s" % (key, os_name))
    entry = rule[os_name]
    if isinstance(entry, dict) and not set(entry) & {"apt", "pip", "source", "packages"}:
        # A map from release to packages: the release's own entry wins, then '*'.
        if release in entry:
            entry = entry[release]
        elif "*" in entry:
            entry = entry["*"]
        else:
            raise UnresolvableKey("key '%s' has no rule for %s %s" % (key, os_name, release))
    if isinstance(entry, dict):
        installer = entry.get("apt") or entry.get("pip") or entry
        entry = installer.get("packages") if isinstance(installer, dict) else installer
    if not entry:
        raise UnresolvableKey("key '%s' is defined as not available for %s %s" % (key, os_name, release))
    return list(entry)


def debian_package_list():
    names = set()
    with open(os.path.join(REPO, "scripts", "debian-packages.txt")) as f:
        for line in f:
            names.update(line.split("#", 1)[0].split())
    return names


class PackageDependencies(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rules = {}
        cls.rules.update(load_yaml("base.yaml"))
        cls.rules.update(load_yaml("python.yaml"))
        cls.ros_packages = load_yaml("noetic_packages.yaml")
        cls.deps = package_dependencies(os.path.join(REPO, "package.xml"))

    def test_every_key_resolves_on_every_supported_platform(self):
        problems = []
        for key in sorted(self.deps):
            for os_name, release in PLATFORMS:
                try:
                    resolve(key, os_name, release, self.rules, self.ros_packages)
                except UnresolvableKey as e:
                    problems.append(str(e))
        self.assertEqual(problems, [], "\n".join(problems))

    def test_the_resolver_refuses_what_rosdep_refuses(self):
        # The rule that stopped `rosdep install` on focal: python3-torch is null there.
        with self.assertRaisesRegex(UnresolvableKey, "not available for ubuntu focal"):
            resolve("python3-torch", "ubuntu", "focal", self.rules, self.ros_packages)
        self.assertEqual(resolve("python3-torch", "ubuntu", "jammy", self.rules, self.ros_packages),
                         ["python3-torch"])
        # torchvision likewise: null on focal, so package.xml cannot declare it either.
        with self.assertRaisesRegex(UnresolvableKey, "not available for ubuntu focal"):
            resolve("python3-torchvision", "ubuntu", "focal", self.rules, self.ros_packages)
        with self.assertRaisesRegex(UnresolvableKey, "in no rule"):
            resolve("no-such-key", "ubuntu", "focal", self.rules, self.ros_packages)
        self.assertEqual(resolve("tf2_ros", "ubuntu", "focal", self.rules, self.ros_packages),
                         ["ros-noetic-tf2-ros"])
        self.assertNotIn("python3-torch", self.deps)
        self.assertNotIn("python3-torchvision", self.deps)

    def test_every_ros_package_the_code_uses_is_declared(self):
        used = set()
        include = re.compile(r"^\s*#\s*include\s*<([A-Za-z0-9_]+)/", re.M)
        for top in ("src", "include"):
            for dirpath, _, files in os.walk(os.path.join(REPO, top)):
                for name in files:
                    if name.endswith((".cpp", ".hpp", ".h")):
                        with open(os.path.join(dirpath, name), errors="replace") as f:
                            used.update(include.findall(f.read()))
        used &= set(self.ros_packages)
        with open(os.path.join(REPO, "CMakeLists.txt")) as f:
            cmake = f.read()
        match = re.search(r"find_package\(catkin REQUIRED COMPONENTS([^)]*)\)", cmake)
        self.assertIsNotNone(match, "CMakeLists.txt has no find_package(catkin REQUIRED COMPONENTS ...)")
        components = set(match.group(1).split())
        self.assertEqual(sorted(used - set(self.deps)), [],
                         "ROS packages whose headers the code includes but package.xml omits")
        self.assertEqual(sorted(components - set(self.deps)), [],
                         "catkin components CMakeLists.txt finds but package.xml omits")
        build_deps = {k for k, tags in self.deps.items()
                      if {"depend", "build_depend", "buildtool_depend"} & set(tags)}
        self.assertEqual(sorted((used | components) - build_deps - {"catkin"}), [],
                         "used at build time but declared only for run or test time")

    def test_the_debian_list_installs_every_system_key(self):
        listed = debian_package_list()
        missing = []
        for key in sorted(self.deps):
            if key in self.ros_packages or key in NOT_LISTED_FOR_DEBIAN:
                continue
            wanted = resolve(key, "debian", "bookworm", self.rules, self.ros_packages)
            missing += ["%s (%s)" % (p, key) for p in wanted if p not in listed]
        self.assertEqual(missing, [], "scripts/debian-packages.txt lacks what package.xml needs")
        # PyTorch and torchvision are not declared (null on focal) but the Python tools need them:
        # Debian's are listed.
        self.assertIn("python3-torch", listed)
        self.assertIn("python3-torchvision", listed)

    @unittest.skipIf(shutil.which("catkin_lint") is None, "catkin_lint is not installed (catkin-lint)")
    def test_catkin_lint_finds_no_error(self):
        # catkin_lint checks package.xml against CMakeLists.txt the way the ROS build farm does
        # (undeclared or unconfigured dependencies, what catkin_package() must export, install
        # rules). src/core is a plain-CMake subproject by design.
        # The package's own folder, not the symlink catkin's workspace reaches it by; the
        # quick-start workspace inside it (.catkin_ws/src/norm2tex) links back to it.
        repo = os.path.realpath(REPO)
        lint = subprocess.run(["catkin_lint", "-W0", "--ignore", "subproject", "--skip-path",
                               os.path.join(repo, ".catkin_ws"), repo],
                              capture_output=True, text=True, timeout=300)
        self.assertEqual(lint.returncode, 0, lint.stdout + lint.stderr)
        self.assertIn("checked 1 packages", lint.stdout + lint.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
