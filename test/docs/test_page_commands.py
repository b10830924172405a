#!/usr/bin/env python3
"""The pages' commands, run as written.

Every command of a shell block (```bash, sh, shell, console) and every ```python block of
README.md and docs/*.md either runs here and must work, or is in EXCLUDED with the reason it
cannot run in a test (root, a display, a Slurm cluster, the interactive simulation, minutes of
work). A command that is neither fails the test, and so does an EXCLUDED entry that no page has,
so the table cannot rot.
(test_docs.py checks that the commands name programs and options that exist; this runs them.)

How the commands run, as a reader would run them:
  - page by page, in page order, in one bash shell per page whose directory is a fresh temporary
    one standing in for the clone: scripts/, config/, test/ ... link to the package's own and
    .catkin_ws/devel to the devel space the suite runs from. Files an earlier command wrote and
    shell variables carry over to the next command; every block starts in that directory (a
    block's `cd` holds within the block: the pages write each block's paths from the clone's
    root); stdin is /dev/null;
  - in the suite's environment (the devel space sourced), with CI=true, no DISPLAY, ROS_HOME in
    the temporary directory, a ROS master URI on a free port (nothing here starts one) and the
    package's programs on PATH (the pages' bare `norm2tex_X` synopses say "each as
    `rosrun norm2tex norm2tex_X ...`");
  - a usage synopsis runs in its shortest form: optional `[...]` groups are dropped, of `A|B`
    alternatives the first is taken, and its placeholders (NORMAL.png, DIR, M ...) are replaced
    from SUBSTITUTIONS. The reader's own files a page names (bg.png, press_*.png ...) are put in
    the directory first, from FILES. Absolute paths under /data/ and /tmp/ go to the temporary
    directory's data/ and tmp/;
  - each command must exit with status 0 within its timeout (TIMEOUTS, else DEFAULT_TIMEOUT),
    and every file it is told to write (the argument of -o, --out, --out-dir, --report, --json,
    --csv, --*-out ...) must exist afterwards.

A ```python block is one command: python3 runs the block as it stands, in the page's shell.

Usage: test_page_commands.py [PACKAGE_ROOT [TOOLS_DIR]]   (TOOLS_DIR: the devel space's
lib/norm2tex; default $NORM2TEX_TOOLS_DIR, else PACKAGE_ROOT/.catkin_ws/devel/lib/norm2tex).
test_page_commands.py --list [PACKAGE_ROOT [TOOLS_DIR]] prints every command and what is done
with it. Stdlib only (and the package's own programs; PIL, a dependency, converts fixtures).
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import unittest.mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_docs as docs  # noqa: E402  (the pages and their fenced blocks)

_ARGS = [a for a in sys.argv[1:] if os.path.isdir(a)]  # (not pytest's own arguments)
ROOT = os.path.abspath(_ARGS[0] if _ARGS else
                       os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
TOOLS_DIR = os.path.abspath(_ARGS[1] if len(_ARGS) > 1 else os.environ.get(
    "NORM2TEX_TOOLS_DIR", os.path.join(ROOT, ".catkin_ws", "devel", "lib", "norm2tex")))
DEVEL = os.path.dirname(os.path.dirname(TOOLS_DIR))
FIXTURES = os.path.join(ROOT, "test", "fixtures")
S09 = os.path.join(FIXTURES, "digit_s09")

SHELL_BLOCKS = ("bash", "sh", "shell", "console")
# A ```python block is one command: the block, given to python3 as a reader pastes it.
_PY_HEAD, _PY_END = "python3 - <<'__PAGE_PYTHON__'\n", "\n__PAGE_PYTHON__"

# --- what does not run, and why ------------------------------------------------------------------
# Keys are commands as the page has them (comments dropped, whitespace collapsed); a key ending in
# " *" covers every command it begins. Each key must match a command of some page.
SIM = "starts the simulation, which runs until stopped (Ctrl-C); test/ros runs the launch files"
NEEDS_SIM = "needs the simulation of the line above running (a second terminal)"
EXCLUDED = {
    # the quickstart and the suite
    "scripts/quickstart run": "installs Debian packages (root), builds, then runs the main job "
                              "(the simulation, for minutes)",
    "scripts/quickstart test": "the whole suite (8-13 min), this test among it",
    "scripts/quickstart test unit": "the suite without the rostests (minutes)",
    "scripts/compat bullseye": "debootstrap chroot of Debian 11: root, network, a full build",
    "bash .ci/run": "CI itself: the suite and two chroot builds",
    "catkin_make run_tests && catkin_test_results": "the whole suite, this test among it",
    "catkin_make run_tests_norm2tex_gtest_norm2tex_core_test":
        "builds in the workspace the suite is running from (a make inside its make)",
    # install.md: a workspace from scratch
    "mkdir -p ~/catkin_ws/src && cd ~/catkin_ws/src": "a new workspace in the home directory: "
                                                      "the from-scratch install below",
    "git clone <this repository> norm2tex": "network; <this repository> is the reader's URL",
    "cd ~/catkin_ws": "the from-scratch workspace of the lines above",
    "rosdep update --include-eol-distros": "network",
    "rosdep install --from-paths src --ignore-src -y": "root (apt), network",
    "pip install torch torchvision": "network, a large download",
    "catkin_make -DCMAKE_BUILD_TYPE=Release": "a full build of the from-scratch workspace",
    "source devel/setup.bash": "the from-scratch workspace's devel space",
    # the simulation and what talks to it
    "roslaunch norm2tex gripper_sim.launch *": SIM,
    "roslaunch norm2tex hand_sim.launch *": SIM,
    "roslaunch norm2tex record_dataset.launch material:=wood samples:=6000 out:=/data/wood":
        "slow: records 6000 samples (minutes)",
    "rostopic pub -1 /gripper/command *": NEEDS_SIM,
    "rostopic pub -1 /hand_sim/joint_command *": NEEDS_SIM,
    "rosservice call /contact_sim/step *": NEEDS_SIM,
    "rosservice call /hand_sim/step *": NEEDS_SIM,
    "rosrun norm2tex norm2tex_grasp_demo /tmp/grasp": NEEDS_SIM + "; test/tools runs its "
                                                      "command line",
    "rosrun norm2tex dataset_recorder _output_dir:=/data/grasps _samples:=6000":
        NEEDS_SIM + ", driven step by step",
    "rviz -d $(rospack find norm2tex)/rviz/norm2tex.rviz": "a display",
    "python3 -c 'from norm2tex.envs.ros_backend import RosBackend; *": NEEDS_SIM,
    # datasets and learning
    "scripts/record_dataset /data/all material:=all samples:=6000":
        "slow: records 6000 samples (minutes)",
    "rosrun norm2tex norm2tex_export /data/all/*.bag -o /data/all_png":
        "needs /data/all of the (slow) line above",
    "scripts/train_material_classifier /data/all_png --test-variants 3":
        "needs /data/all_png of the lines above",
    "rosrun norm2tex train_material_classifier /data/small_png --test-variants 3":
        "slow: about 20 minutes of training on 2 cores (the page says); the recording and the "
        "export before it run",
    "scripts/record_dataset /tmp/wood material:=wood samples:=6000":
        "slow: records 6000 samples (minutes)",
    "scripts/slurm/submit_dataset 8 /data/probe material:=all samples:=6000 -- --partition=cpu":
        "a Slurm cluster (test/slurm runs the job array on a local one)",
    "rosrun norm2tex hold_cube_experiment --out results/":
        "slow: about 40 minutes",
    "rosrun norm2tex hold_cube_experiment --quick --out /tmp/smoke":
        "54 s here; test/python/test_hold_cube_experiment.py runs the same --quick end to end",
    "rosrun norm2tex hold_cube_experiment --table results/":
        "needs results/ of the 40-minute run above",
    "rosrun norm2tex hold_cube_experiment --images --out results/":
        "slow: renders and classifies every material's images (minutes)",
    "python: import torch from torch import nn from norm2tex.envs import HoldCubeVectorEnv *":
        "slow: 20 000 PPO steps, 2.5 min on 2 cores (test/python/test_ppo.py trains small "
        "problems)",
    "python: import torch from norm2tex_dataset import ExportedDataset, BagDataset *":
        "needs /data/small and /data/small_png of README.md's small recipe (which runs there)",
    "python: env = HandEnv(hand, object_pose=[0, 0, 0.015], noise=False, backend=\"ros\")":
        NEEDS_SIM + ", and `hand` of the example above",
    "python: from norm2tex.envs import HoldCubeEnv env = HoldCubeEnv(backend=\"ros\")": NEEDS_SIM,
    # measurements
    "scripts/ros_benchmark 600": "slow: 600 s of the simulation under ROS",
    "scripts/bake_timing 3 10": "slow: 12 cold bakes of 2048² and 4096² maps, each after 10 s "
                                "idle (minutes); norm2tex_bench's BM_Bake above runs",
    "scripts/env_benchmark --hand test/fixtures/robots/allegro_hand_description/"
    "allegro_palm_up.yaml *": "starts the hand simulation under ROS and measures it (minutes)",
    "scripts/env_benchmark --hand test/fixtures/robots/wsg50/wsg50_top_grasp.yaml *":
        "starts the hand simulation under ROS and measures it (minutes)",
    "scripts/env_benchmark --hand HAND_YAML --ros --launch":
        "HAND_YAML stands for the commands above (excluded)",
    # synopses that are not a whole command
    "norm2tex_render ... --material print3d": "'...' stands for the rest of a norm2tex_render "
                                              "command (docs/sensor.md's, which runs)",
}

# --- what the commands are given -----------------------------------------------------------------
# Files the pages ask the reader to bring, put in the page's directory before its commands run.
# A value is a fixture path (copied; a .png of a .jpg fixture is converted) or a list of
# arguments of one of the package's programs (found in TOOLS_DIR) that writes the file.
REAL_PRESSES = [os.path.join(S09, "frame_%d.jpg" % i) for i in range(0, 30, 2)]
# test/fixtures/digit_s09: 15 real DIGIT presses of a 6 mm ball at 0.0532 mm per pixel, and
# frame_30.jpg, the no-contact frame (see its README.md).
CALIBRATION_FILES = dict([("bg.png", os.path.join(S09, "frame_30.jpg"))] +
                         [("press_%02d.png" % i, f) for i, f in enumerate(REAL_PRESSES)])
# Presses of a flat wood sample, light to firm (2, 5, 12 N), tilted so that part of the gel stays
# free: rendered by norm2tex_render onto that background (after bg.png, in the page directory).
for _i, (_force, _press) in enumerate([("2", "0.3"), ("5", "0.45"), ("12", "0.6")], 1):
    CALIBRATION_FILES["wood_%d.png" % _i] = [
        "norm2tex_render", "--mesh", "box:30x30x10", "--pose", "0 0 0.005 0.1 0 0", "--press-mm",
        _press, "--material", "wood", "--force-n", _force, "--background", "bg.png", "-o"]
# calibration.md's second session to judge a sensor on (bg2.png, press2_*.png): the fixtures hold
# one session of real presses, so the same frames again.
JUDGE_FILES = dict([("bg2.png", os.path.join(S09, "frame_30.jpg"))] +
                   [("press2_%02d.png" % i, f) for i, f in enumerate(REAL_PRESSES)])
# Two presses of the 6 mm ball 8 mm apart along the gel (--scale-presses here.png moved.png
# --scale-distance-mm 8): rendered by norm2tex_render onto bg.png.
SCALE_FILES = {name: ["norm2tex_render", "--mesh", "sphere:3", "--pose", "%s 0 0.003 0 0 0" % x,
                      "--press-mm", "0.5", "--background", "bg.png", "-o"]
               for name, x in (("here.png", "-0.004"), ("moved.png", "0.004"))}
# gelsight_mini.md's own Mini's frames (mini_bg.png, mini_press_*.png): a no-contact frame and six
# presses of a 6 mm ball at different places, rendered by the Mini profile itself (dots and all).
MINI = ["--sensor", "config/gelsight_mini.yaml"]
GELSIGHT_MINI_FILES = {"mini_bg.png": ["norm2tex_render", "--mesh", "sphere:3", "--pose",
                                       "0 0 0.01 0 0 0", "--seed", "1"] + MINI + ["-o"]}
for _i, (_x, _y) in enumerate([(-5, -3), (4, -3), (0, 0), (-3, 3), (5, 3), (1, -4)]):
    GELSIGHT_MINI_FILES["mini_press_%d.png" % _i] = [
        "norm2tex_render", "--mesh", "sphere:3", "--pose",
        "%g %g 0.003 0 0 0" % (_x * 1e-3, _y * 1e-3), "--press-mm", "0.5",
        "--seed", str(_i + 2)] + MINI + ["-o"]
# norm2tex_make_demo_normal_map: the package's normal map of known relief (waves, bumps, ridges).
DEMO_NORMAL_MAP = ["norm2tex_make_demo_normal_map", "--size", "256", "-o"]
FILES = {
    "README.md": dict(CALIBRATION_FILES, **{"my_normal.png": DEMO_NORMAL_MAP}),
    "docs/calibration.md": dict(CALIBRATION_FILES, **JUDGE_FILES, **SCALE_FILES),
    "docs/gelsight_mini.md": GELSIGHT_MINI_FILES,
    # A material yaml of your own: the shipped wood's.
    "docs/materials.md": {"my_wood.yaml": os.path.join(ROOT, "config", "materials", "wood.yaml")},
    "docs/texture.md": {"my_normal.png": DEMO_NORMAL_MAP},
}

# Placeholders of the synopses, per page: word -> what it stands for. Outputs go to the page's
# temporary directory; inputs are fixtures or FILES.
WSG50_DIGIT_MESH = os.path.join(FIXTURES, "robots", "wsg50", "digit.STL")  # TACTO's DIGIT housing
SUBSTITUTIONS = {
    "docs/materials.md": {"NORMAL.png": "normal.png", "IN.stl": WSG50_DIGIT_MESH,
                          "DIR": "variants", "GALLERY.png": "gallery.png"},
    "docs/sensor.md": {"M": "sphere:5", '"x y z roll pitch yaw"': '"0 0 0.005 0 0 0"',
                       "P": '"0 0 0.005 0 0 0"', "OUT.png": "out.png", "SHEET.png": "sheet.png",
                       '"FX,FY,T;..."': '"0,0,0;1,0,0"'},
    "docs/texture.md": {"NORMAL_MAP": "my_normal.png", "OUT.tiff": "out.tiff"},
}

DEFAULT_TIMEOUT = 120  # s; a hang, not a speed test (the commands here take 0.1-17 s)
TIMEOUTS = {}  # command key -> s, for slower ones that run (none at present)

# Options whose argument is a file or folder the command writes.
_OUTPUT_OPTIONS = re.compile(r"^(?:-o|--out|--output|--out-dir|--out-mesh|--report|--json|--csv|"
                             r"--figure|--[\w-]+-out)$")


# --- the commands of a page ----------------------------------------------------------------------
def _open_quote(text):
    """The quote character left open at the end of text (shell rules, roughly), or None."""
    quote, escaped = None, False
    for c in text:
        if escaped:
            escaped = False
        elif c == "\\" and quote != "'":
            escaped = True
        elif quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
    return quote


def page_commands(text):
    """[(line number, command, block number)] of a page's shell blocks. A trailing backslash or an
    open quote continues a command on the next line; so does an indented line (a synopsis's
    layout). Comments are dropped."""
    out = []
    for block, (info, start, lines) in enumerate(docs.fenced_blocks(text)):
        language = (info.split() or [""])[0].lower()
        if language == "python":
            out.append((start, _PY_HEAD + "\n".join(lines) + _PY_END, block))
        if language not in SHELL_BLOCKS:
            continue
        cur, cur_line = None, 0
        for number, line in enumerate(lines, start):
            if cur is not None and _open_quote(cur):
                cur += "\n" + line
                continue
            code = docs._strip_comment(line)[1:].rstrip()
            if cur is not None and cur.endswith("\\"):
                cur = cur[:-1].rstrip() + " " + code.strip()
                continue
            if not code.strip():
                continue
            if cur is not None and line[:1].isspace():
                cur += " " + code.strip()
                continue
            if cur is not None:
                out.append((cur_line, cur, block))
            cur, cur_line = code, number
        if cur is not None:
            out.append((cur_line, cur, block))
    return out


def is_python(command):
    return command.startswith(_PY_HEAD)


def key(command):
    """The command as EXCLUDED names it: whitespace collapsed; a Python block as "python: " and
    its code without comments."""
    if is_python(command):
        code = command[len(_PY_HEAD):-len(_PY_END)].split("\n")
        return "python: " + " ".join(" ".join(docs._strip_comment(l) for l in code).split())
    return " ".join(command.split())


def exclusion(command):
    """(EXCLUDED key, reason) that covers the command, or None."""
    k = key(command)
    if k in EXCLUDED:
        return k, EXCLUDED[k]
    for pattern, reason in EXCLUDED.items():
        if pattern.endswith(" *") and (k + " ").startswith(pattern[:-1]):
            return pattern, reason
    return None


def _words(command):
    """The command's words outside quotes, raw (quotes kept)."""
    words, cur, quote, escaped = [], "", None, False
    for c in command:
        if escaped:
            cur, escaped = cur + c, False
        elif c == "\\" and quote != "'":
            cur, escaped = cur + c, True
        elif quote:
            cur += c
            quote = None if c == quote else quote
        elif c in "'\"":
            cur, quote = cur + c, c
        elif c.isspace():
            if cur:
                words.append(cur)
            cur = ""
        else:
            cur += c
    if cur:
        words.append(cur)
    return words


