function s = rths_run_summary(matfile)
% RTHS_RUN_SUMMARY  Load a file written by `rths export` (MATLAB v5 or v7.3) and summarise the run.
%
%   s = rths_run_summary('runs/test1/export.mat')
%
% Returns a struct with the run's steps, dt_s, duration_s, the Eq. 31 tracking error
% sqrt(sum((r - y).^2) / sum(r.^2)) * 100 [%] (as `rths run` prints it), the peak damper force [kN]
% and the peak displacement [mm]; prints them. Works in MATLAB and GNU Octave (docs/export.md).
% A plot of the tracking: plot(d.rths.signals.t_s, [d.rths.signals.r_mm, d.rths.signals.y_mm])
  d = load(matfile);
  r = d.rths;
  g = r.signals;
  s.steps = numel(g.k);
  s.dt_s = r.meta.dt_s;
  s.duration_s = s.steps * s.dt_s;
  s.tracking_nrmse_pct = sqrt(sum((g.r_mm - g.y_mm).^2) / sum(g.r_mm.^2)) * 100;
  s.peak_force_kN = max(abs(g.f_kN));
  s.peak_displacement_mm = max(abs(g.y_mm));
  % char(): GNU Octave reads the strings of a v7.3 file as uint16 codes.
  status = char(r.meta.status);
  fprintf('%s: %d steps of %g s (%s)\n', matfile, s.steps, s.dt_s, status);
  fprintf('  tracking error     %.3f %% (RMS, Eq. 31)\n', s.tracking_nrmse_pct);
  fprintf('  peak damper force  %.2f %s\n', s.peak_force_kN, char(r.units.f_kN));
  fprintf('  peak displacement  %.3f %s\n', s.peak_displacement_mm, char(r.units.y_mm));
end
