"""Curve-file friction links follow the same gross-slip rule as damper loop and damper fmu."""
import numpy as np
import pytest

from contact_core.curve import VirginCurve, write_curve
from harmonic_balance.model import load_elements

MU, N = 0.5, 120.0


def _write(tmp_path, T_end):
    u = np.linspace(0.0, 1.6e-6, 9)
    T = T_end * (1.0 - (1.0 - u / u[-1]) ** 1.5)   # Cattaneo-Mindlin shape (concave)
    # the producer states the tail (schema 2): flat when the curve ends at gross slip
    write_curve(VirginCurve(u=u, T=T, N=N, mu=MU, tail="flat" if T_end == MU * N else "slope"),
                tmp_path / "c.json")
    (tmp_path / "el.toml").write_text('[[element]]\ndofs = [0]\ntype = "curve"\npath = "c.json"\n')
    return load_elements(tmp_path / "el.toml")[0].element


def test_curve_ending_at_mu_N_saturates_at_mu_N(tmp_path):
    el = _write(tmp_path, MU * N)
    assert el.k_res == 0.0
    # far past the end of the table the force stays at mu N (gross slip), it does not keep rising
    F = el.series(np.array([0.0, 1.6e-6, 50e-6])).F
    assert F[-1] == pytest.approx(MU * N, rel=1e-12)


def test_curve_ending_below_mu_N_keeps_its_last_slope(tmp_path):
    el = _write(tmp_path, 0.8 * MU * N)
    assert el.k_res > 0.0


def test_contact_elements_from_the_elements_file(tmp_path):
    """type = "contact": Jenkins, Iwan curve (slip limits x N / N_ref) and normal-only contacts."""
    from harmonic_balance.contact import ContactElement

    u = np.linspace(0.0, 1.6e-6, 9)
    write_curve(VirginCurve(u=u, T=MU * N * (1.0 - (1.0 - u / u[-1]) ** 1.5), N=N, mu=MU),
                tmp_path / "c.json")
    (tmp_path / "el.toml").write_text(
        '[[element]]\ntype = "contact"\ndofs = [0, 1]\nnormal = [0.0, 1.0]\ntangent = [1.0, 0.0]\n'
        'k_n = 1e8\nk_t = 8e7\nmu = 0.5\npreload = 1e-6\nbeta_c = 1e-6\n'
        '[[element]]\ntype = "contact"\ndofs = [2, 0]\nnormal = [0.6, 0.8]\ntangent = [0.8, -0.6]\n'
        'delta = [[1.0, 0.0], [0.0, -1.0]]\nk_n = 2e8\ncurve = "c.json"\n'
        '[[element]]\ntype = "contact"\ndofs = [1]\nnormal = [1.0]\nk_n = 1e7\n')
    jen, iwan, normal = load_elements(tmp_path / "el.toml")
    assert all(isinstance(e, ContactElement) for e in (jen, iwan, normal))
    assert (jen.k_t, jen.friction.fs[0], jen.preload, jen.beta_c) == (8e7, 0.5, 1e-6, 1e-6)
    assert np.array_equal(iwan.kinematics.Q, [[0.8, 0.6], [-0.6, 0.8]])  # [t; -n] @ delta
    assert iwan.friction.N_ref == N and normal.m == 1 and normal.friction is None
    (tmp_path / "bad.toml").write_text('[[element]]\ntype = "contact"\ndofs = [0]\nnormal = [1.0]\n')
    with pytest.raises(ValueError, match=r"element\[0\]\.contact\.k_n: missing"):
        load_elements(tmp_path / "bad.toml")
