function marths_independent(data_dir, record, compensator, seconds)
% An independent implementation of the maRTHS benchmark's loop, noise off, in GNU Octave, written
% from the equations of docs/marths.md without any of rths's code, for tests/studies/marths_octave_test.cpp
% to compare J1-J10 with (lib/studies/marths_loop.h). Where rths takes one formulation, this takes
% another: Rayleigh coefficients from the two damping equations solved directly; Newmark's average
% acceleration in its effective-stiffness form solved by backslash; the feedback frame's stiffness
% written from the frame's closed-form entries; the plant as four SISO transfer functions, each in
% its own phase-variable realisation, stepped by explicit RK4 stages; RoDeAC's algebraic loop by
% fixed-point iteration; finddelay through an FFT cross-correlation. Prints "key value" lines.
%
%   marths_independent(DATA_DIR, RECORD, COMPENSATOR, SECONDS)   (COMPENSATOR: none | rodeac; the
%   record's first SECONDS, Inf for all of it)
  dt = 1 / 1024;
  K = csvread(fullfile(data_dir, 'reference_K_N_per_m.csv'));
  M = csvread(fullfile(data_dir, 'reference_M_kg.csv'));
  n = rows(K);
  % Rayleigh: zeta = aM / (2 w) + aK w / 2 at both frequencies.
  w = [13.493; 165.125];
  ab = [1 ./ (2 * w), w / 2] \ [0.05; 0.05];
  C = ab(1) * M + ab(2) * K;
  l = zeros(n, 1);  l([13 26 27]) = 1;
  % The ideal physical bay (density 785e3 kg/m^3), DOFs 27, 29, 21.
  in = 0.0254;  E = 200e9;  Lb = 0.762;  Lc = 0.635;
  Ic = 2.52 * in^4;  Ib = 0.6132 * in^4;  Ac = 1.67 * in^2;  Ab = 0.947 * in^2;  rho = 785e3;
  a = E * Ic / Lc^2;  r = 3 * E * Ic / Lc + 4 * E * Ib / Lb;  c2 = 2 * E * Ib / Lb;
  Kp = [6 * E * Ic / Lc^3, -3 * a, -3 * a; -3 * a, r, -c2; -3 * a, -c2, r];
  mb = rho * Ab * Lb;  mc = rho * Ac * Lc;  J = mb / 2 * Lb^2 / 12 + mc / 2 * Lc^2 / 12;
  Mp = diag([mb + mc, J, J]);
  wp = sqrt(sort(eig(Kp, Mp)));
  abp = [1 ./ (2 * wp([1 3])), wp([1 3]) / 2] \ [0.05; 0.05];
  Cp = abp(1) * Mp + abp(2) * Kp;
  d = [27 29 21];
  Kn = K;  Kn(d, d) -= Kp;
  Cn = C;  Cn(d, d) -= Cp;
  Mn = M;  Mn(27, 27) -= Mp(1, 1);
  % The virtual specimen: 5-DOF frame [X, th1, th2, th3, th4], columns 0.64135 m at 0.7 I_c.
  Lc5 = 0.64135;  k = E * 0.7 * Ic / Lc5;  kb = E * 4.21372e-7 / Lb;  s = 6 * k / Lc5;
  K5 = [4 * s / Lc5, s, s, s, s;
        s, 4 * k + 4 * kb, 2 * kb, 0, 2 * k;
        s, 2 * kb, 4 * k + 4 * kb, 2 * k, 0;
        s, 0, 2 * k, 4 * k, 0;
        s, 2 * k, 0, 0, 4 * k];
  mb5 = 7850 * 7.56e-4 * Lb;  mc5 = 7850 * Ac * Lc5;
  M5 = 1.1 * diag([(mb5 + 2 * mc5) / 2, (mb5 / 2 * Lb^2 + mc5 / 2 * Lc5^2) / 3 * [1 1], mc5 / 2 * Lc5^2 / 3 * [1 1]]);
  [V, D] = eig(K5, M5);
  C5 = zeros(5);
  for i = 1:5
    wi = round(100 * sqrt(D(i, i))) / 100;
    v = V(:, i);
    C5 += M5 * v * v' * M5 * (2 * 0.05 * wi / (v' * M5 * v));
  end
  T = -K5(3:5, 3:5) \ K5(3:5, 1:2);
  % The coupler.
  dv = hypot(0.2667, 0.127);  al = 25.4633 * pi / 180;
  fwd = @(x, th) 1000 * [x + dv * (cos(th - al) - cos(al)); x + dv * (cos(th + al) - cos(al))];
  % The plant: Hij = k (s - z...) / ((s - p1)(s - p2)(s - pf)(s - conj pf)), every root in rad/s.
  tp = 2 * pi;  pf = (-50 + 63i) * tp;
  den1 = real(poly([-2.65 * tp, -40 * tp, pf, conj(pf)]));
  den2 = real(poly([-3.5 * tp, -18.5 * tp, pf, conj(pf)]));
  num = {2165.2 * poly([-120 * tp, -90 * tp]), 4.5394e6 * poly(-3 * tp); 349.95 * poly([-120 * tp, -90 * tp]), 1.9238e7 * poly(-5 * tp)};
  den = {den1, den2; den1, den2};
  sys = cell(2, 2);
  for i = 1:2
    for j = 1:2
      sys{i, j} = phase_variables(num{i, j}, den{i, j});
    end
  end
  % The record x 0.4, linear interpolation at t_k, zero after its end.
  g = dlmread(fullfile(data_dir, record), ' ', 1, 0);
  N = floor(min(seconds, g(end, 1)) / dt + 1e-9) + 1;
  ag = 0.4 * interp1(g(:, 1), g(:, 2), (0:N - 1)' * dt, 'linear', 0);
  % Newmark, average acceleration, effective-stiffness form.
  Kh = Kn + 4 / dt^2 * Mn + 2 / dt * Cn;
  Kr = K + 4 / dt^2 * M + 2 / dt * C;
  U = zeros(n, 3);  Ur = zeros(n, 3);          % [displacement, velocity, acceleration]
  x = cellfun(@(q) zeros(rows(q.A), 1), sys, 'UniformOutput', false);
  q1 = zeros(5, 1);  qd1 = zeros(5, 1);  started = false;
  if strcmp(compensator, 'rodeac')
    pr = strsplit(fileread(fullfile(data_dir, 'rodeac_initial_parameters.txt')), "\n");
    [th{1}, P{1}, th{2}, P{2}] = deal(0);
    for i = 1:numel(pr)
      f = strsplit(strtrim(pr{i}));
      if isempty(f{1}) || f{1}(1) == '#', continue; end
      v = str2double(f(2:end))';
      switch f{1}
        case 'theta0_1', th{1} = v;
        case 'theta0_2', th{2} = v;
        case 'P0_1', P{1} = reshape(v, 4, 4)';
        case 'P0_2', P{2} = reshape(v, 4, 4)';
      end
    end
    [bf, af] = butterworth4(20, 1 / dt);
    zy = {zeros(4, 1), zeros(4, 1)};  zu = zy;   % transposed direct form II states
    Tt = {zeros(4, 1), zeros(4, 1)};  Ph = Tt;
  end
  out = zeros(N, 18);
  for kk = 1:N
    y = [sys{1, 1}.C * x{1, 1} + sys{1, 2}.C * x{1, 2}; sys{2, 1}.C * x{2, 1} + sys{2, 2}.C * x{2, 2}];
    rr = (y(1) - y(2)) / 1000 / (2 * dv * sin(al));
    the = asin(rr);
    xe = y(1) / 1000 - dv * (cos(-al + rr) - cos(-al));
    q = [xe; the; T * [xe; the]];
    if started
      qd = (q - q1) / dt;  qdd = (qd - qd1) / dt;
    else
      qd = zeros(5, 1);  qdd = zeros(5, 1);  started = true;
    end
    fr = K5 * q + C5 * qd + M5 * qdd;
    q1 = q;  qd1 = qd;
    F = zeros(n, 1);  F(27) = fr(1);  F(21) = -fr(2);  F(29) = -fr(3);
    U = newmark(U, Kh, Mn, Cn, -Mn * l * ag(kk) - F, dt);
    Ur = newmark(Ur, Kr, M, C, -M * l * ag(kk), dt);
    xt = fwd(U(27, 1), -U(21, 1));
    u = xt;
    if strcmp(compensator, 'rodeac')
      for i = 1:2
        [yf, zy{i}] = filter(bf, af, y(i), zy{i});
        Tt{i} = [xt(i); Tt{i}(1:3)];  Ph{i} = [yf; Ph{i}(1:3)];
        Kg = P{i} * Ph{i} / (1 + Ph{i}' * P{i} * Ph{i});
        ui = Tt{i}' * th{i};
        for it = 1:200                               % the algebraic loop, iterated to its fixed point
          uf = filter(bf, af, ui, zu{i});
          tn = th{i} + Kg * (uf - Ph{i}' * th{i});
          un = Tt{i}' * tn;
          if abs(un - ui) <= 1e-15 * max(1, abs(un)), ui = un; break; end
          ui = un;
        end
        [uf, zu{i}] = filter(bf, af, ui, zu{i});
        th{i} = th{i} + Kg * (uf - Ph{i}' * th{i});
        P{i} = P{i} - Kg * Ph{i}' * P{i};
        u(i) = ui;
      end
    end
    for i = 1:2
      for j = 1:2
        x{i, j} = rk4(sys{i, j}, x{i, j}, u(j), dt);
      end
    end
    out(kk, :) = [xt', y', 1000 * xe, the, 1000 * U(27, 1), -U(21, 1), 1000 * Ur(27, 1), -Ur(21, 1), ...
                  U(26, 1), U(22, 1), U(13, 1), U(3, 1), Ur(26, 1), Ur(22, 1), Ur(13, 1), Ur(3, 1)];
  end
  sd = @(a, b) 100 * std(a - b) / std(b);
  mx = @(a, b) 100 * max(abs(a - b)) / max(abs(b));
  o = @(c) out(:, c);
  printf('J1_1_ms %.17g\nJ1_2_ms %.17g\n', delay(o(1), o(3)) * dt * 1000, delay(o(2), o(4)) * dt * 1000);
  printf('J2_1_pct %.17g\nJ2_2_pct %.17g\n', sd(o(3), o(1)), sd(o(4), o(2)));
  printf('J3_1_pct %.17g\nJ3_2_pct %.17g\n', mx(o(3), o(1)), mx(o(4), o(2)));
  printf('J5_X_pct %.17g\nJ5_TH_pct %.17g\n', sd(o(5), o(7)), sd(o(6), o(8)));
  printf('J6_X_pct %.17g\nJ6_TH_pct %.17g\n', mx(o(5), o(7)), mx(o(6), o(8)));
  printf('J7_X_pct %.17g\nJ7_TH_pct %.17g\n', sd(o(5), o(9)), sd(o(6), o(10)));
  printf('J8_X2_pct %.17g\nJ8_TH2_pct %.17g\n', sd(o(11), o(15)), sd(o(12), o(16)));
  printf('J8_X3_pct %.17g\nJ8_TH3_pct %.17g\n', sd(o(13), o(17)), sd(o(14), o(18)));
  printf('J9_X_pct %.17g\nJ9_TH_pct %.17g\n', mx(o(5), o(9)), mx(o(6), o(10)));
  printf('J10_X2_pct %.17g\nJ10_TH2_pct %.17g\n', mx(o(11), o(15)), mx(o(12), o(16)));
  printf('J10_X3_pct %.17g\nJ10_TH3_pct %.17g\n', mx(o(13), o(17)), mx(o(14), o(18)));
end

function s = phase_variables(num, den)
  % x' = A x + B u, y = C x for num(s)/den(s), den monic of degree m, num of lower degree.
  m = numel(den) - 1;
  s.A = [zeros(m - 1, 1), eye(m - 1); -fliplr(den(2:end))];
  s.B = [zeros(m - 1, 1); 1];
  s.C = [fliplr(num), zeros(1, m - numel(num))];
end

function x = rk4(s, x, u, h)
  f = @(z) s.A * z + s.B * u;
  k1 = f(x);  k2 = f(x + h / 2 * k1);  k3 = f(x + h / 2 * k2);  k4 = f(x + h * k3);
  x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
end

function U = newmark(U, Kh, M, C, p, dt)
  u0 = U(:, 1);  v0 = U(:, 2);  a0 = U(:, 3);
  u1 = Kh \ (p + M * (4 / dt^2 * u0 + 4 / dt * v0 + a0) + C * (2 / dt * u0 + v0));
  v1 = 2 / dt * (u1 - u0) - v0;
  a1 = 4 / dt^2 * (u1 - u0) - 4 / dt * v0 - a0;
  U = [u1, v1, a1];
end

function d = delay(x, y)
  % The lag d maximising |sum x(n) y(n + d)|, ties to the smaller |d| then the positive one.
  L = 2^nextpow2(2 * numel(x));
  c = real(ifft(conj(fft(x, L)) .* fft(y, L)));
  lags = [0:numel(x) - 1, -(numel(x) - 1):-1];
  c = abs(c([1:numel(x), L - numel(x) + 2:L]));
  best = max(c);
  cand = lags(c >= best * (1 - 1e-12));
  [~, i] = min(abs(cand) - 0.5 * (cand > 0));
  d = cand(i);
end

function [b, a] = butterworth4(fc, fs)
  % 4th-order Butterworth low-pass by the bilinear transform with the cutoff prewarped.
  wc = 2 * fs * tan(pi * fc / fs);
  p = wc * exp(1i * pi * (2 * (1:4) + 4 - 1) / 8);      % the analog poles in the left half plane
  zd = (1 + p / (2 * fs)) ./ (1 - p / (2 * fs));
  a = real(poly(zd));
  b = poly(-ones(1, 4));
  b = b * sum(a) / sum(b);                                % unit gain at DC
end