def shortest_form(command):
    """A synopsis as the shortest command it allows: optional [...] groups dropped (outside
    quotes, at a word's start), the first of A|B alternatives."""
    out, depth, quote, prev = "", 0, None, " "
    for c in command:
        if depth:
            depth += {"[": 1, "]": -1}.get(c, 0)
        elif quote:
            out += c
            quote = None if c == quote else quote
        elif c == "[" and prev.isspace():
            depth = 1
        else:
            if c in "'\"":
                quote = c
            out += c
        prev = c
    words = []
    for w in _words(out):
        if "|" in w and w.strip("|") and not re.search(r"['\"$(]", w):
            w = w.split("|")[0]
        words.append(w)
    return " ".join(words)


def substituted(command, page, page_dir):
    """The command as run: the page's own /data/ and /tmp/ paths moved into the page's directory,
    then its placeholders replaced. In that order: a placeholder's value is a real path already
    (a fixture of a clone that may itself live under /tmp)."""
    subs = SUBSTITUTIONS.get(page, {})
    moved = [re.sub(r"(^|[\s=])/(data|tmp)/", lambda m: "%s%s/%s/" % (m.group(1), page_dir,
                                                                   m.group(2)), w)
             for w in _words(command)]
    return " ".join(subs.get(w, w) for w in moved)


