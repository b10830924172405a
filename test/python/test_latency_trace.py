"""The real-time latency trace: scripts/latency_trace's arithmetic on traces with known stages,
its errors, and a real gripper_sim.launch (nodelets, real time, trace_dir) traced while
norm2tex_ros_bench receives its images: every received frame is in every node's trace, with its
stages in the order the chain runs them, and the stages add up to the latency the subscriber saw.

Starts its own master on a free port. Run (with the workspace sourced; NORM2TEX_TOOLS_DIR: the
directory of norm2tex_ros_bench):
    /usr/bin/python3 -m pytest -q test/python/test_latency_trace.py
"""
import csv
import importlib.machinery
import importlib.util
import os
import re
import subprocess
import xmlrpc.client

import pytest

import ros_launch

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "scripts", "latency_trace")


def _load_script():
    loader = importlib.machinery.SourceFileLoader("latency_trace", SCRIPT)
    spec = importlib.util.spec_from_loader("latency_trace", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


latency_trace = _load_script()
MS = 1_000_000  # ns


def _write(path, header, rows):
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(header)
        writer.writerows(rows)


def _synthetic_trace(directory, frames=40, first_left=True):
    """Frames 1/60 s apart whose stages take known times: woke +0.2 ms, physics +0.1, TF +0.05,
    SimFrame +0.05; left takes it at +0.1 after the physics, right at +0.3; pose +0.02; render
    1.0 (left) / 1.5 (right) ms; publish +0.1; at the subscriber +0.4 after that."""
    def ns(ms):  # whole nanoseconds: stamps near 1.7e18 ns are beyond a float's precision
        return int(round(ms * MS))

    sim, left, right, arrivals = [], [], [], []
    for i in range(frames):
        t = 1_700_000_000 * 1_000_000_000 + i * 16_666_667
        woke, physics = t + ns(0.2), t + ns(0.3)
        sim.append([t, woke, physics, physics + ns(0.05), physics + ns(0.1)])
        rows = {}
        for name, taken, render in (("left", 0.1, 1.0), ("right", 0.3, 1.5)):
            received = physics + ns(taken)
            pose = received + ns(0.02)
            rendered = pose + ns(render)
            published = rendered + ns(0.1)
            rows[name] = [t, received, pose, rendered, published]
        left.append(rows["left"])
        right.append(rows["right"])
        at_left, at_right = rows["left"][4] + ns(0.4), rows["right"][4] + ns(0.4)
        if first_left:
            arrivals.append([t, at_left, at_right, "digit_left_gel"])
        else:  # the frame ids decide which sensor an arrival belongs to
            arrivals.append([t, at_right, at_left, "digit_right_gel"])
    _write(os.path.join(directory, "contact_sim.csv"),
           ["stamp_ns", "woke_ns", "physics_ns", "tf_ns", "frame_ns"], sim)
    header = ["stamp_ns", "received_ns", "pose_ns", "rendered_ns", "published_ns"]
    _write(os.path.join(directory, "digit_left.csv"), header, left)
    _write(os.path.join(directory, "digit_right.csv"), header, right)
    _write(os.path.join(directory, "arrivals.csv"),
           ["stamp_ns", "first_ns", "second_ns", "first_frame_id"], arrivals)


def _stages(summary):
    return {s["stage"]: s for s in summary["stages"]}


@pytest.mark.parametrize("first_left", [True, False])
def test_known_stages_come_out_of_the_table(tmp_path, first_left):
    _synthetic_trace(str(tmp_path), first_left=first_left)
    summary = latency_trace.summarise(str(tmp_path))
    stages = _stages(summary)
    assert summary["frames"] == 40
    expected = {
        "tick -> clock thread awake": 0.2,
        "awake -> physics done": 0.1,
        "physics -> TF sent": 0.05,
        "TF -> SimFrame sent": 0.05,
        "digit_left: physics -> SimFrame taken": 0.1,
        "digit_right: physics -> SimFrame taken": 0.3,
        "digit_left: pose -> rendered": 1.0,
        "digit_right: pose -> rendered": 1.5,
        "digit_right: published -> at the subscriber": 0.4,
        # The right image comes last: its chain is the frame's.
        "last image's sensor: pose -> rendered": 1.5,
        "last image's sensor: physics -> SimFrame taken": 0.3,
        "stamp -> first image": 0.3 + 0.1 + 0.02 + 1.0 + 0.1 + 0.4,
        "stamp -> both images": 0.3 + 0.3 + 0.02 + 1.5 + 0.1 + 0.4,
    }
    for name, ms in expected.items():
        for p in ("p50_ms", "p99_ms"):
            assert stages[name][p] == pytest.approx(ms, abs=1e-5), name


def test_percentiles_are_of_the_spread(tmp_path):
    _synthetic_trace(str(tmp_path), frames=100)
    # Two frames in 100 whose clock thread woke 3 ms late: p99 sees them, p50 and p90 do not.
    path = tmp_path / "contact_sim.csv"
    rows = list(csv.reader(open(path)))
    for late_row in (21, 51):
        rows[late_row][1] = str(int(rows[late_row][0]) + 3 * MS)
    _write(str(path), rows[0], rows[1:])
    stages = _stages(latency_trace.summarise(str(tmp_path)))
    late = stages["tick -> clock thread awake"]
    assert late["p50_ms"] == pytest.approx(0.2, abs=1e-5)
    assert late["p90_ms"] == pytest.approx(0.2, abs=1e-5)
    assert late["p99_ms"] == pytest.approx(3.0, abs=1e-5)


def test_missing_or_short_traces_are_clear_errors(tmp_path, capsys):
    _synthetic_trace(str(tmp_path), frames=5)
    assert latency_trace.main([str(tmp_path)]) == 1
    assert "only 5 frames" in capsys.readouterr().err
    os.remove(tmp_path / "digit_right.csv")
    assert latency_trace.main([str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "digit_right.csv not found" in err and "trace_dir" in err
    _write(str(tmp_path / "digit_right.csv"), ["stamp_ns", "received_ns"], [[1, 2]])
    assert latency_trace.main([str(tmp_path)]) == 1
    assert "no column pose_ns" in capsys.readouterr().err


def _tools_dir():
    tools = os.environ.get("NORM2TEX_TOOLS_DIR")
    if tools:
        return tools
    return os.path.join(REPO, ".catkin_ws", "devel", "lib", "norm2tex")


def _threads_cpus(pid):
    """{thread id: the CPUs it may run on} of a process (/proc)."""
    cpus = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/status") as f:
                for line in f:
                    if line.startswith("Cpus_allowed_list:"):
                        cpus[int(tid)] = line.split(":", 1)[1].strip()
        except FileNotFoundError:  # a thread that ended meanwhile
            pass
    return cpus


def _node_pid(master_uri, node):
    master = xmlrpc.client.ServerProxy(master_uri)
    code, message, uri = master.lookupNode("/latency_trace_test", node)
    assert code == 1, message
    code, message, pid = xmlrpc.client.ServerProxy(uri).getPid("/latency_trace_test")
    assert code == 1, message
    return pid


def test_a_traced_real_time_launch_accounts_for_every_received_frame(tmp_path):
    # With two or more CPUs, the renderers also run on CPUs of their own (left_cpu, right_cpu):
    # their frame threads must be the manager's only threads held to one CPU each.
    pinned = os.cpu_count() >= 2
    bench = os.path.join(_tools_dir(), "norm2tex_ros_bench")
    if not os.access(bench, os.X_OK):
        pytest.fail(f"{bench} not built (NORM2TEX_TOOLS_DIR)")
    trace_dir = tmp_path / "trace"
    trace_dir.mkdir()
    port = ros_launch.free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOSTNAME="localhost",
               ROS_HOME=str(tmp_path / "ros_home"))
    log = open(tmp_path / "roslaunch.log", "w+")
    # rehearse_ms: each renderer renders its last frame again between frames; no frame may be
    # lost or reordered for it.
    launch = ros_launch.start(
        ["-p", str(port), "norm2tex", "gripper_sim.launch", "mode:=real_time", "manager:=true",
         f"trace_dir:={trace_dir}", "rehearse_ms:=5"] +
        (["left_cpu:=0", "right_cpu:=1"] if pinned else []),
        env, log)
    try:
        bench_run = subprocess.run(
            [bench, "real_time", "60", "--arrivals", str(trace_dir / "arrivals.csv")],
            env=env, capture_output=True, text=True, timeout=120)
        if pinned and bench_run.returncode == 0:
            cpus = _threads_cpus(_node_pid(env["ROS_MASTER_URI"], "/norm2tex_manager"))
            held = sorted(c for c in cpus.values() if c in ("0", "1"))
            assert held == ["0", "1"], cpus
    finally:
        ros_launch.stop(launch)
        log.seek(0)
        launch_log = log.read()
        log.close()
    assert bench_run.returncode == 0, bench_run.stderr + launch_log
    # The nodes wrote their traces when the launch ended.
    for name in ("contact_sim", "digit_left", "digit_right"):
        assert (trace_dir / f"{name}.csv").is_file(), launch_log
    sim = latency_trace.read_rows(str(trace_dir / "contact_sim.csv"), latency_trace.SIM_STAGES)
    renders = {s: latency_trace.read_rows(str(trace_dir / f"{s}.csv"),
                                          latency_trace.RENDER_STAGES)
               for s in latency_trace.SENSORS}
    arrivals = latency_trace.read_arrivals(str(trace_dir / "arrivals.csv"))
    assert len(arrivals) >= 60
    for stamp, at in arrivals.items():
        # Every frame the subscriber received both images of was simulated and rendered by
        # every node of the trace, under the same stamp, with every stage reached.
        assert stamp in sim and len(sim[stamp]) == 4, stamp
        s = sim[stamp]
        # The stamp is the tick's scheduled time: the thread wakes after it, then steps the
        # physics, then sends TF, then the SimFrame.
        assert stamp <= s["woke"] <= s["physics"] <= s["tf"] <= s["frame"], (stamp, s)
        for sensor in latency_trace.SENSORS:
            r = renders[sensor][stamp]
            assert len(r) == 4, (sensor, stamp, r)
            # A renderer takes the frame once its SimFrame is sent (while the send returns, in
            # one process), finds the pose, renders, publishes; the image arrives after the
            # render (possibly before the publish call has returned).
            assert s["tf"] <= r["received"] <= r["pose"] <= r["rendered"] <= r["published"], (
                sensor, stamp, s, r)
            assert r["rendered"] <= at[sensor], (sensor, stamp, r, at)
    summary = latency_trace.summarise(str(trace_dir))
    stages = _stages(summary)
    assert summary["frames"] == len(arrivals)
    # The table's whole is what the subscriber measured (its own p50 line).
    bench_p50 = float(bench_run.stdout.split("p50 ")[1].split(" ms")[0])
    assert stages["stamp -> both images"]["p50_ms"] == pytest.approx(bench_p50, abs=0.01)
    # Each renderer rehearsed between frames (the shutdown line), at most once per frame: a
    # rehearsal is skipped only after the first frame or when a frame ran late.
    for sensor in latency_trace.SENSORS:
        assert f"{sensor}: rehearsing each real-time frame 5.0 ms" in launch_log, launch_log
        found = re.search(sensor + r": (\d+) frames rendered, (\d+) rehearsed 5.0 ms", launch_log)
        assert found, launch_log
        rendered, rehearsed = int(found.group(1)), int(found.group(2))
        assert rendered >= len(arrivals) and rendered // 2 <= rehearsed <= rendered, found.group(0)
    # Rendering is real work: on every frame, each sensor's render takes time.
    for sensor in latency_trace.SENSORS:
        assert stages[f"{sensor}: pose -> rendered"]["p50_ms"] > 0.1
