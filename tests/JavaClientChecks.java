// The Java client's errors, run by tests/java_client_test.sh with Java's source launcher:
//   java -cp leaflux-client.jar:protobuf.jar:jeromq.jar tests/JavaClientChecks.java CHECK ENDPOINT [MS]
// CHECK is
//   errors ENDPOINT   a cycle of a session never opened is refused ERROR_CODE_UNKNOWN_SESSION
//                     (field "session"), and a cycle sent twice ERROR_CODE_INVALID_ARGUMENT
//                     (field "number"), as LeafluxExceptions carrying the daemon's code;
//                     A cycle given a resync source after its session was closed is
//                     resynced and lit (ERROR_CODE_UNKNOWN_SESSION handled);
//   stale             against a stand-in daemon (a jeromq ROUTER) that answers first with
//                     another request's id and a frame that is no Reply: both are dropped
//                     and the reply of the request's own id is taken;
//   timeout ENDPOINT MS  against no daemon, a Status times out within MS (and not much
//                     later) with a RequestTimeoutException naming ENDPOINT, and so does
//                     the next request on the new connection.
// Prints what it saw; exits 0 when every check holds, 1 with "FAIL: …" otherwise.
import org.leaflux.client.LeafluxClient;
import org.leaflux.client.LeafluxException;
import org.leaflux.client.RequestTimeoutException;
import org.leaflux.v1.Band;
import org.leaflux.v1.BandOptics;
import org.leaflux.v1.Cycle;
import org.leaflux.v1.ErrorCode;
import org.leaflux.v1.Mesh;
import org.leaflux.v1.Node;
import org.leaflux.v1.NodeType;
import org.leaflux.v1.Optics;
import org.leaflux.v1.Organ;
import org.leaflux.v1.OutputRequest;
import org.leaflux.v1.Reply;
import org.leaflux.v1.Request;
import org.leaflux.v1.StatusReply;
import org.leaflux.v1.ProtocolVersion;
import org.leaflux.v1.Scene;
import org.leaflux.v1.Sun;
import org.leaflux.v1.TopologyDelta;
import org.leaflux.v1.Vec3;
import org.zeromq.ZMQ;

public final class JavaClientChecks {
    static String endpoint = "";

    static void fail(String message) {
        System.out.println("FAIL: " + message);
        System.exit(1);
    }

    static Cycle cycle(String session, long number, TopologyDelta delta) {
        return Cycle.newBuilder().setSession(session).setNumber(number).setDelta(delta)
                .setOutputs(OutputRequest.newBuilder().setLeaves(true)).build();
    }

    /** Runs {@code call}, which must throw a LeafluxException of {@code code}; returns it. */
    static LeafluxException expect(ErrorCode code, String what, Runnable call) {
        try {
            call.run();
        } catch (LeafluxException e) {
            System.out.println(what + ": " + e.getClass().getSimpleName() + " " + e.code()
                    + " field '" + e.field() + "' node " + e.node() + ": " + e.getMessage());
            if (e.code() != code) {
                fail(what + ": expected " + code + ", got " + e.code());
            }
            if (!e.endpoint().equals(endpoint) || !e.getMessage().contains(endpoint)) {
                fail(what + ": the error does not name the endpoint " + endpoint);
            }
            return e;
        }
        fail(what + ": expected " + code + ", got a reply");
        return null;
    }

    static void errors() {
        try (LeafluxClient client = new LeafluxClient(endpoint)) {
            LeafluxException e = expect(ErrorCode.ERROR_CODE_UNKNOWN_SESSION, "unknown session",
                    () -> client.cycle(cycle("0123456789abcdef0123456789abcdef", 1,
                                             TopologyDelta.getDefaultInstance())));
            Scene.Builder scene = Scene.newBuilder()
                    .setVersion(ProtocolVersion.PROTOCOL_VERSION_CURRENT)
                    .addBands(Band.newBuilder().setName("PAR"))
                    .addOptics(Optics.newBuilder().setId("leaf").putBands("PAR",
                            BandOptics.newBuilder().setRhoUpper(0.1).setRhoLower(0.1)
                                    .setTauUpper(0.05).setTauLower(0.05).build()))
                    .addSuns(Sun.newBuilder().setDirection(Vec3.newBuilder().setZ(1))
                            .putNormalIrradiance("PAR", 400))
                    .addNodes(Node.newBuilder().setId(1).setType(NodeType.NODE_TYPE_PLANT));
            String session = client.open(scene.build(), null, "checks");
            Node leaf = Node.newBuilder().setId(2).setParent(1).setType(NodeType.NODE_TYPE_LEAF)
                    .setOrgan(Organ.newBuilder().setOptics("leaf").setMesh(Mesh.newBuilder()
                            .addPositions(0).addPositions(0).addPositions(0.5)
                            .addPositions(0.1).addPositions(0).addPositions(0.5)
                            .addPositions(0).addPositions(0.1).addPositions(0.5)
                            .addTriangles(0).addTriangles(1).addTriangles(2)))
                    .build();
            var light = client.cycle(cycle(session, 1, TopologyDelta.newBuilder().addAdded(leaf)
                                                  .build()));
            if (light.getOrgansCount() != 1) {
                fail("the cycle lit " + light.getOrgansCount() + " organs, not 1");
            }
            e = expect(ErrorCode.ERROR_CODE_INVALID_ARGUMENT, "cycle sent twice",
                    () -> client.cycle(cycle(session, 1, TopologyDelta.getDefaultInstance())));
            if (!e.field().equals("number")) {
                fail("the repeated cycle's error names the field '" + e.field() + "', not 'number'");
            }
            client.closeSession(session);
            expect(ErrorCode.ERROR_CODE_UNKNOWN_SESSION, "closed session",
                    () -> client.cycle(cycle(session, 2, TopologyDelta.getDefaultInstance())));
            // With a resync source, the lost session is given back whole and the cycle lit.
            Scene before = scene.addNodes(leaf).build();
            int[] resyncs = {0};
            light = client.cycle(cycle(session, 2, TopologyDelta.getDefaultInstance()), () -> {
                resyncs[0]++;
                return new LeafluxClient.SceneState(before, null);
            });
            if (resyncs[0] != 1 || light.getNumber() != 2 || light.getOrgansCount() != 1) {
                fail("the resynced cycle: " + resyncs[0] + " resyncs, cycle " + light.getNumber()
                        + ", " + light.getOrgansCount() + " organs");
            }
            System.out.println("resynced the closed session and lit cycle 2");
            client.closeSession(session);
        }
    }

