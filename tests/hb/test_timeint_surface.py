"""Time integration with a contact surface (harmonic_balance.timeint_surface) against the
harmonic balance and the quasi-static march of the same surface.

The model: one mass on the tangential input of a planar cylinder surface (the
contact core's condensed cylinder on a block, a small grid), its approach held by a
constant normal force (massless, with the node DOFs), a spring to ground and light
viscous damping on the mass. The time integration shares with the harmonic balance
only the model (the C element's law); with the quasi-static march
(``surface_static``) only the surface and its laws.
"""
from __future__ import annotations

import numpy as np
import pytest

from contact_core.condense import condense
from contact_core.spec import ContactSpec
from harmonic_balance import surface as sf
from harmonic_balance import surface_static as ss
from harmonic_balance import timeint_surface as ts
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model
from harmonic_balance.newton import newton
from harmonic_balance.residual import FullResidual

pytestmark = pytest.mark.slow

#: The requirement: time integration and HB agree within 1 % at a point and at the peak
#: (measured 0.13 % and 0.38 % at H = 7 and 256 steps per period).
HB_RTOL = 0.01
#: Quasi-static limit (forcing at OMEGA_SLOW of the stuck frequency): amplitude and
#: friction work per cycle against the load-controlled static march (the inertia and
#: damping forces left are ~(OMEGA_SLOW)^2 and ~2 zeta OMEGA_SLOW of the elastic ones).
QS_RTOL = 0.01
OMEGA_SLOW = 0.01
#: HB harmonics and Newton tolerance relative to the normal load.
H, NEWTON_RTOL = 7, 1e-9
#: Penalty of the dynamics (the UPD surfaces' own, damper.upd_surface).
PENALTY = 100.0
MU, NORMAL = 0.5, 100.0
#: Mass [kg], ground spring as a share of the surface's stuck k_t, damping ratio.
MASS, SPRING_SHARE, ZETA = 0.05, 0.5, 0.005


@pytest.fixture(scope="module")
def surface(tmp_path_factory):
    cc = condense(ContactSpec(body="cylinder", radius=2.5e-3, length=1.2e-3, model="real", grid=5),
                  directions=("z", "x"), cache=tmp_path_factory.mktemp("surface_cache"))
    surf = sf.build(cc, MU, penalty=PENALTY, tangents=("x",))
    return surf, ss.preload(surf, NORMAL)


def mass_on_surface(surf, static, force, spring_share=SPRING_SHARE):
    """(model, omega_0): the mass on the tangential input, f = force cos(omega t) on it."""
    n, iu = surf.n_dof, surf.input_dof("tangential_x")
    k = (1.0 + spring_share) * ss.stuck_stiffness(surf, static)
    M, C, K = np.zeros((n, n)), np.zeros((n, n)), surf.K.copy()
    M[iu, iu], C[iu, iu] = MASS, 2 * ZETA * np.sqrt(k * MASS)
    K[iu, iu] += spring_share * ss.stuck_stiffness(surf, static)
    f0, f1 = np.zeros(n), np.zeros(n, complex)
    f0[surf.input_dof("approach")], f1[iu] = NORMAL, force
    return Model(LinearModel(M=M, C=C, K=K), list(surf.elements), {0: f0, 1: f1}, iu), np.sqrt(k / MASS)


class HBSweep:
    """HB solutions at frequencies, each Newton started from the last solution."""

    def __init__(self, surf, static, force):
        self.model, self.omega0 = mass_on_surface(surf, static, force)
        self.b = FourierBasis(H)
        self.res = FullResidual(self.model, self.b)
        x = np.zeros((self.b.nb, surf.n_dof))
        x[self.b.index(0)[0]] = static.x        # the preloaded surface, at rest
        self.x, self.omega = x.ravel(), 0.8 * self.omega0
        for level in np.linspace(0.1, 1.0, 10):   # forcing homotopy from the static state
            r = FullResidual(mass_on_surface(surf, static, level * force)[0], self.b)
            self.x = newton(lambda z, r=r: r(z, self.omega)[:2], self.x, NEWTON_RTOL * NORMAL).x

    def amplitude(self, omega: float) -> float:
        """Peak |u| of the mass over the period [m]."""
        self.x = newton(lambda z: self.res(z, omega)[:2], self.x, NEWTON_RTOL * NORMAL).x
        X = self.x.reshape(self.b.nb, -1)
        return self.b.peak_abs(X[:, self.model.response_dof])

    def peak(self, lo: float, hi: float, iters: int = 14) -> tuple:
        """Golden-section search of the amplitude's maximum on [lo, hi]: (omega, amplitude)."""
        g = (np.sqrt(5) - 1) / 2
        a, b = lo, hi
        c, d = b - g * (b - a), a + g * (b - a)
        fc, fd = self.amplitude(c), self.amplitude(d)
        for _ in range(iters):
            if fc > fd:
                b, d, fd = d, c, fc
                c = b - g * (b - a)
                fc = self.amplitude(c)
            else:
                a, c, fc = c, d, fd
                d = a + g * (b - a)
                fd = self.amplitude(d)
        return (c, fc) if fc > fd else (d, fd)


