"""Normal contact: FE condensation and active-set solve against Hertz and invariants."""
from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg as sla
from refcheck import check
from scipy import optimize

from contact_core import api, assembly, hertz, mesh, normal, report
from contact_core.condense import condense
from contact_core.spec import ContactSpec
from damper.cli import main as damper

F_SPHERE = 200.0
F_CYL = 350.0
#: Contact radius and peak pressure against Hertz (the goal was 2 %). Measured
#: on the 21-node grid: a -0.40 % (real), -0.43 % (half-space), -0.24 %
#: (dissimilar, 15 nodes); p0 within 0.05 %.
HERTZ_RTOL = 0.0065
#: Approach against Hertz's half-space a^2/R: finite bodies are stiffer
#: (references.md: 1-3 % for a real half-sphere); measured -1.95 % (real),
#: -1.57 % (half-space blocks).
APPROACH_RTOL = 0.03
#: k_n against 2 E* a: the same finite-body stiffening; measured +2.89 % (real),
#: +2.15 % (half-space).
KN_RTOL = 0.045
#: Cylinder mid-length against 2D (plane-strain) Hertz: a finite cylinder is
#: not in plane strain and its ends carry more than F/L (edge effect), and the
#: 15-node grid is coarse; measured -2.97 % (half-width) and -1.83 % (p0).
CYL_RTOL = 0.045
#: The edge pressure peak at the cylinder's ends is well above the mid-length
#: peak (thesis Fig. 9: ~3x on a fine grid; 1.76x measured on 15 nodes).
EDGE_PEAK_RATIO = 1.3
#: k_t / k_n of a stuck rigid patch on like half-spaces: 4 G*/E* = 2(1-nu)/(2-nu)
#: (Mindlin); the coarse 9-node grid and finite blocks give +1.38 % (measured).
KT_KN_RTOL = 0.021
#: Stiffness matrix against scikit-fem: same quadrature, so round-off only.
ASSEMBLY_RTOL = 1e-10
#: Seeds of the random LCP instances, written out.
LCP_SEEDS = (20261122, 31415926, 27182818)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["sphere_real", "sphere_halfspace"])
def test_sphere_matches_hertz(condensed, specs, name):
    cc = condensed(name)
    sol = normal.solve_force(cc, F_SPHERE)
    out = report.summarize(cc, sol, "sphere")
    ref = hertz.sphere(F_SPHERE, specs[name].radius, specs[name].Estar)
    case = f"sphere R = 10 mm, {F_SPHERE:g} N, {name.split('_')[1]} bodies, grid {specs[name].grid}"
    hz = "Hertz (Johnson 1985, ch. 4)"
    check(f"contact radius a [m], {case}", out["contact_radius"], ref["a"], rtol=HERTZ_RTOL, source=hz)
    check(f"peak pressure p0 [Pa], {case}", out["p_max"], ref["p0"], rtol=HERTZ_RTOL, source=hz)
    check(f"approach [m], {case}", out["approach"], ref["approach"], rtol=APPROACH_RTOL,
          source="Hertz half-space a^2/R (finite bodies are stiffer)")
    check(f"k_n [N/m], {case}", out["k_n"], 2 * specs[name].Estar * out["contact_radius"], rtol=KN_RTOL,
          source="Hertz k_n = 2 E* a")
    assert out["iterations"] >= 1 and not out["zone_edge_in_contact"]
    if name == "sphere_real":  # thesis 2.2.5: the sphere's own compression is < 8 %
        assert 0 < out["body1_share_far"] < 0.08


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_solution_is_in_equilibrium_without_tension_or_penetration(condensed):
    cc = condensed("sphere_real")
    sol = normal.solve_force(cc, F_SPHERE)
    tol = normal.GAP_RTOL * np.max(np.abs(cc.grid.h - sol.q[0]))
    assert np.sum(cc.grid.mult * sol.f) == pytest.approx(F_SPHERE, rel=normal.FORCE_RTOL)
    assert np.all(sol.f >= 0)                        # no tension
    assert np.all(sol.g >= -tol)                     # no penetration
    assert np.all(sol.f[~sol.active] == 0)
    assert np.all(np.abs(sol.g[sol.active]) <= tol)  # complementarity
    # the gap is the one of the data contract
    assert np.allclose(sol.g, cc.grid.h - cc.rigid @ sol.q + cc.Czz @ sol.f, atol=tol)


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_force_and_displacement_control_agree(condensed):
    cc = condensed("sphere_halfspace")
    sol_f = normal.solve_force(cc, 123.0)
    assert sol_f.newton >= 1
    sol_d = normal.solve_displacement(cc, sol_f.q[0])
    assert normal.resultants(cc, sol_d.f)[0] == pytest.approx(123.0, rel=1e-8)
    assert np.array_equal(sol_d.active, sol_f.active)


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_k_n_is_the_derivative_of_force_by_approach(condensed):
    cc = condensed("sphere_real")
    sol = normal.solve_force(cc, F_SPHERE)
    k_n = normal.tangent(cc, sol.active)[0, 0]
    d, eps = sol.q[0], 1e-7 * sol.q[0]
    Fp = normal.resultants(cc, normal.solve_displacement(cc, d + eps).f)[0]
    Fm = normal.resultants(cc, normal.solve_displacement(cc, d - eps).f)[0]
    assert (Fp - Fm) / (2 * eps) == pytest.approx(k_n, rel=1e-6)


