#!/usr/bin/env python3
"""leafluxd stopping on SIGTERM with work under way, as a service manager stops it:

1. a cycle in flight that outlasts --grace-seconds (3) is answered with SHUTTING_DOWN once
   the grace has passed, a queued cycle at once, and the daemon exits 0 soon after;
2. a cycle in flight that ends within the grace is answered with its light, and the
   daemon exits without waiting out the grace;
3. a second signal ends the daemon at once, whatever is in flight.

Usage: daemon_shutdown.py BUILD_DIR
"""
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples"))
import zmq  # noqa: E402

from leaflux_client import Client, pb  # noqa: E402

BUILD = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("LEAFLUX_BUILD", "build/release")


def fail(message, log=None):
    print("FAIL:", message)
    if log:
        with open(log) as text:
            print(text.read()[-3000:])
    sys.exit(1)


def start(*arguments):
    log = tempfile.NamedTemporaryFile(suffix=".log", delete=False).name
    daemon = subprocess.Popen([os.path.join(BUILD, "server", "leafluxd"), "--bind",
                               "tcp://127.0.0.1:*", "--log-file", log, "--solver-threads", "1",
                               *arguments], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(500):
        with open(log) as text:
            match = re.search(r"serving (tcp://\S+)", text.read())
        if match:
            return daemon, match.group(1), log
        time.sleep(0.02)
    daemon.kill()
    fail("leafluxd did not start", log)


def scene(samples, leaves=1):
    s = pb.Scene(version=pb.PROTOCOL_VERSION_CURRENT)
    s.bands.add(name="PAR")
    s.optics.add(id="leaf").bands["PAR"].CopyFrom(pb.BandOptics(rho_upper=0.1, rho_lower=0.1))
    s.nodes.add(id=1, type=pb.NODE_TYPE_PLANT)
    for k in range(leaves):
        n = s.nodes.add(id=2 + k, parent=1, type=pb.NODE_TYPE_LEAF, name=f"leaf{k}" if k else "leaf")
        n.organ.optics = "leaf"
        z = 1 + 0.05 * k
        n.organ.mesh.positions.extend([0, 0, z, 0.1, 0, z, 0.1, 0.1, z])
        n.organ.mesh.triangles.extend([0, 1, 2])
    sun = s.suns.add()
    sun.direction.z = 1
    sun.normal_irradiance["PAR"] = 1000
    settings = pb.SolverSettings(solver=pb.SOLVER_KIND_MONTE_CARLO, samples=samples, threads=1)
    return s, settings


class Pending:
    """A cycle sent on a connection of its own, its reply read later."""

    def __init__(self, endpoint, session, number=1, request_id=7):
        self.socket = zmq.Context.instance().socket(zmq.DEALER)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.connect(endpoint)
        request = pb.Request(version=pb.PROTOCOL_VERSION_CURRENT, request_id=request_id)
        request.cycle.session, request.cycle.number = session, number
        request.cycle.outputs.leaves = True
        self.socket.send_multipart([b"", request.SerializeToString()])
        self.sent = time.monotonic()

    def reply(self, timeout_s):
        """(reply, seconds since the signal) or (None, None)."""
        if not self.socket.poll(int(timeout_s * 1000)):
            return None, None
        reply = pb.Reply()
        reply.ParseFromString(self.socket.recv_multipart()[-1])
        return reply, time.monotonic()


def open_session(endpoint, samples, leaves=1):
    with Client(endpoint, timeout_s=30) as client:
        return client.open(*scene(samples, leaves))


def exit_status(daemon, timeout_s):
    try:
        return daemon.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return None


def grace_then_cancel():
    daemon, endpoint, log = start("--workers", "1", "--grace-seconds", "3")
    # 16 leaves of 2^24 paths: about 50 s of one core, cancelled after the grace (one leaf
    # took 3.0 s on a fast machine and ended within it).
    slow = open_session(endpoint, 1 << 24, 16)
    queued = open_session(endpoint, 16)
    in_flight = Pending(endpoint, slow)
    time.sleep(0.3)
    waiting = Pending(endpoint, queued)  # behind the slow solve: one worker
    time.sleep(0.3)
    daemon.send_signal(signal.SIGTERM)
    signalled = time.monotonic()
    late = Pending(endpoint, queued, number=2, request_id=8)  # after the signal
    reply, at = waiting.reply(10)
    if reply is None or reply.error.code != pb.ERROR_CODE_SHUTTING_DOWN:
        fail(f"the queued cycle got {reply} instead of SHUTTING_DOWN", log)
    if at - signalled > 2.0:
        fail(f"the queued cycle waited {at - signalled:.2f} s for its refusal", log)
    reply, _ = late.reply(10)
    if reply is not None and reply.error.code != pb.ERROR_CODE_SHUTTING_DOWN:
        fail(f"a request after the signal got {reply}", log)
    reply, at = in_flight.reply(20)
    if reply is None or reply.error.code != pb.ERROR_CODE_SHUTTING_DOWN:
        fail(f"the cycle in flight got {reply} instead of SHUTTING_DOWN", log)
    if at - signalled < 2.9:
        fail(f"the cycle in flight was cancelled after {at - signalled:.2f} s, before the grace",
             log)
    status = exit_status(daemon, 10)
    if status != 0:
        fail(f"leafluxd exited with {status} after the grace", log)
    print(f"grace: queued refused at once, in-flight cancelled after {at - signalled:.2f} s, exit 0")
    os.unlink(log)


def in_flight_finishes():
    daemon, endpoint, log = start("--workers", "1", "--grace-seconds", "60")
    session = open_session(endpoint, 1 << 20)  # a fraction of a second
    in_flight = Pending(endpoint, session)
    time.sleep(0.05)
    daemon.send_signal(signal.SIGTERM)
    reply, _ = in_flight.reply(60)
    if reply is None or not reply.HasField("cycle") or len(reply.cycle.organs) != 1:
        fail(f"the cycle in flight got {reply} instead of its light", log)
    status = exit_status(daemon, 30)
    if status != 0:
        fail(f"leafluxd exited with {status} or waited out its grace", log)
    print("grace: a cycle in flight that ends within it gets its light, exit 0")
    os.unlink(log)


def second_signal():
    daemon, endpoint, log = start("--workers", "1", "--grace-seconds", "600")
    session = open_session(endpoint, 1 << 24)
    in_flight = Pending(endpoint, session)
    time.sleep(0.3)
    daemon.send_signal(signal.SIGTERM)
    if exit_status(daemon, 0.5) is not None:
        fail("leafluxd did not give its solve in flight any grace", log)
    daemon.send_signal(signal.SIGINT)
    start_wait = time.monotonic()
    status = exit_status(daemon, 5)
    if status is None:
        daemon.kill()
        fail("a second signal did not end leafluxd", log)
    if status == 0:
        fail("leafluxd ended on a second signal as if it had stopped cleanly", log)
    del in_flight
    print(f"second signal: exit {status} after {time.monotonic() - start_wait:.2f} s")
    os.unlink(log)


if __name__ == "__main__":
    grace_then_cancel()
    in_flight_finishes()
    second_signal()
    print("leafluxd stops on SIGTERM: queued work refused, in-flight work given its grace")
