"""``opaline serve`` in a child process on a free loopback port, for tests, benchmarks
and notebooks that want a real HTTP service and must not leave one running.

    with LocalServer(workers=1, env={"OPALINE_QUEUE_SIZE": "2"}) as server:
        urllib.request.urlopen(server.base + "/healthz")
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
from pathlib import Path

HOST = "127.0.0.1"
ROOT = Path(__file__).resolve().parents[2]  # the source root service/, holding this opaline
PROXY_VARS = ("http_proxy", "https_proxy", "all_proxy", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY")


class ServerError(RuntimeError):
    """The service exited or did not become ready; the message ends with its log."""


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind((HOST, 0))
        port: int = sock.getsockname()[1]
        return port


def loopback_env(**extra: str) -> dict[str, str]:
    """This environment without proxies (every request goes to 127.0.0.1), plus ``extra``."""
    env = {k: v for k, v in os.environ.items() if k not in PROXY_VARS}
    env["NO_PROXY"] = env["no_proxy"] = "127.0.0.1,localhost"
    env["PYTHONPATH"] = os.pathsep.join(filter(None, (str(ROOT), env.get("PYTHONPATH"))))
    return {**env, **extra}


class LocalServer:
    """A real uvicorn process; ready once ``ready_path`` answers 200, stopped on exit."""

    def __init__(self, workers: int = 1, env: dict[str, str] | None = None,
                 ready_path: str = "/readyz", start_timeout_s: float = 60.0,
                 log_level: str = "warning") -> None:
        self.port = free_port()
        self.base = f"http://{HOST}:{self.port}"
        self.ready_path = ready_path
        self.start_timeout_s = start_timeout_s
        # A file, not a pipe: an unread pipe could fill up and stall the server.
        self.log = tempfile.TemporaryFile("w+")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "opaline.cli.main", "serve", "--host", HOST, "--port",
             str(self.port), "--workers", str(workers), "--log-level", log_level],
            cwd=ROOT, env=loopback_env(**(env or {})), stdout=self.log, stderr=subprocess.STDOUT)

    def log_text(self, last: int = 3000) -> str:
        self.log.seek(0)
        return self.log.read()[-last:]

    def __enter__(self) -> LocalServer:
        opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
        deadline = time.monotonic() + self.start_timeout_s
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                text = self.log_text()
                self.log.close()
                raise ServerError(f"opaline serve exited with {self.proc.returncode}:\n{text}")
            try:
                with opener.open(self.base + self.ready_path, timeout=2) as answer:
                    if answer.status == 200:
                        return self
            except (urllib.error.URLError, OSError):
                pass
            time.sleep(0.1)
        text = self.log_text()
        self.stop()
        raise ServerError(f"opaline serve was not ready in {self.start_timeout_s:.0f} s:\n{text}")

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        if not self.log.closed:
            self.log.close()