def outputs(command):
    """The files or folders a command says it writes (the arguments of output options)."""
    if is_python(command):
        return []
    words = _words(command)
    out = []
    for option, value in zip(words, words[1:]):
        if _OUTPUT_OPTIONS.match(option) and not value.startswith("-"):
            out.append(value.strip("'\""))
    return out


def all_commands(root=ROOT):
    """[(page, line, command, block, exclusion or None)] of every page, in page order."""
    out = []
    for path, text in docs.pages(root):
        page = os.path.relpath(path, root)
        for line, command, block in page_commands(text):
            out.append((page, line, command, block, exclusion(command)))
    return out


# --- running a page ------------------------------------------------------------------------------
def _free_port():
    return subprocess.check_output([sys.executable, os.path.join(ROOT, "scripts", "free_port")],
                                   universal_newlines=True).strip()


def environment(page_dir):
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    env.update({
        "CI": "true",
        "PATH": TOOLS_DIR + os.pathsep + env.get("PATH", ""),
        "ROS_HOME": os.path.join(page_dir, ".ros"),
        "ROS_HOSTNAME": "localhost",
        "ROS_MASTER_URI": "http://localhost:%s" % _free_port(),
    })
    env.pop("ROS_IP", None)
    return env


def make_page_dir(page, parent):
    """A directory standing in for the clone, with the page's FILES."""
    page_dir = os.path.join(parent, re.sub(r"\W", "_", page))
    os.makedirs(os.path.join(page_dir, ".catkin_ws"))
    for name in os.listdir(ROOT):
        if name not in (".git", ".catkin_ws"):
            os.symlink(os.path.join(ROOT, name), os.path.join(page_dir, name))
    os.symlink(DEVEL, os.path.join(page_dir, ".catkin_ws", "devel"))
    for sub in ("data", "tmp", ".ros"):
        os.makedirs(os.path.join(page_dir, sub))
    for name, source in FILES.get(page, {}).items():
        target = os.path.join(page_dir, name)
        if isinstance(source, list):
            subprocess.check_call([os.path.join(TOOLS_DIR, source[0])] + source[1:] + [target],
                                  cwd=page_dir, stdout=subprocess.DEVNULL)
        elif os.path.splitext(source)[1] != os.path.splitext(name)[1]:
            from PIL import Image  # python3-pil, an exec_depend of the package
            Image.open(source).save(target)
        else:
            shutil.copyfile(source, target)
    return page_dir


