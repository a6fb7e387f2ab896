"""The examples' way to the leaflux Python package (python/leaflux), for scripts run from
a checkout without installing it: `from leaflux_client import Client, LocalDaemon, pb`.

The client itself is the package's (docs/python.md); this module only finds it: the
checkout's python/ first, then an installed `leaflux`. It also puts the build's generated
modules (build/release/proto and growth_stub, or $LEAFLUX_BUILD's) on sys.path for
scenario_pb2, and makes `import leaflux_pb2` give the package's module, so that messages of
both are of the same classes.
"""
import os
import sys

_root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
_python = os.path.join(_root, "python")
if os.path.isdir(os.path.join(_python, "leaflux")) and _python not in sys.path:
    sys.path.insert(0, _python)

# The build whose modules and programs the examples use: LEAFLUX_BUILD, or build/release.
_build = os.environ.get("LEAFLUX_BUILD") or os.path.join(_root, "build", "release")
for _module_dir in (os.path.join(_build, "proto"), os.path.join(_build, "growth_stub")):
    if os.path.isdir(_module_dir) and _module_dir not in sys.path:
        sys.path.append(_module_dir)

import leaflux  # noqa: E402
from leaflux import *  # noqa: E402,F401,F403
from leaflux import pb  # noqa: E402,F401

sys.modules.setdefault("leaflux_pb2", leaflux.leaflux_pb2)
sys.modules.setdefault("policy_pb2", leaflux.policy_pb2)
