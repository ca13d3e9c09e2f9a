function text = rths_lti_toml(cnum, cden, tnum, tden, domain, discretisation)
% RTHS_LTI_TOML  The [controller] lines of an rths scenario for u = C (T r - y) (docs/controllers.md).
%
%   rths_lti_toml(cnum, cden)                        C only (T = 1), continuous (s), Tustin
%   rths_lti_toml(cnum, cden, tnum, tden)            C and T, continuous (s)
%   rths_lti_toml(cnum, cden, tnum, tden, 'z')       already discrete at the run's dt
%   rths_lti_toml(cnum, cden, tnum, tden, 's', 'zoh')
%   text = rths_lti_toml(...)                        returns the text instead of printing it
%
% Coefficients in descending powers, as tf() and tfdata() hold them: with the Control System
% Toolbox, [cnum, cden] = tfdata(c2d(tf(C), dt, 'tustin'), 'v') gives the 'z' form. Pass [] for a
% transfer function you leave out (it is 1). Every digit is kept (%.17g). Paste the lines into the
% scenario (they replace its [controller] table). Works in MATLAB and GNU Octave, no toolbox needed.
  if nargin < 3, tnum = []; end
  if nargin < 4, tden = []; end
  if nargin < 5 || isempty(domain), domain = 's'; end
  if nargin < 6 || isempty(discretisation), discretisation = 'tustin'; end
  if ~any(strcmp(domain, {'s', 'z'})), error('rths_lti_toml: domain must be ''s'' or ''z'''); end
  if ~any(strcmp(discretisation, {'tustin', 'zoh'})), error('rths_lti_toml: discretisation must be ''tustin'' or ''zoh'''); end
  lines = {'[controller]', 'kind = "lti"', '', '[controller.lti]'};
  lines{end + 1} = tf_line('feedback', cnum, cden);
  lines{end + 1} = tf_line('reference', tnum, tden);
  lines{end + 1} = sprintf('domain = "%s"', domain);
  lines{end + 1} = sprintf('discretisation = "%s"', discretisation);
  lines = lines(~cellfun(@isempty, lines) | (1:numel(lines)) == 3);
  out = sprintf('%s\n', lines{:});
  if nargout > 0
    text = out;
  else
    fprintf('%s', out);
  end
end

function s = tf_line(name, num, den)
  if isempty(num) && isempty(den)
    s = '';  % left out: 1
    return
  end
  if isempty(num) || isempty(den), error('rths_lti_toml: %s needs both num and den', name); end
  s = sprintf('%s = { num = %s, den = %s }', name, vec(num), vec(den));
end

function s = vec(v)
  parts = arrayfun(@(x) sprintf('%.17g', x), v(:)', 'UniformOutput', false);
  s = ['[', strjoin(parts, ', '), ']'];
end
