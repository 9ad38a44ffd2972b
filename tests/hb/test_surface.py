"""The contact surface (harmonic_balance.surface) against the contact core's own solves.

The same condensed bodies, mesh and mu: the quasi-static hysteresis loop of the
surface (node-to-node 3D contact points on the condensed faces, penalty contact)
against the contact core's direct cyclic stick/slip solve
(``contact_core.tangential_curve.hysteresis_loop``), and the flat face under an
eccentric normal load against ``contact_core.normal.solve_force``.
"""
from __future__ import annotations

import numpy as np
import pytest

from contact_core import normal
from contact_core import tangential_curve as tc
from contact_core.condense import condense
from contact_core.spec import ContactSpec
from contact_core.tangential import TangentialProblem
from harmonic_balance import surface as sf
from harmonic_balance import surface_static as ss

#: Acceptance bound on loop energy, k_t and force amplitude against the contact
#: core (the penalty sf.PENALTY leaves ~1e-4; the bound leaves room for the steps).
LOOP_RTOL = 0.01
#: Acceptance bound on the eccentric contact length and pressure distribution
#: (pressure error relative to the peak pressure; measured ~3e-5).
PRESSURE_RTOL = 0.02
#: Load steps per leg of the surface loop (the friction work is exact for the
#: straight paths between steps; 30 kept it within 2e-4 of the core).
STEPS = 30
#: Finite-difference step relative to the displacement scale, and the Jacobian
#: agreement it allows (piecewise-linear laws: exact away from a kink).
FD_STEP, FD_RTOL = 1e-7, 1e-5
MU = 0.5
CASES = {
    "cylinder": (ContactSpec(body="cylinder", radius=2.5e-3, length=1.2e-3, model="real", grid=15),
                 100.0, None),
    "flat": (ContactSpec(body="flat", width=1.2e-3, length=5e-3, grid=9), 500.0, None),
}
#: Flat face W = 1.2 mm: e2 (whole face in contact) and e6 (part lifts), shares of W/2.
ECCENTRIC = {"e2": 0.2 * 0.6e-3, "e6": 0.65 * 0.6e-3}


@pytest.fixture(scope="module")
def condensed(tmp_path_factory):
    cache = tmp_path_factory.mktemp("surface_cache")
    built = {}

    def get(name):
        if name not in built:
            built[name] = condense(CASES[name][0], directions=("z", "x", "y"), cache=cache)
        return built[name]

    return get


@pytest.mark.parametrize("name", ["cylinder", "flat"])
def test_surface_loop_matches_contact_core_cyclic_solve(condensed, name):
    cc = condensed(name)
    force = CASES[name][1]
    core = TangentialProblem(cc, normal.solve_force(cc, force).f, MU)
    a = 0.7 * core.gross_slip_displacement(core.initial_state())
    _, ref = tc.hysteresis_loop(core, a)
    surface = sf.build(cc, MU)
    state = ss.preload(surface, force)
    _, got = ss.hysteresis_loop(surface, state, a, steps=STEPS)
    assert ss.stuck_stiffness(surface, state) == pytest.approx(core.k_t, rel=LOOP_RTOL)
    assert got["W_friction"] == pytest.approx(ref["W_friction"], rel=LOOP_RTOL)
    assert got["T_amplitude"] == pytest.approx(ref["T_amplitude"], rel=LOOP_RTOL)
    assert ref["W_friction"] > 0.0   # the loop is open: part of the surface slips


def test_surface_slip_starts_at_the_edges_of_the_cylinder(condensed):
    cc = condensed("cylinder")
    surface = sf.build(cc, MU)
    state = ss.preload(surface, 100.0)
    core = TangentialProblem(cc, normal.solve_force(cc, 100.0).f, MU)
    path = ss.tangential_path(surface, state, [0.3 * core.gross_slip_displacement(core.initial_state())])
    x = path.state.x
    w_x = x[0:3 * surface.n:3]
    slip = np.abs(w_x - w_x[np.argmin(np.abs(cc.grid.x) + np.abs(cc.grid.y))]) > 1e-3 * np.abs(w_x).max()
    edge = np.abs(cc.grid.x) >= 0.999 * np.abs(cc.grid.x[surface.normal_forces(x) > 0]).max()
    on = surface.normal_forces(x) > 0
    assert slip[on & edge].any() and not slip[on & (np.abs(cc.grid.x) < 1e-12)].any()


@pytest.mark.parametrize("case", sorted(ECCENTRIC))
def test_eccentric_flat_matches_contact_core_length_and_pressure(condensed, case):
    cc = condensed("flat")
    e, force = ECCENTRIC[case], 500.0
    ref = normal.solve_force(cc, force, e)
    surface = sf.build(cc, MU)
    f = surface.normal_forces(ss.preload(surface, force, e).x)
    p_ref, p = ref.f / cc.grid.area, f / cc.grid.area
    assert np.max(np.abs(p - p_ref)) <= PRESSURE_RTOL * p_ref.max()
    row = np.flatnonzero(np.abs(cc.grid.y) < 1e-12)
    row = row[np.argsort(cc.grid.x[row])]

    def length(forces):  # contact length along x on the mid row: segments in contact at both ends
        on = forces[row] > 0
        return float(np.sum(np.diff(cc.grid.x[row])[on[:-1] & on[1:]]))

    assert length(f) == pytest.approx(length(ref.f), rel=PRESSURE_RTOL)
    assert (ref.f > 0).sum() < cc.n if case == "e6" else (ref.f > 0).all()


