"""Half-space influence coefficients: closed forms against quadrature and point-force limits."""
import numpy as np
import pytest
from refcheck import check
from scipy import integrate

from contact_core import halfspace_bem as hb

#: Closed-form rectangle integrals against adaptive quadrature (smooth integrand
#: on cells away from the source): quadrature accuracy.
QUAD_RTOL = 1e-9
#: Far cells act as point forces: relative error ~ (cell / distance)^2 / 24 = 2.6e-5 at
#: 40 cells. Measured 2.2e-5 (normal) and 1.3e-5 (tangential) (revision a12e5f1);
#: 2.5e-4, ~10x: the error is the discretisation's, the same on every platform.
FAR_RTOL = 2.5e-4

E, NU = 200e9, 0.3
G = E / (2 * (1 + NU))

OFFSET_CELLS = [(0.3, 1.3, 0.2, 0.7), (-2.0, -1.0, 0.5, 3.0), (-0.5, 0.5, 1.0, 2.0), (1.0, 4.0, -3.0, -2.5)]


@pytest.mark.parametrize("X1,X2,Y1,Y2", OFFSET_CELLS)
def test_rectangle_integrals_match_quadrature(X1, X2, Y1, Y2):
    args = [np.array(v) for v in (X1, X2, Y1, Y2)]
    q1 = integrate.dblquad(lambda y, x: 1 / np.hypot(x, y), X1, X2, Y1, Y2, epsabs=0, epsrel=1e-12)[0]
    q2 = integrate.dblquad(lambda y, x: x * x / np.hypot(x, y) ** 3, X1, X2, Y1, Y2,
                           epsabs=0, epsrel=1e-12)[0]
    assert float(hb._rect_inv_rho(*args)) == pytest.approx(q1, rel=QUAD_RTOL)
    assert float(hb._rect_x2_rho3(*args)) == pytest.approx(q2, rel=QUAD_RTOL)


def test_self_cell_integrals_match_polar_quadrature():
    """Source at the centre of a 2A x 2B cell: integrate rho d(rho) d(theta) in polar form."""
    A, B = 0.7, 0.3
    theta_c = np.arctan2(B, A)

    def edge(th):  # distance from the centre to the cell edge along direction th
        return min(A / abs(np.cos(th)) if np.cos(th) else np.inf, B / abs(np.sin(th)) if np.sin(th) else np.inf)

    # 1/rho * rho drho dth = R(th) dth; x^2/rho^3 * rho drho dth = cos^2 R(th) dth
    pts = [theta_c, np.pi - theta_c]
    i1 = 2 * integrate.quad(edge, 0, np.pi, points=pts, epsrel=1e-13)[0]
    i2 = 2 * integrate.quad(lambda t: np.cos(t) ** 2 * edge(t), 0, np.pi, points=pts, epsrel=1e-13)[0]
    args = [np.array(v) for v in (-A, A, -B, B)]
    assert float(hb._rect_inv_rho(*args)) == pytest.approx(i1, rel=QUAD_RTOL)
    assert float(hb._rect_x2_rho3(*args)) == pytest.approx(i2, rel=QUAD_RTOL)


def test_far_cells_act_as_boussinesq_and_cerruti_point_forces():
    grid = hb.regular_grid(1e-4, 0.5e-4, 41, 21)
    I1, I2 = hb.cell_integrals(grid)
    Czz, Cxx = hb.body_compliances(I1, I2, grid.area, E, NU)
    i, j = 0, grid.x.size - 1  # opposite corners: ~40 cells apart
    X, Y = grid.x[i] - grid.x[j], grid.y[i] - grid.y[j]
    rho = np.hypot(X, Y)
    check("normal influence coefficient [m/N], cells ~40 apart", Czz[i, j], (1 - NU**2) / (np.pi * E * rho),
          rtol=FAR_RTOL, source="Boussinesq point force (Johnson 1985, ch. 3)")
    cerruti = ((1 - NU) / rho + NU * X**2 / rho**3) / (2 * np.pi * G)
    check("tangential influence coefficient [m/N], cells ~40 apart", Cxx[i, j], cerruti, rtol=FAR_RTOL,
          source="Cerruti point force (Johnson 1985, ch. 3)")


def test_compliances_are_reciprocal_and_positive_definite():
    contact = hb.sphere(0.01, 1e-4, 9)
    for C in (contact.Czz, contact.Cxx):
        np.testing.assert_allclose(C, C.T, rtol=1e-12, atol=0)
        assert np.linalg.eigvalsh(C).min() > 0
    np.testing.assert_allclose(contact.Cxx, sum(contact.Cxx_bodies), rtol=1e-14)
    assert contact.grid.mult.tolist() == [1.0] * contact.n
    assert contact.rigid.shape == (contact.n, 1)


def test_uniform_pressure_on_a_square_gives_love_centre_displacement():
    """Love (1929): centre of a uniformly loaded square 2c x 2c sinks by
    4 ln(1 + sqrt 2) (2 c p (1 - nu^2) / (pi E)), whatever the grid."""
    c, p = 1e-4, 1e8
    grid = hb.regular_grid(c, c, 15, 15)
    I1, I2 = hb.cell_integrals(grid)
    Czz, _ = hb.body_compliances(I1, I2, grid.area, E, NU)
    centre = grid.x.size // 2
    w = Czz[centre] @ (p * grid.area)
    love = 4 * np.log(1 + np.sqrt(2)) * 2 * c * p * (1 - NU**2) / (np.pi * E)
    check("centre displacement [m] of a uniformly loaded square, 15x15 cells", w, love, rtol=1e-12,
          source="Love 1929")


@pytest.mark.parametrize("bad", [dict(radius=-1.0), dict(half_width=0.0), dict(radius=np.nan)])
def test_bad_geometry_is_refused(bad):
    kwargs = dict(radius=0.01, half_width=1e-4, n=5) | bad
    with pytest.raises(ValueError):
        hb.sphere(**kwargs)


def test_bad_material_is_refused():
    grid = hb.regular_grid(1e-4, 1e-4, 3, 3)
    I1, I2 = hb.cell_integrals(grid)
    with pytest.raises(ValueError, match="Poisson"):
        hb.body_compliances(I1, I2, grid.area, E, 0.5)


def test_dissimilar_bodies_add_their_compliances():
    """Each body keeps its own compliance; the pair's is their sum (1/E* rule)."""
    mats = ((200e9, 0.3), (110e9, 0.34))
    contact = hb.sphere(0.01, 1e-4, 7, materials=mats)
    like = hb.sphere(0.01, 1e-4, 7)
    C1, C2 = contact.Czz_bodies
    assert C1 is not C2
    np.testing.assert_allclose(contact.Czz, C1 + C2, rtol=1e-14)
    # normal compliance scales with (1 - nu^2) / E of each body
    ratio = ((1 - 0.34**2) / 110e9) / ((1 - 0.3**2) / 200e9)
    np.testing.assert_allclose(C2, ratio * C1, rtol=1e-12)
    np.testing.assert_allclose(C1, like.Czz_bodies[0], rtol=1e-14)
