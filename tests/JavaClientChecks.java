// The Java client's errors, run by tests/java_client_test.sh with Java's source launcher:
//   java -cp leaflux-client.jar:protobuf.jar:jeromq.jar tests/JavaClientChecks.java CHECK ENDPOINT [MS]
// CHECK is
//   errors ENDPOINT   a cycle of a session never opened is refused ERROR_CODE_UNKNOWN_SESSION
//                     (field "session"), and a cycle sent twice ERROR_CODE_INVALID_ARGUMENT
//                     (field "number"), as LeafluxExceptions carrying the daemon's code;
//   timeout ENDPOINT MS  against no daemon, a Status times out within MS (and not much
//                     later) with a RequestTimeoutException naming ENDPOINT, and so does
//                     the next request on the new connection.
// Prints what it saw; exits 0 when every check holds, 1 with "FAIL: …" otherwise.
import org.leaflux.client.LeafluxClient;
import org.leaflux.client.LeafluxException;
import org.leaflux.client.RequestTimeoutException;
import org.leaflux.v1.BandOptics;
import org.leaflux.v1.Band;
import org.leaflux.v1.Cycle;
import org.leaflux.v1.ErrorCode;
import org.leaflux.v1.Mesh;
import org.leaflux.v1.Node;
import org.leaflux.v1.NodeType;
import org.leaflux.v1.Optics;
import org.leaflux.v1.Organ;
import org.leaflux.v1.OutputRequest;
import org.leaflux.v1.ProtocolVersion;
import org.leaflux.v1.Scene;
import org.leaflux.v1.Sun;
import org.leaflux.v1.TopologyDelta;
import org.leaflux.v1.Vec3;

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
        }
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

    public static void main(String[] args) {
        if (args.length == 2 && args[0].equals("errors")) {
            endpoint = args[1];
            errors();
        } else if (args.length == 3 && args[0].equals("timeout")) {
            endpoint = args[1];
            timeout(Long.parseLong(args[2]));
        } else {
            System.err.println("usage: JavaClientChecks errors ENDPOINT | timeout ENDPOINT MS");
            System.exit(2);
        }
        System.out.println("ok");
    }
}
