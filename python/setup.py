"""Builds the leaflux package: leaflux_pb2.py and policy_pb2.py are generated from the
repository's proto/ (or $LEAFLUX_PROTO_DIR) by `protoc --python_out` at build time."""
import os
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "leaflux"))
import _generate  # noqa: E402  (the package's generator, without importing the package)


def proto_dir():
    directory = os.environ.get("LEAFLUX_PROTO_DIR") or os.path.join(HERE, "..", "proto")
    if not os.path.isfile(os.path.join(directory, "leaflux.proto")):
        sys.exit(f"leaflux: no leaflux.proto in {os.path.abspath(directory)}: build from a "
                 "leaflux checkout (pip install ./python at its root) or set LEAFLUX_PROTO_DIR")
    return directory


class BuildPyWithProtos(build_py):
    """build_py, then protoc into the built package."""

    def run(self):
        super().run()
        if self.dry_run:
            return
        try:
            for module in _generate.generate(proto_dir(), os.path.join(self.build_lib, "leaflux")):
                print(f"generated {module}")
        except _generate.ProtocMissing as e:
            sys.exit(str(e))


setup(cmdclass={"build_py": BuildPyWithProtos})