@pytest.mark.slow
def test_cylinder_mid_length_matches_2d_hertz_with_edge_peak(condensed, specs):
    cc = condensed("cylinder_real")
    out = report.summarize(cc, normal.solve_force(cc, F_CYL), "cylinder")
    spec = specs["cylinder_real"]
    ref = hertz.cylinder(F_CYL, spec.length, spec.radius, spec.Estar)
    case = f"cylinder D = 5 mm, L = 1.2 mm, {F_CYL:g} N, mid-length, grid {spec.grid}"
    hz = "2D Hertz, plane strain (Johnson 1985, ch. 4)"
    check(f"contact half-width b [m], {case}", out["contact_halfwidth"], ref["b"], rtol=CYL_RTOL, source=hz)
    check(f"peak pressure p0 [Pa], {case}", out["p_mid_max"], ref["p0"], rtol=CYL_RTOL, source=hz)
    assert out["p_end_max"] > EDGE_PEAK_RATIO * out["p_mid_max"]
    assert out["contact_halfwidth_end"] >= out["contact_halfwidth_mid_extent"]  # widens (thesis Fig. 5)
    assert 0.2 < out["body1_share"] < 0.8
    # compression of the cylinder outside the contact (thesis 2.2.5: 25-40 %)
    assert 0.1 < out["body1_share_far"] < out["body1_share"]


def test_flat_face_meets_force_and_eccentricity(condensed, specs):
    cc = condensed("flat")
    width = specs["flat"].width
    for e in (0.0, 1e-4, 0.4 * width):
        sol = normal.solve_force(cc, 500.0, e)
        F, M = normal.resultants(cc, sol.f)
        assert F == pytest.approx(500.0, rel=1e-8)
        assert M == pytest.approx(500.0 * e, abs=1e-8 * 500.0 * width)
        if e:
            assert np.sign(sol.q[1]) == np.sign(e)  # the face tilts towards the resultant
    assert not sol.active.all()  # a large eccentricity lifts the heel of the face
    # the centred load is symmetric in x
    sol = normal.solve_force(cc, 500.0, 0.0)
    mirror = np.lexsort((cc.grid.y, -cc.grid.x))
    order = np.lexsort((cc.grid.y, cc.grid.x))
    assert np.allclose(sol.f[order], sol.f[mirror], rtol=1e-6, atol=1e-12 * sol.f.max())