def run_page(page, commands, parent):
    """Runs a page's commands in one shell; [(line, command, problem)] of those that failed."""
    page_dir = make_page_dir(page, parent)
    logs = os.path.join(page_dir, ".commands")
    os.makedirs(logs)
    script, runs, block = [], [], None
    for i, (line, command, command_block) in enumerate(commands):
        shell_command = command if is_python(command) else \
            substituted(shortest_form(command), page, page_dir)
        runs.append((line, command, shell_command))
        log = os.path.join(logs, str(i))
        if command_block != block:  # each block starts in the clone's root, as pages write it
            script.append("cd %s" % _quote(page_dir))
            block = command_block
        script.append("{ %s\n} </dev/null >%s 2>&1; __n2t_rc=$?; pwd >%s; echo $__n2t_rc >%s; "
                      "mv %s %s" % (shell_command, _quote(log + ".out"), _quote(log + ".pwd"),
                                    _quote(log + ".tmp"), _quote(log + ".tmp"),
                                    _quote(log + ".rc")))
    with open(os.path.join(logs, "page.sh"), "w") as f:
        f.write("\n".join(script) + "\n")
    process = subprocess.Popen(["bash", os.path.join(logs, "page.sh")], cwd=page_dir,
                               env=environment(page_dir), stdin=subprocess.DEVNULL,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)
    failures = []
    try:
        for i, (line, command, shell_command) in enumerate(runs):
            log = os.path.join(logs, str(i))
            timeout = TIMEOUTS.get(key(command), DEFAULT_TIMEOUT)
            started = time.time()
            while not os.path.exists(log + ".rc"):
                if time.time() - started > timeout:
                    failures.append((line, command, "timed out after %d s\n%s" %
                                     (timeout, _tail(log + ".out"))))
                    return failures
                if process.poll() is not None and not os.path.exists(log + ".rc"):
                    failures.append((line, command, "the page's shell ended\n" +
                                     _tail(log + ".out")))
                    return failures
                time.sleep(0.05)
            seconds = time.time() - started
            with open(log + ".rc") as f:
                status = int(f.read())
            with open(log + ".pwd") as f:
                cwd = f.read().strip()
            if os.environ.get("NORM2TEX_PAGE_COMMANDS_VERBOSE"):
                sys.stderr.write("%s:%d %.1f s status %d: %s\n" % (page, line, seconds, status,
                                                                    key(command)))
            if status != 0:
                failures.append((line, command, "exit status %d\n%s" % (status,
                                                                        _tail(log + ".out"))))
                continue
            missing = [o for o in outputs(shell_command)
                       if not os.path.exists(os.path.join(cwd, os.path.expanduser(o)))]
            if missing:
                failures.append((line, command, "did not write %s\n%s" %
                                 (", ".join(missing), _tail(log + ".out"))))
        process.wait(timeout=10)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    return failures


