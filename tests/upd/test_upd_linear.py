"""UPD-24 linear limits: direct solve against modal superposition, peaks against modes."""
import numpy as np
import pytest
from refcheck import check

from harmonic_balance.bladed_disk.sector import (
    linear_response,
    modal_response,
    modes_table,
    natural_frequencies,
    peak_of,
)

#: Direct solve vs complex modal superposition; measured 2e-8 (free), 4e-7 (stuck).
MODAL_RTOL = 1e-6
#: Peak frequency vs undamped natural frequency: the displacement peak lies below the
#: natural frequency by ~zeta^2 = 4e-6 (0.2 % damping). Measured 4.0e-6 (free), 5.0e-6
#: (stuck) (revision a12e5f1); 2e-5, 4x the larger: deterministic, a shift of the
#: modes or of the peak search by 2e-5 fails.
PEAK_RTOL = 2e-5


@pytest.mark.parametrize("damper", ["free", "stuck", "sliding"])
def test_direct_equals_modal(sector, damper):
    w = 2 * np.pi * np.linspace(300, 600, 31)
    a = linear_response(sector, w, damper)
    b = modal_response(sector, w, damper)
    assert np.max(np.abs(a - b)) <= MODAL_RTOL * np.max(np.abs(a))


@pytest.mark.parametrize("damper", ["free", "stuck"])
def test_peak_at_natural_frequency(sector, damper):
    f_n = natural_frequencies(sector, sector.cfg.engine_order, damper)[0]
    w, a = peak_of(lambda om: abs(linear_response(sector, om, damper)[0, sector.response]),
                   2 * np.pi * 380, 2 * np.pi * 520)
    check(f"UPD-24 linear FRF peak [Hz], damper {damper}, EO 6", w / (2 * np.pi), f_n, rtol=PEAK_RTOL,
          kind="self-consistency", source="natural frequency of the cyclic sector (eigenvalue problem)")
    # Peak amplitude from the single-mode modal formula |phi_a|^2 F0 / (omega_r^2 2 zeta_r)
    # is checked against the modal superposition (all modes).
    am = abs(modal_response(sector, w, damper)[0, sector.response])
    assert a == pytest.approx(am, rel=MODAL_RTOL)


def test_free_nd6_damping_is_0p2_percent(sector):
    """beta = 1.494e-6 s gives 0.2 % at the free ND6 first mode (the model's specification)."""
    f = natural_frequencies(sector, 6, "free")[0]
    zeta = sector.beta * 2 * np.pi * f / 2
    assert zeta == pytest.approx(0.002, rel=1e-3)  # measured 2.00005e-3


def test_modes_table_shape_and_order(sector):
    tab = modes_table(sector)
    assert tab["nodal_diameter"] == list(range(13))
    # the stuck damper stiffens the first bending family at ND >= 1
    for nd in range(1, 13):
        assert tab["stuck_hz"][nd][0] > tab["free_hz"][nd][0]


def test_cyclic_stiffness_is_hermitian(sector):
    Kc = sector.K_contact(sector.cfg.phi)
    assert np.allclose(Kc, Kc.conj().T, rtol=0, atol=1e-6 * np.abs(Kc).max())
    assert np.all(np.linalg.eigvalsh(Kc) > -1e-6 * np.abs(Kc).max())