def _random_lcp(seed, n=60):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    C = A @ A.T / n + 0.05 * np.eye(n)
    b = rng.standard_normal(n)
    return C, b


@pytest.mark.parametrize("seed", LCP_SEEDS)
def test_lcp_matches_nnls_oracle(seed):
    C, b = _random_lcp(seed)
    f, active, it = normal.lcp(C, b)
    # min 1/2 f'Cf + b'f, f >= 0  ==  min |L'f + L^-1 b|, f >= 0 with C = L L'
    L = np.linalg.cholesky(C)
    f_ref, _ = optimize.nnls(L.T, -sla.solve_triangular(L, b, lower=True))
    assert np.allclose(f, f_ref, atol=1e-9 * np.abs(f_ref).max())
    assert it >= 1 and np.all(f[~active] == 0) and np.all(f[active] > 0)


def test_lcp_reports_non_convergence():
    C, b = _random_lcp(LCP_SEEDS[0])
    with pytest.raises(RuntimeError, match="did not converge"):
        normal.lcp(C, b, P0=np.zeros(b.size, bool), max_iter=1)


def test_tangential_compliance_has_mindlin_stiffness_ratio(contact_cache):
    spec = ContactSpec(body="sphere", model="halfspace", grid=9)
    cc = condense(spec, directions=("x",), cache=contact_cache)
    assert cc.Cxx is not None and np.allclose(cc.Cxx, cc.Cxx.T)
    r = np.hypot(cc.grid.x, cc.grid.y)
    P = r < 0.55 * r.max()
    m = cc.grid.mult[P]
    k_n = m @ np.linalg.solve(cc.Czz[np.ix_(P, P)], np.ones(P.sum()))
    k_t = m @ np.linalg.solve(cc.Cxx[np.ix_(P, P)], np.ones(P.sum()))
    nu = spec.nu1
    check("k_t / k_n of a stuck patch, like half-space blocks, grid 9", k_t / k_n, 2 * (1 - nu) / (2 - nu),
          rtol=KT_KN_RTOL, source="Mindlin 1949: 2(1 - nu)/(2 - nu)")


def test_cache_returns_identical_results(contact_cache):
    spec = ContactSpec(body="sphere", model="halfspace", grid=5)
    first = condense(spec, cache=contact_cache)
    again = condense(spec, cache=contact_cache)
    assert again.meta["cache"]["hit"] and again.meta["cache"]["key"] == first.meta["cache"]["key"]
    assert again.meta["cache"]["hits"] == {"z": True} and first.meta["cache"]["hits"] == {"z": False}
    assert np.array_equal(first.Czz, again.Czz) and np.array_equal(first.grid.h, again.grid.h)
    fresh = condense(spec, cache=False)
    assert not fresh.meta["cache"]["hit"]
    assert np.allclose(fresh.Czz, first.Czz, rtol=1e-12, atol=0)
    other = condense(ContactSpec(body="sphere", model="halfspace", grid=5, E2=100e9), cache=contact_cache)
    assert other.meta["cache"]["key"] != first.meta["cache"]["key"]
    # another load case below the design pressure reuses the condensed model
    load_case = condense(ContactSpec(body="sphere", model="halfspace", grid=5, load_hint=150.0),
                         cache=contact_cache)
    assert load_case.meta["cache"]["hit"]


def test_scipy_fallback_equals_default_solver(monkeypatch):
    spec = ContactSpec(body="sphere", model="real", grid=5)
    default = condense(spec, cache=False)
    monkeypatch.setenv("DAMPER_SOLVER", "scipy")
    fallback = condense(spec, cache=False)
    assert fallback.meta["solver"] == "superlu"
    assert np.allclose(fallback.Czz, default.Czz, rtol=1e-9, atol=0)