def _quote(path):
    return "'" + path.replace("'", "'\\''") + "'"


def _tail(path, lines=15):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-lines:])
    except OSError:
        return ""


# --- the tests -----------------------------------------------------------------------------------
class PageCommandsAreAccountedFor(unittest.TestCase):
    """Every command runs or is excluded with a reason; every exclusion is of a command."""

    def test_every_excluded_entry_is_a_command_of_a_page(self):
        used = {e[0] for _, _, _, _, e in all_commands() if e}
        unused = sorted(set(EXCLUDED) - used)
        self.assertEqual(unused, [], "EXCLUDED entries no page has (remove them)")

    def test_tables_name_pages(self):
        names = {os.path.relpath(p, ROOT) for p, _ in docs.pages(ROOT)}
        self.assertLessEqual(set(FILES) | set(SUBSTITUTIONS), names)
        runnable = {key(c) for _, _, c, _, e in all_commands() if not e}
        self.assertLessEqual(set(TIMEOUTS), runnable, "TIMEOUTS of commands that do not run")

    def test_pages_have_commands(self):
        commands = all_commands()
        self.assertGreater(len([c for c in commands if not c[4]]), 10)
        self.assertGreater(len([c for c in commands if c[4]]), 10)


class PageCommandsRun(unittest.TestCase):
    """The commands of each page, run (test methods added below, one per page)."""

    @classmethod
    def setUpClass(cls):
        cls.parent = tempfile.mkdtemp(prefix="norm2tex_page_commands_")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.parent, ignore_errors=True)

    def check_page(self, page):
        commands = [(line, c, b) for p, line, c, b, e in all_commands() if p == page and not e]
        failures = run_page(page, commands, self.parent)
        self.assertFalse(failures, "\n" + "\n".join(
            "%s:%d: %s\n  %s" % (page, line, key(c), why.replace("\n", "\n  "))
            for line, c, why in failures))


