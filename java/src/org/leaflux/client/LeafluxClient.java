package org.leaflux.client;

import com.google.protobuf.InvalidProtocolBufferException;
import java.util.HashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.function.Supplier;
import java.util.logging.Logger;
import org.leaflux.v1.CloseSession;
import org.leaflux.v1.Cycle;
import org.leaflux.v1.CycleResult;
import org.leaflux.v1.ErrorCode;
import org.leaflux.v1.Node;
import org.leaflux.v1.OpenSession;
import org.leaflux.v1.ProtocolVersion;
import org.leaflux.v1.Reply;
import org.leaflux.v1.Request;
import org.leaflux.v1.Resync;
import org.leaflux.v1.Scene;
import org.leaflux.v1.Shutdown;
import org.leaflux.v1.SolverSettings;
import org.leaflux.v1.StatusReply;
import org.leaflux.v1.StatusRequest;
import org.zeromq.ZMQ;

/**
 * One connection to leafluxd: a ZeroMQ DEALER socket sending each request as two frames, an
 * empty delimiter and the serialised {@code leaflux.v1.Request} (docs/protocol.md).
 *
 * <p>Every request gets a new {@code request_id} and only the reply of that id is taken (or
 * id 0 with an error: the daemon could not decode the request); any other reply, the late
 * answer to a request given up on, is dropped. A request unanswered in time throws
 * {@link RequestTimeoutException} naming the endpoint, after the socket is closed and a new
 * one connected. An {@code Error} reply throws {@link LeafluxException} with its code, field
 * and node. Given a resync source, {@link #cycle(Cycle, Supplier)} survives a daemon restart
 * or a lost reply: it reconnects, resyncs the session and sends the cycle once more.
 *
 * <p>Not thread-safe: one thread uses a client at a time (ZeroMQ sockets are single-threaded).
 * The client owns its ZeroMQ context and socket; {@link #close()} releases both.
 */
public final class LeafluxClient implements AutoCloseable {
    public static final String DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555";

    private static final Logger LOG = Logger.getLogger("org.leaflux.client");
    private static final int LARGE_REQUEST_BYTES = 1 << 20;

    /**
     * How long a request waits for its reply, as the C++ and Python clients': Status,
     * CloseSession and Shutdown wait {@code statusMs}; OpenSession, Resync and Cycle, which
     * validate or solve a scene, wait {@code sceneMs} plus {@code perOrganMs} for each organ
     * of the session's scene (as far as this client sent them).
     */
    public record Timeouts(long statusMs, long sceneMs, double perOrganMs) {
        /** 30 s; 60 s plus 10 ms per organ. */
        public static final Timeouts DEFAULT = new Timeouts(30_000, 60_000, 10.0);

        /** Every request waits {@code ms}, whatever its scene. */
        public static Timeouts all(long ms) {
            return new Timeouts(ms, ms, 0.0);
        }
    }

    /** A session's whole scene and settings, as handed to Resync. */
    public record SceneState(Scene scene, SolverSettings settings) {}

    private final String endpoint;
    private final Timeouts timeouts;
    private final ZMQ.Context context = ZMQ.context(1);
    private ZMQ.Socket socket;
    private long nextId = 1;
    private final Map<String, Integer> organs = new HashMap<>();  // by session: organs sent
    private long maxMessageBytes = -1;  // the daemon's, once asked; -1: not asked

    public LeafluxClient(String endpoint) {
        this(endpoint, Timeouts.DEFAULT);
    }

    public LeafluxClient(String endpoint, Timeouts timeouts) {
        if (!endpoint.startsWith("tcp://")) {
            // jeromq speaks TCP only (its ipc:// is not libzmq's), and has no CurveZMQ.
            throw new IllegalArgumentException(
                    "leaflux: the Java client connects to tcp://HOST:PORT endpoints, not '"
                            + endpoint + "'");
        }
        this.endpoint = endpoint;
        this.timeouts = timeouts;
        reconnect();
    }

    public String endpoint() {
        return endpoint;
    }

    public Timeouts timeouts() {
        return timeouts;
    }

    /** A new connection to the same endpoint: replies to the old one are never read. */
    public void reconnect() {
        disconnect();
        maxMessageBytes = -1;  // perhaps another daemon now
        socket = context.socket(ZMQ.DEALER);
        socket.setLinger(0);
        socket.connect(endpoint);
    }

