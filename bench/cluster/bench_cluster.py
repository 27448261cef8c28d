#!/usr/bin/env python3
"""bench_cluster.py - `make bench-cluster`, a benchmark (not a test):

1. throughput of JOBS mid-size jobs (compound morphs of FRAMES frames)
   with one kmorphd of one worker, and with two kmorphd of one worker
   each behind nginx sharing jobs through Redis (target: two >= 1.7x
   one); for comparison also one and two instances with the in-memory
   store (two: the client alternates the instances, as nothing is shared);
2. the Redis store's overhead against the in-memory one, one instance of
   one worker, on a 60-frame job run REPEAT times each, alternating the
   two stores so that the machine's other load falls on both alike
   (target: Redis within 10%).

Real redis-server, nginx and kmorphd on loopback (tests/cluster/
cluster.py). Prints the figures as a Markdown section for
bench/RESULTS.md. Without --jobs in kmorphd, only the in-memory figures.
Sizes: BENCH_JOBS (200), BENCH_FRAMES (20), BENCH_REPEAT (15).
"""
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "cluster"))
sys.path.insert(0, os.path.join(ROOT, "tests", "server"))
from cluster import (Cluster, Daemon, Redis,  # noqa: E402
                     daemon_has_jobs_flag, wait_for)
from kmtest import ring_morph_body  # noqa: E402

JOBS = int(os.environ.get("BENCH_JOBS", "200"))
FRAMES = int(os.environ.get("BENCH_FRAMES", "20"))
REPEAT = int(os.environ.get("BENCH_REPEAT", "15"))
FLAGS = ("--threads", "1", "--max-jobs", "100000", "--job-keep", "100000",
         "--access-log", "0")


def run_jobs(targets, bodies, timeout=1800):
    """Submit every body (alternating targets; poll each job where it was
    submitted) and wait until all are done: wall seconds."""
    t0 = time.monotonic()
    where = []
    for k, b in enumerate(bodies):
        t = targets[k % len(targets)]
        r = t.request("POST", "/v1/jobs", body=b)
        if r.status != 202:
            raise SystemExit("POST /v1/jobs: %d %s" % (r.status, r.body[:200]))
        where.append((t, r.json()["id"]))
    pending = list(where)

    def step():
        nonlocal pending
        left = []
        for t, jid in pending:
            s = t.request("GET", "/v1/jobs/" + jid).json()
            if s["state"] == "failed" or s["state"] == "cancelled":
                raise SystemExit("job %s: %s" % (jid, s))
            if s["state"] != "done":
                left.append((t, jid))
        pending = left
        return not pending
    if not wait_for(step, timeout, interval=0.05):
        raise SystemExit("jobs did not finish in %d s" % timeout)
    return time.monotonic() - t0


def one_job_seconds(target, body):
    t0 = time.monotonic()
    r = target.request("POST", "/v1/jobs", body=body)
    jid = r.json()["id"]
    wait_for(lambda: target.request("GET", "/v1/jobs/" + jid).json()["state"]
             in ("done", "failed"), 300, interval=0.002)
    return time.monotonic() - t0


def git_commit():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short",
                               "HEAD"], capture_output=True, text=True,
                              timeout=10).stdout.strip()
    except OSError:
        return "?"


def main():
    shared = daemon_has_jobs_flag()
    bodies = [ring_morph_body(FRAMES) for _ in range(JOBS)]
    rows = []
    load0 = os.getloadavg()

    def throughput(label, seconds):
        rows.append((label, seconds, JOBS / seconds))
        print("%-44s %7.2f s  %7.1f jobs/s" % (label, seconds, JOBS / seconds),
              flush=True)

    d = Daemon(*FLAGS)
    try:
        throughput("1 instance x 1 worker, in memory", run_jobs([d], bodies))
    finally:
        d.stop()
    with Cluster(instances=2, flags=FLAGS, shared=False, proxy=False) as c:
        throughput("2 instances x 1 worker, in memory (client alternates)",
                   run_jobs(c.instances, bodies))
    if shared:
        with Cluster(instances=1, flags=FLAGS) as c:
            throughput("1 instance x 1 worker, Redis, via nginx",
                       run_jobs([c], bodies))
        with Cluster(instances=2, flags=FLAGS) as c:
            throughput("2 instances x 1 worker, Redis, via nginx",
                       run_jobs([c], bodies))

    body60 = ring_morph_body(60)
    mem, red = [], []
    d = Daemon(*FLAGS)
    redis = dr = None
    try:
        if shared:
            redis = Redis()
            dr = Daemon(*FLAGS, "--jobs", redis.url)
        one_job_seconds(d, body60)  # warm both
        if dr:
            one_job_seconds(dr, body60)
        for _ in range(REPEAT):
            mem.append(one_job_seconds(d, body60))
            if dr:
                red.append(one_job_seconds(dr, body60))
    finally:
        d.stop()
        if dr:
            dr.stop()
        if redis:
            redis.close()
    load1 = os.getloadavg()

    print()
    print("## Cluster: %s, commit %s, %d cores, load average %.1f -> %.1f"
          % (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), git_commit(),
             os.cpu_count(), load0[0], load1[0]))
    print()
    print("`make bench-cluster`: %d jobs of %d compound frames (a ring of "
          "two circles to two squares), kmorphd --threads 1 per instance."
          % (JOBS, FRAMES))
    print()
    print("| set-up | wall s | jobs/s |")
    print("|---|---:|---:|")
    for label, s, tp in rows:
        print("| %s | %.2f | %.1f |" % (label, s, tp))
    by = {label: tp for label, _, tp in rows}
    print()
    m2 = by["2 instances x 1 worker, in memory (client alternates)"] / \
        by["1 instance x 1 worker, in memory"]
    print("Two instances / one, in memory: %.2fx." % m2)
    if shared:
        r2 = by["2 instances x 1 worker, Redis, via nginx"] / \
            by["1 instance x 1 worker, Redis, via nginx"]
        print("Two instances / one, Redis behind nginx: %.2fx (target "
              ">= 1.7x)." % r2)
    print()
    mm = statistics.median(mem)
    print("60-frame job, one instance, median of %d: in memory %.1f ms"
          % (REPEAT, mm * 1e3), end="")
    if red:
        mr = statistics.median(red)
        print(", Redis %.1f ms: %+.1f%% (target within 10%%)." %
              (mr * 1e3, (mr / mm - 1) * 100))
    else:
        print("; Redis store not measured: kmorphd has no --jobs.")


if __name__ == "__main__":
    main()