def _add_page_tests():
    pages = []
    for page, _, _, _, e in all_commands():
        if not e and page not in pages:
            pages.append(page)
    for page in pages:
        name = "test_" + re.sub(r"\W", "_", page)
        setattr(PageCommandsRun, name, lambda self, page=page: self.check_page(page))


_add_page_tests()


class ParsingTest(unittest.TestCase):
    """The command extraction and the synopsis rules themselves."""

    def test_continuations_and_comments(self):
        page = ("```bash\n"
                "a --x 1 \\\n    --y 2      # comment\n"
                "# only a comment\n"
                "b \"{k: [1, 2],\n  v: 3}\"\n"
                "c --m M [--opt V]\n"
                "  [--more | --other] -o OUT.png\n"
                "```\n```python\nx = 1  # a comment\nprint(x)\n```\n```yaml\nk: v\n```\n")
        self.assertEqual([(n, key(c), b) for n, c, b in page_commands(page)],
                         [(2, "a --x 1 --y 2", 0), (5, 'b "{k: [1, 2], v: 3}"', 0),
                          (7, "c --m M [--opt V] [--more | --other] -o OUT.png", 0),
                          (11, "python: x = 1 print(x)", 1)])

    def test_shortest_form(self):
        self.assertEqual(shortest_form("t -o OUT.tiff|OUT.png [--mask M [--scale S]] [--bits 8|16]"
                                       " --x \"[0, 1]\" | grep a"),
                         't -o OUT.tiff --x "[0, 1]" | grep a')

    def test_substitution_and_outputs(self):
        cmd = substituted("norm2tex_render --mesh M --pose \"x y z roll pitch yaw\" -o OUT.png "
                          "--json /tmp/x.json", "docs/sensor.md", "/T")
        self.assertEqual(cmd, 'norm2tex_render --mesh sphere:5 --pose "0 0 0.005 0 0 0" '
                              '-o out.png --json /T/tmp/x.json')
        self.assertEqual(outputs(cmd), ["out.png", "/T/tmp/x.json"])

    def test_a_placeholders_path_under_tmp_is_kept(self):
        # A clone under /tmp (as CI's is) has its fixtures there: they are not the page's /tmp.
        fixture = "/tmp/clone/test/fixtures/robots/wsg50/digit.STL"
        with unittest.mock.patch.dict(SUBSTITUTIONS, {"docs/materials.md": {"IN.stl": fixture}}):
            self.assertEqual(substituted("norm2tex_texgen --mesh IN.stl -o /tmp/n.png",
                                         "docs/materials.md", "/T"),
                             "norm2tex_texgen --mesh %s -o /T/tmp/n.png" % fixture)

    def test_exclusion_prefix(self):
        self.assertIsNotNone(exclusion("roslaunch norm2tex gripper_sim.launch"))
        self.assertIsNotNone(exclusion("roslaunch norm2tex gripper_sim.launch  mode:=synchronous"))
        self.assertIsNone(exclusion("roslaunch norm2tex gripper_sim.launchx"))


def main_list():
    for page, line, command, _, e in all_commands():
        print("%s:%d: %s\n    %s" % (page, line, key(command),
                                     "EXCLUDED: " + e[1] if e else "runs"))


if __name__ == "__main__":
    if "--list" in sys.argv:
        main_list()
    else:
        unittest.main(argv=sys.argv[:1])