def test_mass_on_a_surface_time_integration_matches_harmonic_balance(surface):
    surf, static = surface
    hb = HBSweep(surf, static, force=5.0)
    w0 = hb.omega0
    a_point = hb.amplitude(0.8 * w0)
    w_peak, a_peak = hb.peak(0.85 * w0, 1.0 * w0)
    ti = ts.march_curve(hb.model, [0.8 * w0, w_peak], 256, max_periods=400)
    assert ti.converged.all()
    assert ti.W_friction[1] > 0.0          # the peak slips (partial slip at the edges)
    assert ti.amplitude[0] == pytest.approx(a_point, rel=HB_RTOL)
    assert ti.amplitude[1] == pytest.approx(a_peak, rel=HB_RTOL)


def static_cycle(surf, static, force, steps=200):
    """Load-controlled quasi-static march of the tangential force force cos(theta), two
    periods; returns the second period's amplitude (max - min) / 2 [m] and friction work [J]."""
    state, u, W = static, [], []
    for th in 2 * np.pi * np.arange(1, 2 * steps + 1) / steps:
        state = ss.step(surf, state, {}, {"approach": NORMAL, "tangential_x": force * np.cos(th)})
        u.append(state.x[surf.input_dof("tangential_x")])
        W.append(sum(s.W for s in state.friction))
    u = np.array(u[steps:])
    return 0.5 * (u.max() - u.min()), W[-1] - W[steps - 1]


def test_slow_forcing_gives_the_quasi_static_loop_of_the_surface(surface):
    surf, static = surface
    force = 0.6 * MU * NORMAL                  # partial slip: the edges slip, the centre sticks
    model, w0 = mass_on_surface(surf, static, force, spring_share=0.0)
    ti = ts.march_curve(model, [OMEGA_SLOW * w0], 256, max_periods=200)
    assert ti.converged.all()
    u = ti.x_last[0]
    amplitude, work = static_cycle(surf, static, force)
    assert work > 0.0
    assert 0.5 * (u.max() - u.min()) == pytest.approx(amplitude, rel=QS_RTOL)
    assert ti.W_friction[0] == pytest.approx(work, rel=QS_RTOL)


#: Grouped call against each node's own element: the homogeneity F_c(u, N) = c F_1(u, N / c)
#: is exact; the scaled inputs round differently (~1e-15 relative).
GROUPED_RTOL = 1e-11


def test_nodes_sharing_one_c_call_give_each_elements_own_forces(surface):
    """The node contacts of a surface (one Jenkins law up to each node's k_t, one C call)
    stepped along a random path give the forces of every node's own ContactElement."""
    from harmonic_balance.massless import MasslessContacts

    surf, static = surface
    dofs = np.arange(surf.n_w)
    nodes = MasslessContacts(surf.elements, dofs, 1)
    assert len(nodes.groups) == 1
    own = [el.stepper() for el in surf.elements]
    rng = np.random.default_rng(20261127)
    w0 = static.x[:surf.n_w]
    slip = MU * NORMAL / ss.stuck_stiffness(surf, static)      # the face's gross-slip scale [m]
    for _ in range(40):
        w = w0.copy()
        w[0::2] += slip * rng.uniform(-1.5, 1.5)                # a tangential sweep of all nodes
        w[1::2] *= rng.uniform(0.7, 1.3)                        # the normal load breathing
        fc, _, trial = nodes.evaluate(w[None, :])
        nodes.commit(trial)
        ref = np.concatenate([o.force(w[2 * i:2 * i + 2]) for i, o in enumerate(own)])
        assert np.allclose(fc[0], ref, rtol=GROUPED_RTOL, atol=GROUPED_RTOL * np.abs(ref).max())


#: A march started on the HB's periodic state and one from rest settle to the same state:
#: their amplitudes differ by the settling tolerances (SETTLE_TOL each, extrapolated) and
#: the HB's truncation does not enter (the march does not know its start).
SETTLE_TOL, SAME_STATE_RTOL = 1e-7, 1e-5


def test_march_started_on_the_hb_state_settles_sooner_to_the_same_state(surface):
    surf, static = surface
    hb = HBSweep(surf, static, force=5.0)
    w = 0.8 * hb.omega0
    hb.amplitude(w)
    X = hb.x.reshape(hb.b.nb, -1)
    rest = ts.march_curve(hb.model, [w], 256, max_periods=400, tol=SETTLE_TOL)
    own = ts.march_curve(hb.model, [w], 256, max_periods=400, tol=SETTLE_TOL,
                         start=lambda ns: FourierBasis(H, ns).E @ X)
    assert rest.converged.all() and own.converged.all()
    assert own.periods[0] < rest.periods[0]
    assert own.amplitude[0] == pytest.approx(rest.amplitude[0], rel=SAME_STATE_RTOL)


def test_march_refuses_a_start_of_the_wrong_shape(surface):
    surf, static = surface
    model, w0 = mass_on_surface(surf, static, 5.0)
    with pytest.raises(ValueError, match="start must give"):
        ts.march_curve(model, [w0], 256, max_periods=2, start=lambda ns: np.zeros((ns, 3)))