def test_assembly_matches_scikit_fem():
    from skfem import Basis, ElementHex1, ElementVector, MeshHex, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    b1, _, _ = mesh.build(ContactSpec(body="sphere", model="real", grid=5))  # mapped, distorted
    K = assembly.stiffness(b1.p, b1.t, 210e9, 0.28)
    basis = Basis(MeshHex(b1.p, b1.t), ElementVector(ElementHex1()), intorder=3)
    K_ref = asm(linear_elasticity(*lame_parameters(210e9, 0.28)), basis)
    n = b1.p.shape[1]
    perm = np.empty(3 * n, dtype=int)
    perm[(3 * np.arange(n)[None, :] + np.arange(3)[:, None]).ravel()] = basis.nodal_dofs.ravel()
    diff = abs(K - K_ref[perm][:, perm]).max()
    assert diff <= ASSEMBLY_RTOL * abs(K).max()


def test_cli_json_has_the_interface_keys(tmp_path, capsys):
    rc = damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "200", "--grid", "5",
                 "--model", "halfspace", "--json", "--cache-dir", str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("force", "approach", "contact_area", "p_max", "p_mean", "k_n", "iterations",
                "n_contact_nodes", "contact_radius"):
        assert key in out and np.isfinite(out[key])
    assert out["force"] == pytest.approx(200.0, rel=1e-8)


BAD_INPUT = [
    ["--body", "sphere", "--radius", "0.01", "--force", "200", "--nu", "0.5"],
    ["--body", "sphere", "--radius", "0.01", "--force", "200", "--E", "0"],
    ["--body", "sphere", "--radius", "-0.01", "--force", "200"],
    ["--body", "sphere", "--radius", "0.01", "--force", "200", "--grid", "2"],
    ["--body", "sphere", "--radius", "0.01", "--force", "0"],
    ["--body", "sphere", "--radius", "0.01", "--force", "-5"],
    ["--body", "cylinder", "--diameter", "5e-3", "--force", "350"],
    ["--body", "flat", "--width", "1.2e-3", "--length", "5e-3", "--force", "500", "--eccentricity", "7e-4"],
    ["--body", "sphere", "--radius", "0.01", "--force", "200", "--E2", "-1"],
]


@pytest.mark.parametrize("argv", BAD_INPUT)
def test_bad_input_exits_2_with_a_message(argv, tmp_path, capsys):
    out_file = tmp_path / "r.json"
    rc = damper(["normal", *argv, "--no-cache", "--out", str(out_file)])
    assert rc == 2
    assert "error:" in capsys.readouterr().err
    assert not out_file.exists()


def test_run_normal_reports_hertz_errors(contact_cache):
    spec = ContactSpec(body="sphere", model="halfspace", grid=5)
    out = api.run_normal(spec, approach=4e-6, cache=contact_cache, curve_points=3)
    assert out["approach"] == 4e-6 and len(out["curve"]["force"]) == 3
    assert set(out["hertz"]) >= {"error_size", "error_p0", "error_approach", "error_k_n"}


def _export_pair(tmp_path, spec, suffix=".npz"):
    """Write a built-in pair in the bring-your-own format; return the CLI file args."""
    from contact_core import byo

    b1, b2, meta = mesh.build(spec)
    files = []
    for i, (body, E, nu) in enumerate(((b1, spec.E1, spec.nu1), (b2, spec.E2, spec.nu2)), start=1):
        K = assembly.stiffness(body.p, body.t, E, nu)
        files.append((tmp_path / f"K{i}{suffix}", tmp_path / f"nodes{i}.npz"))
        byo.export_body(body, K, *files[-1], symmetry=meta["symmetry"])
    return files


