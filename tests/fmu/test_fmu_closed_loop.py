"""Smoke test of examples/fmu_closed_loop.py: the master needs the FMU's kt for a stiff
contact, and the energy balance per cycle closes."""
import numpy as np
import pytest


@pytest.mark.slow
def test_closed_loop_example_runs_and_shows_the_kt_coupling(load_example, capsys):
    ex = load_example("fmu_closed_loop")
    out = ex.main(["--quick"])
    text = capsys.readouterr().out
    assert "largest stable step" in text and "closure" in text
    ref, stable = out["ref"], out["stable"]
    assert ref["ok"] and 0.0 < out["ref_amp"] < ex.U_S            # microslip regime
    # measured (quick): explicit 2.3e-5 s, kt 4.6e-4 s: the tangent buys > 10x
    assert stable["kt"] > 10.0 * stable["explicit"]
    # the discrete Newmark identity of the master: exact to round-off per cycle
    mech = ref["viscous"] + ref["damper"] + ref["dE_mech"]
    np.testing.assert_allclose(mech, ref["input"], rtol=1e-9)
    # the FMU's W + stored energy against the master's applied damper work: they differ
    # by the coupling defect at this step (measured 6e-5 of the input work)
    closure = (ref["damper"] - ref["W"] - ref["dE_stored"]) / ref["input"]
    assert np.all(np.abs(closure[1:]) < 1e-4)
