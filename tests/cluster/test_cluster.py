"""test_cluster.py - several kmorphd instances sharing jobs through a real
redis-server, behind a real nginx (round robin), all on loopback and
started and stopped by the tests (cluster.py):

- 200 jobs through nginx all finish, each result equal frame by frame to
  the same request run as a job by one instance with the in-memory store,
  and GET of any job through either instance agrees;
- one long job is rendered by both instances (their metrics);
- kill -9 of one instance while 50 jobs run: every accepted job finishes,
  no frame missing or duplicated (results and counters);
- both instances stopped with jobs queued and running, one started again:
  every one of those jobs finishes.

The tests that need the shared store fail, with the reason, on a kmorphd
without --jobs. Workloads are a few seconds of compute on two cores; every
wait is bounded.
"""
import os
import signal
import subprocess
import sys
import unittest

from cluster import (Cluster, ClusterError, Daemon, require_jobs_flag,
                     wait_for)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "server"))
from kmtest import (ContractCase, circle_svg, ring_morph_body,  # noqa: E402
                    square_svg)

# Every instance: one compute worker (two instances = the two cores), job
# limits high enough for the batches of jobs submitted here.
FLAGS = ("--threads", "1", "--max-jobs", "1000", "--job-keep", "2000",
         "--job-ttl", "600", "--access-log", "0")
FRAMES_METRIC = "kmorph_job_frames_rendered_total"


def small_body(i):
    """A distinct small job (8 frames, a few milliseconds of compute)."""
    return {"from": circle_svg(1.0 + 0.05 * i), "to": square_svg(2.0 + 0.1 * (i % 7)),
            "frames": 8}


def metric_sum(target, name):
    """The sum of every sample of one metric in target's /metrics (None if
    the metric is absent)."""
    r = target.request("GET", "/metrics")
    if r.status != 200:
        return None
    total = None
    for line in r.body.decode().splitlines():
        if line.startswith(name + " ") or line.startswith(name + "{"):
            total = (total or 0.0) + float(line.rsplit(" ", 1)[1])
    return total


def submit(target, bodies):
    ids = []
    for b in bodies:
        r = target.request("POST", "/v1/jobs", body=b)
        if r.status != 202:
            raise AssertionError("POST /v1/jobs: %d %s" %
                                 (r.status, r.body[:300]))
        ids.append(r.json()["id"])
    return ids


def statuses(target, ids):
    out = {}
    for jid in ids:
        r = target.request("GET", "/v1/jobs/" + jid)
        out[jid] = r.json() if r.status == 200 else {"state": "http %d" %
                                                     r.status}
    return out


def wait_final(target, ids, timeout):
    """Poll until every job is done, failed or cancelled; their last
    status documents (some not final if the time ran out)."""
    last = {}
    pending = list(ids)

    def step():
        nonlocal pending
        last.update(statuses(target, pending))
        pending = [j for j in pending
                   if last[j].get("state") not in ("done", "failed",
                                                   "cancelled")]
        return not pending
    wait_for(step, timeout, interval=0.2)
    return last


def frames_of(target, jid):
    r = target.request("GET", "/v1/jobs/%s/result" % jid)
    if r.status != 200:
        raise AssertionError("result of %s: %d %s" % (jid, r.status,
                                                      r.body[:300]))
    return r.json()["frames"]


def reference_frames(bodies):
    """Each body run as a job by one instance with the in-memory store."""
    d = Daemon(*FLAGS)
    try:
        ids = submit(d, bodies)
        final = wait_final(d, ids, 120)
        for jid in ids:
            if final[jid]["state"] != "done":
                raise AssertionError("reference job %s: %s" % (jid,
                                                              final[jid]))
        return [frames_of(d, jid) for jid in ids]
    finally:
        d.stop()