    /** Closes the connection (sessions stay open in the daemon). */
    public void disconnect() {
        if (socket != null) {
            socket.close();
            socket = null;
        }
    }

    @Override
    public void close() {
        disconnect();
        context.term();
    }

    /** The milliseconds {@code request} waits for its reply. */
    public long timeoutMs(Request request) {
        int n;
        switch (request.getBodyCase()) {
            case OPEN_SESSION:
                n = countOrgans(request.getOpenSession().getScene().getNodesList());
                break;
            case RESYNC:
                n = countOrgans(request.getResync().getScene().getNodesList());
                break;
            case CYCLE:
                n = organs.getOrDefault(request.getCycle().getSession(), 0)
                        + countOrgans(request.getCycle().getDelta().getAddedList());
                break;
            default:
                return timeouts.statusMs();
        }
        return timeouts.sceneMs() + Math.round(timeouts.perOrganMs() * n);
    }

    /**
     * Sends a request (its version and request_id are set here) and returns its reply.
     *
     * @throws LeafluxException on an Error reply, or {@code ERROR_CODE_TOO_LARGE}, unsent,
     *     for a request over the daemon's {@code max_message_bytes}
     * @throws RequestTimeoutException when no reply comes in time
     */
    public Reply call(Request request) {
        if (socket == null) {
            reconnect();
        }
        String kind = kindOf(request);
        long requestId = nextId++;
        Request sent = request.toBuilder()
                .setVersion(ProtocolVersion.PROTOCOL_VERSION_CURRENT)
                .setRequestId(requestId)
                .build();
        long timeoutMs = timeoutMs(sent);
        byte[] payload = sent.toByteArray();
        // ZeroMQ cuts off, unanswered, a frame over twice the daemon's limit: a large request
        // is checked against the limit first (asked once a connection).
        if (payload.length > LARGE_REQUEST_BYTES && sent.getBodyCase() != Request.BodyCase.STATUS) {
            if (maxMessageBytes < 0) {
                maxMessageBytes = status("").getMaxMessageBytes();
            }
            if (maxMessageBytes > 0 && payload.length > maxMessageBytes) {
                throw new LeafluxException(ErrorCode.ERROR_CODE_TOO_LARGE,
                        "the request of " + payload.length + " bytes exceeds the daemon's limit of "
                                + maxMessageBytes + " bytes (leafluxd --max-message-mb): not sent",
                        kind, 0, endpoint);
            }
        }
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        socket.setSendTimeOut((int) Math.min(Integer.MAX_VALUE, timeoutMs));
        if (!socket.sendMore(new byte[0]) || !socket.send(payload, 0)) {
            reconnect();
            throw new RequestTimeoutException(endpoint, kind, timeoutMs);
        }
        Reply reply;
        while (true) {
            byte[] last = receiveLastFrame(deadline);
            if (last == null) {
                reconnect();  // a late reply must not answer the next request
                throw new RequestTimeoutException(endpoint, kind, timeoutMs);
            }
            try {
                reply = Reply.parseFrom(last);
            } catch (InvalidProtocolBufferException e) {
                LOG.warning("leaflux: dropped a message from " + endpoint
                        + " that is not a leaflux.v1.Reply");
                continue;
            }
            // Id 0: the daemon could not read the request's id (it did not decode).
            if (reply.getRequestId() == requestId
                    || (reply.getRequestId() == 0 && reply.hasError())) {
                break;
            }
            LOG.fine("leaflux: dropped a stale reply (request_id " + reply.getRequestId()
                    + ", waiting for " + requestId + ")");
        }
        if (reply.hasError()) {
            var e = reply.getError();
            throw new LeafluxException(e.getCode(), e.getMessage(), e.getField(), e.getNode(),
                                       endpoint);
        }
        if (sent.getBodyCase() == Request.BodyCase.CYCLE) {
            Cycle c = sent.getCycle();
            organs.merge(c.getSession(), countOrgans(c.getDelta().getAddedList()), Integer::sum);
        }
        return reply;
    }

