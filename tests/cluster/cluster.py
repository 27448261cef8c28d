"""cluster.py - a kmorph cluster on loopback for the tests and the
benchmark: a real redis-server, N kmorphd processes sharing it through
`--jobs redis://127.0.0.1:PORT/0` (or each with its own in-memory store)
and a real nginx in front, round robin over the instances. Every process
is started on a free loopback port, in a private folder, and stopped by
its pid; every wait is bounded in time.

Standard library only (plus tests/pylib/kmdaemon.py).

    with Cluster(instances=2, flags=("--threads", "1")) as c:
        c.request("POST", "/v1/jobs", body=...)     # through nginx
        c.instances[0].request("GET", "/metrics")   # one instance
"""
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "pylib"))
from kmdaemon import (DAEMON, HOST, ROOT, Daemon, request,  # noqa: E402,F401
                      wait_for)

REDIS_SERVER = os.environ.get("REDIS_SERVER", "/usr/bin/redis-server")
NGINX = os.environ.get("NGINX", "/usr/sbin/nginx")


class ClusterError(RuntimeError):
    pass


def free_port():
    """A loopback port nothing listens on now (the OS's choice)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def daemon_has_jobs_flag(exe=None):
    """Whether kmorphd knows --jobs (the shared Redis job store)."""
    try:
        out = subprocess.run([exe or DAEMON, "--help"], capture_output=True,
                             timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return b"--jobs" in out.stdout + out.stderr


def require_jobs_flag(exe=None):
    """Raise with a clear message unless kmorphd has the shared store:
    the tests that need it fail (not skip) on a daemon without it."""
    if not daemon_has_jobs_flag(exe):
        raise ClusterError(
            "%s has no --jobs flag: these tests need the Redis job store "
            "(kmorphd --jobs redis://HOST:PORT/DB)" % (exe or DAEMON))


def _stop_pid(proc, timeout=15.0):
    """SIGTERM, then SIGKILL if it has not exited within timeout."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


class Redis:
    """redis-server on a free loopback port, its data in a private folder.
    persist=True keeps an append-only file there, so that a restart on the
    same folder (restart()) finds the data again."""

    def __init__(self, persist=False, start_timeout=15.0):
        self.dir = tempfile.mkdtemp(prefix="kmorph-redis-")
        self.persist = persist
        self.port = None
        self.proc = None
        self._start(start_timeout)

    def _start(self, timeout):
        last = ""
        for _ in range(5):  # a port taken between choosing and binding
            self.port = free_port()
            args = [REDIS_SERVER, "--bind", HOST, "--port", str(self.port),
                    "--dir", self.dir, "--daemonize", "no",
                    "--logfile", os.path.join(self.dir, "redis.log"),
                    "--save", "", "--protected-mode", "yes"]
            args += ["--appendonly", "yes" if self.persist else "no"]
            self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL,
                                         stderr=subprocess.DEVNULL)
            if wait_for(lambda: self.proc.poll() is not None or self.ping(),
                        timeout) and self.proc.poll() is None:
                return
            last = self.log()[-1500:]
            _stop_pid(self.proc)
        raise ClusterError("redis-server did not start: " + last)

    @property
    def url(self):
        return "redis://%s:%d/0" % (HOST, self.port)

    def log(self):
        try:
            with open(os.path.join(self.dir, "redis.log"),
                      encoding="utf-8", errors="replace") as f:
                return f.read()
        except OSError:
            return ""

    def command(self, *args, timeout=5.0):
        """One command in RESP; the raw reply (bytes), or None if the
        server did not answer."""
        msg = b"*%d\r\n" % len(args)
        for a in args:
            a = a if isinstance(a, bytes) else str(a).encode()
            msg += b"$%d\r\n%s\r\n" % (len(a), a)
        try:
            with socket.create_connection((HOST, self.port),
                                          timeout=timeout) as s:
                s.sendall(msg)
                return s.recv(65536)
        except OSError:
            return None

    def ping(self):
        return self.command("PING", timeout=1.0) == b"+PONG\r\n"

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def stop(self):
        if self.proc is not None:
            _stop_pid(self.proc)

    def restart(self, timeout=15.0):
        """Stop and start again on the same port and folder."""
        self.stop()
        port = self.port
        args = [REDIS_SERVER, "--bind", HOST, "--port", str(port),
                "--dir", self.dir, "--daemonize", "no",
                "--logfile", os.path.join(self.dir, "redis.log"),
                "--save", "", "--appendonly",
                "yes" if self.persist else "no"]
        self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        if not wait_for(self.ping, timeout):
            raise ClusterError("redis-server did not restart: " +
                               self.log()[-1500:])

    def close(self):
        self.stop()
        shutil.rmtree(self.dir, ignore_errors=True)


