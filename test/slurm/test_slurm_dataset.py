"""The Slurm job array for real: a one-node Slurm cluster (munge, slurmctld, slurmd) started on
this machine, a 2-task array of a small probe dataset submitted with scripts/slurm/submit_dataset
(which waits and merges), and the merged result checked; merge_dataset's refusals too.
Skips, visibly, where a cluster cannot be started (not root, Slurm or munge not installed).

Usage (catkin passes it): test_slurm_dataset.py REPO_DIR
"""
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

REPO = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")


def _free_port():
    # scripts/free_port: below the kernel's ephemeral range (see there).
    return int(subprocess.run([os.path.join(REPO, "scripts", "free_port")], capture_output=True,
                              text=True, check=True).stdout)


def _run(command, **kwargs):
    return subprocess.run(command, capture_output=True, text=True, **kwargs)


class OneNodeCluster:
    """munged (if none answers), slurmctld and slurmd with a config of their own."""

    def __init__(self, root):
        self.root, self.started_munged = root, False
        self.host = socket.gethostname().split(".")[0]
        self.conf = os.path.join(root, "slurm.conf")
        self.env = dict(os.environ, SLURM_CONF=self.conf)

    def start(self):
        if _run(["sh", "-c", "munge -n | unmunge"]).returncode != 0:
            if not os.path.exists("/etc/munge/munge.key"):
                _run(["mungekey", "--create"])  # munge 0.5.15; the package usually made one
            os.makedirs("/run/munge", exist_ok=True)
            shutil.chown("/run/munge", "munge", "munge")
            started = _run(["runuser", "-u", "munge", "--", "/usr/sbin/munged"])
            if started.returncode != 0:
                raise RuntimeError("munged did not start: " + started.stderr)
            self.started_munged = True
        for sub in ("state", "spool", "log"):
            os.makedirs(os.path.join(self.root, sub), exist_ok=True)
        cpus = os.cpu_count() or 1
        with open(self.conf, "w") as f:
            f.write(f"""ClusterName=norm2tex_test
SlurmctldHost={self.host}
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
StateSaveLocation={self.root}/state
SlurmdSpoolDir={self.root}/spool
SlurmctldPidFile={self.root}/slurmctld.pid
SlurmdPidFile={self.root}/slurmd.pid
SlurmctldLogFile={self.root}/log/slurmctld.log
SlurmdLogFile={self.root}/log/slurmd.log
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
NodeName={self.host} CPUs={cpus} RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes={self.host} Default=YES MaxTime=INFINITE State=UP
""")
        for daemon in (["slurmctld", "-c"], ["slurmd"]):
            started = _run(daemon, env=self.env)
            if started.returncode != 0:
                raise RuntimeError(f"{daemon[0]} did not start: {started.stderr}")
        deadline = time.time() + 60
        while time.time() < deadline:
            state = _run(["sinfo", "-h", "-o", "%T"], env=self.env).stdout.strip()
            if state in ("idle", "mixed"):
                return
            time.sleep(0.5)
        raise RuntimeError(f"the node did not become idle within 60 s (sinfo: {state!r}); "
                           f"see {self.root}/log")

    def stop(self):
        for pid_file in ("slurmd.pid", "slurmctld.pid"):
            try:
                with open(os.path.join(self.root, pid_file)) as f:
                    os.kill(int(f.read().strip()), 15)
            except (OSError, ValueError):
                pass
        if self.started_munged:
            _run(["pkill", "-x", "munged"])


class SlurmDatasetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        missing = [t for t in ("slurmctld", "slurmd", "sbatch", "munged") if not shutil.which(t)
                   and not os.path.exists("/usr/sbin/" + t)]
        if missing:
            raise unittest.SkipTest(f"Slurm cannot be started here: {', '.join(missing)} not "
                                    "installed (apt install slurm-wlm munge)")
        if os.geteuid() != 0:
            raise unittest.SkipTest("Slurm cannot be started here: the one-node cluster needs root")
        cls.dir = tempfile.mkdtemp(prefix="norm2tex_slurm_test_")
        cls.cluster = OneNodeCluster(os.path.join(cls.dir, "cluster"))
        try:
            cls.cluster.start()
        except RuntimeError as e:
            cls.cluster.stop()
            raise unittest.SkipTest(f"Slurm cannot be started here: {e}")

    @classmethod
    def tearDownClass(cls):
        cls.cluster.stop()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_a_two_task_array_gives_disjoint_shards_that_merge_complete(self):
        out = os.path.join(self.dir, "dataset")
        # 10 images of wood in presses of 5 frames: 2 presses, one per shard.
        submitted = _run([os.path.join(REPO, "scripts/slurm/submit_dataset"), "2", out,
                          "material:=wood", "variants:=1", "samples:=10", "slides:=4", "seed:=9"],
                         env=self.cluster.env, timeout=600)
        self.assertEqual(submitted.returncode, 0, submitted.stdout + submitted.stderr)
        for k in (0, 1):
            with open(os.path.join(out, f"shard_{k}", f"norm2tex_shard{k}.yaml")) as f:
                manifest = f.read()
            self.assertIn("complete: true", manifest)
            self.assertIn("images: 5", manifest)
        with open(os.path.join(out, "merged", "dataset.yaml")) as f:
            merged = f.read()
        self.assertIn("shards: 2", merged)
        self.assertIn("images: 10", merged)
        self.assertIn("'wood/variant0': 2", merged)
        names = sorted(os.listdir(os.path.join(out, "merged")))
        self.assertEqual([n for n in names if n.endswith(".bag")],
                         ["norm2tex_shard0_0.bag", "norm2tex_shard1_0.bag"])
        verify = _run([os.path.join(REPO, "scripts/merge_dataset"), os.path.join(out, "shard_0"),
                       os.path.join(out, "shard_1"), "--verify-only", "--expect-samples", "10"])
        self.assertEqual(verify.returncode, 0, verify.stderr)

        # A shard missing, the same shard twice, a wrong total: refused, saying why.
        merge = os.path.join(REPO, "scripts/merge_dataset")
        shard0 = os.path.join(out, "shard_0")
        cases = [([shard0, "--verify-only"], "shards [1] of 2 are missing"),
                 ([shard0, shard0, "--verify-only"], "shard 0 appears twice"),
                 ([shard0, os.path.join(out, "shard_1"), "--verify-only", "--expect-samples",
                   "12"], "wood holds 10 images, expected 12")]
        for args, message in cases:
            refused = _run([merge] + args)
            self.assertEqual(refused.returncode, 1, args)
            self.assertIn(message, refused.stderr)


if __name__ == "__main__":
    unittest.main()
