function peer_nlvib(case_file, out_file, nlvib_dir)
% One benchmark curve by NLvib (GNU Octave or MATLAB); run by damper.bench.peers.
%
%   peer_nlvib(CASE.json, OUT.json, NLVIB_DIR)
%
% CASE.json: a benchmark case (harmonic_balance.bench_models.BenchCase.spec: M, K, C,
% force, links [a b k fs] 0-based with b = -1 for the ground, response_dof, harmonics,
% band) plus the peer's settings nti (AFT samples), ds0, ds_max and x0 ('stuck': the
% linear solution with the links stuck, NLvib's usual start; 'free': without them).
%
% How NLvib poses it: MechanicalSystem(M, C, K, links, force) with one
% 'elasticDryFriction' element (hysteretic Jenkins: stiffness k, friction limit force
% fs) per link on the force direction w = e_a - e_b; HB_residual (harmonics 0..H, N
% samples) continued by solve_and_continue (arc-length, tangent predictor) from the
% start to the end of the band.
%
% OUT.json: omega and a1 (first-harmonic amplitude of the response DOF) of every point,
% points, evaluations (Solinfo.FCtotal), solve_s (wall) and cpu_s of the continuation, error.
addpath(fullfile(nlvib_dir, 'SRC'));
addpath(fullfile(nlvib_dir, 'SRC', 'MechanicalSystems'));
s = jsondecode(fileread(case_file));
M = s.M; K = s.K; C = s.C; F = s.force(:);
n = size(M, 1);
L = s.links;
ne = cell(1, size(L, 1));
dK = zeros(n);
for i = 1:size(L, 1)
  w = zeros(n, 1);
  w(L(i, 1) + 1) = 1;
  if L(i, 2) >= 0
    w(L(i, 2) + 1) = -1;
  end
  ne{i} = struct('type', 'elasticDryFriction', 'stiffness', L(i, 3), ...
                 'friction_limit_force', L(i, 4), 'ishysteretic', true, 'force_direction', w);
  dK = dK + L(i, 3) * (w * w');
end
mech = MechanicalSystem(M, C, K, ne, F);
H = s.harmonics; N = s.nti; Om_s = s.band(1); Om_e = s.band(2);
if strcmp(s.x0, 'free')
  dK = 0 * dK;
end
Q1 = (-Om_s^2 * M + 1i * Om_s * C + K + dK) \ F;
x0 = zeros((2 * H + 1) * n, 1);
x0(n + (1:2 * n)) = [real(Q1); -imag(Q1)];
Sopt = struct('stepmax', 20000, 'dsmax', s.ds_max, 'dsmin', s.ds0 / 20, 'parametrization', 'arc_length');
Solopt = optimset('Display', 'off', 'Jacobian', 'on', 'MaxIter', 50, 'TolFun', 1e-10, 'TolX', 1e-10);
out = struct('omega', [], 'a1', [], 'points', 0, 'evaluations', [], 'error', '');
t0 = tic; c0 = cputime;
try
  [X, info] = solve_and_continue(x0, @(Y) HB_residual(Y, mech, H, N, 'frf'), Om_s, Om_e, s.ds0, ...
                                 Sopt, {}, Solopt);
  r = s.response_dof + 1;
  out.omega = X(end, :);
  out.a1 = hypot(X(r + n, :), X(r + 2 * n, :));
  out.points = size(X, 2);
  out.evaluations = info.FCtotal;
catch err
  out.error = err.message;
end
out.solve_s = toc(t0);
out.cpu_s = cputime - c0;
fid = fopen(out_file, 'w');
fputs(fid, jsonencode(out));
fclose(fid);
end
