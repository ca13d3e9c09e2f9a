#!/usr/bin/python3
"""An rths participant written in Python, playing the role "plant" (docs/participant.md).

The plant is the linear servohydraulic actuator of Phillips & Spencer 2013, Eq. 30 (the scenario's
[plant] kind = "linear", actuator = "avg"; Eqs. 28 and 29 and a table {K, p, b, c} work too):

    G(s) = K / ((s + p)(s^2 + b s + c)),  K = 1.600e7 1/s^3, p = 151.7 1/s, b = 250.4 1/s,
                                          c = 1.061e5 1/s^2       (command u [mm] -> y [mm])

discretised exactly with a zero-order hold at the run's dt, as rths does (lib/models/servo_linear.h),
with no specimen (specimen = "none": force 0 kN). A lab would put its hardware interface or its
own model where step() is.

    PYTHONPATH=build/examples/python_plant /usr/bin/python3 examples/python_plant/plant.py \
        --lcm-url URL --run-id N --scenario FILE [--heartbeat-s S] [--transport auto|lcm|own]

Needs python3 and python3-numpy (Debian 12), and the message types made by
`lcm-gen --python lcmtypes/*.lcm` (the build writes them to build/examples/python_plant/rths/).
Transport: the `lcm` Python module if it can be imported, else lcm_udpm.py beside this file (the
LCM udpm wire format in the standard library). The step count and dt come from the scenario's
[run] duration_s and dt_s (Python 3.11's tomllib); --steps and --dt override them.

Protocol (docs/lockstep.md, docs/participant.md; examples/java_plant/JavaPlant.java does the same
in Java): HELLO on REQUEST with the SHA-256 of the scenario file and our pid; start on GO (or on
the clock's first desired_t or repair_t); measured_t 0 at rest; measured_t k from command_t k-1 and
current_t k-1; the last four answers kept as bytes and re-sent unchanged when a repair_t wants
them; what we lack asked for when the clock re-requests; BYE on every DONE, exit on CLOSE (or
after a short linger); our pid in HELLO when the URL has ttl=0 (the clock's host). Exit codes: 0
done, 2 bad use, 3 the clock was silent too long (running: after sending ABORT), 4 someone else
aborted the run, 5 we failed ourselves (after sending ABORT with the reason). The times come from
the scenario's [lockstep] as rths's own participants use them (class Timing).
"""

import argparse
import hashlib
import math
import os
import signal
import struct
import sys
import time

import numpy as np

try:
    import tomllib  # Python 3.11+ (Debian 12's python3)
except ImportError:
    tomllib = None

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import lcm_udpm  # noqa: E402 (beside this file: our own udpm transport and URL parser)

# The generated types: PYTHONPATH, else the default build tree of this checkout.
sys.path.append(os.path.join(HERE, "..", "..", "build", "examples", "python_plant"))
try:
    from rths import command_t, current_t, desired_t, handshake_t, measured_t, repair_t
except ImportError as e:
    print(f"plant: cannot import the message types ({e}): generate them with\n"
          f"  lcm-gen --python --ppath DIR lcmtypes/*.lcm\n"
          f"and set PYTHONPATH=DIR (the build does this into build/examples/python_plant)", file=sys.stderr)
    sys.exit(2)

# handshake_t.phase (lcmtypes/handshake_t.lcm)
REQUEST, HELLO, GO, ABORT, DONE, BYE, CLOSE, HEARTBEAT = 1, 2, 3, 4, 5, 6, 7, 8
# repair_t.want_channel codes (lcmtypes/repair_t.lcm)
CH_COMMAND, CH_MEASURED, CH_CURRENT = 2, 3, 4
ROLE, CLOCK = "plant", "integrator"

# Eqs. 28-30: the identified servo models (K [1/s^3], p [1/s], b [1/s], c [1/s^2]).
SERVO_PRESETS = {
    "0.0A": (1.730e7, 182.7, 225.3, 9.499e4),  # Eq. 28
    "2.5A": (1.613e7, 134.2, 324.6, 1.211e5),  # Eq. 29
    "avg": (1.600e7, 151.7, 250.4, 1.061e5),  # Eq. 30
}


