#!/usr/bin/env python3
"""A bounded soak of leafluxd on loopback: 16 clients × 100 cycles of a small plant, each
client closing its session and opening a new one every 10 cycles (open/close churn).

Writes one CSV row (clients, cycles, seconds, cycles_per_s, p50_ms, p99_ms, rss_before_kb,
rss_after_kb, rss_growth_kb, rss_bound_kb) and fails when a cycle fails, when the daemon's
resident memory grows by more than --max-rss-growth-mb (16) between the warm-up (every
client through one open, 10 cycles and a close) and the end, or when the cycles take more
than --max-seconds (240): each client then stops where it is, and the soak ends by itself.

Usage: daemon_soak.py --leafluxd BUILD/server/leafluxd [--csv out.csv]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples"))
from leaflux_client import Client, pb  # noqa: E402


def scene(leaves):
    s = pb.Scene(version=pb.PROTOCOL_VERSION_CURRENT)
    s.bands.add(name="PAR")
    s.optics.add(id="leaf").bands["PAR"].CopyFrom(
        pb.BandOptics(rho_upper=0.1, rho_lower=0.1, tau_upper=0.05, tau_lower=0.05))
    s.nodes.add(id=1, type=pb.NODE_TYPE_PLANT, name="plant")
    for i in range(leaves):
        s.nodes.append(leaf(2 + i, 0.12 * i, 1.0 - 0.03 * i))
    sun = s.suns.add()
    sun.direction.x, sun.direction.z = 0.3, 0.9
    sun.normal_irradiance["PAR"] = 800
    s.sky.model = pb.SKY_MODEL_UNIFORM
    s.sky.horizontal_irradiance["PAR"] = 100
    return s


def leaf(node, x, z):
    n = pb.Node(id=node, parent=1, type=pb.NODE_TYPE_LEAF, name=f"leaf{node}")
    n.organ.optics = "leaf"
    n.organ.mesh.positions.extend([x, 0, z, x + 0.1, 0, z, x + 0.1, 0.1, z, x, 0.1, z])
    n.organ.mesh.triangles.extend([0, 1, 2, 0, 2, 3])
    return n


def rss_kb(pid):
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return -1


def client_run(endpoint, index, cycles, churn, deadline, latencies, failures):
    settings = pb.SolverSettings(solver=pb.SOLVER_KIND_HRC, epsilon=1e-3, threads=1)
    try:
        with Client(endpoint, timeout_s=30) as client:  # a cycle takes milliseconds
            session = None
            for c in range(cycles):
                if time.monotonic() > deadline:
                    failures.append(f"client {index}: out of time after {c} cycles")
                    break
                if c % churn == 0:
                    if session:
                        client.close(session)
                    session = client.open(scene(4 + index % 4), settings)
                    number = 0
                number += 1
                # Each cycle moves the last leaf a little: a real solve, not a reused one.
                moved = leaf(2 + 3 + index % 4, 0.01 * (c % 7), 0.5)
                start = time.perf_counter()
                result = client.cycle(session, number, updated=[moved], bands=["PAR"])
                latencies.append(time.perf_counter() - start)
                if len(result.organs) != 4 + index % 4:
                    failures.append(f"client {index} cycle {c}: {len(result.organs)} organs")
            client.close(session)
    except Exception as e:  # noqa: BLE001 (any failure fails the soak)
        failures.append(f"client {index}: {e}")


def run_clients(endpoint, clients, cycles, churn, seconds):
    latencies, failures = [], []
    deadline = time.monotonic() + seconds
    threads = [threading.Thread(target=client_run,
                                args=(endpoint, i, cycles, churn, deadline, latencies, failures))
               for i in range(clients)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - start, sorted(latencies), failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--leafluxd", required=True)
    parser.add_argument("--clients", type=int, default=16)
    parser.add_argument("--cycles", type=int, default=100)
    parser.add_argument("--churn", type=int, default=10, help="cycles per session")
    parser.add_argument("--workers", type=int, default=4)
    parser.add_argument("--max-rss-growth-mb", type=float, default=16.0)
    parser.add_argument("--max-seconds", type=float, default=240.0,
                        help="time the cycles may take, warm-up included")
    parser.add_argument("--csv")
    args = parser.parse_args()

    log = tempfile.NamedTemporaryFile(suffix=".log", delete=False).name
    daemon = subprocess.Popen([args.leafluxd, "--bind", "tcp://127.0.0.1:*", "--log-file", log,
                               "--workers", str(args.workers),
                               "--solver-threads", "1", "--max-sessions", "64"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        endpoint = None
        for _ in range(500):
            with open(log) as text:
                match = re.search(r"serving (tcp://\S+)", text.read())
            if match:
                endpoint = match.group(1)
                break
            time.sleep(0.02)
        if endpoint is None:
            sys.exit("leafluxd did not start")
        started = time.monotonic()
        _, _, failures = run_clients(endpoint, args.clients, args.churn, args.churn,
                                     args.max_seconds)  # warm-up
        if failures:
            sys.exit("warm-up failed: " + "; ".join(failures[:5]))
        before = rss_kb(daemon.pid)
        seconds, latencies, failures = run_clients(
            endpoint, args.clients, args.cycles, args.churn,
            args.max_seconds - (time.monotonic() - started))
        after = rss_kb(daemon.pid)
        if daemon.poll() is not None:
            sys.exit(f"leafluxd exited with status {daemon.returncode}")
        with Client(endpoint, timeout_s=10) as client:
            open_sessions = client.status().session_count
    finally:
        daemon.kill()
        daemon.wait()
        os.unlink(log)

    done = len(latencies)
    p50 = 1000 * latencies[done // 2] if done else float("nan")
    p99 = 1000 * latencies[min(done - 1, int(0.99 * done))] if done else float("nan")
    bound_kb = int(1024 * args.max_rss_growth_mb)
    header = ("clients,cycles,seconds,cycles_per_s,p50_ms,p99_ms,rss_before_kb,rss_after_kb,"
              "rss_growth_kb,rss_bound_kb")
    row = (f"{args.clients},{done},{seconds:.2f},{done / seconds:.1f},{p50:.1f},{p99:.1f},"
           f"{before},{after},{after - before},{bound_kb}")
    print(header)
    print(row)
    if args.csv:
        with open(args.csv, "w") as out:
            out.write(header + "\n" + row + "\n")
    if failures:
        sys.exit("failures: " + "; ".join(failures[:5]))
    if done != args.clients * args.cycles:
        sys.exit(f"{done} cycles answered of {args.clients * args.cycles}")
    if open_sessions != 0:
        sys.exit(f"{open_sessions} sessions left open after every client closed its own")
    if after - before > bound_kb:
        sys.exit(f"RSS grew by {(after - before) / 1024:.1f} MiB "
                 f"(bound {args.max_rss_growth_mb} MiB)")
    print(f"soak passed: RSS grew by {(after - before) / 1024:.1f} MiB "
          f"(bound {args.max_rss_growth_mb} MiB)")


if __name__ == "__main__":
    main()