def test_bring_your_own_bodies_reproduce_the_built_in_model(tmp_path, contact_cache):
    from contact_core import byo

    spec = ContactSpec(body="sphere", model="real", grid=5)
    (k1, n1), (k2, n2) = _export_pair(tmp_path, spec, ".mtx")
    cc = byo.condense_bodies(byo.load_matrix(k1), byo.load_nodes(n1), byo.load_matrix(k2),
                             byo.load_nodes(n2), cache=False)
    ref = condense(spec, cache=contact_cache)
    assert np.allclose(cc.Czz, ref.Czz, rtol=1e-9, atol=0)
    assert np.allclose(cc.grid.h, ref.grid.h, rtol=0, atol=1e-15)
    assert np.allclose(cc.grid.area, ref.grid.area) and np.array_equal(cc.grid.mult, ref.grid.mult)
    rc = damper(["normal", "--body", "sphere", "--force", "150", "--json", "--stiffness", str(k1), str(k2),
                 "--nodes", str(n1), str(n2), "--cache-dir", str(tmp_path / "c")])
    assert rc == 0


def test_inconsistent_imported_matrices_exit_2(tmp_path, capsys):
    import scipy.sparse as sp

    from contact_core import byo

    spec = ContactSpec(body="sphere", model="halfspace", grid=3)
    (k1, n1), (k2, n2) = _export_pair(tmp_path, spec)
    K = byo.load_matrix(k1)
    bad = {"short": K[:-3, :-3], "asym": K + sp.csr_matrix(([1e3 * abs(K).max()], ([0], [1])), shape=K.shape)}
    for name, M in bad.items():
        path = tmp_path / f"{name}.npz"
        sp.save_npz(path, sp.csr_matrix(M))
        rc = damper(["normal", "--body", "sphere", "--force", "100", "--no-cache",
                     "--stiffness", str(path), str(k2), "--nodes", str(n1), str(n2)])
        assert rc == 2, name
    nodes = dict(np.load(n1))
    nodes["coords"] = nodes["coords"] + np.array([1e-4, 0, 0])  # contact nodes no longer coincide
    np.savez(tmp_path / "moved.npz", **nodes)
    rc = damper(["normal", "--body", "sphere", "--force", "100", "--no-cache",
                 "--stiffness", str(k1), str(k2), "--nodes", str(tmp_path / "moved.npz"), str(n2)])
    assert rc == 2
    assert "x-y" in capsys.readouterr().err


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_tiny_load_is_flagged_under_resolved_not_nan(condensed):
    cc = condensed("sphere_halfspace")
    out = report.summarize(cc, normal.solve_force(cc, 1e-3), "sphere")
    assert out["under_resolved"] and out["contact_size_method"] == "area"
    assert all(np.isfinite(v) for v in out.values() if isinstance(v, float))
    assert not report.summarize(cc, normal.solve_force(cc, F_SPHERE), "sphere")["under_resolved"]


#: FE half-space variant against the Boussinesq influence-coefficient model on
#: the same zone and grid (an independent computation): a and p0 agree to
#: 0.21 % and 0.056 % measured; the approach differs by the finite blocks.
BEM_RTOL = 0.0032


def test_fe_halfspace_agrees_with_boussinesq_model(condensed, specs):
    from contact_core import halfspace_bem

    fe = condensed("sphere_halfspace")
    bem = halfspace_bem.condense(specs["sphere_halfspace"], ("z",))
    out = [report.summarize(cc, normal.solve_force(cc, F_SPHERE), "sphere") for cc in (fe, bem)]
    assert out[0]["contact_radius"] == pytest.approx(out[1]["contact_radius"], rel=BEM_RTOL)
    assert out[0]["p_max"] == pytest.approx(out[1]["p_max"], rel=BEM_RTOL)
    assert out[0]["approach"] < out[1]["approach"]  # clamped finite blocks are stiffer