class Timing:
    """The scenario's [lockstep] times, with rths's defaults (lib/lockstep/config.h) [s]."""

    def __init__(self, lockstep):
        stall_budget_s = float(lockstep.get("stall_budget_s", 10.0))
        rerequest_s = float(lockstep.get("rerequest_ms", 100.0)) / 1000.0
        self.handshake_s = float(lockstep.get("handshake_timeout_s", 20.0))  # no GO and a silent clock: give up
        self.watchdog_s = stall_budget_s + 2.0  # running, and the clock silent this long: give up
        self.linger_s = min(stall_budget_s, max(0.5, 10.0 * rerequest_s))  # after BYE, if CLOSE is lost


# --- the model -------------------------------------------------------------------------------

def expm(a):
    """exp(a) of a square matrix: Pade (13, 13) approximant with scaling and squaring (Higham 2005,
    the degree-13 branch of Eigen's MatrixExponential that rths uses for the same matrix)."""
    b = (64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0,
         129060195264000.0, 10559470521600.0, 670442572800.0, 33522128640.0, 1323241920.0,
         40840800.0, 960960.0, 16380.0, 182.0, 1.0)
    norm1 = np.abs(a).sum(axis=0).max()  # largest column sum
    squarings = max(0, math.frexp(norm1 / 5.371920351148152)[1])  # theta_13 = 5.37
    a = a / 2.0**squarings
    ident = np.eye(a.shape[0])
    a2 = a @ a
    a4 = a2 @ a2
    a6 = a4 @ a2
    u = a @ (a6 @ (b[13] * a6 + b[11] * a4 + b[9] * a2) + b[7] * a6 + b[5] * a4 + b[3] * a2 + b[1] * ident)
    v = a6 @ (b[12] * a6 + b[10] * a4 + b[8] * a2) + b[6] * a6 + b[4] * a4 + b[2] * a2 + b[0] * ident
    r = np.linalg.solve(v - u, v + u)
    for _ in range(squarings):
        r = r @ r
    return r


class LinearServo:
    """Eq. 30 in phase variables, z = [y, y', y''] [mm, mm/s, mm/s^2] (lib/models/servo_linear.h):

        z' = A z + B u,  y = z[0],  A = [[0, 1, 0], [0, 0, 1], [-d0, -d1, -d2]],  B = [0, 0, K]^T,
        (s + p)(s^2 + b s + c) = s^3 + d2 s^2 + d1 s + d0,

    and its zero-order-hold discretisation z_{k+1} = Phi z_k + Gamma u_k, the command u_k [mm] held
    over [t_k, t_{k+1}) (the D/A converter's hold)."""

    def __init__(self, K, p, b, c, dt_s):
        d2, d1, d0 = p + b, p * b + c, p * c
        A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-d0, -d1, -d2]])
        B = np.array([0.0, 0.0, K])
        # Van Loan: exp([[A, B], [0, 0]] dt) = [[Phi, Gamma], [0, 1]], taken (as rths does) in the
        # balanced basis z~ = D z, D = diag(1, 1/w, 1/w^2), w = d0^(1/3), where every entry of
        # D A D^-1 is the size of a pole; then Phi = D^-1 Phi~ D and Gamma = D^-1 Gamma~.
        w = np.cbrt(d0)
        d = np.array([1.0, 1.0 / w, 1.0 / (w * w)])
        aug = np.zeros((4, 4))
        aug[:3, :3] = d[:, None] * A * (1.0 / d)[None, :]
        aug[:3, 3] = d * B
        e = expm(aug * dt_s)
        phi = (1.0 / d)[:, None] * e[:3, :3] * d[None, :]
        gamma = (1.0 / d) * e[:3, 3]
        # Plain floats: a 3x3 step is faster in Python arithmetic than through numpy.
        self.phi = [[float(x) for x in row] for row in phi]
        self.gamma = [float(x) for x in gamma]
        self.z = [0.0, 0.0, 0.0]  # at rest

    def y_mm(self):
        return self.z[0]

    def step(self, u_mm):
        """z_{k+1} = Phi z_k + Gamma u_k."""
        z0, z1, z2 = self.z
        self.z = [row[0] * z0 + row[1] * z1 + row[2] * z2 + g * u_mm for row, g in zip(self.phi, self.gamma)]


