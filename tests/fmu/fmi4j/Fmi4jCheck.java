// Drives an FMI 2 co-simulation FMU with FMI4j (JVM importer, Maven Central
// info.laht.fmi4j:fmi-import), for tests/fmu/test_fmu_fmi4j.py.
//
// Usage: java Fmi4jCheck <fmu> <input file: lines "u N"> <output file>
// Writes one line "F W" per input sample (outputs after the step to that sample),
// then "dFdu <value>" (directional derivative after the last sample) and
// "rollback <0|1>" (1 when a restored FMU state repeats the last 10 samples
// bit for bit).
import java.io.File;
import java.io.PrintWriter;
import java.nio.file.Files;
import java.util.ArrayList;
import java.util.List;
import no.ntnu.ihb.fmi4j.importer.fmi2.CoSimulationSlave;
import no.ntnu.ihb.fmi4j.importer.fmi2.Fmu;

public class Fmi4jCheck {
    static final long[] INPUTS = {1, 2};   // u, N (fmu_src/fmi/damper_vr.h)
    static final long[] OUTPUTS = {3, 5};  // F, W
    static final double H = 1e-3;

    static double[] step(CoSimulationSlave s, double[] in, double t) {
        double[] out = new double[2];
        s.writeReal(INPUTS, in);
        if (!s.doStep(t, H)) throw new IllegalStateException("doStep failed at t = " + t);
        s.readReal(OUTPUTS, out);
        return out;
    }

    public static void main(String[] args) throws Exception {
        List<double[]> inputs = new ArrayList<>();
        for (String line : Files.readAllLines(new File(args[1]).toPath())) {
            String[] p = line.trim().split("\\s+");
            if (p.length == 2) inputs.add(new double[] {Double.parseDouble(p[0]), Double.parseDouble(p[1])});
        }
        try (Fmu fmu = Fmu.from(new File(args[0]));
             PrintWriter w = new PrintWriter(args[2])) {
            CoSimulationSlave s = fmu.asCoSimulationFmu().newInstance();
            s.simpleSetup();
            int n = inputs.size();
            double[][] out = new double[n][];
            long state = 0;
            for (int k = 0; k < n; k++) {
                if (k == n - 10) state = s.getFMUstate();
                out[k] = step(s, inputs.get(k), k * H);
            }
            for (double[] o : out) w.println(o[0] + " " + o[1]);
            double[] d = s.getDirectionalDerivative(new long[] {3}, new long[] {1}, new double[] {1.0});
            w.println("dFdu " + d[0]);
            boolean same = s.setFMUstate(state);
            for (int k = n - 10; k < n; k++) {
                double[] again = step(s, inputs.get(k), k * H);
                same &= again[0] == out[k][0] && again[1] == out[k][1];
            }
            w.println("rollback " + (same ? 1 : 0));
            s.freeFMUstate(state);
            s.terminate();
            s.close();
        }
    }
}