class ClusterCase(ContractCase):
    instances = 2
    extra_flags = ()
    persist = False

    def setUp(self):
        require_jobs_flag()
        self.cluster = Cluster(instances=self.instances,
                               flags=FLAGS + tuple(self.extra_flags),
                               persist=self.persist)
        self.addCleanup(self.cluster.close)

    def assertSameFrames(self, got, want, what):
        self.assertEqual(len(got), len(want), "%s: frame count" % what)
        for k, (g, w) in enumerate(zip(got, want)):
            self.assertEqual(g, w, "%s: frame %d differs from the "
                             "single-instance run" % (what, k))

    def assertAllDone(self, final, ids):
        bad = {j: final[j] for j in ids if final[j].get("state") != "done"}
        self.assertEqual(bad, {}, "%d of %d jobs did not finish" %
                         (len(bad), len(ids)))
        for j in ids:
            s = final[j]
            self.assertEqual(s["frames_done"], s["frames_total"], s)
            self.assertEqual(s["progress"], 1, s)


class TwoHundredJobs(ClusterCase):

    def test_200_jobs_through_nginx_equal_one_instance(self):
        bodies = [small_body(i) for i in range(200)]
        want = reference_frames(bodies)
        c = self.cluster
        ids = submit(c, bodies)
        self.assertEqual(len(set(ids)), 200, "every job has its own id")
        final = wait_final(c, ids, 180)
        self.assertAllDone(final, ids)
        a, b = c.instances
        for k, jid in enumerate(ids):
            self.assertSameFrames(frames_of(c, jid), want[k], "job %d" % k)
            # Any instance answers for any job, and they agree.
            sa = a.request("GET", "/v1/jobs/" + jid)
            sb = b.request("GET", "/v1/jobs/" + jid)
            self.assertEqual((sa.status, sb.status), (200, 200))
            # age_seconds grows between the two reads (as it does on one
            # instance); everything else is equal.
            ja, jb = sa.json(), sb.json()
            self.assertLess(abs(ja.pop("age_seconds") -
                                jb.pop("age_seconds")), 1.0, "job %d" % k)
            self.assertEqual(ja, jb, "job %d" % k)
            ra = a.request("GET", "/v1/jobs/%s/result" % jid)
            rb = b.request("GET", "/v1/jobs/%s/result" % jid)
            self.assertEqual((ra.status, rb.status), (200, 200))
            self.assertEqual(ra.json(), rb.json(), "job %d" % k)
        # Round robin spread the submissions: both instances took some.
        for d in (a, b):
            posted = metric_sum_labelled(d, "kmorph_http_requests_total",
                                         'route="jobs"')
            self.assertGreater(posted or 0, 0, "both instances took POSTs")


def metric_sum_labelled(target, name, label):
    r = target.request("GET", "/metrics")
    total = 0.0
    for line in r.body.decode().splitlines():
        if line.startswith(name + "{") and label in line:
            total += float(line.rsplit(" ", 1)[1])
    return total


class OneLongJob(ClusterCase):

    FRAMES = 600  # ~1.5 s of compute on one core: many batches

    def test_long_job_rendered_by_both_instances(self):
        body = ring_morph_body(self.FRAMES)
        want = reference_frames([body])[0]
        c = self.cluster
        before = [metric_sum(d, FRAMES_METRIC) for d in c.instances]
        self.assertNotIn(None, before, "%s on every instance" %
                         FRAMES_METRIC)
        (jid,) = submit(c, [body])
        final = wait_final(c, [jid], 120)
        self.assertAllDone(final, [jid])
        self.assertSameFrames(frames_of(c, jid), want, "long job")
        after = [metric_sum(d, FRAMES_METRIC) for d in c.instances]
        rendered = [x - y for x, y in zip(after, before)]
        for k, n in enumerate(rendered):
            self.assertGreater(n, 0, "instance %d rendered frames of the "
                               "job (rendered: %s)" % (k, rendered))
        # Every frame rendered at least once; with no instance lost,
        # none twice.
        self.assertEqual(sum(rendered), self.FRAMES, rendered)


