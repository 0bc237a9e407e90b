## lti_bench.m -- the Octave side of bench/lti_bench.cpp (same jobs, same data). From the repo root:
##     octave --no-gui --quiet bench/octave/lti_bench.m
## (a) frequency response of the 100-state system of bench/data/ss100.txt (make_ss100.m) at 10,000
##     log-spaced frequencies 2 pi [1 Hz, 10 kHz] with the control package's freqresp (dense solve
##     per frequency after prescaling);
## (b) root locus of the report's IFF loop L = -K0 G (eqs. 2.3 and 2.4, g = 1) with rlocus(L)'s
##     automatic gain grid (polynomial roots at each gain, adaptive refinement), and the maximum
##     damping of the 95 Hz branch found as in scripts/fixtures/make_lti_fixtures.m (log grid of
##     gains with nearest-pole tracking, then fminbnd) -- Octave has no built-in for the latter.
## Each job is run `reps` times; the minimum and the median wall-clock times are printed.
1;
pkg load control
reps = 5;
p = pkg ("list", "control");
printf ("tool: GNU Octave %s, control %s\n", OCTAVE_VERSION, p{1}.version);

function [A, B, C, D] = read_ss (file)
  fid = fopen (file, "r");
  dims = fscanf (fid, "%d", 3);
  n = dims(1); m = dims(2); q = dims(3);
  A = fscanf (fid, "%g", [n, n]).';
  B = fscanf (fid, "%g", [m, n]).';
  C = fscanf (fid, "%g", [n, q]).';
  D = fscanf (fid, "%g", [m, q]).';
  fclose (fid);
endfunction

function report (label, t)
  printf ("%-40s min %10.3f ms   median %10.3f ms   (%d runs)\n", label, 1e3 * min (t), 1e3 * median (t), numel (t));
endfunction

## (a)
[A, B, C, D] = read_ss ("bench/data/ss100.txt");
sys = ss (A, B, C, D);
w = logspace (log10 (2*pi*1), log10 (2*pi*1e4), 10000);
t = zeros (reps, 1);
for r = 1:reps
  tic; H = freqresp (sys, w); t(r) = toc;
endfor
report ("freqresp ss100 x 10000", t);
printf ("  check: |H| at w(1), w(5000), w(10000) = %.12g %.12g %.12g\n", abs (H(1, 1, 1)), abs (H(1, 1, 5000)), abs (H(1, 1, 10000)));

## (b)
g0 = 0.64; wz = 2*pi*42.7; xz = 0.004; wp = 2*pi*95.2; xp = 0.02; w_hpf = 2*pi*0.4;
G = tf (g0 * conv ([1/wz^2, 2*xz/wz, 1], [1, 0]), conv ([1/wp^2, 2*xp/wp, 1], [1, w_hpf]));
K0 = tf ([-10, 0], conv (conv ([1, 2*pi*2], [1, 2*pi*20]), [1, 2*pi*2000]));
L = -K0 * G;
t = zeros (reps, 1);
for r = 1:reps
  tic; [rldata, kb, rlpol, gvec] = rlocus (L); t(r) = toc;
endfor
report ("rlocus(L) automatic gains", t);
printf ("  gains: %d, from %g to %g\n", numel (gvec), min (gvec), max (gvec));

Lss = ss (L);
[aL, bL, cL] = ssdata (Lss);
function p = nearest_pole (ps, target)
  [~, j] = min (abs (ps - target));
  p = ps(j);
endfunction
## -damping of the branch pole nearest `target` at gain g (one eig per evaluation).
function v = minus_damping (aL, bL, cL, g, target)
  p = nearest_pole (eig (aL - g * bL * cL), target);
  v = real (p) / abs (p);
endfunction
function [gopt, zopt] = max_damping (aL, bL, cL, start)
  ggrid = logspace (0, 7, 2001);
  branch = start; zb = zeros (size (ggrid)); bp = zeros (size (ggrid));
  for k = 1:numel (ggrid)
    branch = nearest_pole (eig (aL - ggrid(k) * bL * cL), branch);
    bp(k) = branch; zb(k) = -real (branch) / abs (branch);
  endfor
  [~, kb] = max (zb);
  f = @(lg) minus_damping (aL, bL, cL, 10^lg, bp(kb));
  [lg, fo] = fminbnd (f, log10 (ggrid(kb - 1)), log10 (ggrid(kb + 1)), optimset ("TolX", 1e-10));
  gopt = 10^lg; zopt = -fo;
endfunction
pL = pole (Lss);
[~, i0] = min (abs (pL - (-xp*wp + 1i*wp*sqrt (1 - xp^2))));
t = zeros (reps, 1);
for r = 1:reps
  tic; [gopt, zopt] = max_damping (aL, bL, cL, pL(i0)); t(r) = toc;
endfor
report ("max damping on the 95 Hz branch", t);
printf ("  optimum: damping %.9f at g = %.6g\n", zopt, gopt);
