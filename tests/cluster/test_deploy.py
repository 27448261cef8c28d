"""test_deploy.py - deploy/compose.yaml and deploy/nginx.conf parse and
agree: the services are Redis, two kmorphd sharing it through KMORPH_JOBS
and nginx; nginx's upstream names exactly the kmorphd services on their
port; and nginx itself accepts the configuration (`nginx -t` on a copy
whose service names are loopback addresses). Nothing is run in a
container here."""
import os
import re
import shutil
import subprocess
import tempfile
import unittest

import yaml

from cluster import NGINX, ROOT

DEPLOY = os.path.join(ROOT, "deploy")


def load_compose():
    with open(os.path.join(DEPLOY, "compose.yaml"), encoding="utf-8") as f:
        return yaml.safe_load(f)


def read_nginx_conf():
    with open(os.path.join(DEPLOY, "nginx.conf"), encoding="utf-8") as f:
        return f.read()


def upstream_servers(conf):
    m = re.search(r"upstream\s+kmorph\s*\{(.*?)\}", conf, re.S)
    if not m:
        return []
    return re.findall(r"^\s*server\s+([^\s;]+)", m.group(1), re.M)


class Compose(unittest.TestCase):

    def setUp(self):
        self.doc = load_compose()
        self.services = self.doc["services"]

    def kmorphd_services(self):
        return sorted(n for n, s in self.services.items()
                      if "KMORPH_JOBS" in (s.get("environment") or {}))

    def test_services_redis_two_instances_nginx(self):
        self.assertEqual(self.kmorphd_services(), ["kmorph1", "kmorph2"])
        self.assertEqual(set(self.services),
                         {"redis", "kmorph1", "kmorph2", "nginx"})
        self.assertTrue(self.services["redis"]["image"].startswith("redis:7"))

    def test_instances_share_redis_and_build_from_the_tree(self):
        for name in self.kmorphd_services():
            s = self.services[name]
            env = s["environment"]
            self.assertRegex(env["KMORPH_JOBS"],
                             r"^redis://redis:6379/\d+$", name)
            self.assertEqual(env["KMORPH_BIND"], "0.0.0.0", name)
            self.assertIn("redis", s["depends_on"], name)
            ctx = os.path.normpath(os.path.join(DEPLOY,
                                                s["build"]["context"]))
            self.assertTrue(os.path.isfile(os.path.join(
                ctx, s["build"]["dockerfile"])), name)

    def test_nginx_mounts_the_config_and_publishes_its_port(self):
        n = self.services["nginx"]
        mounts = [v.split(":") for v in n["volumes"]]
        self.assertIn(["./nginx.conf", "/etc/nginx/nginx.conf", "ro"],
                      mounts)
        listen = re.search(r"^\s*listen\s+(\d+)\s*;", read_nginx_conf(),
                           re.M)
        self.assertIsNotNone(listen)
        published = [p.split(":") for p in n["ports"]]
        self.assertIn(listen.group(1), [p[-1] for p in published])

    def test_nginx_upstream_is_the_kmorphd_services(self):
        servers = upstream_servers(read_nginx_conf())
        want = ["%s:%s" % (name,
                           self.services[name]["environment"]["KMORPH_PORT"])
                for name in self.kmorphd_services()]
        self.assertEqual(sorted(servers), want)


class NginxConf(unittest.TestCase):

    def test_nginx_accepts_the_config(self):
        conf = read_nginx_conf()
        tmp = tempfile.mkdtemp(prefix="kmorph-deploy-")
        self.addCleanup(shutil.rmtree, tmp, True)
        # The container's service names do not resolve here: loopback
        # addresses in their place, and files under the scratch folder.
        for k, name in enumerate(sorted(set(
                s.split(":")[0] for s in upstream_servers(conf)))):
            conf = re.sub(r"\b%s:" % re.escape(name), "127.0.0.%d:" % (k + 1),
                          conf)
        conf = conf.replace("pid /tmp/nginx.pid;",
                            "pid %s/nginx.pid;" % tmp)
        self.assertNotIn("kmorph1:", conf)
        path = os.path.join(tmp, "nginx.conf")
        with open(path, "w", encoding="utf-8") as f:
            f.write(conf)
        r = subprocess.run([NGINX, "-t", "-c", path, "-p", tmp, "-e",
                            os.path.join(tmp, "error.log")],
                           capture_output=True, timeout=30)
        err = r.stderr.decode(errors="replace")
        self.assertEqual(r.returncode, 0, err)
        self.assertIn("syntax is ok", err)


if __name__ == "__main__":
    unittest.main()