def decode(msg_type, channel, data):
    """msg_type.decode(data), with an error that says what to do when the types are stale."""
    try:
        return msg_type.decode(data)
    except (ValueError, struct.error) as e:
        raise ValueError(f"{channel}: cannot decode an rths.{msg_type.__name__} ({e}): generate the types "
                         "again from this checkout's lcmtypes/*.lcm (lcm-gen --python)") from None


# --- the participant -------------------------------------------------------------------------

class PlantParticipant:
    def __init__(self, lc, run_id, n_steps, dt_s, sha256, servo, heartbeat_s, announce_pid):
        self.lc = lc
        self.run_id, self.n_steps, self.dt_s, self.sha256 = run_id, n_steps, dt_s, sha256
        self.servo = servo
        self.heartbeat_s = heartbeat_s
        self.announce_pid = announce_pid
        self.command = {}  # k -> u_k [mm], first copy wins
        self.current = {}  # k -> i_k [A]
        self.cache = [None] * 4  # bytes of measured_t k at slot k % 4
        self.cache_k = [-1] * 4
        self.next = 0  # the next measured_t to publish
        self.running = False
        self.done = False
        self.exit_code = None
        self.last_clock = time.monotonic()  # last sign of life from the clock (or our start)
        self.hello_sent = False
        for channel, handler in (("RTHS_HANDSHAKE", self.on_handshake), ("RTHS_DESIRED", self.on_desired),
                                 ("RTHS_COMMAND", self.on_command), ("RTHS_CURRENT", self.on_current),
                                 ("RTHS_REPAIR", self.on_repair)):
            lc.subscribe(channel, handler)  # never RTHS_MEASURED: that is our own answer

    def handshake(self, phase, k, reason=""):
        h = handshake_t()
        h.run_id, h.phase, h.participant = self.run_id, phase, ROLE
        h.scenario_sha256, h.n_steps, h.dt_s, h.k = self.sha256, self.n_steps, self.dt_s, k
        h.n_roster, h.roster_names, h.roster_sha256 = 0, [], []
        h.reason = reason
        # On the clock's host (a ttl=0 URL) our pid lets the supervisor notice at once if we die;
        # heartbeat_s > 0 promises a HEARTBEAT every heartbeat_s (for a participant on another host).
        h.pid = os.getpid() if phase == HELLO and self.announce_pid else 0
        h.heartbeat_s = self.heartbeat_s if phase == HELLO else 0.0
        self.lc.publish("RTHS_HANDSHAKE", h.encode())

    def abort(self, reason, exit_code=5):
        """Our own failure (exit 5), or a silent clock (exit 3): ABORT in three copies, like the clock's."""
        print(f"plant: {reason}", file=sys.stderr)
        try:
            for _ in range(3):
                self.handshake(ABORT, self.next - 1 if self.running or self.done else -1, f"plant: {reason}")
        except OSError as e:
            print(f"plant: cannot send ABORT: {e}", file=sys.stderr)
        self.exit_code = exit_code

    def publish_measured(self, k, current_A):
        """measured_t k: the sensors at t_k (y = z[0]; no specimen: f = 0 kN), cached as bytes.
        current_A is the commanded current held over the last step, i_{k-1} [A], as rths's linear
        plant without a specimen reports it (checked with [semiactive] mode "passive_off" and
        "passive_on")."""
        m = measured_t()
        m.run_id, m.k = self.run_id, k
        m.y_mm, m.f_kN, m.current_A = self.servo.y_mm(), 0.0, current_A
        data = m.encode()
        self.cache[k % 4], self.cache_k[k % 4] = data, k
        self.lc.publish("RTHS_MEASURED", data)

    def start(self):
        """GO (or an implicit one): measured_t 0 at rest, with no current yet."""
        if self.running or self.done:
            return
        self.running = True
        self.publish_measured(0, 0.0)
        self.next = 1

    def try_step(self):
        """measured_t next from command_t next-1 and current_t next-1, held over [t_{next-1}, t_next)."""
        while (self.running and self.next < self.n_steps and self.next - 1 in self.command
               and self.next - 1 in self.current):
            u_mm = self.command.pop(self.next - 1)
            i_A = self.current.pop(self.next - 1)
            self.servo.step(u_mm)
            self.publish_measured(self.next, i_A)
            self.next += 1

    # Handlers: callback(channel, data) for the lcm module and for lcm_udpm.py alike.

    def on_handshake(self, channel, data):
        h = decode(handshake_t, channel, data)
        if h.run_id != self.run_id or h.participant == ROLE:
            return  # another run, or our own echo
        if h.phase == ABORT:
            print(f"plant: {h.participant} aborted the run: {h.reason}", file=sys.stderr)
            self.exit_code = 4
            return
        if h.participant != CLOCK:
            return
        self.last_clock = time.monotonic()
        if h.phase == REQUEST and not self.running and not self.done:
            self.handshake(HELLO, -1)
            self.hello_sent = True
        elif h.phase == GO:
            self.start()
        elif h.phase == DONE:
            self.done, self.running = True, False
            self.handshake(BYE, h.k)  # to every DONE: a BYE may be lost
        elif h.phase == CLOSE and self.done:
            self.exit_code = 0

    def on_desired(self, channel, data):
        d = decode(desired_t, channel, data)
        if d.run_id != self.run_id:
            return
        self.last_clock = time.monotonic()
        if not self.done:
            self.start()  # GO was lost: the clock is already stepping

    def on_command(self, channel, data):
        c = decode(command_t, channel, data)
        if c.run_id == self.run_id and c.k >= self.next - 1 and c.k not in self.command:
            self.command[c.k] = c.u_mm  # the first copy of a new step: the clock asked for it
            self.last_clock = time.monotonic()
        self.try_step()

    def on_current(self, channel, data):
        c = decode(current_t, channel, data)
        if c.run_id == self.run_id and c.k >= self.next - 1 and c.k not in self.current:
            self.current[c.k] = c.i_cmd_A
            self.last_clock = time.monotonic()
        self.try_step()

    def on_repair(self, channel, data):
        r = decode(repair_t, channel, data)
        if r.run_id != self.run_id or r.participant == ROLE:
            return
        for ch, k in zip(r.want_channel, r.want_k):  # re-send our cached answers, byte for byte
            if ch == CH_MEASURED and k >= 0 and self.cache_k[k % 4] == k:
                self.lc.publish("RTHS_MEASURED", self.cache[k % 4])
        if r.participant != CLOCK:
            return
        self.last_clock = time.monotonic()
        if not self.done:
            self.start()
        # The clock re-requests step k; its barrier holds measured_t k and k+1. If our next answer
        # is one of them, say which of its inputs (command_t and current_t next-1) we lack.
        if self.next > r.k + 1 or self.next >= self.n_steps:
            return
        wants = [(ch, self.next - 1) for ch, box in ((CH_COMMAND, self.command), (CH_CURRENT, self.current))
                 if self.next - 1 not in box]
        if not wants:
            return
        out = repair_t()
        out.run_id, out.k, out.participant = self.run_id, r.k, ROLE
        out.n_want = len(wants)
        out.want_channel = [ch for ch, _ in wants]
        out.want_k = [k for _, k in wants]
        self.lc.publish("RTHS_REPAIR", out.encode())

    def run(self, timing):
        """The event loop: messages, HEARTBEATs, the linger after DONE and the watchdog on the clock."""
        next_beat = None
        done_since = None
        while self.exit_code is None:
            now = time.monotonic()
            wait_s = 0.01
            if next_beat is not None:
                wait_s = min(wait_s, max(0.0, next_beat - now))
            self.lc.handle_timeout(int(wait_s * 1000))
            now = time.monotonic()
            if self.heartbeat_s > 0 and self.hello_sent:  # from HELLO until we exit, lingering included
                if next_beat is None:
                    next_beat = now + self.heartbeat_s
                elif now >= next_beat:
                    self.handshake(HEARTBEAT, -1)
                    next_beat = max(next_beat + self.heartbeat_s, now)
            silent_s = now - self.last_clock
            if self.done:
                if done_since is None:
                    done_since = now
                if now - done_since > timing.linger_s:
                    self.exit_code = 0  # CLOSE was lost
            elif not self.running:
                # Before GO the clock sends REQUEST every 0.1 s and judges the handshake itself.
                if silent_s > timing.handshake_s:
                    print(f"plant: no GO from the clock ({CLOCK}): nothing heard from it for {timing.handshake_s:g} s; "
                          "is it running on the same LCM URL and run id?", file=sys.stderr)
                    self.exit_code = 3
            elif silent_s > timing.watchdog_s:
                self.abort(f"step {self.next - 1}: the clock ({CLOCK}) stopped answering: silent for {silent_s:.3g} s",
                           exit_code=3)
        return self.exit_code


