"""The exceptions of the leaflux client: one class per protocol ErrorCode, and timeouts."""
from __future__ import annotations

from typing import Dict, Optional, Type

from . import leaflux_pb2 as pb


class LeafluxError(Exception):
    """A request that failed. `code` is the ErrorCode's name (e.g. "ERROR_CODE_NOT_FOUND"),
    `field` the field path concerned ("" if none), `node` the node id concerned (0: none),
    `message` the daemon's sentence, `endpoint` the daemon's."""

    def __init__(self, code: str, message: str, field: str = "", node: int = 0,
                 endpoint: str = "") -> None:
        self.code = code
        self.message = message
        self.field = field
        self.node = node
        self.endpoint = endpoint
        where = f" ({field})" if field else ""
        at = f" node {node}" if node else ""
        super().__init__(f"{code}{where}{at}: {message}")

    @property
    def code_value(self) -> int:
        """The ErrorCode as its number."""
        return pb.ErrorCode.Value(self.code)


class DaemonError(LeafluxError):
    """The daemon answered with an Error."""


class InvalidArgument(DaemonError):
    """ERROR_CODE_INVALID_ARGUMENT: a value out of range or inconsistent."""


class NotFound(DaemonError):
    """ERROR_CODE_NOT_FOUND: a reference to something absent."""


class AlreadyExists(DaemonError):
    """ERROR_CODE_ALREADY_EXISTS: a duplicate id or name."""


class Degenerate(DaemonError):
    """ERROR_CODE_DEGENERATE: geometry that cannot be lit."""


class ParentCycle(DaemonError):
    """ERROR_CODE_CYCLE: parent links that loop."""


class ParseError(DaemonError):
    """ERROR_CODE_PARSE: a payload or an imported file that does not parse."""


class FileError(DaemonError):
    """ERROR_CODE_IO: a file the scene names cannot be read."""


class Unsupported(DaemonError):
    """ERROR_CODE_UNSUPPORTED: an unknown request body or a newer protocol version."""


class UnknownSession(DaemonError):
    """ERROR_CODE_UNKNOWN_SESSION: closed, never opened, or the daemon restarted."""


class TooLarge(DaemonError):
    """ERROR_CODE_TOO_LARGE: a message or a count over a limit (also raised before sending
    a request over the daemon's max_message_bytes)."""


class ShuttingDown(DaemonError):
    """ERROR_CODE_SHUTTING_DOWN: the daemon is stopping; nothing of the request was kept."""


class InternalError(DaemonError):
    """ERROR_CODE_INTERNAL: a bug in the daemon."""


class RequestTimeout(LeafluxError, TimeoutError):
    """No reply within the timeout (code ERROR_CODE_IO, as the C++ client's). The client
    has reconnected: the late reply will not be read. Also a built-in TimeoutError."""

    def __init__(self, endpoint: str, kind: str, timeout_s: float) -> None:
        self.kind = kind
        self.timeout_s = timeout_s
        super().__init__(
            "ERROR_CODE_IO",
            f"no reply to {kind} from leafluxd at {endpoint} within {timeout_s:g} s "
            "(is it running? busy with a long solve?)", field=kind, endpoint=endpoint)


class DaemonStartError(LeafluxError, RuntimeError):
    """LocalDaemon could not find or start leafluxd."""

    def __init__(self, message: str) -> None:
        super().__init__("ERROR_CODE_IO", message)

    def __str__(self) -> str:
        return self.message


ERROR_CLASSES: Dict[str, Type[DaemonError]] = {
    "ERROR_CODE_INVALID_ARGUMENT": InvalidArgument,
    "ERROR_CODE_NOT_FOUND": NotFound,
    "ERROR_CODE_ALREADY_EXISTS": AlreadyExists,
    "ERROR_CODE_DEGENERATE": Degenerate,
    "ERROR_CODE_CYCLE": ParentCycle,
    "ERROR_CODE_PARSE": ParseError,
    "ERROR_CODE_IO": FileError,
    "ERROR_CODE_UNSUPPORTED": Unsupported,
    "ERROR_CODE_UNKNOWN_SESSION": UnknownSession,
    "ERROR_CODE_TOO_LARGE": TooLarge,
    "ERROR_CODE_SHUTTING_DOWN": ShuttingDown,
    "ERROR_CODE_INTERNAL": InternalError,
}


def from_reply(error: "pb.Error", endpoint: str = "") -> DaemonError:
    """The exception of an Error reply, of the class of its code."""
    try:
        code = pb.ErrorCode.Name(error.code)
    except ValueError:
        code = f"ERROR_CODE_{error.code}"
    cls: Optional[Type[DaemonError]] = ERROR_CLASSES.get(code)
    return (cls or DaemonError)(code, error.message, error.field, error.node, endpoint)
