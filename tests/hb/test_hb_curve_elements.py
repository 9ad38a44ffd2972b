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
