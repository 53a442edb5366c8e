"""Debian's nginx in front of local replicas, on loopback, for tests and benchmarks.

Fills in ``deploy/nginx/opaline.conf.template`` (so what is tested is what is
deployed) with a free 127.0.0.1 port and the replicas' addresses, and runs
nginx in the foreground with every file (pid, logs, temporary files, cache)
in a temporary folder: never /etc/nginx, never another address. Needs a source
checkout (the template is not in the wheel) and the ``nginx`` binary.

    with LocalServer() as a, LocalServer() as b, LocalProxy([a.base, b.base]) as proxy:
        httpx.get(proxy.base + "/v1/render")
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
import time
import urllib.error
import urllib.request
from pathlib import Path

from opaline.server.localserver import HOST, ROOT, ServerError, free_port, loopback_env

TEMPLATE = ROOT.parent / "deploy" / "nginx" / "opaline.conf.template"
NGINX_PATHS = ("/usr/sbin/nginx", "/usr/local/sbin/nginx")


def nginx_binary() -> str | None:
    return shutil.which("nginx") or next((p for p in NGINX_PATHS if Path(p).is_file()), None)


def render_config(listen: str, prefix: Path, upstreams: list[str], cache_max: str = "256m",
                  template: Path = TEMPLATE) -> str:
    """The template with its placeholders filled in; ``upstreams`` are host:port."""
    servers = "\n".join(f"        server {u} max_fails=1 fail_timeout=2s;" for u in upstreams)
    text = template.read_text()
    for name, value in (("LISTEN", listen), ("PREFIX", str(prefix)), ("SERVERS", servers),
                        ("CACHE_MAX", cache_max)):
        text = text.replace(f"@{name}@", value)
    if re.search("@[A-Z_]+@", text):
        raise ValueError("a placeholder of the nginx template was left unfilled")
    return text


class LocalProxy:
    """nginx on a free loopback port, proxying to ``bases`` (http://127.0.0.1:PORT each)."""

    def __init__(self, bases: list[str], start_timeout_s: float = 15.0) -> None:
        binary = nginx_binary()
        if binary is None:
            raise ServerError("nginx is not installed (Debian: apt-get install nginx-light)")
        upstreams = [b.removeprefix("http://").rstrip("/") for b in bases]
        if any(not u.startswith(f"{HOST}:") for u in upstreams):
            raise ValueError(f"replicas must listen on {HOST}: {upstreams}")
        self.port = free_port()
        self.base = f"http://{HOST}:{self.port}"
        self.prefix = Path(tempfile.mkdtemp(prefix="opaline-nginx-"))
        # Started as root, nginx's workers run as an unprivileged user: they must reach the
        # cache and temporary folders (nginx makes those itself, owned by that user).
        self.prefix.chmod(0o755)
        (self.prefix / "tmp").mkdir()
        self.conf = self.prefix / "nginx.conf"
        self.conf.write_text(render_config(f"{HOST}:{self.port}", self.prefix, upstreams))
        self.start_timeout_s = start_timeout_s
        self.proc = subprocess.Popen(
            [binary, "-p", str(self.prefix), "-c", str(self.conf), "-e",
             str(self.prefix / "error.log"), "-g", "daemon off;"],
            stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT, env=loopback_env())

    def log(self, name: str = "access.log") -> str:
        path = self.prefix / name
        return path.read_text() if path.is_file() else ""

    def __enter__(self) -> LocalProxy:
        opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
        deadline = time.monotonic() + self.start_timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                text = self.log("error.log")
                self.stop()
                raise ServerError(f"nginx exited with {self.proc.returncode}:\n{text}")
            try:
                with opener.open(self.base + "/nginx-healthz", timeout=2) as answer:
                    if answer.status == 200:
                        return self
            except (urllib.error.URLError, OSError):
                pass
            time.sleep(0.05)
        text = self.log("error.log")
        self.stop()
        raise ServerError(f"nginx did not answer in {self.start_timeout_s:.0f} s:\n{text}")

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()  # SIGTERM: nginx's fast shutdown
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        shutil.rmtree(self.prefix, ignore_errors=True)
