#!/usr/bin/python3
"""The manual's commands, run as a user would run them, so that the docs cannot go stale.

Every ```sh and ```python block of README.md and docs/*.md is run, in the order of its
document, from a checkout of its own (links to this one's folders, `build/release` the build
under test, `out/` and HOME fresh), one bash process a document so that a block may use
what an earlier one made. A block the test cannot run (one that installs packages, builds
another preset or runs for hours) says so in the line before it:
`<!-- docs-test: skip BECAUSE -->`; every other block must succeed. A ``` block whose info
is `NAME file=PATH` is written to PATH before the document's blocks run.

What a user would type is adjusted only where the test must differ: leafluxd is started by
the test on a free port (the docs' `leafluxd --bind tcp://127.0.0.1:5555 &` lines stand for
it, and 5555 is that port), the `leaflux client` lines get its --endpoint, a session id
written out (`S=5684b41c…`) is the one the last `client open` printed, and a command the
docs show failing (followed by `#   error …`) must fail.

Usage: docs_commands.py BUILD_DIR SOURCE_DIR [DOCUMENT ...]
"""
import glob
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^```(\S*)(.*)$")
SKIP = re.compile(r"<!--\s*docs-test:\s*skip\b(.*?)-->")
SESSION = re.compile(r"\b[0-9a-f]{8}(?:[0-9a-f]{24}|…)")


def blocks(path):
    """(line, language, text, skip reason or None, file= target or None) of each block."""
    lines = open(path, encoding="utf-8").read().split("\n")
    found, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m or not m.group(1) and not m.group(2):
            i += 1
            continue
        language, info, start = m.group(1), m.group(2), i
        i += 1
        body = []
        while i < len(lines) and not lines[i].startswith("```"):
            body.append(lines[i])
            i += 1
        i += 1
        before = "\n".join(lines[max(0, start - 3):start])
        skip = SKIP.search(before)
        target = re.search(r"\bfile=(\S+)", info)
        found.append((start + 1, language, "\n".join(body) + "\n",
                      skip.group(1).strip() if skip else None,
                      target.group(1) if target else None))
    return found


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


ENDPOINT = re.compile(r"tcp://(?:HOST|0\.0\.0\.0|127\.0\.0\.1):(\d+)")


def adjust(text, endpoint, state, ports):
    """The block's commands as the test runs them (see the module's docstring). `ports`
    maps the docs' ports to free ones (5555 to the test's leafluxd)."""
    port = endpoint.rsplit(":", 1)[1]
    ports.setdefault("5555", port)

    def local(m):
        return "tcp://127.0.0.1:" + ports.setdefault(m.group(1), str(free_port()))
    logical, current = [], ""
    for line in text.split("\n"):  # join continuation lines
        current += line
        if line.endswith("\\"):
            current = current[:-1] + " "
            continue
        logical.append(current)
        current = ""
    out = []
    for n, line in enumerate(logical):
        nxt = logical[n + 1] if n + 1 < len(logical) else ""
        line = ENDPOINT.sub(local, line).replace("5555", port)
        code = line.split("#", 1)[0]
        if re.search(r"\bleafluxd\b.*--bind\b.*&\s*$", code) and "--curve" not in code:
            out.append(f"true  # the test's leafluxd serves {endpoint}")
            continue
        if re.search(r"\bleaflux client\b", code) and "--endpoint" not in code:
            line = line.replace("leaflux client", f"leaflux client --endpoint {endpoint}", 1)
        line = SESSION.sub('"$S"', line) if not line.lstrip().startswith("#") else line
        if re.match(r"\s*S=", line):
            line = f"S=$(sed -n 's/.*session: \"\\([0-9a-f]*\\)\".*/\\1/p' \"{state}/open.txt\")"
        elif re.search(r"\bleaflux client\b.*\bopen\b", code) and ">" not in code:
            line = f"{line.split(' #', 1)[0]} | tee \"{state}/open.txt\""
        if nxt.lstrip().startswith("#   error"):  # `! cmd` would not stop `set -e`
            line = (f"if {line.split(' #', 1)[0]}; then echo 'expected to fail: {code.strip()}'; "
                    f"exit 1; fi")
        out.append(line)
    return "\n".join(out) + "\n"


