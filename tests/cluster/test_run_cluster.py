"""test_run_cluster.py - `make run-cluster` / `make stop-cluster`
(tools/run_cluster.py) on free loopback ports and a scratch state folder:
start leaves redis-server, two kmorphd and nginx running with their pid
files and answers through nginx on both instances; a second start is
refused; stop ends exactly those pids and removes the files."""
import os
import shutil
import subprocess
import tempfile
import unittest

from cluster import ROOT, free_port, request

TOOL = os.path.join(ROOT, "tools", "run_cluster.py")
NAMES = ("redis", "kmorphd1", "kmorphd2", "nginx")


def alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


class RunCluster(unittest.TestCase):

    def test_start_answers_then_stop_ends_each_pid(self):
        state = tempfile.mkdtemp(prefix="kmorph-run-cluster-")
        self.addCleanup(shutil.rmtree, state, True)
        front, k1, k2, rp = (free_port() for _ in range(4))
        env = dict(os.environ, CLUSTER_STATE=state, CLUSTER_PORT=str(front),
                   CLUSTER_KMORPHD_PORTS="%d,%d" % (k1, k2),
                   CLUSTER_REDIS_PORT=str(rp))

        def tool(cmd):
            return subprocess.run(["python3", TOOL, cmd], env=env,
                                  capture_output=True, text=True, timeout=60)
        self.addCleanup(tool, "stop")
        r = tool("start")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("http://127.0.0.1:%d/" % front, r.stdout)
        pids = {}
        for n in NAMES:
            with open(os.path.join(state, n + ".pid")) as f:
                pids[n] = int(f.read())
            self.assertTrue(alive(pids[n]), n)
        for port in (front, k1, k2):
            self.assertEqual(request(port, "GET", "/healthz").status, 200)
        again = tool("start")
        self.assertNotEqual(again.returncode, 0)
        self.assertIn("already running", again.stderr)
        r = tool("stop")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        for n in NAMES:
            self.assertIn("stopped %s (pid %d)" % (n, pids[n]), r.stdout)
            self.assertFalse(alive(pids[n]), n)
            self.assertFalse(os.path.exists(os.path.join(state, n + ".pid")))


if __name__ == "__main__":
    unittest.main()
