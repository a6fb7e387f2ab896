package org.leaflux.example;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.TreeMap;
import org.leaflux.client.LeafluxClient;
import org.leaflux.client.LeafluxException;
import org.leaflux.v1.Band;
import org.leaflux.v1.BandLight;
import org.leaflux.v1.BandOptics;
import org.leaflux.v1.Cycle;
import org.leaflux.v1.CycleResult;
import org.leaflux.v1.Frame;
import org.leaflux.v1.Mesh;
import org.leaflux.v1.Node;
import org.leaflux.v1.NodeType;
import org.leaflux.v1.Optics;
import org.leaflux.v1.Organ;
import org.leaflux.v1.OrganLight;
import org.leaflux.v1.OutputRequest;
import org.leaflux.v1.ProtocolVersion;
import org.leaflux.v1.Scene;
import org.leaflux.v1.Sky;
import org.leaflux.v1.SkyDiscretization;
import org.leaflux.v1.SkyModel;
import org.leaflux.v1.SolverKind;
import org.leaflux.v1.SolverSettings;
import org.leaflux.v1.Sun;
import org.leaflux.v1.Surface;
import org.leaflux.v1.TopologyDelta;
import org.leaflux.v1.Vec3;

/**
 * A growth model coupled to leafluxd from Java, as a GroIMP model would be: a small plant
 * (a stem of internodes, a leaf on each, spiralling at the golden angle) under a sun and a
 * CIE overcast sky, in two bands, PAR and NIR.
 *
 * <p>Each cycle adds two phytomers (an internode and its leaf); the new leaves share the
 * biomass that the PAR the plant absorbed in the cycle before makes (radiation use
 * efficiency 2.5 g/MJ over a cycle of two 8-hour days, half of it to leaf blades at a
 * specific leaf area of 0.03 m²/g). The first cycle's leaves are 20 cm² each. A daemon that
 * restarts, or a cycle that goes unanswered, costs only time: the cycle is resynced with
 * the nodes already lit and sent again.
 *
 * <p>Usage: {@code java -jar leaflux-client.jar [--endpoint tcp://HOST:PORT] [--cycles 5]
 * [--cycle-timeout-ms 60000]}
 */
public final class GrowthLoop {
    static final double RUE_G_PER_MJ = 2.5;
    static final double LIGHT_SECONDS_PER_CYCLE = 2 * 8 * 3600.0;  // two 8-hour days
    static final double LEAF_FRACTION = 0.5;
    static final double SLA_M2_PER_G = 0.03;
    static final double FIRST_LEAF_M2 = 0.0020;  // 20 cm²
    static final double MIN_LEAF_M2 = 0.0005;    // 5 cm²
    static final double MAX_LEAF_M2 = 0.0100;    // 1 dm²
    static final double INTERNODE_M = 0.03;
    static final double STEM_WIDTH_M = 0.008;
    static final double LEAF_RAISE_DEG = 30;
    static final double PHYLLOTAXY_DEG = 137.5;
    static final double PAR_UMOL_PER_J = 4.57;  // daylight PAR

    private final List<Node> lit = new ArrayList<>();  // nodes the daemon has lit, in order
    private final Map<Integer, Double> leafAreasM2 = new TreeMap<>();  // by phytomer

    private GrowthLoop() {}

    /** The scene without the growing plant: bands, optics, a ground, the sun and sky. */
    static Scene.Builder environment() {
        Scene.Builder s = Scene.newBuilder().setVersion(ProtocolVersion.PROTOCOL_VERSION_CURRENT);
        s.addBands(Band.newBuilder().setName("PAR").setWavelengthMinNm(400).setWavelengthMaxNm(700));
        s.addBands(Band.newBuilder().setName("NIR").setWavelengthMinNm(700).setWavelengthMaxNm(2500));
        s.addOptics(optics("leaf", leafSide(0.10, 0.05), leafSide(0.45, 0.40)));
        s.addOptics(optics("stem", leafSide(0.10, 0.0), leafSide(0.40, 0.0)));
        s.addOptics(optics("ground", leafSide(0.10, 0.0), leafSide(0.30, 0.0)));
        s.addEnvironment(Surface.newBuilder().setName("ground").setOptics("ground")
                .setMesh(quad(new double[] {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0})));
        s.addSuns(Sun.newBuilder()
                .setDirection(Vec3.newBuilder().setX(0.3).setY(0.4).setZ(0.866))
                .putNormalIrradiance("PAR", 400).putNormalIrradiance("NIR", 350));
        s.setSky(Sky.newBuilder().setModel(SkyModel.SKY_MODEL_CIE_OVERCAST)
                .putHorizontalIrradiance("PAR", 80).putHorizontalIrradiance("NIR", 70)
                .setDiscretization(SkyDiscretization.SKY_DISCRETIZATION_TURTLE_46));
        s.addNodes(Node.newBuilder().setId(1).setType(NodeType.NODE_TYPE_PLANT).setName("plant"));
        return s;
    }

