// JavaPlant: an rths participant written in Java (docs/participant.md), playing the role
// "plant": the linear servohydraulic model of Eq. 30, G(s) = K / ((s + p)(s^2 + b s + c)),
// discretised with a zero-order hold, and no specimen (force 0). It is what a lab's MATLAB code
// or hardware interface would do through the same LCM Java classes.
//
//   java -cp lcm.jar:rths_lcmtypes.jar:. JavaPlant --lcm-url URL --run-id N --scenario FILE \
//        --steps N --dt S [--K 1.6e7 --p 151.7 --b 250.4 --c 1.061e5]
//
// Protocol (docs/lockstep.md): HELLO on REQUEST (with the SHA-256 of the scenario file), start on
// GO (or on the clock's first desired_t / repair_t), measured_t 0 at rest; measured_t k from
// command_t k-1 and current_t k-1; the last four answers kept as bytes and re-sent unchanged when
// a repair_t wants them; what we lack asked for when the clock re-requests; BYE on DONE, exit on
// CLOSE (or after a short linger), exit 4 on ABORT, exit 3 if the clock is silent too long.
import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Paths;
import java.security.MessageDigest;
import java.util.HashMap;
import java.util.Map;

import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;
import rths.command_t;
import rths.current_t;
import rths.handshake_t;
import rths.measured_t;
import rths.repair_t;

public class JavaPlant implements LCMSubscriber {
  static final byte REQUEST = 1, HELLO = 2, GO = 3, ABORT = 4, DONE = 5, BYE = 6, CLOSE = 7;
  static final byte CH_COMMAND = 2, CH_MEASURED = 3, CH_CURRENT = 4;

  final LCM lcm;
  final long runId, nSteps;
  final double dt;
  final String sha256;
  final double[][] phi;
  final double[] gamma;
  double[] z = new double[3];          // [y, y', y''] at sample next-1 .. next
  final Map<Long, Double> command = new HashMap<>(), current = new HashMap<>();
  final byte[][] cache = new byte[4][];
  final long[] cacheK = {-1, -1, -1, -1};
  long next = 0;                       // next measured_t to publish
  boolean running = false, done = false;
  volatile int exitCode = -1;
  volatile long lastClockMs = System.currentTimeMillis();