class KillOneInstance(ClusterCase):

    JOBS = 50
    FRAMES = 40  # 50 x 40 compound frames: ~2.5 s of work on two cores

    def test_kill_9_while_50_jobs_run(self):
        bodies = [ring_morph_body(self.FRAMES) for _ in range(self.JOBS)]
        want = reference_frames(bodies[:1])[0]
        c = self.cluster
        victim, survivor = c.instances
        survivor_before = metric_sum(survivor, FRAMES_METRIC)
        self.assertIsNotNone(survivor_before, FRAMES_METRIC)
        ids = submit(c, bodies)
        # The victim has rendered frames of these jobs: it holds work.
        self.assertTrue(wait_for(
            lambda: (metric_sum(victim, FRAMES_METRIC) or 0) >= 1, 30),
            "the instance to kill rendered some frames")
        victim.kill()
        # What is stored now is all that the dead instance left; every
        # other frame must come from the survivor.
        at_kill = statuses(survivor, ids)
        self.assertEqual({j: s for j, s in at_kill.items()
                          if "frames_done" not in s}, {},
                         "the survivor answers for every job")
        done_at_kill = sum(s["frames_done"] for s in at_kill.values())
        total = self.JOBS * self.FRAMES
        self.assertLess(done_at_kill, total,
                        "jobs were still running when the instance died")
        final = wait_final(survivor, ids, 180)
        self.assertAllDone(final, ids)
        for k, jid in enumerate(ids):
            self.assertSameFrames(frames_of(survivor, jid), want,
                                  "job %d" % k)
        # Through nginx too, with one upstream dead.
        r = c.request("GET", "/v1/jobs/" + ids[0])
        self.assertEqual(r.status, 200)
        survivor_rendered = metric_sum(survivor, FRAMES_METRIC) - \
            survivor_before
        self.assertGreaterEqual(survivor_rendered, total - done_at_kill,
                                "the survivor rendered every frame "
                                "missing when the other died")


class StopAllAndRestart(ClusterCase):

    JOBS = 20
    FRAMES = 40
    extra_flags = ("--shutdown-grace", "0.5")

    def test_stop_both_with_jobs_queued_and_running_start_one(self):
        bodies = [ring_morph_body(self.FRAMES) for _ in range(self.JOBS)]
        want = reference_frames(bodies[:1])[0]
        c = self.cluster
        ids = submit(c, bodies)
        self.assertTrue(wait_for(
            lambda: sum(metric_sum(d, FRAMES_METRIC) or 0
                        for d in c.instances) >= 1, 30),
            "the instances started rendering")
        for d in c.instances:  # both at once (one SIGTERM each), then wait
            d.proc.send_signal(signal.SIGTERM)
        for d in c.instances:
            try:
                rc = d.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                rc = None
            self.assertEqual(rc, 0, "graceful stop: %s" % d.text()[-1500:])
        fresh = c.start_instance()
        left = [j for j, s in statuses(fresh, ids).items()
                if s.get("state") != "done"]
        self.assertTrue(left, "jobs were left unfinished by the stop")
        for j, s in statuses(fresh, ids).items():
            self.assertIn(s.get("state"), ("queued", "running", "done"),
                          "job %s after the restart: %s" % (j, s))
        final = wait_final(fresh, ids, 180)
        self.assertAllDone(final, ids)
        for k, jid in enumerate(ids):
            self.assertSameFrames(frames_of(fresh, jid), want, "job %d" % k)