    private static BandOptics leafSide(double rho, double tau) {
        return BandOptics.newBuilder().setRhoUpper(rho).setRhoLower(rho).setTauUpper(tau)
                .setTauLower(tau).build();
    }

    private static Optics optics(String id, BandOptics par, BandOptics nir) {
        return Optics.newBuilder().setId(id).putBands("PAR", par).putBands("NIR", nir).build();
    }

    private static Mesh quad(double[] positions) {
        Mesh.Builder m = Mesh.newBuilder();
        for (double p : positions) {
            m.addPositions(p);
        }
        return m.addTriangles(0).addTriangles(1).addTriangles(2)
                .addTriangles(0).addTriangles(2).addTriangles(3).build();
    }

    private static Frame frame(double... m) {
        Frame.Builder f = Frame.newBuilder();
        for (double v : m) {
            f.addM(v);
        }
        return f.build();
    }

    /** Internode k, a vertical strip, on top of internode k − 1 (or at the plant's foot). */
    static Node internode(int k) {
        double w = STEM_WIDTH_M / 2, h = INTERNODE_M;
        return Node.newBuilder().setId(100 + 2L * k).setParent(k == 0 ? 1 : 100 + 2L * (k - 1))
                .setType(NodeType.NODE_TYPE_INTERNODE).setName("internode" + k)
                .setFrame(frame(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, k == 0 ? 0 : INTERNODE_M))
                .setOrgan(Organ.newBuilder().setOptics("stem")
                        .setMesh(quad(new double[] {-w, 0, 0, w, 0, 0, w, 0, h, -w, 0, h})))
                .build();
    }

    /**
     * Leaf k at the top of internode k: a diamond blade of {@code areaM2} (length L, width
     * L / 2), upper side up, raised 30° and turned 137.5° from leaf k − 1.
     */
    static Node leaf(int k, double areaM2) {
        double length = Math.sqrt(4 * areaM2);
        double azimuth = Math.toRadians(PHYLLOTAXY_DEG * k);
        double raise = Math.toRadians(LEAF_RAISE_DEG);
        double ca = Math.cos(azimuth), sa = Math.sin(azimuth);
        double cr = Math.cos(raise), sr = Math.sin(raise);
        // Rz(azimuth) · Ry(−raise), at the internode's top.
        Frame f = frame(ca * cr, -sa, -ca * sr, 0,
                        sa * cr, ca, -sa * sr, 0,
                        sr, 0, cr, INTERNODE_M);
        return Node.newBuilder().setId(101 + 2L * k).setParent(100 + 2L * k)
                .setType(NodeType.NODE_TYPE_LEAF).setName("leaf" + k).setFrame(f)
                .setOrgan(Organ.newBuilder().setOptics("leaf").setMesh(quad(new double[] {
                        0, 0, 0, length / 2, -length / 4, 0, length, 0, 0,
                        length / 2, length / 4, 0})))
                .build();
    }

    /** The new leaves' area each (m²): what the absorbed PAR (W) makes, shared by {@code count}. */
    static double newLeafAreaM2(double absorbedParW, int count) {
        double biomassG = RUE_G_PER_MJ * absorbedParW * LIGHT_SECONDS_PER_CYCLE * 1e-6;
        double area = SLA_M2_PER_G * LEAF_FRACTION * biomassG / count;
        return Math.max(MIN_LEAF_M2, Math.min(MAX_LEAF_M2, area));
    }

    private static double absorbedW(CycleResult result, String band) {
        double sum = 0;
        for (OrganLight organ : result.getOrgansList()) {
            if (organ.getNode() == 0) {
                continue;  // the ground
            }
            for (BandLight b : organ.getBandsList()) {
                if (b.getBand().equals(band)) {
                    sum += b.getAbsorbedW();
                }
            }
        }
        return sum;
    }

    private double leafAreaM2() {
        double sum = 0;
        for (double a : leafAreasM2.values()) {
            sum += a;
        }
        return sum;
    }