def test_surface_jacobian_matches_finite_differences(condensed):
    cc = condensed("flat")
    surface = sf.build(cc, MU)
    state = ss.preload(surface, 500.0, ECCENTRIC["e6"])
    core = TangentialProblem(cc, normal.solve_force(cc, 500.0, ECCENTRIC["e6"]).f, MU)
    state = ss.tangential_path(surface, state, [0.3 * core.gross_slip_displacement(
        core.initial_state())]).state
    rng = np.random.default_rng(20261127)
    x = state.x.copy()
    w_x = x[0:3 * surface.n:3]
    x[0:3 * surface.n:3] += 0.2 * np.abs(w_x).max()   # a trial step: some nodes slip further
    _, J = ss.contact_forces(surface, state, x)
    h = FD_STEP * np.abs(state.x[:3 * surface.n]).max()
    for k in rng.choice(3 * surface.n, 12, replace=False):
        dx = np.zeros(surface.n_dof)
        dx[k] = h
        fd = (ss.contact_forces(surface, state, x + dx, jac=False)[0]
              - ss.contact_forces(surface, state, x - dx, jac=False)[0]) / (2 * h)
        assert np.allclose(fd, J[:, k], rtol=FD_RTOL, atol=FD_RTOL * np.abs(J).max())


def test_y_compliance_of_a_sphere_mirrors_its_x_compliance(tmp_path):
    """Axisymmetric body: C_yy at (x, y) equals C_xx at the mirrored nodes (y, x)."""
    cc = condense(ContactSpec(body="sphere", radius=0.01, model="halfspace", grid=9),
                  directions=("z", "x", "y"), cache=tmp_path)
    key = {(round(x * 1e9), round(y * 1e9)): i for i, (x, y) in enumerate(zip(cc.grid.x, cc.grid.y))}
    mirror = np.array([key[(round(y * 1e9), round(x * 1e9))] for x, y in zip(cc.grid.x, cc.grid.y)])
    assert np.allclose(cc.Cyy, cc.Cxx[np.ix_(mirror, mirror)], rtol=1e-6, atol=1e-6 * cc.Cxx.max())


@pytest.mark.parametrize("nodes", [3, 4, 42, 99, 7.0, True])
def test_surface_node_count_outside_its_bound_is_refused(nodes):
    with pytest.raises(ValueError, match="surface nodes per side"):
        sf.check_nodes(nodes)


@pytest.mark.parametrize("force, e, match", [(0.0, 0.0, "falls out of contact"),
                                             (-5.0, 0.0, "falls out of contact"),
                                             (500.0, 0.7e-3, "outside the face")])
def test_surface_without_a_holding_normal_load_is_refused(condensed, force, e, match):
    surface = sf.build(condensed("flat"), MU)
    with pytest.raises(ValueError, match=match):
        ss.preload(surface, force, e)


def test_surface_needs_all_three_compliances(condensed, tmp_path):
    cc = condense(CASES["flat"][0], directions=("z", "x"), cache=tmp_path)
    with pytest.raises(ValueError, match="compliances in z, x, y"):
        sf.build(cc, MU)
    assert sf.build(cc, MU, tangents=("x",)).d == 2   # a planar surface needs z and x only


def test_planar_surface_gives_the_loop_of_the_3d_surface(condensed):
    """x and y are decoupled (like materials), so dropping y changes nothing under an x load
    but the slider penalty (1 / min(C_xx,ii, C_yy,ii) in 3D, 1 / C_xx,ii planar): within
    the penalty's own effect, 1 / PENALTY."""
    cc = condensed("flat")
    core = TangentialProblem(cc, normal.solve_force(cc, 500.0, ECCENTRIC["e6"]).f, MU)
    a = 0.7 * core.gross_slip_displacement(core.initial_state())
    loops = []
    for tangents in (("x", "y"), ("x",)):
        surface = sf.build(cc, MU, tangents=tangents)
        state = ss.preload(surface, 500.0, ECCENTRIC["e6"])
        loops.append(ss.hysteresis_loop(surface, state, a, steps=10)[0])
    tol = 1.0 / sf.PENALTY
    assert np.allclose(loops[1].T, loops[0].T, rtol=tol, atol=tol * np.abs(loops[0].T).max())


def test_surface_whose_contact_reaches_the_zone_edge_is_refused(condensed):
    """The cylinder's zone holds its Hertz contact at the design pressure (~450 N here):
    at 1000 N the contact would reach beyond the modelled nodes."""
    surface = sf.build(condensed("cylinder"), MU)
    assert surface.zone_edge.any() and not sf.build(condensed("flat"), MU).zone_edge.any()
    with pytest.raises(ValueError, match="edge of the potential contact zone"):
        ss.preload(surface, 1000.0)
