"""A model holding a LinearElement (exact harmonics, no AFT samples) traces its curve: the
same curve as the model with that spring in K."""
import numpy as np
import pytest
from hbcases import two_dof

from harmonic_balance.forces import LinearElement
from harmonic_balance.frf import compute_frf
from harmonic_balance.kinematics import Kinematics
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model

#: The two models differ only in where the spring's force is added (K x against the
#: element's I (x) K): the same residual to round-off; the peak's refinement tolerance
#: (1e-6 in omega, amplitude flat there) bounds what the curves may differ by.
SAME_PEAK_RTOL = 1e-6


def test_a_linear_element_gives_the_curve_of_its_spring_in_k():
    base = two_dof()
    lin = base.linear
    K = lin.K.copy()
    K[1, 1] -= 0.5                       # the ground spring of mass 2 moved into an element
    moved = Model(LinearModel(M=lin.M, C=lin.C, K=K),
                  [*base.links, LinearElement(Kinematics([1], [[1.0]]), [[0.5]], name="spring")],
                  base.forcing, response_dof=base.response_dof)
    a = compute_frf(base, 5, (0.6, 1.6), truncation_check=False)
    b = compute_frf(moved, 5, (0.6, 1.6))   # with the truncation check: richer sets too
    assert b.peak_amplitude == pytest.approx(a.peak_amplitude, rel=SAME_PEAK_RTOL)
    assert b.peak_omega == pytest.approx(a.peak_omega, rel=SAME_PEAK_RTOL)
    assert np.isfinite(b.peak_amplitude)