  JavaPlant(LCM lcm, long runId, long nSteps, double dt, String sha256, double K, double p, double b, double c) {
    this.lcm = lcm;
    this.runId = runId;
    this.nSteps = nSteps;
    this.dt = dt;
    this.sha256 = sha256;
    // Phase-variable realisation (lib/models/servo_linear.h): z' = A z + B u, y = z[0].
    final double d2 = p + b, d1 = p * b + c, d0 = p * c;
    double[][] a = {{0, 1, 0, 0}, {0, 0, 1, 0}, {-d0, -d1, -d2, K}, {0, 0, 0, 0}};
    double[][] e = expm(a, dt);  // [[Phi, Gamma], [0, 1]] (Van Loan)
    phi = new double[3][3];
    gamma = new double[3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) phi[i][j] = e[i][j];
      gamma[i] = e[i][3];
    }
  }

  /// exp(M t) by scaling and squaring of a 24-term Taylor series (4x4; accurate to ~1e-13 here).
  static double[][] expm(double[][] m, double t) {
    int n = m.length;
    double norm = 0;
    for (double[] row : m) {
      double s = 0;
      for (double v : row) s += Math.abs(v * t);
      norm = Math.max(norm, s);
    }
    int squarings = Math.max(0, (int) Math.ceil(Math.log(norm / 0.25) / Math.log(2)));
    double scale = t / Math.pow(2, squarings);
    double[][] result = identity(n), term = identity(n);
    for (int k = 1; k <= 24; ++k) {
      term = mul(term, m);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) term[i][j] *= scale / k;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) result[i][j] += term[i][j];
    }
    for (int s = 0; s < squarings; ++s) result = mul(result, result);
    return result;
  }

  static double[][] identity(int n) {
    double[][] r = new double[n][n];
    for (int i = 0; i < n; ++i) r[i][i] = 1;
    return r;
  }

  static double[][] mul(double[][] x, double[][] y) {
    int n = x.length;
    double[][] r = new double[n][n];
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j) r[i][j] += x[i][k] * y[k][j];
    return r;
  }

  static byte[] encode(lcm.lcm.LCMEncodable msg) {
    try {
      ByteArrayOutputStream bytes = new ByteArrayOutputStream();
      msg.encode(new DataOutputStream(bytes));
      return bytes.toByteArray();
    } catch (IOException e) {
      throw new RuntimeException(e);
    }
  }

  void send(String channel, byte[] bytes) {
    try {
      lcm.publish(channel, bytes, 0, bytes.length);
    } catch (IOException e) {
      System.err.println("plant: cannot publish on " + channel + ": " + e);
      exitCode = 5;
    }
  }

  void handshake(byte phase, long k) {
    handshake_t h = new handshake_t();
    h.run_id = runId;
    h.phase = phase;
    h.participant = "plant";
    h.scenario_sha256 = sha256;
    h.n_steps = nSteps;
    h.dt_s = dt;
    h.k = k;
    h.n_roster = 0;
    h.roster_names = new String[0];
    h.roster_sha256 = new String[0];
    h.reason = "";
    // On the clock's host: our pid, so the supervisor notices at once if we die (docs/participant.md).
    h.pid = (phase == 2) ? (int) ProcessHandle.current().pid() : 0;
    h.heartbeat_s = 0;
    send("RTHS_HANDSHAKE", encode(h));
  }

  /// measured_t k: the sensors at t_k (y = z[0]; no specimen: f = 0), cached and published.
  void publishMeasured(long k, double currentA) {
    measured_t m = new measured_t();
    m.run_id = runId;
    m.k = k;
    m.y_mm = z[0];
    m.f_kN = 0.0;
    m.current_A = currentA;
    byte[] bytes = encode(m);
    int slot = (int) (k % 4);
    cache[slot] = bytes;
    cacheK[slot] = k;
    send("RTHS_MEASURED", bytes);
  }

  void start() {
    if (running || done) return;
    running = true;
    publishMeasured(0, 0.0);
    next = 1;
  }

  /// measured_t next from command_t next-1 and current_t next-1 (ZOH over [t_{k-1}, t_k)).
  void tryStep() {
    while (running && next < nSteps && command.containsKey(next - 1) && current.containsKey(next - 1)) {
      double u = command.remove(next - 1);
      double i = current.remove(next - 1);
      double[] zn = new double[3];
      for (int r = 0; r < 3; ++r) zn[r] = phi[r][0] * z[0] + phi[r][1] * z[1] + phi[r][2] * z[2] + gamma[r] * u;
      z = zn;
      publishMeasured(next, i);
      ++next;
    }
  }

  @Override
  public synchronized void messageReceived(LCM lcm, String channel, LCMDataInputStream in) {
    try {
      switch (channel) {
        case "RTHS_HANDSHAKE": {
          handshake_t h = new handshake_t(in);
          if (h.run_id != runId || h.participant.equals("plant")) return;
          if (h.phase == ABORT) {
            System.err.println("plant: " + h.participant + " aborted the run: " + h.reason);
            exitCode = 4;
            return;
          }
          if (!h.participant.equals("integrator")) return;
          lastClockMs = System.currentTimeMillis();
          if (h.phase == REQUEST && !running && !done) handshake(HELLO, -1);
          else if (h.phase == GO) start();
          else if (h.phase == DONE) {
            done = true;
            running = false;
            handshake(BYE, h.k);
          } else if (h.phase == CLOSE && done) exitCode = 0;
          return;
        }
        case "RTHS_DESIRED": {
          rths.desired_t d = new rths.desired_t(in);
          if (d.run_id != runId) return;
          lastClockMs = System.currentTimeMillis();
          if (!done) start();  // GO was lost: the clock is already stepping
          return;
        }
        case "RTHS_COMMAND": {
          command_t c = new command_t(in);
          if (c.run_id == runId && c.k >= next - 1) command.putIfAbsent(c.k, c.u_mm);  // first copy wins
          tryStep();
          return;
        }
        case "RTHS_CURRENT": {
          current_t c = new current_t(in);
          if (c.run_id == runId && c.k >= next - 1) current.putIfAbsent(c.k, c.i_cmd_A);
          tryStep();
          return;
        }
        case "RTHS_REPAIR": {
          repair_t r = new repair_t(in);
          if (r.run_id != runId || r.participant.equals("plant")) return;
          for (int i = 0; i < r.n_want; ++i) {  // re-send our cached answers, byte for byte
            if (r.want_channel[i] != CH_MEASURED) continue;
            int slot = (int) (r.want_k[i] % 4);
            if (r.want_k[i] >= 0 && cacheK[slot] == r.want_k[i]) {
              send("RTHS_MEASURED", cache[slot]);
            }
          }
          if (!r.participant.equals("integrator")) return;
          lastClockMs = System.currentTimeMillis();
          if (!done) start();
          // The barrier of step k holds measured_t k+1: up to next = k+1 we may lack inputs it needs.
          if (next > r.k + 1 || next >= nSteps) return;
          // The clock re-requests step k: say which inputs of measured_t next we lack.
          java.util.List<long[]> wants = new java.util.ArrayList<>();
          if (!command.containsKey(next - 1)) wants.add(new long[] {CH_COMMAND, next - 1});
          if (!current.containsKey(next - 1)) wants.add(new long[] {CH_CURRENT, next - 1});
          if (wants.isEmpty()) return;
          repair_t out = new repair_t();
          out.run_id = runId;
          out.k = r.k;
          out.participant = "plant";
          out.n_want = wants.size();
          out.want_channel = new byte[wants.size()];
          out.want_k = new long[wants.size()];
          for (int i = 0; i < wants.size(); ++i) {
            out.want_channel[i] = (byte) wants.get(i)[0];
            out.want_k[i] = wants.get(i)[1];
          }
          byte[] bytes = encode(out);
          send("RTHS_REPAIR", bytes);
          return;
        }
        default:
          return;
      }
    } catch (IOException e) {
      System.err.println("plant: bad message on " + channel + ": " + e);
    }
  }

  public static void main(String[] args) throws Exception {
    Map<String, String> a = new HashMap<>();
    for (int i = 0; i + 1 < args.length; i += 2) a.put(args[i], args[i + 1]);
    for (String key : new String[] {"--lcm-url", "--run-id", "--scenario", "--steps", "--dt"}) {
      if (!a.containsKey(key)) {
        System.err.println("usage: JavaPlant --lcm-url URL --run-id N --scenario FILE --steps N --dt S "
            + "[--K K --p P --b B --c C] (missing " + key + ")");
        System.exit(2);
      }
    }
    byte[] scenario = Files.readAllBytes(Paths.get(a.get("--scenario")));
    StringBuilder hex = new StringBuilder();
    for (byte x : MessageDigest.getInstance("SHA-256").digest(scenario)) hex.append(String.format("%02x", x));
    // Eq. 30, the average servohydraulic model (the scenario's actuator = "avg").
    double K = Double.parseDouble(a.getOrDefault("--K", "1.600e7"));
    double p = Double.parseDouble(a.getOrDefault("--p", "151.7"));
    double b = Double.parseDouble(a.getOrDefault("--b", "250.4"));
    double c = Double.parseDouble(a.getOrDefault("--c", "1.061e5"));
    LCM lcm = new LCM(a.get("--lcm-url"));
    JavaPlant plant = new JavaPlant(lcm, Long.parseLong(a.get("--run-id")), Long.parseLong(a.get("--steps")),
        Double.parseDouble(a.get("--dt")), hex.toString(), K, p, b, c);
    for (String ch : new String[] {"RTHS_HANDSHAKE", "RTHS_DESIRED", "RTHS_COMMAND", "RTHS_CURRENT", "RTHS_REPAIR"}) {
      lcm.subscribe(ch, plant);
    }
    final long watchdogMs = 12000, lingerMs = 1000;
    long doneSince = -1;
    while (plant.exitCode < 0) {
      Thread.sleep(10);
      long now = System.currentTimeMillis();
      synchronized (plant) {
        if (plant.done && doneSince < 0) doneSince = now;
      }
      if (doneSince >= 0 && now - doneSince > lingerMs) plant.exitCode = 0;  // CLOSE was lost
      if (doneSince < 0 && now - plant.lastClockMs > watchdogMs) {
        System.err.println("plant: the clock (integrator) is silent; giving up");
        plant.exitCode = 3;
      }
    }
    lcm.close();
    System.exit(plant.exitCode);
  }
}
