"""test_jobs.py - the asynchronous job life cycle: queued -> running ->
done, result 409 before done, cancel, 429 at the job limit, 410 after
expiry."""
import json
import threading
import time
import unittest

from kmtest import (ContractCase, Daemon, circle_svg, close_to, metric,
                    morph_body, request, ring_morph_body, run_job, wait_for)

import math


class JobLifeCycle(ContractCase):
    """One worker, so that jobs run one after another (the oldest live job
    gets the frames) and the states can be seen."""

    TTL = 2.0

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--max-jobs", "2",
                       "--job-ttl", str(cls.TTL), "--job-keep", "10")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def create(self, body):
        r = self.d.request("POST", "/v1/jobs", body=body)
        doc = self.assertDocumented(r, "/v1/jobs", "post")
        self.assertEqual(r.status, 202, r.body[:300])
        self.assertEqual(r.header("Location"), "/v1/jobs/" + doc["id"])
        self.assertEqual(doc["state"], "queued")
        return doc

    def status(self, jid):
        r = self.d.request("GET", "/v1/jobs/" + jid)
        return self.assertDocumented(r, "/v1/jobs/{id}", "get")

    def test_life_cycle_cancel_and_expiry(self):
        # Given a long job A and a short job B behind it,
        a = self.create(ring_morph_body(2000))
        b = self.create(morph_body(5))
        self.assertEqual(a["frames_total"], 2000)
        running = wait_for(lambda: self.status(a["id"])["state"] == "running"
                           and self.status(a["id"]), 10)
        self.assertTrue(running, "job A starts running")
        # then B waits while A runs, and B's result is a 409 problem;
        sb = self.status(b["id"])
        self.assertEqual(sb["state"], "queued")
        self.assertEqual(sb["progress"], 0)
        r = self.d.request("GET", "/v1/jobs/%s/result" % b["id"])
        self.assertProblem(r, 409, "/v1/jobs/{id}/result", "get")
        # a third job is refused while two are live;
        r = self.d.request("POST", "/v1/jobs", body=morph_body(3))
        self.assertProblem(r, 429, "/v1/jobs", "post")
        # progress of A grows and stays frames_done / frames_total;
        p1 = self.status(a["id"])
        time.sleep(0.2)
        p2 = self.status(a["id"])
        for p in (p1, p2):
            self.assertAlmostEqual(p["progress"],
                                   p["frames_done"] / p["frames_total"], 5)
        self.assertGreaterEqual(p2["frames_done"], p1["frames_done"])
        # when A is cancelled it stops short of its frames at once,
        r = self.d.request("DELETE", "/v1/jobs/" + a["id"])
        self.assertDocumented(r, "/v1/jobs/{id}", "delete")
        self.assertEqual(r.status, 204)
        sa = self.status(a["id"])
        self.assertEqual(sa["state"], "cancelled")
        self.assertLess(sa["frames_done"], sa["frames_total"])
        r = self.d.request("GET", "/v1/jobs/%s/result" % a["id"])
        self.assertProblem(r, 409, "/v1/jobs/{id}/result", "get")
        # and B, which could only run once A gave up the worker, is done;
        done = wait_for(lambda: self.status(b["id"])["state"] == "done", 20)
        self.assertTrue(done, "job B finishes after A is cancelled")
        sb = self.status(b["id"])
        self.assertEqual((sb["frames_done"], sb["progress"]), (5, 1))
        r = self.d.request("GET", "/v1/jobs/%s/result" % b["id"])
        doc = self.assertDocumented(r, "/v1/jobs/{id}/result", "get")
        self.assertEqual(r.status, 200)
        self.assertEqual([f["t"] for f in doc["frames"]],
                         [0, 0.25, 0.5, 0.75, 1])
        self.assertTrue(close_to(doc["frames"][2]["metrics"]["length"],
                                 3 * math.pi, 1e-4))
        m = self.d.request("GET", "/metrics").body.decode()
        self.assertGreaterEqual(metric(m, "kmorph_jobs", {"state": "done"}), 1)
        self.assertEqual(metric(m, "kmorph_workers_busy"), 0,
                         "no worker still renders the cancelled job")
        # Finally, after the time to live both are forgotten, and said to
        # be gone (410, with the limit that let them go), not unknown.
        time.sleep(self.TTL + 0.3)
        for jid in (a["id"], b["id"]):
            r = self.d.request("GET", "/v1/jobs/" + jid)
            doc = self.assertProblem(r, 410, "/v1/jobs/{id}", "get")
            self.assertIn("KMORPH_JOB_TTL", doc["detail"])
            r = self.d.request("GET", "/v1/jobs/%s/result" % jid)
            self.assertProblem(r, 410, "/v1/jobs/{id}/result", "get")

    def test_unknown_job_is_404_for_every_method(self):
        for method, path in (("GET", "/v1/jobs/%s"),
                             ("DELETE", "/v1/jobs/%s"),
                             ("GET", "/v1/jobs/%s/result")):
            p = path % ("0" * 32)
            r = self.d.request(method, p)
            tmpl = path.replace("%s", "{id}")
            self.assertProblem(r, 404, tmpl, method.lower())

    def test_deleting_a_finished_job_forgets_it(self):
        j = self.create(morph_body(2))
        self.assertTrue(wait_for(
            lambda: self.status(j["id"])["state"] == "done", 20))
        r = self.d.request("DELETE", "/v1/jobs/" + j["id"])
        self.assertEqual(r.status, 204)
        r = self.d.request("GET", "/v1/jobs/" + j["id"])
        self.assertProblem(r, 404, "/v1/jobs/{id}", "get")

    def test_invalid_job_request_is_refused_before_a_job_exists(self):
        r = self.d.request("POST", "/v1/jobs",
                           body={"from": {"type": "svg", "d": "M 0 0 Q"},
                                 "to": {"type": "svg", "d": "M 0 0 L 1 1"}})
        doc = self.assertProblem(r, 422, "/v1/jobs", "post")
        self.assertTrue(doc["errors"][0]["pointer"].startswith("/from"))