def start_daemon(build, env, state):
    """The test's leafluxd on a free port: (process, endpoint, None), or (None, None, why).
    A port found free may be taken before leafluxd binds it (by another test's daemon): a
    daemon that exits instead of serving is started again on another port, so that the
    blocks never talk to a daemon that is not the test's."""
    why = "no attempt"
    log = os.path.join(state, "leafluxd.log")
    for _ in range(5):
        endpoint = f"tcp://127.0.0.1:{free_port()}"
        daemon = subprocess.Popen([os.path.join(build, "server", "leafluxd"), "--bind", endpoint,
                                   "--log-level", "info"], stderr=open(log, "w"), env=env)
        deadline = time.time() + 10
        while daemon.poll() is None and time.time() < deadline:
            # It logs that it serves the endpoint once bound, or exits when it cannot bind.
            if f"serving {endpoint}" in open(log, errors="replace").read() and not subprocess.run(
                    [os.path.join(build, "server", "leaflux"), "client", "--endpoint", endpoint,
                     "--timeout", "1", "status"], capture_output=True).returncode:
                return daemon, endpoint, None
            time.sleep(0.05)
        daemon.kill()
        daemon.wait()
        why = f"leafluxd on {endpoint} did not answer (exit {daemon.returncode})"
    return None, None, why


def run_document(doc, build, source, workdir):
    """Runs `doc`'s blocks; returns (ran, skipped, failure text or None)."""
    checkout = os.path.join(workdir, "checkout")
    os.makedirs(os.path.join(checkout, "build"))
    for entry in os.listdir(source):
        if entry not in ("build", "out", ".git"):
            os.symlink(os.path.join(source, entry), os.path.join(checkout, entry))
    os.symlink(os.path.abspath(build), os.path.join(checkout, "build", "release"))
    home, state = os.path.join(workdir, "home"), os.path.join(workdir, "state")
    os.makedirs(home)
    os.makedirs(state)
    env = dict(os.environ, HOME=home, XDG_DATA_HOME=os.path.join(home, "data"),
               XDG_CACHE_HOME=os.path.join(home, "cache"), LEAFLUX_BUILD="build/release",
               PYTHONPATH=os.pathsep.join([os.path.join(checkout, "python"),
                                           os.path.join(build, "proto")]),
               PATH=os.pathsep.join([os.path.join(build, "server"),
                                     os.path.join(build, "growth_stub"), os.environ["PATH"]]))
    # The blocks that run, the others set aside, the files written.
    runnable, skipped = [], []
    for line, language, text, skip, target in blocks(doc):
        where = f"{os.path.relpath(doc, source)}:{line}"
        if target:
            path = os.path.join(checkout, target)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            open(path, "w").write(text)
        elif language in ("sh", "python"):
            if skip is None:
                runnable.append((where, line, language, text))
            else:
                skipped.append(f"{where} ({skip})")
    if not runnable:
        return [], skipped, None
    daemon, endpoint, failure = start_daemon(build, env, state)
    if failure:
        return [], [], failure
    script = ["set -euo pipefail",
              f"trap 'echo \"FAILED in the block at $DOCS_TEST_BLOCK\" >&2' ERR"]
    ran, ports = [], {}
    for where, line, language, text in runnable:
        ran.append(where)
        script.append(f"DOCS_TEST_BLOCK={where}; echo '### {where}'")
        if language == "python":
            name = os.path.join(state, f"block{line}.py")
            open(name, "w").write(adjust(text, endpoint, state, ports) if "5555" in text else text)
            script.append(f"/usr/bin/python3 {name}")
        else:
            script.append(adjust(text, endpoint, state, ports))
    open(os.path.join(state, "run.sh"), "w").write("\n".join(script) + "\n")
    # The output goes to a file, not a pipe: what a block leaves running in the background
    # (a daemon) keeps a pipe open after the script has ended.
    log = os.path.join(state, "run.log")
    with open(log, "w") as sink:
        run = subprocess.Popen(["bash", os.path.join(state, "run.sh")], cwd=checkout, env=env,
                               stdout=sink, stderr=subprocess.STDOUT, start_new_session=True)
        timed_out = False
        try:
            run.wait(timeout=1800)
        except subprocess.TimeoutExpired:
            timed_out = True
        finally:
            try:
                os.killpg(run.pid, signal.SIGKILL)  # what the blocks left in the background
            except ProcessLookupError:
                pass
            run.wait()
            daemon.kill()
            daemon.wait()
    output = open(log, errors="replace").read() + ("\n(timed out after 1800 s)" if timed_out else "")
    if run.returncode != 0:
        return ran, skipped, output[-6000:]
    return ran, skipped, None


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    build, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    docs = [os.path.join(source, d) for d in sys.argv[3:]] or \
        [os.path.join(source, "README.md")] + sorted(glob.glob(os.path.join(source, "docs", "*.md")))
    failures = 0
    for doc in docs:
        workdir = tempfile.mkdtemp(prefix="leaflux_docs_")
        try:
            start = time.time()
            ran, skipped, failure = run_document(doc, build, source, workdir)
        finally:
            shutil.rmtree(workdir, ignore_errors=True)
        name = os.path.relpath(doc, source)
        print(f"{name}: {len(ran)} blocks run, {len(skipped)} skipped, "
              f"{time.time() - start:.0f} s" + (" FAILED" if failure else ""))
        for s in skipped:
            print(f"  skipped {s}")
        if failure:
            failures += 1
            print(failure)
        sys.stdout.flush()
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
