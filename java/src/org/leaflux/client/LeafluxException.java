package org.leaflux.client;

import org.leaflux.v1.ErrorCode;

/**
 * A request that failed: the daemon's {@code Error} reply (its code, message, the field path
 * and node id concerned), or a failure on this side (a timeout, a request too large to
 * send), always naming the endpoint of the daemon.
 */
public class LeafluxException extends RuntimeException {
    private static final long serialVersionUID = 1L;

    private final ErrorCode code;
    private final String field;
    private final long node;
    private final String endpoint;

    public LeafluxException(ErrorCode code, String message, String field, long node,
                            String endpoint) {
        super(describe(code, message, field, node, endpoint));
        this.code = code;
        this.field = field == null ? "" : field;
        this.node = node;
        this.endpoint = endpoint;
    }

    /** The error's code, e.g. {@code ERROR_CODE_UNKNOWN_SESSION}. */
    public ErrorCode code() {
        return code;
    }

    /** The field path concerned, e.g. {@code number} or {@code optics[leaf].bands[NIR]}; empty: none. */
    public String field() {
        return field;
    }

    /** The node id concerned; 0: none. */
    public long node() {
        return node;
    }

    /** The daemon's endpoint, e.g. {@code tcp://127.0.0.1:5555}. */
    public String endpoint() {
        return endpoint;
    }

    private static String describe(ErrorCode code, String message, String field, long node,
                                   String endpoint) {
        StringBuilder s = new StringBuilder(code.name());
        if (field != null && !field.isEmpty()) {
            s.append(" [").append(field).append(']');
        }
        if (node != 0) {
            s.append(" [node ").append(node).append(']');
        }
        return s.append(": ").append(message).append(" (leafluxd at ").append(endpoint)
                .append(')').toString();
    }
}