class RedisRestartAndOutage(ClusterCase):
    """Redis with its append-only file: restarted under running jobs, the
    instances carry on; while it is down, job endpoints say 503 with
    Retry-After, /readyz 503, and synchronous morphs still work."""

    JOBS = 20
    FRAMES = 40
    persist = True

    def test_redis_restart_mid_run(self):
        bodies = [ring_morph_body(self.FRAMES) for _ in range(self.JOBS)]
        want = reference_frames(bodies[:1])[0]
        c = self.cluster
        ids = submit(c, bodies)
        self.assertTrue(wait_for(
            lambda: sum(metric_sum(d, FRAMES_METRIC) or 0
                        for d in c.instances) >= 1, 30),
            "the instances started rendering")
        c.redis.restart()
        final = wait_final(c, ids, 180)
        for d in c.instances:
            self.assertTrue(d.alive(), d.text()[-1500:])
        for k, jid in enumerate(ids):
            s = final[jid]
            self.assertIn(s.get("state"), ("done", "failed"),
                          "job %d ends, done or failed: %s" % (k, s))
            if s["state"] == "failed":
                self.assertTrue(s.get("error"), "a failed job says why")
            else:
                self.assertSameFrames(frames_of(c, jid), want, "job %d" % k)

    def test_redis_unreachable(self):
        c = self.cluster
        (jid,) = submit(c, [small_body(1)])
        wait_final(c, [jid], 30)
        c.redis.stop()
        for d in c.instances:
            self.assertTrue(wait_for(
                lambda: d.request("GET", "/readyz").status == 503, 15),
                "/readyz says not ready without Redis")
            self.assertEqual(d.request("GET", "/healthz").status, 200)
            r = d.request("POST", "/v1/jobs", body=small_body(2))
            self.assertProblem(r, 503, "/v1/jobs", "post")
            self.assertTrue(r.header("Retry-After"))
            r = d.request("GET", "/v1/jobs/" + jid)
            self.assertProblem(r, 503, "/v1/jobs/{id}", "get")
            self.assertTrue(r.header("Retry-After"))
            r = d.request("POST", "/v1/morph", body=small_body(2))
            self.assertEqual(r.status, 200, r.body[:300])
        # Redis back: the instances reconnect by themselves.
        c.redis.restart()
        for d in c.instances:
            self.assertTrue(wait_for(
                lambda: d.request("GET", "/readyz").status == 200, 60),
                "ready again once Redis is back")
        self.assertEqual(statuses(c, [jid])[jid].get("state"), "done",
                         "the job finished before the outage is kept")
        (again,) = submit(c, [small_body(3)])
        self.assertAllDone(wait_final(c, [again], 60), [again])


class Harness(unittest.TestCase):
    """The harness itself, with in-memory instances (no shared store):
    nginx spreads requests over both, and answers as they do."""

    def test_nginx_round_robin_over_instances(self):
        with Cluster(instances=2, flags=FLAGS, shared=False) as c:
            body = small_body(3)
            direct = c.instances[0].request("POST", "/v1/morph", body=body)
            self.assertEqual(direct.status, 200)
            for _ in range(10):
                r = c.request("POST", "/v1/morph", body=body)
                self.assertEqual(r.status, 200, r.body[:300])
                self.assertEqual(r.json(), direct.json())
            counts = [metric_sum_labelled(d, "kmorph_http_requests_total",
                                          'route="morph"')
                      for d in c.instances]
            self.assertEqual(sum(counts), 11, counts)
            self.assertGreaterEqual(min(counts), 4, "round robin: %s" %
                                    counts)
        for d in c.instances:
            self.assertFalse(d.alive(), "stopped by pid")
        self.assertIsNotNone(c.nginx.proc.poll(), "nginx stopped")

    def test_nginx_passes_over_a_killed_instance(self):
        with Cluster(instances=2, flags=FLAGS, shared=False) as c:
            c.instances[0].kill()
            for _ in range(6):
                r = c.request("POST", "/v1/morph", body=small_body(1))
                self.assertEqual(r.status, 200, r.body[:300])

    def test_shared_store_needs_jobs_flag(self):
        # A daemon without --jobs is named in the failure, not skipped.
        try:
            require_jobs_flag(exe="/bin/true")
        except ClusterError as e:
            self.assertIn("--jobs", str(e))
        else:
            self.fail("a daemon without --jobs passes the check")


if __name__ == "__main__":
    unittest.main()