# --- set-up ----------------------------------------------------------------------------------

def open_lcm(url, which):
    """The `lcm` module if wanted and importable, else our own udpm transport (lcm_udpm.py)."""
    if which in ("auto", "lcm"):
        try:
            import lcm
            return lcm.LCM(url), "the lcm module"
        except ImportError:
            if which == "lcm":
                raise ValueError("--transport lcm: the lcm Python module is not installed")
    return lcm_udpm.LcmUdpm(url), "lcm_udpm.py (no lcm module)"


def read_scenario(path, steps, dt_s):
    """(sha256 hex, n_steps, dt_s, (K, p, b, c), Timing, warnings) of the scenario file."""
    with open(path, "rb") as f:
        raw = f.read()
    sha256 = hashlib.sha256(raw).hexdigest()  # of the file's bytes, as every participant hashes it
    if tomllib is None:
        if steps is None or dt_s is None:
            raise SystemExit("plant: this Python has no tomllib (3.11+) to read the scenario: give --steps and --dt")
        return sha256, steps, dt_s, SERVO_PRESETS["avg"], Timing({}), []
    doc = tomllib.loads(raw.decode("utf-8"))
    run = doc.get("run", {})
    if dt_s is None:
        dt_s = float(run.get("dt_s", 0.0005))  # rths's defaults (lib/scenario/scenario.h)
    if steps is None:
        steps = int(math.floor(float(run.get("duration_s", 20.0)) / dt_s + 0.5))  # llround
    plant = doc.get("plant", {})
    actuator = plant.get("actuator", "avg")
    if isinstance(actuator, str):
        if actuator not in SERVO_PRESETS:
            raise ValueError(f"[plant] actuator = \"{actuator}\": allowed \"0.0A\", \"2.5A\", \"avg\" "
                             "or a table {K, p, b, c}")
        servo = SERVO_PRESETS[actuator]
    else:
        missing = [key for key in ("K", "p", "b", "c") if key not in actuator]
        if missing:
            raise ValueError(f"[plant] actuator: the table lacks {', '.join(missing)} (it needs K, p, b, c)")
        servo = tuple(float(actuator[key]) for key in ("K", "p", "b", "c"))
    # What this example does not model (a scenario rths wrote back, RUN/scenario.toml, lists every
    # key with its default: only values that change the answers count).
    warnings = []
    if plant.get("kind", "linear") != "linear":
        warnings.append(f"[plant] kind = \"{plant['kind']}\"")
    if plant.get("specimen", "mr_damper") != "none":
        warnings.append(f"[plant] specimen = \"{plant.get('specimen', 'mr_damper')}\"")
    for key in ("noise_y_mm_rms", "noise_f_kN_rms"):
        if plant.get(key, 0):
            warnings.append(f"[plant] {key}")
    if any(plant.get("unmodelled", {}).values()):
        warnings.append("[plant.unmodelled]")
    if plant.get("effects"):
        warnings.append("[plant.effects]")
    return sha256, steps, dt_s, servo, Timing(doc.get("lockstep", {})), warnings


