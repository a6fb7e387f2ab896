#!/usr/bin/env python3
"""The Python client (the package python/leaflux, through examples/leaflux_client.py) when
the daemon is slow or gone:

1. a timeout names the endpoint, and the late reply of the request given up on is never
   taken for the answer to the next one;
2. on one connection, replies to other requests and messages that are not a Reply, sent
   before the answer, are dropped: the reply of the request's own id is taken;
3. a request over twice the daemon's limit, which ZeroMQ would cut off unanswered, is
   refused with TOO_LARGE at once;
4. a cycle given `resync=` survives a daemon killed (SIGKILL) and started again on the same
   endpoint: it reconnects, resyncs and sends the cycle again, with the light it would have
   had.

Usage: python_client_test.py BUILD_DIR
"""
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

import zmq

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples"))
from leaflux_client import Client, LeafluxError, pb  # noqa: E402

BUILD = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("LEAFLUX_BUILD", "build/release")


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def start(endpoint="tcp://127.0.0.1:*", max_message_mb=256):
    log = tempfile.NamedTemporaryFile(suffix=".log", delete=False).name
    daemon = subprocess.Popen([os.path.join(BUILD, "server", "leafluxd"), "--bind", endpoint,
                               "--log-file", log, "--solver-threads", "1",
                               "--max-message-mb", str(max_message_mb)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(500):
        with open(log) as text:
            match = re.search(r"serving (tcp://\S+)", text.read())
        if match:
            os.unlink(log)
            return daemon, match.group(1)
        time.sleep(0.02)
    daemon.kill()
    fail("leafluxd did not start")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scene(leaves=2):
    s = pb.Scene(version=pb.PROTOCOL_VERSION_CURRENT)
    s.bands.add(name="PAR")
    s.optics.add(id="leaf").bands["PAR"].CopyFrom(pb.BandOptics(rho_upper=0.1, rho_lower=0.1,
                                                                tau_upper=0.1, tau_lower=0.1))
    s.nodes.add(id=1, type=pb.NODE_TYPE_PLANT)
    for i in range(leaves):
        s.nodes.append(leaf(2 + i, 0.05 * i, 1.0 - 0.1 * i))
    sun = s.suns.add()
    sun.direction.x, sun.direction.z = 0.2, 1
    sun.normal_irradiance["PAR"] = 1000
    return s


def leaf(node, x, z):
    n = pb.Node(id=node, parent=1, type=pb.NODE_TYPE_LEAF, name=f"leaf{node}")
    n.organ.optics = "leaf"
    n.organ.mesh.positions.extend([x, 0, z, x + 0.1, 0, z, x + 0.1, 0.1, z])
    n.organ.mesh.triangles.extend([0, 1, 2])
    return n


def late_reply_dropped():
    daemon, endpoint = start()
    try:
        slow = pb.SolverSettings(solver=pb.SOLVER_KIND_MONTE_CARLO, samples=1 << 21, threads=1)
        with Client(endpoint, timeout_s=0.3) as client:
            session = client.open(scene(1), slow)
            try:
                client.cycle(session, 1)
                fail("a cycle of seconds answered within 0.3 s")
            except TimeoutError as e:
                if endpoint not in str(e):
                    fail(f"the timeout does not name {endpoint}: {e}")
            with Client(endpoint, timeout_s=10) as watcher:
                for _ in range(300):
                    if watcher.status(session).sessions[0].cycles == 1:
                        break
                    time.sleep(0.1)
            time.sleep(0.2)  # the late reply has been sent
            status = client.status(session)
            if len(status.sessions) != 1 or status.sessions[0].cycles != 1:
                fail(f"status() answered with a late reply: {status}")
        print("a timeout names the endpoint; the late reply is dropped")
    finally:
        daemon.kill()
        daemon.wait()


def stale_replies_dropped():
    """A stand-in ROUTER answers each request with a late status, a late cycle and a
    message that is not a Reply before the reply of the request's own id."""
    router = zmq.Context.instance().socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    router.bind("tcp://127.0.0.1:*")
    endpoint = router.getsockopt_string(zmq.LAST_ENDPOINT)
    stop = threading.Event()

    def serve():
        while not stop.is_set():
            if not router.poll(50):
                continue
            frames = router.recv_multipart()
            request = pb.Request()
            request.ParseFromString(frames[-1])
            late_status = pb.Reply(request_id=request.request_id + 1)
            late_status.status.session_count = 99
            late_cycle = pb.Reply(request_id=request.request_id + 1000)
            late_cycle.cycle.session = "a" * 32
            own = pb.Reply(request_id=request.request_id)
            own.status.session_count = 7
            for message in (late_status.SerializeToString(), late_cycle.SerializeToString(),
                            b"\xff\xff\xff", own.SerializeToString()):
                router.send_multipart(frames[:-1] + [message])

    thread = threading.Thread(target=serve)
    thread.start()
    try:
        with Client(endpoint, timeout_s=5) as client:
            for i in range(3):
                count = client.status().session_count
                if count != 7:
                    fail(f"status {i} took another request's reply (session_count {count})")
    finally:
        stop.set()
        thread.join()
        router.close()
    print("on one connection, stale replies and non-Replies are dropped")


def too_large_refused():
    daemon, endpoint = start(max_message_mb=1)
    try:
        big = scene(1)
        big.nodes[1].name = "n" * (3 << 20)  # 3 MiB: ZeroMQ would cut it off unanswered
        with Client(endpoint, timeout_s=5) as client:
            started = time.monotonic()
            try:
                client.open(big)
                fail("a 3 MiB request to a daemon of 1 MiB was answered")
            except LeafluxError as e:
                if e.code != "ERROR_CODE_TOO_LARGE" or time.monotonic() - started > 4:
                    fail(f"a 3 MiB request: {e} after {time.monotonic() - started:.1f} s")
            client.status()
        print("a request over the daemon's limit is refused with TOO_LARGE, not a timeout")
    finally:
        daemon.kill()
        daemon.wait()


def survives_a_restart():
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    settings = pb.SolverSettings(solver=pb.SOLVER_KIND_HRC)
    moved = leaf(3, 0.02, 0.8)

    def as_before():
        return scene(2), settings

    expected = None
    for restart in (False, True):
        daemon, _ = start(endpoint)
        with Client(endpoint, status_timeout_s=10, scene_timeout_s=3) as client:
            session = client.open(scene(2), settings)
            client.cycle(session, 1, resync=as_before)
            if restart:
                daemon.send_signal(signal.SIGKILL)
                daemon.wait()
                daemon, _ = start(endpoint)
            result = client.cycle(session, 2, updated=[moved], resync=as_before)
            light = [(o.node, b.irradiance_upper_wm2, b.irradiance_lower_wm2)
                     for o in result.organs for b in o.bands]
            if len(light) != 2:
                fail(f"cycle 2 lit {len(light)} organs, not 2")
            if restart and light != expected:
                fail(f"after the restart: {light}, uninterrupted: {expected}")
            expected = light
        daemon.kill()
        daemon.wait()
    print("a cycle given resync= survives a daemon restart with the same light")


if __name__ == "__main__":
    late_reply_dropped()
    stale_replies_dropped()
    too_large_refused()
    survives_a_restart()
