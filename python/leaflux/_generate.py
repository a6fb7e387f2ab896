"""Generates leaflux_pb2.py and policy_pb2.py from the repository's proto/ with protoc alone.

Used by setup.py at install time and by the package when imported from a source checkout.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from typing import Sequence

PROTOS: Sequence[str] = ("leaflux.proto", "policy.proto")


class ProtocMissing(RuntimeError):
    """No `protoc` to generate the protocol's Python modules with."""


def find_protoc() -> str:
    protoc = os.environ.get("PROTOC") or shutil.which("protoc")
    if not protoc:
        raise ProtocMissing(
            "leaflux: `protoc` (the protocol buffer compiler) is needed to generate "
            "leaflux_pb2.py from proto/leaflux.proto and was not found on PATH (or in $PROTOC); "
            "on Debian: apt install protobuf-compiler")
    return protoc


def generated_modules(proto_dir: str, out_dir: str) -> list[str]:
    return [os.path.join(out_dir, p.replace(".proto", "_pb2.py")) for p in PROTOS]


def generated_stubs(out_dir: str) -> list[str]:
    return [os.path.join(out_dir, p.replace(".proto", "_pb2.pyi")) for p in PROTOS]


def stale(proto_dir: str, out_dir: str) -> bool:
    """Whether a module or its stub is missing or older than its .proto."""
    files = zip([*PROTOS, *PROTOS], [*generated_modules(proto_dir, out_dir),
                                     *generated_stubs(out_dir)])
    for proto, module in files:
        if not os.path.exists(module):
            return True
        if os.path.getmtime(module) < os.path.getmtime(os.path.join(proto_dir, proto)):
            return True
    return False


def generate(proto_dir: str, out_dir: str) -> list[str]:
    """Runs `protoc --python_out --pyi_out` on proto_dir's files into out_dir, the package's
    folder.

    The generated modules import each other as top-level modules (`import leaflux_pb2`);
    they are rewritten to import within the package. Each module is written to a temporary
    file and moved into place, so that processes generating at once do not clash.
    """
    protoc = find_protoc()
    missing = [p for p in PROTOS if not os.path.isfile(os.path.join(proto_dir, p))]
    if missing:
        raise FileNotFoundError(f"leaflux: {', '.join(missing)} not found in {proto_dir}")
    os.makedirs(out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="leaflux_protoc_") as tmp:
        command = [protoc, f"--python_out={tmp}", f"--pyi_out={tmp}", "-I", proto_dir,
                   *(os.path.join(proto_dir, p) for p in PROTOS)]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"leaflux: {' '.join(command)} failed ({run.returncode}):\n"
                               f"{run.stderr.strip()}")
        written = []
        siblings = [p[: -len(".proto")] + "_pb2" for p in PROTOS]
        # The modules, then their type stubs (for type checkers).
        for name in [p.replace(".proto", "_pb2.py" + ext) for ext in ("", "i") for p in PROTOS]:
            with open(os.path.join(tmp, name)) as f:
                code = f.read()
            for sibling in siblings:
                code = re.sub(rf"^import {sibling} as ", f"from . import {sibling} as ", code,
                              flags=re.MULTILINE)
                # A public import (policy.proto re-exports leaflux.proto's policy messages).
                code = re.sub(rf"^from {sibling} import \*", f"from .{sibling} import *", code,
                              flags=re.MULTILINE)
            target = os.path.join(out_dir, name)
            fd, partial = tempfile.mkstemp(prefix=f".{name}.", dir=out_dir)
            with os.fdopen(fd, "w") as f:
                f.write(code)
            os.chmod(partial, 0o644)
            os.replace(partial, target)
            written.append(target)
    return written