def main():
    ap = argparse.ArgumentParser(description="A plant participant for rths in Python (the linear servo of Eq. 30).")
    ap.add_argument("--lcm-url", required=True, help="the run's LCM URL, as rths run --external prints it")
    ap.add_argument("--run-id", required=True, type=int, help="the run id rths run printed")
    ap.add_argument("--scenario", required=True, help="the scenario file rths run printed (hashed, and read)")
    ap.add_argument("--steps", type=int, help="number of steps (default: round([run] duration_s / dt_s))")
    ap.add_argument("--dt", type=float, help="step [s] (default: [run] dt_s, else 0.0005)")
    ap.add_argument("--heartbeat-s", type=float, default=0.0,
                    help="send a HEARTBEAT every S seconds from HELLO until exit (0: none) [s]")
    ap.add_argument("--transport", choices=("auto", "lcm", "own"), default="auto",
                    help="auto: the lcm module if installed, else lcm_udpm.py; own: always lcm_udpm.py")
    a = ap.parse_args()
    if a.heartbeat_s < 0:
        ap.error("--heartbeat-s must be >= 0")
    try:
        sha256, n_steps, dt_s, (K, p, b, c), timing, warnings = read_scenario(a.scenario, a.steps, a.dt)
    except (OSError, ValueError, KeyError) as e:
        print(f"plant: cannot read the scenario {a.scenario}: {e}", file=sys.stderr)
        return 2
    if warnings:
        print("plant: warning: this example models only the linear servo with no specimen, noise or effects; "
              f"the scenario sets {', '.join(warnings)}: its answers will differ from the built-in plant's",
              file=sys.stderr)
    try:
        _, _, ttl = lcm_udpm.parse_udpm_url(a.lcm_url)  # the same URL rules for either transport
        lc, transport = open_lcm(a.lcm_url, a.transport)
    except (OSError, ValueError) as e:
        print(f"plant: {e}", file=sys.stderr)
        return 2
    # Our pid means something to the clock only on its host: ttl=0 guarantees that (as rths's own
    # participants decide). From another host, --heartbeat-s is how the clock sees us alive.
    announce_pid = ttl == 0
    if not announce_pid and a.heartbeat_s == 0:
        print("plant: note: with ttl > 0 the clock may be on another host; --heartbeat-s 0.2 lets it notice "
              "at once if this plant dies", file=sys.stderr)
    print(f"plant: {n_steps} steps of {dt_s:g} s, G(s) = {K:g} / ((s + {p:g})(s^2 + {b:g} s + {c:g})), "
          f"over {transport}", file=sys.stderr)
    plant = PlantParticipant(lc, a.run_id, n_steps, dt_s, sha256, LinearServo(K, p, b, c, dt_s), a.heartbeat_s,
                             announce_pid)

    def on_term(signum, frame):
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, on_term)
    try:
        code = plant.run(timing)
    except KeyboardInterrupt:
        plant.abort("stopped by a signal")
        code = plant.exit_code
    except Exception as e:  # our own failure: tell the others, then exit non-zero
        plant.abort(f"{type(e).__name__}: {e}")
        code = plant.exit_code
    return code


if __name__ == "__main__":
    sys.exit(main())