    private void grow(LeafluxClient client, int cycles) {
        SolverSettings settings = SolverSettings.newBuilder()
                .setSolver(SolverKind.SOLVER_KIND_HRC).setEpsilon(1e-4).build();
        Scene.Builder first = environment();
        int phytomers = 3;
        for (int k = 0; k < phytomers; k++) {
            leafAreasM2.put(k, FIRST_LEAF_M2);
            first.addNodes(internode(k)).addNodes(leaf(k, FIRST_LEAF_M2));
        }
        String session = client.open(first.build(), settings, "java-growth-loop");
        lit.addAll(first.getNodesList().subList(1, first.getNodesCount()));
        System.out.printf("%5s %6s %13s %14s %18s %14s%n", "cycle", "leaves", "leaf_area_dm2",
                          "absorbed_PAR_W", "absorbed_PAR_umol_s", "absorbed_NIR_W");
        double lastParW = -1;
        for (int number = 1; number <= cycles; number++) {
            double area = lastParW < 0 ? FIRST_LEAF_M2 : newLeafAreaM2(lastParW, 2);
            TopologyDelta.Builder delta = TopologyDelta.newBuilder();
            for (int i = 0; i < 2; i++, phytomers++) {
                leafAreasM2.put(phytomers, area);
                delta.addAdded(internode(phytomers)).addAdded(leaf(phytomers, area));
            }
            Cycle cycle = Cycle.newBuilder().setSession(session).setNumber(number).setDelta(delta)
                    .setOutputs(OutputRequest.newBuilder().setLeaves(true).setLightVectors(false))
                    .build();
            // The session as it was before this cycle, should the daemon have lost it.
            List<Node> before = List.copyOf(lit);
            CycleResult result = client.cycle(cycle, () -> new LeafluxClient.SceneState(
                    environment().addAllNodes(before).build(), settings));
            lit.addAll(delta.getAddedList());
            lastParW = absorbedW(result, "PAR");
            System.out.printf(Locale.ROOT, "%5d %6d %13.3f %14.4f %18.3f %14.4f%n", number,
                              leafAreasM2.size(), 100 * leafAreaM2(), lastParW,
                              PAR_UMOL_PER_J * lastParW, absorbedW(result, "NIR"));
            System.out.flush();
        }
        client.closeSession(session);
        System.out.println("closed session after " + cycles + " cycles");
    }

    private static void usage() {
        System.out.println("usage: java -jar leaflux-client.jar [--endpoint tcp://HOST:PORT] "
                + "[--cycles N] [--cycle-timeout-ms MS]\n"
                + "Grows a small plant (a stem, a leaf a phytomer, two new phytomers a cycle) "
                + "with the light leafluxd computes.\n"
                + "  --endpoint          leafluxd's endpoint (default "
                + LeafluxClient.DEFAULT_ENDPOINT + ")\n"
                + "  --cycles            cycles to grow (default 5)\n"
                + "  --cycle-timeout-ms  ms to wait for a cycle before resyncing, plus 10 ms an "
                + "organ (default 60000)");
    }

    public static void main(String[] args) {
        String endpoint = LeafluxClient.DEFAULT_ENDPOINT;
        int cycles = 5;
        long cycleTimeoutMs = 60_000;
        for (int i = 0; i < args.length; i++) {
            String a = args[i];
            if (a.equals("--help") || a.equals("-h")) {
                usage();
                return;
            }
            if (i + 1 >= args.length) {
                System.err.println("growth loop: " + a + " needs a value (--help)");
                System.exit(2);
            }
            String v = args[++i];
            try {
                switch (a) {
                    case "--endpoint" -> endpoint = v;
                    case "--cycles" -> cycles = Integer.parseInt(v);
                    case "--cycle-timeout-ms" -> cycleTimeoutMs = Long.parseLong(v);
                    default -> {
                        System.err.println("growth loop: unknown option " + a + " (--help)");
                        System.exit(2);
                    }
                }
            } catch (NumberFormatException e) {
                System.err.println("growth loop: " + a + " takes a whole number, not '" + v + "'");
                System.exit(2);
            }
        }
        if (cycles < 1) {
            System.err.println("growth loop: --cycles must be at least 1, not " + cycles);
            System.exit(2);
        }
        var timeouts = new LeafluxClient.Timeouts(30_000, cycleTimeoutMs, 10.0);
        try (LeafluxClient client = new LeafluxClient(endpoint, timeouts)) {
            new GrowthLoop().grow(client, cycles);
        } catch (LeafluxException | IllegalArgumentException e) {
            System.err.println("growth loop: " + e.getMessage());
            System.exit(1);
        }
    }
}
