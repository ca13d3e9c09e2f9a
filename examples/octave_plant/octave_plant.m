function code = octave_plant(lcm_url, run_id, scenario_path, varargin)
% OCTAVE_PLANT  An rths plant participant in GNU Octave (or MATLAB), over LCM's Java classes.
%
%   code = octave_plant(lcm_url, run_id, scenario_path)
%   code = octave_plant(lcm_url, run_id, scenario_path, 'heartbeat_s', 0.5, 'codec', 'octave', ...
%                       'types_jar', 'build/rths_lcmtypes.jar', 'lcm_jar', '/usr/share/java/lcm.jar')
%
% Plays the role "plant" of docs/participant.md: the linear servohydraulic actuator of Phillips &
% Spencer 2013, Eq. 30, G(s) = K / ((s + p)(s^2 + b s + c)), discretised with a zero-order hold
% at the run's dt, and no specimen (force 0). The scenario must say [plant] kind = "linear",
% specimen = "none" (actuator: a preset of Eqs. 28-30 or an inline {K, p, b, c} table).
%
%   lcm_url        the URL `rths run --external plant` prints (e.g. 'udpm://239.255.76.67:34121?ttl=0')
%   run_id         the printed run id, AS A STRING (a 63-bit integer does not fit in a double), or int64
%   scenario_path  the printed scenario file: its SHA-256 goes into HELLO, and [run] duration_s,
%                  [run] dt_s, [plant] and [lockstep] are read from it
%   'heartbeat_s'  send a HEARTBEAT (handshake phase 8) every S seconds from HELLO on (default 0: none)
%   'codec'        'java' (default): every message through the lcm-gen classes, as MATLAB users do;
%                  'octave': command_t, current_t and measured_t read and written by byte position
%                  (checked against the classes at start), about 15 % less time per step
%   'types_jar'    the lcm-gen --java types (default: build/rths_lcmtypes.jar of this source tree)
%   'lcm_jar'      LCM's Java classes (default: Debian's liblcm-java, /usr/share/java/lcm.jar)
%
% Returns the exit code of docs/lockstep.md: 0 the run completed; 2 bad arguments or a scenario this
% plant does not implement (it says so in an ABORT); 3 the clock fell silent; 4 another participant
% (or the supervisor) aborted the run; 5 this plant failed (it sends ABORT with the reason). From a
% shell, pass it on to the process:
%
%   octave-cli --no-init-file --eval "addpath('examples/octave_plant'); exit(octave_plant('<lcm_url>', '<run_id>', '<scenario>'))"
%   matlab -batch "addpath('examples/octave_plant'); exit(octave_plant('<lcm_url>', '<run_id>', '<scenario>'))"
%
% Protocol (docs/lockstep.md, docs/participant.md; the same steps as examples/java_plant/JavaPlant.java):
% HELLO on the clock's REQUEST (with the scenario's SHA-256, n_steps, dt and, on a ttl=0 URL, our
% pid); start on GO, or on the clock's first desired_t or repair_t if GO was lost; measured_t 0 at
% rest; measured_t k from command_t k-1 and current_t k-1; the bytes of the last four answers kept
% and re-sent unchanged when a repair_t wants them; what we lack asked for when the clock
% re-requests a step; BYE on every DONE, return on CLOSE (or after a short linger); HEARTBEATs if
% asked for; an ABORT naming the clock when it has been silent too long.
%
% Octave/MATLAB notes, each of which costs time if ignored (README.md has the measurements):
%  - Java long fields come back as doubles: exact for k, not for run_id. So run_id is compared on
%    the raw bytes (bytes 9..16 of every rths message, after the 8-byte fingerprint) and set from
%    an int64, which Octave hands to Java exactly.
%  - Pass Java int/long arguments as int32/int64: with doubles Octave's method lookup is ~5x slower.
%  - In Octave, `lcm.lcm.LCM(...)` would call Octave's lcm() (least common multiple): use javaObject.
%  - Octave cannot set a Java byte field (handshake_t.phase), and hands a 1-element vector to a Java
%    array field as an empty array (repair_t.want_*): see send_handshake and on_repair.
%  - isequal() and swapbytes() are m-files in Octave, 10x dearer than all(a == b) and indexing.

  code = 2;
  if nargin < 3
    fprintf(2, ['usage: octave_plant(lcm_url, run_id, scenario_path [, ''heartbeat_s'', S, ', ...
                '''codec'', ''java''|''octave'', ''types_jar'', JAR, ''lcm_jar'', JAR])\n']);
    return;
  end
  here = fileparts(mfilename('fullpath'));
  opt = struct('heartbeat_s', 0, 'codec', 'java', 'lcm_jar', '/usr/share/java/lcm.jar', ...
               'types_jar', fullfile(here, '..', '..', 'build', 'rths_lcmtypes.jar'));
  for i = 1:2:numel(varargin)
    name = lower(varargin{i});
    if ~isfield(opt, name) || i + 1 > numel(varargin)
      fprintf(2, 'octave_plant: unknown or incomplete option "%s"\n', varargin{i});
      return;
    end
    opt.(name) = varargin{i + 1};
  end
  if ~any(strcmp(opt.codec, {'java', 'octave'}))
    fprintf(2, 'octave_plant: codec must be ''java'' or ''octave'' (got "%s")\n', opt.codec);
    return;
  end
  [rid, ok] = parse_run_id(run_id);
  if ~ok
    fprintf(2, 'octave_plant: run_id must be an integer given as a string or int64 (got "%s")\n', ...
            num2str(run_id));
    return;
  end
  for jar = {opt.lcm_jar, opt.types_jar}
    if ~exist(jar{1}, 'file')
      fprintf(2, ['octave_plant: %s not found (Debian: apt-get install liblcm-java; the types jar ', ...
                  'is made by the rths build or lcm-gen --java)\n'], jar{1});
      return;
    end
    if ~any(strcmp(javaclasspath('-dynamic'), jar{1})), javaaddpath(jar{1}); end
  end
  if ~exist(scenario_path, 'file')
    fprintf(2, 'octave_plant: scenario %s not found\n', scenario_path);
    return;
  end

  % Everything the handshake and the steps need, in one struct P passed through the local functions.
  P = struct();
  P.run_id = rid;                                   % int64, exact
  P.rid_bytes = big_endian(rid);                    % the same, as the 8 bytes of the wire format
  P.sha256 = sha256_of_file(scenario_path);
  try
    [sc, why] = read_scenario(scenario_path);
  catch err
    fprintf(2, 'octave_plant: %s: %s\n', scenario_path, err.message);
    return;  % code 2
  end
  P.n_steps = sc.n_steps;
  P.dt_s = sc.dt_s;
  P.heartbeat_s = opt.heartbeat_s;
  % Our pid lets the clock watch this process, but only on its own host: a URL with ttl=0 (LCM's
  % default) keeps us there. From another host, give 'heartbeat_s' instead (docs/participant.md).
  P.pid = int32(process_id() * isempty(regexp(lcm_url, 'ttl=0*[1-9]', 'once')));

  P.lc = javaObject('lcm.lcm.LCM', {lcm_url});      % {url}: the constructor is LCM(String... urls)
  P.enc_bytes = javaObject('java.io.ByteArrayOutputStream');
  P.enc_stream = javaObject('java.io.DataOutputStream', P.enc_bytes);
  if ~isempty(why)
    % We cannot play this scenario: say so to the run (the clock is in its handshake) and stop.
    fprintf(2, 'octave_plant: %s\n', why);
    send_handshake(P, 4, -1, ['plant (octave_plant): ', why]);
    P.lc.close();
    return;  % code 2
  end

  % Eq. 30 (or Eqs. 28-29), ZOH-discretised at dt: z_{k+1} = Phi z_k + Gamma u_k, y_k = z_k(1).
  [P.Phi, P.Gamma] = servo_zoh(sc.K, sc.p, sc.b, sc.c, P.dt_s);
  P.z = zeros(3, 1);                                % [y mm; y' mm/s; y'' mm/s^2], at rest
  % Inputs held until used, in rings of 4 indexed by mod(k, 4) (only command_t/current_t next-1
  % can be pending: command_t k needs our measured_t k): the step k each slot holds, and the value.
  P.cmd_k = -ones(1, 4);  P.cmd_u_mm = zeros(1, 4);
  P.cur_k = -ones(1, 4);  P.cur_i_A = zeros(1, 4);
  % Our last four answers, as the exact bytes we published (re-sent unchanged on a repair_t).
  P.cache = cell(1, 4);   P.cache_k = -ones(1, 4);
  P.meas = javaObject('rths.measured_t');           % reused: filled and encoded once per step
  P.meas.run_id = rid;
  P.meas.f_kN = 0;                                  % no specimen: the load cell reads 0 kN
  % The per-step messages (command_t, current_t in, measured_t out) through the lcm-gen classes
  % ('java', as MATLAB users do), or read and written by byte position ('octave', faster).
  P.java_codec = ~strcmp(opt.codec, 'octave');
  P.meas.k = int64(0);  P.meas.y_mm = 0;  P.meas.current_A = 0;
  head = encode(P, P.meas);
  P.meas_head = head(1:16)';                        % fingerprint + run_id of measured_t
  P.fp_command = fingerprint(P, 'rths.command_t');
  P.fp_current = fingerprint(P, 'rths.current_t');
  if ~P.java_codec && ~codec_matches(P)
    why = 'the ''octave'' codec does not match this rths_lcmtypes.jar (use ''codec'', ''java'')';
    fprintf(2, 'octave_plant: %s\n', why);
    send_handshake(P, 4, -1, ['plant (octave_plant): ', why]);
    P.lc.close();
    code = 5;
    return;
  end
  P.next = 0;                                       % the next measured_t k to publish
  P.running = false;
  P.done = false;
  P.code = -1;                                      % set when the loop should end

  P.agg = javaObject('lcm.lcm.MessageAggregator');
  channels = {'RTHS_HANDSHAKE', 'RTHS_DESIRED', 'RTHS_COMMAND', 'RTHS_CURRENT', 'RTHS_REPAIR'};
  for c = channels
    P.lc.subscribe(c{1}, P.agg);
  end
  P.listening_desired = true;                       % RTHS_DESIRED only matters until we start

  % Give up on a silent clock after stall_budget_s + 2 s, or, before its first REQUEST, after the
  % handshake timeout; wait for CLOSE after BYE as rths does (docs/participant.md, "The handshake").
  watchdog_s = sc.stall_budget_s + 2;
  linger_s = min(sc.stall_budget_s, max(0.5, 10 * sc.rerequest_ms / 1000));
  P.heard_request = false;
  P.t0 = tic;
  P.last_heard_s = 0;
  P.next_beat_s = inf;                              % first HEARTBEAT: heartbeat_s after the first HELLO
  done_since_s = -1;
  wait_ms = int64(10);
  try
    while P.code < 0
      msg = P.agg.getNextMessage(wait_ms);          % [] after wait_ms without a message
      if ~isempty(msg)
        channel = char(msg.channel);
        data = msg.data;                            % int8 column: the fingerprint, then the fields
        % Every rths type starts with int64 run_id: bytes 9..16 (big-endian) tell our run's
        % messages from others'. (all(a == b): isequal() is an m-file, 10x dearer.)
        if numel(data) >= 16 && all(data(9:16) == P.rid_bytes)
          % command_t and current_t, the two messages of every step, are handled here rather than
          % in a function: in Octave a function call that updates P costs 10-20 us. The first copy
          % of each also shows that the clock is alive: command_t and current_t k exist only
          % because it published desired_t k (we stop listening to RTHS_DESIRED once we run).
          switch channel
            case 'RTHS_COMMAND'
              k = -Inf;                             % stays so for a message that is not ours
              if P.java_codec
                try
                  c = javaObject('rths.command_t', data);
                  k = double(c.k);                  % (MATLAB returns a Java long as int64)
                  u_mm = c.u_mm;
                catch                               % another version of command_t: ignored
                end
              elseif all(data(1:8) == P.fp_command)
                k = double(typecast(data(24:-1:17), 'int64'));  % bytes 17-24: k (big-endian)
                u_mm = typecast(data(32:-1:25), 'double');      % bytes 25-32: u_mm
              end
              s = mod(k, 4) + 1;
              if k >= P.next - 1 && k <= P.next + 2 && P.cmd_k(s) ~= k  % first copy wins; old steps ignored
                P.last_heard_s = toc(P.t0);
                P.cmd_k(s) = k;
                P.cmd_u_mm(s) = u_mm;
              end
            case 'RTHS_CURRENT'
              k = -Inf;
              if P.java_codec
                try
                  c = javaObject('rths.current_t', data);
                  k = double(c.k);                  % (MATLAB returns a Java long as int64)
                  i_A = c.i_cmd_A;
                catch
                end
              elseif all(data(1:8) == P.fp_current)
                k = double(typecast(data(24:-1:17), 'int64'));  % bytes 17-24: k
                i_A = typecast(data(32:-1:25), 'double');       % bytes 25-32: i_cmd_A
              end
              s = mod(k, 4) + 1;
              if k >= P.next - 1 && k <= P.next + 2 && P.cur_k(s) ~= k
                P.last_heard_s = toc(P.t0);
                P.cur_k(s) = k;
                P.cur_i_A(s) = i_A;
              end
            otherwise
              P = on_message(P, channel, data);     % RTHS_HANDSHAKE, RTHS_DESIRED, RTHS_REPAIR
          end
          % measured_t next from command_t next-1 (u, mm) and current_t next-1 (i, A), held over
          % [t_{next-1}, t_next) (zero-order hold), as soon as both are in.
          while P.running && P.next < P.n_steps
            s = mod(P.next - 1, 4) + 1;
            if P.cmd_k(s) ~= P.next - 1 || P.cur_k(s) ~= P.next - 1, break; end
            P.z = P.Phi * P.z + P.Gamma * P.cmd_u_mm(s);  % Eq. 30, ZOH
            P = publish_measured(P, P.next, P.cur_i_A(s));
            P.next = P.next + 1;
          end
        end
      end
      now_s = toc(P.t0);
      if now_s >= P.next_beat_s
        send_handshake(P, 8, -1, '');
        P.next_beat_s = P.next_beat_s + P.heartbeat_s;
      end
      if P.done && done_since_s < 0, done_since_s = now_s; end
      if P.code < 0 && done_since_s >= 0 && now_s - done_since_s > linger_s
        P.code = 0;                                 % CLOSE was lost: the run is over anyway
      end
      silent_s = now_s - P.last_heard_s;
      if P.code < 0 && done_since_s < 0 && ((P.heard_request && silent_s > watchdog_s) || ...
                                            (~P.heard_request && silent_s > sc.handshake_timeout_s))
        reason = sprintf('plant (octave_plant): the clock (integrator) has been silent for %.0f s', silent_s);
        fprintf(2, 'octave_plant: %s; giving up\n', reason);
        send_handshake(P, 4, max(P.next - 1, -1), reason);  % k: the step being run, -1 before step 0
        P.code = 3;
      end
    end
  catch err
    % Our own failure (a publish that failed, a bug): tell the run why, then stop with 5.
    reason = sprintf('plant (octave_plant) failed at step %d: %s', max(P.next - 1, -1), err.message);
    fprintf(2, 'octave_plant: %s\n', reason);
    try
      send_handshake(P, 4, max(P.next - 1, -1), reason);
    catch
    end
    P.code = 5;
  end
  P.lc.close();
  code = P.code;
end

% ---------------------------------------------------------------------------------------------
% Messages

function P = on_message(P, channel, data)
% A message of our run on the other channels (the step messages are handled in the main loop).
  switch channel
    case 'RTHS_HANDSHAKE'
      try
        h = javaObject('rths.handshake_t', data);
      catch
        return;                                         % a bad message: ignore it
      end
      P = on_handshake(P, h);
    case 'RTHS_DESIRED'
      P.last_heard_s = toc(P.t0);
      if ~P.done, P = start(P); end                   % the clock is stepping: GO was lost
    case 'RTHS_REPAIR'
      try
        r = javaObject('rths.repair_t', data);
      catch
        return;
      end
      P = on_repair(P, r);
  end
end

function P = start(P)
% GO (or the first sign of a running clock): measured_t 0, the actuator at rest.
  if P.running || P.done, return; end
  P.running = true;
  P = publish_measured(P, 0, 0);
  P.next = 1;
  if P.listening_desired
    P.lc.unsubscribe('RTHS_DESIRED', P.agg);         % its only use was the implicit GO
    P.listening_desired = false;
  end
end

function P = publish_measured(P, k, current_A)
% measured_t k: y_k = z(1) [mm], f_k = 0 [kN], the damper current held over the step [A]. Encoded
% once; the bytes are cached for repairs and published.
  if P.java_codec
    P.meas.k = int64(k);
    P.meas.y_mm = P.z(1);
    P.meas.current_A = current_A;
    bytes = encode(P, P.meas);
  else
    bytes = encode_measured(P.meas_head, k, P.z(1), current_A);
  end
  s = mod(k, 4) + 1;
  P.cache{s} = bytes;
  P.cache_k(s) = k;
  P.lc.publish('RTHS_MEASURED', bytes, int32(0), int32(numel(bytes)));
end

function bytes = encode_measured(head, k, y_mm, current_A)
% The 'octave' codec: measured_t's wire format written directly (lcmtypes/measured_t.lcm): head =
% fingerprint and run_id (16 bytes, taken from a Java encoding), then k (int64), y_mm, f_kN = 0,
% current_A (doubles), each big-endian, then n_act = 0 and n_iface = 0 (int32: one actuator, no
% arrays). Checked against msg.encode() at start (codec_matches).
  % (x86/ARM hosts are little-endian: reversing the bytes of typecast() gives big-endian; reversing
  % the 24 bytes of [current_A, f, y_mm] gives y_mm, f, current_A each big-endian. swapbytes() would
  % do the same, but costs 60 us a call in Octave.)
  kb = typecast(int64(k), 'int8');
  vb = typecast([current_A, 0, y_mm], 'int8');
  bytes = [head, kb(8:-1:1), vb(24:-1:1), zeros(1, 8, 'int8')];
end

function ok = codec_matches(P)
% The 'octave' codec reads and writes bytes by position: prove it against the lcm-gen classes in
% use (a changed type, or a big-endian host, stops here instead of corrupting the run).
  P.meas.k = int64(123456789);  P.meas.y_mm = pi;  P.meas.current_A = 0.5;
  ok = isequal(encode(P, P.meas)', encode_measured(P.meas_head, 123456789, pi, 0.5));
  c = javaObject('rths.command_t');
  c.run_id = P.run_id;  c.k = int64(987654321);  c.u_mm = -exp(1);  c.n_adapt = int32(0);  c.n_act = int32(0);
  b = encode(P, c);
  ok = ok && all(b(1:8) == P.fp_command) && typecast(b(24:-1:17), 'int64') == 987654321 && ...
       typecast(b(32:-1:25), 'double') == -exp(1);
  c = javaObject('rths.current_t');
  c.run_id = P.run_id;  c.k = int64(55);  c.i_cmd_A = 1.25;
  b = encode(P, c);
  ok = ok && all(b(1:8) == P.fp_current) && typecast(b(24:-1:17), 'int64') == 55 && ...
       typecast(b(32:-1:25), 'double') == 1.25;
end

function P = on_handshake(P, h)
  who = char(h.participant);
  if strcmp(who, 'plant'), return; end               % our own, looped back
  phase = double(h.phase);
  if phase == 4                                       % ABORT, from anyone
    fprintf(2, 'octave_plant: %s aborted the run: %s\n', who, char(h.reason));
    P.code = 4;
    return;
  end
  if ~strcmp(who, 'integrator'), return; end
  P.last_heard_s = toc(P.t0);
  switch phase
    case 1                                            % REQUEST -> HELLO
      P.heard_request = true;
      if ~P.running && ~P.done
        send_handshake(P, 2, -1, '');
        if P.heartbeat_s > 0 && isinf(P.next_beat_s)
          P.next_beat_s = toc(P.t0) + P.heartbeat_s;
        end
      end
    case 3                                            % GO
      P = start(P);
    case 5                                            % DONE -> BYE (again for every repeated DONE)
      P.done = true;
      P.running = false;
      send_handshake(P, 6, h.k, '');
    case 7                                            % CLOSE
      if P.done, P.code = 0; end
  end
end

function P = on_repair(P, r)
  who = char(r.participant);
  if strcmp(who, 'plant'), return; end
  n = double(r.n_want);
  if n > 0
    channel = r.want_channel;                         % int8: 3 = RTHS_MEASURED
    want_k = r.want_k;
    for i = 1:n
      k = double(want_k(i));
      if channel(i) ~= 3 || k < 0, continue; end
      s = mod(k, 4) + 1;
      if P.cache_k(s) == k
        send(P, 'RTHS_MEASURED', P.cache{s});          % byte for byte, never recomputed
      end
    end
  end
  if ~strcmp(who, 'integrator'), return; end
  P.last_heard_s = toc(P.t0);
  if ~P.done, P = start(P); end
  % The clock re-requests step k; its barrier holds measured_t k and k+1 (docs/lockstep.md,
  % "Repair", 3). If the next measured_t we owe is one of those, say which of its inputs we lack.
  k = double(r.k);
  if ~P.running || P.next > k + 1 || P.next >= P.n_steps, return; end
  s = mod(P.next - 1, 4) + 1;
  lack = [];
  if P.cmd_k(s) ~= P.next - 1, lack(end + 1) = 2; end  % command_t next-1
  if P.cur_k(s) ~= P.next - 1, lack(end + 1) = 4; end  % current_t next-1
  if isempty(lack), return; end
  out = javaObject('rths.repair_t');
  out.run_id = P.run_id;
  out.k = int64(k);
  out.participant = 'plant';
  out.n_want = int32(numel(lack));
  % Octave passes a 1-element vector to a Java array field as an empty array: give two elements
  % always; encode() writes the first n_want of them.
  want_channel = int8([0, 0]);  want_channel(1:numel(lack)) = lack;
  want_k = int64([0, 0]);       want_k(1:numel(lack)) = P.next - 1;
  out.want_channel = want_channel;
  out.want_k = want_k;
  send(P, 'RTHS_REPAIR', encode(P, out));
end

function send_handshake(P, phase, k, reason)
% phase: 2 HELLO, 4 ABORT, 6 BYE, 8 HEARTBEAT. ABORT goes out in three copies (docs/lockstep.md).
  h = javaObject('rths.handshake_t');
  h.run_id = P.run_id;
  h.participant = 'plant';
  h.scenario_sha256 = P.sha256;
  h.n_steps = int64(P.n_steps);
  h.dt_s = P.dt_s;
  h.k = int64(k);
  h.n_roster = int32(0);
  h.reason = reason;
  if phase == 2
    h.pid = int32(P.pid);                            % the clock's host watches this process
    h.heartbeat_s = P.heartbeat_s;                   % 0: we send no HEARTBEATs
  else
    h.pid = int32(0);
    h.heartbeat_s = 0;
  end
  bytes = encode(P, h);
  % Octave cannot set a Java byte field (h.phase = int8(2) fails with "null value"), so `phase` is
  % written into the encoded bytes: fingerprint (8 bytes), run_id (8), then phase, byte 17.
  % (MATLAB can set h.phase = int8(phase) before encoding; the result is the same bytes.)
  bytes(17) = int8(phase);
  copies = 1 + 2 * (phase == 4);
  for i = 1:copies
    send(P, 'RTHS_HANDSHAKE', bytes);
  end
end

function fp = fingerprint(P, class_name)
% The 8-byte LCM fingerprint that starts every encoded message of this type.
  m = javaObject(class_name);
  m.run_id = int64(0);
  b = encode(P, m);
  fp = b(1:8);
end

function bytes = encode(P, msg)
% The LCM wire bytes of an lcm-gen message (fingerprint + fields), as JavaPlant.encode makes them.
  P.enc_bytes.reset();
  msg.encode(P.enc_stream);
  bytes = P.enc_bytes.toByteArray();                 % int8 column in Octave
end

function send(P, channel, bytes)
% publish(String, byte[], int offset, int length); an IOException becomes an Octave error.
  P.lc.publish(channel, bytes, int32(0), int32(numel(bytes)));
end

% ---------------------------------------------------------------------------------------------
% The model

function [Phi, Gamma] = servo_zoh(K, p, b, c, dt_s)
% G(s) = K / ((s + p)(s^2 + b s + c)) in phase variables z = [y; y'; y''] (lib/models/servo_linear.h):
% z' = A z + B u, y = z(1); ZOH: Phi = e^{A dt}, Gamma = int_0^dt e^{A s} ds B, from one exponential of
% the augmented matrix [[A, B], [0, 0]] dt (Van Loan), taken as rths does in the balanced basis
% D z with D = diag(1, 1/w, 1/w^2), w = d0^(1/3) (every entry then has the size of a pole).
  d2 = p + b;  d1 = p * b + c;  d0 = p * c;          % (s + p)(s^2 + b s + c) = s^3 + d2 s^2 + d1 s + d0
  A = [0, 1, 0; 0, 0, 1; -d0, -d1, -d2];             % [1/s], [1/s^2], [1/s^3]
  B = [0; 0; K];                                     % [1/s^3]
  w = nthroot(d0, 3);
  D = diag([1, 1 / w, 1 / w^2]);
  E = expm([D * A / D, D * B; zeros(1, 4)] * dt_s);
  Phi = D \ E(1:3, 1:3) * D;
  Gamma = D \ E(1:3, 4);
end

% ---------------------------------------------------------------------------------------------
% The scenario file

function [sc, why] = read_scenario(path)
% The keys this plant needs, from a TOML scenario (docs/scenarios.md), defaults as documented. A
% small reader: [section] headers and `key = value` lines (strings, numbers, inline tables), which
% is what scenario files and the scenario.toml that `rths run` writes use.
  t = toml_flat(fileread(path));
  sc.dt_s = toml_number(t, 'run.dt_s', 0.0005);
  duration_s = toml_number(t, 'run.duration_s', 20.0);
  sc.n_steps = round(duration_s / sc.dt_s);
  sc.stall_budget_s = toml_number(t, 'lockstep.stall_budget_s', 10.0);
  sc.rerequest_ms = toml_number(t, 'lockstep.rerequest_ms', 100.0);
  sc.handshake_timeout_s = toml_number(t, 'lockstep.handshake_timeout_s', 20.0);
  kind = toml_string(t, 'plant.kind', 'linear');
  specimen = toml_string(t, 'plant.specimen', 'mr_damper');
  actuator = toml_value(t, 'plant.actuator', '"avg"');
  % The paper's identified servo models: Eq. 28 (0.0 A), Eq. 29 (2.5 A), Eq. 30 (average).
  why = '';
  m = [];
  switch strrep(actuator, '"', '')
    case '0.0A', m = [1.730e7, 182.7, 225.3, 9.499e4];   % K [1/s^3], p [1/s], b [1/s], c [1/s^2]
    case '2.5A', m = [1.613e7, 134.2, 324.6, 1.211e5];
    case 'avg',  m = [1.600e7, 151.7, 250.4, 1.061e5];
    otherwise
      if actuator(1) == '{'                              % inline table {K = ..., p = ..., b = ..., c = ...}
        v = regexp(actuator, '(\w+)\s*=\s*([^,}\s]+)', 'tokens');
        f = struct();
        for i = 1:numel(v), f.(v{i}{1}) = str2double(v{i}{2}); end
        if all(isfield(f, {'K', 'p', 'b', 'c'})), m = [f.K, f.p, f.b, f.c]; end
      end
  end
  if isempty(m)
    why = sprintf('plant.actuator = %s is not a servo model this plant knows', actuator);
    m = [1.600e7, 151.7, 250.4, 1.061e5];
  end
  sc.K = m(1); sc.p = m(2); sc.b = m(3); sc.c = m(4);
  noise = toml_number(t, 'plant.noise_y_mm_rms', 0) + toml_number(t, 'plant.noise_f_kN_rms', 0);
  effects = any(strncmp(keys(t), 'plant.effects.', 14)) || any(strncmp(keys(t), 'plant.unmodelled', 16));
  if ~strcmp(kind, 'linear') || ~strcmp(specimen, 'none')
    why = sprintf('this plant implements [plant] kind = "linear", specimen = "none" (the scenario has "%s", "%s")', ...
                  kind, specimen);
  elseif noise ~= 0 || effects
    why = 'this plant implements no sensor noise and no rig effects ([plant] noise_*, [plant.effects.*])';
  elseif ~(sc.n_steps >= 1) || ~(sc.dt_s > 0)
    why = sprintf('run.duration_s = %g and run.dt_s = %g give no steps', duration_s, sc.dt_s);
  end
end

function t = toml_flat(text)
% TOML text -> containers.Map from 'section.key' to the raw value text (a section alone maps
% 'section.' to '', so that its presence can be seen).
  t = containers.Map();
  section = '';
  lines = regexp(text, '\r?\n', 'split');
  for i = 1:numel(lines)
    line = strip_comment(lines{i});
    if isempty(line), continue; end
    h = regexp(line, '^\[\s*([^\]]+?)\s*\]$', 'tokens', 'once');
    if ~isempty(h)
      section = h{1};
      t([section, '.']) = '';
      continue;
    end
    kv = regexp(line, '^([A-Za-z0-9_-]+)\s*=\s*(.+)$', 'tokens', 'once');
    if ~isempty(kv)
      t([section, '.', kv{1}]) = strtrim(kv{2});
    end
  end
end

function line = strip_comment(line)
% Drops a # comment outside double quotes, and surrounding blanks.
  quoted = false;
  for i = 1:numel(line)
    if line(i) == '"'
      quoted = ~quoted;
    elseif line(i) == '#' && ~quoted
      line = line(1:i - 1);
      break;
    end
  end
  line = strtrim(line);
end

function v = toml_value(t, key, default)
  if isKey(t, key), v = t(key); else, v = default; end
end

function v = toml_number(t, key, default)
  raw = toml_value(t, key, '');
  if isempty(raw), v = default; return; end
  v = str2double(strrep(raw, '_', ''));
  if isnan(v), error('scenario key %s = %s is not a number', key, raw); end
end

function v = toml_string(t, key, default)
  v = strrep(toml_value(t, key, ['"', default, '"']), '"', '');
end

% ---------------------------------------------------------------------------------------------
% Small helpers that differ between Octave and MATLAB

function [v, ok] = parse_run_id(x)
% The run id as an exact int64. A string is parsed digit by digit in int64 (str2double would round
% a 19-digit id to the nearest double, and the clock would ignore us).
  ok = false;
  v = int64(0);
  if isinteger(x)
    v = int64(x); ok = true; return;
  end
  if isnumeric(x)
    ok = isscalar(x) && x == round(x) && abs(x) <= flintmax;
    if ok, v = int64(x); end
    return;
  end
  s = strtrim(char(x));
  if isempty(regexp(s, '^-?[0-9]{1,19}$', 'once')), return; end
  for ch = s(s ~= '-')
    v = v * int64(10) + int64(ch - '0');
  end
  if s(1) == '-', v = -v; end
  ok = strcmp(sprintf('%d', v), s);                   % false if it overflowed int64
end

function b = big_endian(v)
% An int64 as its 8 wire bytes (LCM is big-endian), int8 column like the payloads from Java.
  [~, ~, endian] = computer();
  u = typecast(v, 'int8');
  if endian == 'L', u = u(end:-1:1); end             % little-endian host (x86, ARM)
  b = u(:);
end

function hex = sha256_of_file(path)
% Hex SHA-256 of the file's bytes (what the clock compares). Octave has hash(); MATLAB uses Java.
  fid = fopen(path, 'r');
  bytes = fread(fid, Inf, '*uint8');
  fclose(fid);
  if exist('OCTAVE_VERSION', 'builtin')
    hex = hash('sha256', char(bytes'));
  else
    md = java.security.MessageDigest.getInstance('SHA-256');
    d = typecast(int8(md.digest(typecast(bytes, 'int8'))), 'uint8');
    hex = lower(reshape(dec2hex(d, 2)', 1, []));
  end
end

function pid = process_id()
  if exist('OCTAVE_VERSION', 'builtin')
    pid = getpid();
  else
    pid = feature('getpid');                           % MATLAB
  end
end