class JobWallTime(ContractCase):
    @classmethod
    def setUpClass(cls):
        # 1,000 frames of the ring morph (two contours a frame) take some
        # 3.5 s on two threads, seven times the limit; its preparation,
        # some 0.06 s (0.15 s under ASan), fits well inside it, so the job
        # is accepted and fails in its frames
        cls.d = Daemon("--threads", "2", "--job-time", "0.5")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_job_over_its_wall_time_fails_with_a_clear_error(self):
        r, jid, s = run_job(self.d, ring_morph_body(1000))
        self.assertEqual(r.status, 202, r.body[:300])
        self.assertTrue(s, "the job ends")
        self.assertEqual(s["state"], "failed")
        self.assertIn("KMORPH_JOB_TIME", s["error"]["detail"])
        self.assertEqual(self.assertDocumented(
            self.d.request("GET", "/v1/jobs/" + jid), "/v1/jobs/{id}", "get")
            ["state"], "failed")
        r = self.d.request("GET", "/v1/jobs/%s/result" % jid)
        self.assertProblem(r, 409, "/v1/jobs/{id}/result", "get")


class JobIds(ContractCase):
    """The id of a new job is copied while the job cannot be freed: under
    thousands of tiny jobs from several threads every answer names a job
    that exists (it was heap garbage in some answers)."""

    def test_ids_of_tiny_jobs_name_real_jobs(self):
        # More workers than cores, so that a worker creating a job is
        # preempted while others render and free it.
        d = Daemon("--max-jobs", "100000", "--job-keep", "100000",
                   "--queue", "1000", "--access-log", "0", "--threads", "8")
        try:
            body = json.dumps({"from": circle_svg(1.0),
                               "to": circle_svg(2.0),
                               "frames": 2}).encode()
            bad, ids, lock = [], [], threading.Lock()

            def worker():
                for _ in range(500):
                    r = request(d.port, "POST", "/v1/jobs", body,
                                {"Content-Type": "application/json"})
                    if r.status != 202:
                        continue
                    jid = r.json()["id"]
                    with lock:
                        ids.append(jid)
                        if (len(jid) != 32 or
                                any(c not in "0123456789abcdef"
                                    for c in jid) or
                                r.header("Location") != "/v1/jobs/" + jid):
                            bad.append((jid, r.header("Location")))
            ts = [threading.Thread(target=worker) for _ in range(8)]
            for t in ts:
                t.start()
            for t in ts:
                t.join(timeout=300)
            self.assertGreater(len(ids), 1000)
            self.assertEqual(bad, [], "ids and Location are the job's")
            missing = [j for j in ids[::7]
                       if d.request("GET", "/v1/jobs/" + j).status != 200]
            self.assertEqual(missing, [], "every answered id is a job")
        finally:
            d.stop()



if __name__ == "__main__":
    unittest.main()