def test_superlu_schur_and_block_solves_agree(monkeypatch):
    """The SuperLU paths: Schur block of a nested-dissection factor vs unit-load solves."""
    from contact_core import linsolve
    from contact_core.condense import _fixed_dofs

    monkeypatch.setenv("DAMPER_SOLVER", "scipy")
    b1, _, _ = mesh.build(ContactSpec(body="sphere", model="real", grid=5))
    order_nodes = mesh.nd_order(b1.shape)
    assert np.array_equal(np.sort(order_nodes), np.arange(b1.p.shape[1]))  # a permutation
    K = assembly.stiffness(b1.p, b1.t, 200e9, 0.3)
    free = np.setdiff1d(np.arange(K.shape[0]), _fixed_dofs(b1, "z", "quarter"))
    local = np.full(K.shape[0], -1)
    local[free] = np.arange(free.size)
    dofs = local[3 * b1.contact + 2]
    order = local[(3 * order_nodes[:, None] + np.arange(3)).ravel()]
    Kff = K[free][:, free]
    C_schur = linsolve.compliance_block(Kff, dofs, order[order >= 0])
    C_solve = linsolve.compliance_block(Kff, dofs)
    assert np.allclose(C_schur, C_solve, rtol=1e-10, atol=0)


#: Body 1's share of the approach on two like half-space blocks is its share of
#: the compliance, lambda_1 / (lambda_1 + lambda_2), lambda = (1 - nu^2) / E
#: (Johnson eq. 4.22); 0.076 % measured, the blocks being mirror images.
SHARE_RTOL = 0.0012


@pytest.mark.slow
def test_dissimilar_materials_follow_hertz_with_e_star(contact_cache):
    E2, nu2, F = 70e9, 0.33, 400.0   # steel sphere on an aluminium block
    spec = ContactSpec(body="sphere", model="halfspace", grid=15, E2=E2, nu2=nu2)
    out = api.run_normal(spec, force=F, cache=contact_cache)
    ref = hertz.sphere(F, spec.radius, spec.Estar)
    assert out["contact_radius"] == pytest.approx(ref["a"], rel=HERTZ_RTOL)
    assert out["p_max"] == pytest.approx(ref["p0"], rel=HERTZ_RTOL)
    lam1, lam2 = (1 - spec.nu1**2) / spec.E1, (1 - nu2**2) / E2
    assert out["body1_share"] == pytest.approx(lam1 / (lam1 + lam2), rel=SHARE_RTOL)


def test_lcp_matches_nnls_on_a_boussinesq_like_kernel():
    """A smooth 1/r kernel (ill-conditioned like real compliances) on a 15 x 15 grid."""
    x, y = np.meshgrid(np.linspace(-1, 1, 15), np.linspace(-1, 1, 15))
    x, y = x.ravel(), y.ravel()
    dx = 2 / 14
    r = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    C = 1.0 / np.maximum(r, 0.4 * dx)            # self term ~ a cell's own influence
    b = (x**2 + y**2) / 2 - 0.3                   # h = r^2 / 2R - delta
    f, active, _ = normal.lcp(C, b)
    L = np.linalg.cholesky(C)
    f_ref, _ = optimize.nnls(L.T, -sla.solve_triangular(L, b, lower=True), maxiter=10 * b.size)
    assert np.allclose(f, f_ref, atol=1e-8 * f_ref.max())
    assert 0 < active.sum() < b.size


def test_imported_bodies_whose_contact_reaches_their_edge_are_refused(tmp_path, capsys):
    """Flat blocks (the half-space model's bodies: its curvature lives in the gap, not in the
    coordinates) make a flat punch in contact over every node: a result printed as the
    sphere's; refused as for generated bodies."""
    spec = ContactSpec(body="sphere", model="halfspace", grid=3)
    (k1, n1), (k2, n2) = _export_pair(tmp_path, spec)
    rc = damper(["normal", "--body", "sphere", "--force", "100", "--no-cache", "--json",
                 "--stiffness", str(k1), str(k2), "--nodes", str(n1), str(n2)])
    assert rc == 2 and "edge of the imported bodies' contact nodes" in capsys.readouterr().err
