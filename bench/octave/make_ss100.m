## make_ss100.m -- writes bench/data/ss100.txt, the 100-state lightly damped system shared by
## bench/lti_bench.cpp and bench/octave/lti_bench.m. Run from the repository root:
##     octave --no-gui --quiet bench/octave/make_ss100.m
## 50 modes: natural frequencies log-uniform in [10 Hz, 5 kHz], damping ratios uniform in
## [0.1 %, 2 %], in real 2x2 modal blocks, made dense by a random orthogonal similarity; one input,
## one output, random B and C, D = 0. Fixed seed (Mersenne twister state 20240101): rerunning
## writes the same file with this Octave version.
##
## File format (plain text, numbers with %.17g): line 1 "states inputs outputs", then the rows of
## A, B, C and D, one matrix row per line.
1;
rand ("twister", 20240101);
randn ("twister", 20240101);
nm = 50; n = 2 * nm;
fn = 10 .^ (log10 (10) + (log10 (5000) - log10 (10)) * rand (nm, 1));
zeta = 0.001 + (0.02 - 0.001) * rand (nm, 1);
A = zeros (n);
for k = 1:nm
  wn = 2 * pi * fn(k);
  sg = -zeta(k) * wn; wd = wn * sqrt (1 - zeta(k)^2);
  A(2*k-1:2*k, 2*k-1:2*k) = [sg, wd; -wd, sg];
endfor
[Q, R] = qr (randn (n));
Q = Q * diag (sign (diag (R)));
A = Q * A * Q.';
B = randn (n, 1);
C = randn (1, n);
D = 0;
fid = fopen ("bench/data/ss100.txt", "w");
fprintf (fid, "%d %d %d\n", n, 1, 1);
for M = {A, B, C, D}
  X = M{1};
  for i = 1:rows (X)
    fprintf (fid, "%s\n", strjoin (arrayfun (@(v) sprintf ("%.17g", v), X(i, :), "UniformOutput", false), " "));
  endfor
endfor
fclose (fid);
printf ("wrote bench/data/ss100.txt: %d states, damping %.4f..%.4f, %.1f..%.1f Hz\n", n, min (zeta), max (zeta), min (fn), max (fn));
