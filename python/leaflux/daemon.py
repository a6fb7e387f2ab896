"""LocalDaemon: a leafluxd of one's own on a free loopback port, for a `with` block."""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from typing import List, Optional, Sequence, Union

import zmq

from .client import Client
from .errors import DaemonStartError, RequestTimeout

PathLike = Union[str, "os.PathLike[str]"]

# leaflux/ in a checkout: <root>/python/leaflux.
_SOURCE_ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _candidates(leafluxd: Optional[PathLike]) -> List[str]:
    if leafluxd is not None:
        return [os.fspath(leafluxd)]
    found = []
    build = os.environ.get("LEAFLUX_BUILD")
    if build:
        found.append(os.path.join(build, "server", "leafluxd"))
    on_path = shutil.which("leafluxd")
    if on_path:
        found.append(on_path)
    if os.path.isfile(os.path.join(_SOURCE_ROOT, "proto", "leaflux.proto")):
        found.append(os.path.join(_SOURCE_ROOT, "build", "release", "server", "leafluxd"))
    return found


def find_leafluxd(leafluxd: Optional[PathLike] = None) -> str:
    """The leafluxd to run: `leafluxd` if given, else $LEAFLUX_BUILD/server/leafluxd, else
    leafluxd on PATH, else build/release/server/leafluxd of the checkout this package is
    in. DaemonStartError naming the places looked at if none is an executable."""
    tried = _candidates(leafluxd)
    for path in tried:
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    raise DaemonStartError(
        "leaflux: no leafluxd executable found (looked at: "
        f"{', '.join(tried) or 'nothing: LEAFLUX_BUILD unset and none on PATH'}); pass its "
        "path, set LEAFLUX_BUILD to the build folder, or put leafluxd on PATH")


class LocalDaemon:
    """Starts leafluxd on a free loopback port (or `port`), waits until it answers Status,
    and stops it with SIGTERM at the end of a `with` block (or stop()).

    `endpoint` is where to connect; `args` are more leafluxd options (e.g.
    ["--workers", "4"]); `solver_threads` caps each solve's cores; the daemon's log goes
    to `log_file` (a temporary file otherwise, removed at stop; `log()` reads it).
    `curve_secret_key`: the path of a CurveZMQ secret key (`leaflux keygen`): the daemon then
    encrypts every connection, and `curve_server_key` is the public key clients pass to
    Client(..., curve_server_key=)."""

    def __init__(self, leafluxd: Optional[PathLike] = None, port: Optional[int] = None, *,
                 args: Sequence[str] = (), solver_threads: Optional[int] = None,
                 log_file: Optional[PathLike] = None, start_timeout_s: float = 30.0,
                 stop_timeout_s: float = 30.0,
                 curve_secret_key: Optional[PathLike] = None) -> None:
        self.leafluxd = find_leafluxd(leafluxd)
        self.curve_server_key: Optional[str] = None
        if curve_secret_key is not None:
            with open(curve_secret_key) as f:
                secret = f.read().strip().encode()
            self.curve_server_key = zmq.curve_public(secret).decode()
            args = [*args, "--curve-secret-key", os.fspath(curve_secret_key)]
        self.stop_timeout_s = stop_timeout_s
        self._own_log = log_file is None
        if log_file is None:
            fd, log_file = tempfile.mkstemp(prefix="leafluxd_", suffix=".log")
            os.close(fd)
        self.log_file = os.fspath(log_file)
        bind = f"tcp://127.0.0.1:{port if port is not None else '*'}"
        command = [self.leafluxd, "--bind", bind, "--log-file", self.log_file, *args]
        if solver_threads is not None:
            command += ["--solver-threads", str(solver_threads)]
        self.command = command
        self.endpoint = ""
        # The log may hold an earlier run's lines: only what this one appends is read.
        self._log_start = os.path.getsize(self.log_file) if os.path.exists(self.log_file) else 0
        self._stderr = tempfile.TemporaryFile(mode="w+")  # errors before the log opens
        self._process: Optional[subprocess.Popen] = subprocess.Popen(
            command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=self._stderr)
        try:
            self._wait_until_serving(start_timeout_s)
        except BaseException:
            self._process.kill()
            self._process.wait()
            self._process = None
            self._stderr.close()
            raise

    @property
    def pid(self) -> int:
        return self._process.pid if self._process else 0

    def log(self) -> str:
        """The daemon's log so far (what it wrote to the log file in this run)."""
        try:
            with open(self.log_file) as f:
                f.seek(self._log_start)
                return f.read()
        except OSError:
            return ""

    def _errors(self) -> str:
        self._stderr.seek(0)
        return (self._stderr.read().strip() or self.log().strip())[-2000:]

    def _wait_until_serving(self, timeout_s: float) -> None:
        assert self._process is not None
        deadline = time.monotonic() + timeout_s
        while not self.endpoint:  # its first line: "leafluxd serving ENDPOINT"
            match = re.search(r"serving (tcp://\S+)", self.log())
            if match:
                self.endpoint = match.group(1)
                break
            self._check_alive()
            if time.monotonic() > deadline:
                raise DaemonStartError(f"leaflux: {' '.join(self.command)} did not start "
                                       f"serving within {timeout_s:g} s")
            time.sleep(0.02)
        with Client(self.endpoint, timeout_s=0.5,
                    curve_server_key=self.curve_server_key) as probe:
            while True:
                try:
                    probe.status()
                    return
                except RequestTimeout:
                    self._check_alive()
                    if time.monotonic() > deadline:
                        raise DaemonStartError(
                            f"leaflux: leafluxd at {self.endpoint} did not answer Status "
                            f"within {timeout_s:g} s") from None

    def _check_alive(self) -> None:
        assert self._process is not None
        code = self._process.poll()
        if code is not None:
            raise DaemonStartError(f"leaflux: {' '.join(self.command)} exited with {code}:\n"
                                   f"{self._errors()}")

    def stop(self) -> int:
        """SIGTERM, then waits stop_timeout_s (SIGKILL after it); returns the exit code."""
        if self._process is None:
            return 0
        process, self._process = self._process, None
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(timeout=self.stop_timeout_s)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        self._stderr.close()
        if self._own_log:
            try:
                os.unlink(self.log_file)
            except OSError:
                pass
        return process.returncode

    def __enter__(self) -> "LocalDaemon":
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def __del__(self) -> None:
        process = getattr(self, "_process", None)
        if process is not None and process.poll() is None:
            process.kill()
