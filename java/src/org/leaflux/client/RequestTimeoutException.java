package org.leaflux.client;

import org.leaflux.v1.ErrorCode;

/**
 * No reply came in time. Its code is {@code ERROR_CODE_IO}, as in the C++ client; the
 * message names the endpoint, the request's kind and the time waited. The client has
 * already made a new connection, so that the late reply is never read.
 */
public final class RequestTimeoutException extends LeafluxException {
    private static final long serialVersionUID = 1L;

    private final String kind;
    private final long timeoutMs;

    public RequestTimeoutException(String endpoint, String kind, long timeoutMs) {
        super(ErrorCode.ERROR_CODE_IO,
              "no reply to " + kind + " within " + timeoutMs + " ms; is leafluxd running there?",
              kind, 0, endpoint);
        this.kind = kind;
        this.timeoutMs = timeoutMs;
    }

    /** The request's body, e.g. {@code cycle}. */
    public String kind() {
        return kind;
    }

    /** How long the request waited, in milliseconds. */
    public long timeoutMs() {
        return timeoutMs;
    }
}
