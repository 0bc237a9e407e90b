% Peer of bench/ident_vf_bench.cpp (BM_VectorFit20Poles2000Points5Iterations) in GNU Octave: the
% same data (10 lightly damped pairs from 10 Hz to 1 kHz, constant term 0.1, 2000 log-spaced points
% from 3.2 Hz to 3.2 kHz), 20 log-spaced starting poles with 1 % damping, exactly 5 relocations of
% relaxed vector fitting with a constant term, then the residues.
%
% vectfit3.m (Gustavsen's reference implementation) is not distributed with Octave or Debian, so
% this script implements the same steps the way vectfit3 does them: frequencies scaled by the
% highest one, a real basis for complex pairs, per relocation one economy QR per output of
% [A, -H A_sigma] keeping the sigma block R22 (the "fast" form), the relaxed normalization row,
% column scaling and backslash for the small stacked problem, the zeros of sigma as eig(A - b c/d)
% with unstable ones flipped, and a final least-squares solve for the residues.
%
%   octave --no-gui --quiet bench/ident_vf_octave.m
% prints the median (wall clock and CPU time) and minimum of 7 runs (after one warm-up) and the
% largest relative error of the fitted poles (round-off level: the data are exactly rational).
1;

function [poles, res, d] = vf_relaxed(s, f, poles, iterations)
  ns = numel(s);
  n = numel(poles);
  for it = 1:iterations
    phi = basis(s, poles);
    left = [phi, ones(ns, 1)];                 % partial fractions + d
    sig = [phi, ones(ns, 1)];                  % sigma: partial fractions + its constant
    a = [left, -f .* sig];
    a = [real(a); imag(a)];
    [~, r] = qr(a, 0);
    nl = columns(left);
    r22 = r(nl + 1:end, nl + 1:end);
    scale = norm(f) / ns;
    constraint = scale * real(sum(sig, 1));
    m = [r22; constraint];
    rhs = [zeros(rows(r22), 1); ns * scale];
    colscale = 1 ./ sqrt(sum(m .^ 2, 1));
    x = (m .* colscale) \ rhs;
    x = x(:) .* colscale(:);
    c = x(1:n).';
    dsig = x(n + 1);
    [lam, b] = realization(poles);
    z = eig(lam - b * c / dsig);
    z(real(z) > 0) = -conj(z(real(z) > 0));
    poles = canonical(z);
  end
  phi = basis(s, poles);
  a = [phi, ones(ns, 1)];
  a = [real(a); imag(a)];
  x = a \ [real(f); imag(f)];
  res = zeros(n, 1);
  k = 1;
  while k <= n
    if imag(poles(k)) == 0
      res(k) = x(k); k = k + 1;
    else
      res(k) = x(k) + 1i * x(k + 1); res(k + 1) = conj(res(k)); k = k + 2;
    end
  end
  d = x(n + 1);
end

function phi = basis(s, poles)
  n = numel(poles);
  phi = zeros(numel(s), n);
  k = 1;
  while k <= n
    p = poles(k);
    if imag(p) == 0
      phi(:, k) = 1 ./ (s - p); k = k + 1;
    else
      a = 1 ./ (s - p); b = 1 ./ (s - conj(p));
      phi(:, k) = a + b; phi(:, k + 1) = 1i * (a - b); k = k + 2;
    end
  end
end

function [lam, b] = realization(poles)
  n = numel(poles);
  lam = zeros(n); b = zeros(n, 1);
  k = 1;
  while k <= n
    p = poles(k);
    if imag(p) == 0
      lam(k, k) = real(p); b(k) = 1; k = k + 1;
    else
      lam(k:k + 1, k:k + 1) = [real(p), imag(p); -imag(p), real(p)]; b(k) = 2; k = k + 2;
    end
  end
end

function p = canonical(z)
  re = sort(real(z(imag(z) == 0)));
  up = z(imag(z) > 0);
  [~, i] = sort(imag(up));
  up = up(i);
  p = zeros(numel(re) + 2 * numel(up), 1);
  p(1:numel(re)) = re;
  k = numel(re) + 1;
  for j = 1:numel(up)
    p(k) = up(j); p(k + 1) = conj(up(j)); k = k + 2;
  end
end

two_pi = 2 * pi;
n_poles = 20; n_points = 2000;
true_poles = zeros(n_poles, 1); true_res = zeros(n_poles, 1);
for i = 0:n_poles / 2 - 1
  wn = two_pi * 10 * 100 ^ (i / (n_poles / 2 - 1));
  zeta = 0.01 + 0.002 * i;
  p = -zeta * wn + 1i * wn * sqrt(1 - zeta ^ 2);
  true_poles(2 * i + 1) = p; true_poles(2 * i + 2) = conj(p);
  true_res(2 * i + 1) = (1 + i + 0.3i * i) * wn; true_res(2 * i + 2) = conj(true_res(2 * i + 1));
end
k = (0:n_points - 1).';
omega = two_pi * 10 .^ (0.5 + 3 * k / (n_points - 1));
f = 0.1 + sum(true_res.' ./ (1i * omega - true_poles.'), 2);

scale = omega(end);
s = 1i * omega / scale;
beta = omega(1) * (omega(end) / omega(1)) .^ ((0:n_poles / 2 - 1).' / (n_poles / 2 - 1));
start = zeros(n_poles, 1);
start(1:2:end) = -0.01 * beta + 1i * beta;
start(2:2:end) = conj(start(1:2:end));
start = start / scale;

times = zeros(7, 1);
cpu = zeros(7, 1);
[poles, res, d] = vf_relaxed(s, f, start, 5);  % warm-up
for r = 1:numel(times)
  c0 = cputime();
  t0 = tic;
  [poles, res, d] = vf_relaxed(s, f, start, 5);
  times(r) = toc(t0);
  cpu(r) = cputime() - c0;
end
poles = poles * scale;
err = 0;
for j = 1:n_poles
  err = max(err, min(abs(poles(j) - true_poles)) / abs(true_poles(j)));
end
printf('vector fitting, 20 poles, 2000 points, 5 relocations (Octave %s): median %.1f ms (CPU %.1f ms), min %.1f ms\n', ...
       version(), 1e3 * median(times), 1e3 * median(cpu), 1e3 * min(times));
printf('largest relative pole error %.2e, d = %.12g\n', err, d);