NGINX_CONF = """\
# nginx in front of {n} kmorphd instances (generated by cluster.py)
daemon off;
worker_processes 1;
pid {dir}/nginx.pid;
error_log {dir}/error.log warn;
events {{ worker_connections 1024; }}
http {{
  access_log off;
  client_body_temp_path {dir}/client_body;
  proxy_temp_path {dir}/proxy;
  fastcgi_temp_path {dir}/fastcgi;
  uwsgi_temp_path {dir}/uwsgi;
  scgi_temp_path {dir}/scgi;
  client_max_body_size 8m;
  upstream kmorph {{
{servers}
    keepalive 16;
  }}
  server {{
    listen {host}:{port};
    location / {{
      proxy_pass http://kmorph;
      proxy_http_version 1.1;
      proxy_set_header Connection "";
      proxy_set_header X-Forwarded-For $remote_addr;
      proxy_read_timeout 120s;
      # Answers larger than the buffers are passed on as they come, not
      # spooled: nginx's worker runs as another user than the one that
      # made the private temp folder, and could not write there.
      proxy_max_temp_file_size 0;
      # An instance that is down (refused, reset) is passed over; a
      # request it already received is not sent twice.
      proxy_next_upstream error timeout;
    }}
  }}
}}
"""


def nginx_conf(directory, port, upstreams):
    servers = "\n".join("    server %s:%d max_fails=1 fail_timeout=2s;"
                        % (HOST, p) for p in upstreams)
    return NGINX_CONF.format(n=len(upstreams), dir=directory, host=HOST,
                             port=port, servers=servers)


class Nginx:
    """nginx (`nginx -c CONF -p DIR`, daemon off) on a free loopback port,
    round robin over the given upstream ports."""

    def __init__(self, upstreams, start_timeout=15.0):
        self.dir = tempfile.mkdtemp(prefix="kmorph-nginx-")
        self.conf = os.path.join(self.dir, "nginx.conf")
        self.proc = None
        last = ""
        for _ in range(5):
            self.port = free_port()
            with open(self.conf, "w", encoding="utf-8") as f:
                f.write(nginx_conf(self.dir, self.port, upstreams))
            self.proc = subprocess.Popen(
                [NGINX, "-c", self.conf, "-p", self.dir, "-e",
                 os.path.join(self.dir, "error.log")],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            if wait_for(lambda: self.proc.poll() is not None or
                        self._listening(), start_timeout) and \
                    self.proc.poll() is None:
                return
            last = (self.proc.stderr.read() or b"").decode(errors="replace")
            _stop_pid(self.proc)
        raise ClusterError("nginx did not start: " + last[-1500:])

    def _listening(self):
        try:
            with socket.create_connection((HOST, self.port), timeout=0.5):
                return True
        except OSError:
            return False

    def request(self, method, path, body=None, headers=None, timeout=60.0):
        return request(self.port, method, path, body, headers, timeout)

    def stop(self):
        if self.proc is not None:
            # SIGQUIT: nginx's graceful stop; _stop_pid falls back to kill.
            if self.proc.poll() is None:
                self.proc.send_signal(signal.SIGQUIT)
                try:
                    self.proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    pass
            _stop_pid(self.proc)
            if self.proc.stderr:
                self.proc.stderr.close()

    def close(self):
        self.stop()
        shutil.rmtree(self.dir, ignore_errors=True)


class Cluster:
    """redis-server (shared=True), `instances` kmorphd processes and nginx
    in front of them. flags go to every kmorphd; with shared=True each
    also gets --jobs with the Redis URL (which must be supported: a
    daemon without it raises ClusterError). start_instance() adds one
    (nginx is not told; the tests that restart instances talk to them
    directly)."""

    def __init__(self, instances=2, flags=(), shared=True, persist=False,
                 exe=None, proxy=True):
        self.flags = tuple(flags)
        self.exe = exe
        self.shared = shared
        self.redis = None
        self.nginx = None
        self.instances = []
        try:
            if shared:
                require_jobs_flag(exe)
                self.redis = Redis(persist=persist)
            for _ in range(instances):
                self.start_instance()
            if proxy:
                self.nginx = Nginx([d.port for d in self.instances])
        except BaseException:
            self.close()
            raise

    def instance_flags(self):
        f = list(self.flags)
        if self.shared:
            f += ["--jobs", self.redis.url]
        return f

    def start_instance(self):
        d = Daemon(*self.instance_flags(), exe=self.exe)
        self.instances.append(d)
        return d

    def request(self, method, path, body=None, headers=None, timeout=60.0):
        """Through nginx."""
        return self.nginx.request(method, path, body, headers, timeout)

    def close(self):
        for d in self.instances:
            d.close()
        if self.nginx is not None:
            self.nginx.close()
        if self.redis is not None:
            self.redis.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