    /** Opens a session for a scene (bands, optics, environment, sources, first nodes); returns its id. */
    public String open(Scene scene, SolverSettings settings, String species) {
        OpenSession.Builder open = OpenSession.newBuilder().setScene(scene).setSpecies(species);
        if (settings != null) {
            open.setSettings(settings);
        }
        String session = call(Request.newBuilder().setOpenSession(open).build())
                .getOpened().getSession();
        organs.put(session, countOrgans(scene.getNodesList()));
        return session;
    }

    /**
     * Gives the daemon the session's whole scene under its id (after a restart, or a cycle
     * gone unanswered); {@code lastCycle}: the number of the last cycle the scene includes.
     */
    public void resync(String session, Scene scene, SolverSettings settings, long lastCycle) {
        Resync.Builder resync = Resync.newBuilder().setSession(session).setScene(scene)
                .setLastCycle(lastCycle);
        if (settings != null) {
            resync.setSettings(settings);
        }
        call(Request.newBuilder().setResync(resync).build());
        organs.put(session, countOrgans(scene.getNodesList()));
    }

    /** Sends a cycle (session, number, delta, suns, outputs) and returns its light. */
    public CycleResult cycle(Cycle cycle) {
        return call(Request.newBuilder().setCycle(cycle).build()).getCycle();
    }

    /**
     * Sends a cycle; {@code resync} returns the session's scene and settings as they were
     * before this cycle. A cycle unanswered in time, or whose session the daemon lost (it
     * restarted), is sent once more after a new connection and a Resync with
     * {@code last_cycle} one below the cycle's number.
     */
    public CycleResult cycle(Cycle cycle, Supplier<SceneState> resync) {
        try {
            return cycle(cycle);
        } catch (LeafluxException e) {
            boolean lost = e instanceof RequestTimeoutException
                    || e.code() == ErrorCode.ERROR_CODE_UNKNOWN_SESSION;
            if (resync == null || !lost) {
                throw e;
            }
            LOG.warning("leaflux: cycle " + cycle.getNumber() + " of session "
                    + cycle.getSession() + ": " + e.getMessage()
                    + "; reconnecting, resyncing and sending it again");
        }
        reconnect();
        SceneState state = resync.get();
        resync(cycle.getSession(), state.scene(), state.settings(), cycle.getNumber() - 1);
        return cycle(cycle);
    }

    /** The daemon's counts and limits ({@code session} empty), or one session's. */
    public StatusReply status(String session) {
        return call(Request.newBuilder()
                            .setStatus(StatusRequest.newBuilder().setSession(session))
                            .build())
                .getStatus();
    }

    /** Frees a session in the daemon. */
    public void closeSession(String session) {
        call(Request.newBuilder().setCloseSession(CloseSession.newBuilder().setSession(session))
                     .build());
        organs.remove(session);
    }

    /** Stops the daemon, as SIGTERM does. */
    public void shutdown() {
        call(Request.newBuilder().setShutdown(Shutdown.getDefaultInstance()).build());
    }

    /** The last frame of the next message, or null when none comes before {@code deadline}. */
    private byte[] receiveLastFrame(long deadline) {
        byte[] frame = null;
        // The socket's own clock may wake a millisecond early: wait again until the deadline
        // has truly passed, so that a timeout never comes before the one asked for.
        while (frame == null) {
            long leftNs = deadline - System.nanoTime();
            if (leftNs <= 0) {
                return null;
            }
            long leftMs = (leftNs + 999_999L) / 1_000_000L;
            socket.setReceiveTimeOut((int) Math.min(Integer.MAX_VALUE, leftMs));
            frame = socket.recv(0);
        }
        // The frames of one message come together: read them through to the payload.
        while (socket.hasReceiveMore()) {
            byte[] next = socket.recv(0);
            if (next == null) {
                return null;
            }
            frame = next;
        }
        return frame;
    }

    private static String kindOf(Request request) {
        Request.BodyCase body = request.getBodyCase();
        if (body == Request.BodyCase.BODY_NOT_SET) {
            return "request";
        }
        return body.name().toLowerCase(Locale.ROOT);
    }

    private static int countOrgans(List<Node> nodes) {
        int n = 0;
        for (Node node : nodes) {
            if (node.hasOrgan()) {
                n++;
            }
        }
        return n;
    }
}