    /** A stand-in daemon: answers the first request with a stale reply, junk, then its own. */
    static void stale() throws InterruptedException {
        ZMQ.Context context = ZMQ.context(1);
        ZMQ.Socket router = context.socket(ZMQ.ROUTER);
        router.setLinger(0);
        int port = router.bindToRandomPort("tcp://127.0.0.1");
        endpoint = "tcp://127.0.0.1:" + port;
        String[] problem = {null};
        Thread server = new Thread(() -> {
            try {
                byte[] identity = router.recv(0);
                byte[] delimiter = router.recv(0);
                Request request = Request.parseFrom(router.recv(0));
                if (delimiter.length != 0 || router.hasReceiveMore()) {
                    problem[0] = "the request is not [delimiter, payload]";
                }
                long id = request.getRequestId();
                Reply.Builder reply = Reply.newBuilder().setVersion(request.getVersion());
                for (byte[] payload : new byte[][] {
                        reply.setRequestId(id + 41).setStatus(StatusReply.newBuilder()
                                .setSessionCount(41)).build().toByteArray(),
                        {(byte) 0xff, (byte) 0xff, (byte) 0xff},
                        reply.setRequestId(id).setStatus(StatusReply.newBuilder()
                                .setSessionCount(7)).build().toByteArray()}) {
                    router.sendMore(identity);
                    router.sendMore(new byte[0]);
                    router.send(payload, 0);
                }
            } catch (Exception e) {
                problem[0] = e.toString();
            }
        });
        server.start();
        try (LeafluxClient client = new LeafluxClient(endpoint, LeafluxClient.Timeouts.all(10_000))) {
            int sessions = client.status("").getSessionCount();
            server.join();
            if (problem[0] != null) {
                fail("the stand-in daemon: " + problem[0]);
            }
            if (sessions != 7) {
                fail("took the reply with session_count " + sessions + ", not the one of its id (7)");
            }
            System.out.println("dropped a stale reply and a non-Reply frame, took its own");
        }
        router.close();
        context.term();
    }

    static void timeout(long ms) {
        try (LeafluxClient client = new LeafluxClient(endpoint, LeafluxClient.Timeouts.all(ms))) {
            for (int attempt = 1; attempt <= 2; attempt++) {  // the second on a new connection
                long start = System.nanoTime();
                LeafluxException e = expect(ErrorCode.ERROR_CODE_IO, "timeout " + attempt,
                                            () -> client.status(""));
                long waitedMs = (System.nanoTime() - start) / 1_000_000;
                if (!(e instanceof RequestTimeoutException)) {
                    fail("not a RequestTimeoutException: " + e.getClass().getName());
                }
                if (waitedMs < ms || waitedMs > ms + 2000) {
                    fail("the timeout of " + ms + " ms came after " + waitedMs + " ms");
                }
                System.out.println("timed out after " + waitedMs + " ms (timeout " + ms + " ms)");
            }
        }
    }

    public static void main(String[] args) throws InterruptedException {
        if (args.length == 2 && args[0].equals("errors")) {
            endpoint = args[1];
            errors();
        } else if (args.length == 1 && args[0].equals("stale")) {
            stale();
        } else if (args.length == 3 && args[0].equals("timeout")) {
            endpoint = args[1];
            timeout(Long.parseLong(args[2]));
        } else {
            System.err.println("usage: JavaClientChecks errors ENDPOINT | stale | timeout ENDPOINT MS");
            System.exit(2);
        }
        System.out.println("ok");
    }
}
