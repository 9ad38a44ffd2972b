"""The blade FMU: exact integration (the linear FRF at steady state, step-size independence,
the dissipation per cycle), fmpy validation, refusals."""
import ctypes

import numpy as np
import pytest
from slaves import Slave

from fmu_src.blade_fmu import BladeSpec, build_blade_fmu, check_spec, modal_data

#: Steady-state first harmonic against the direct solve: the required accuracy.
FRF_RTOL = 1e-6
#: Two step sizes on the same input path: only round-off differs (exact integration).
STEP_RTOL = 1e-11


def _steady_h1(slave, f, steps, periods, dof="q_u_a"):
    """First harmonic of ``dof`` over the last of ``periods`` periods of ``steps`` steps."""
    T = 1.0 / f
    h = T / steps
    x = np.empty(steps)
    for p in range(periods):
        for k in range(steps):
            slave.step(h)
            if p == periods - 1:
                x[k] = slave.get(dof)
    t = (periods - 1) * T + h * np.arange(1, steps + 1)
    return 2.0 / steps * np.sum(x * np.exp(-2j * np.pi * f * t))


@pytest.mark.parametrize("version", [2, 3])
def test_fmus_pass_fmpy_validation(part_fmus, version):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(part_fmus["blade", version])) == []
    assert validate_fmu(str(part_fmus["damper", version])) == []


@pytest.mark.parametrize("version", [2, 3])
def test_blade_alone_reproduces_its_linear_frf(specs, part_fmus, version):
    """Interface forces at their static values, neighbours held still (their start values):
    the response DOF's steady first harmonic equals (K + i w C - w^2 M)^-1 F0 e_forced to
    1e-6 (measured 3e-9) at 7 steps a period: the step size plays no part."""
    b, _ = specs
    f = 440.0
    s = Slave(part_fmus["blade", version], version)
    s.set(frequency=f)
    s.start_stepping()
    # decay of the slowest mode (Re lambda = -5.4 1/s) below 1e-8 of the start transient
    H1 = _steady_h1(s, f, 7, 1500)
    s.close()
    w = 2 * np.pi * f
    U = np.linalg.solve(b.K + 1j * w * b.C - w * w * b.M, 30.0 * np.eye(b.n)[b.forced])
    assert abs(H1 - U[b.response]) < FRF_RTOL * abs(U[b.response])


def test_step_size_does_not_change_the_solution(part_fmus):
    """The same input path (forces as straight lines with their rates) in steps of h and h/3:
    equal states at the common points to round-off, and equal cumulative works."""
    f0, rate = {"F_left_x": -60.0, "F_left_y": 60.0}, {"F_left_x_rate": 2e4, "F_left_y_rate": -1e4}
    out = []
    for sub in (1, 3):
        s = Slave(part_fmus["blade", 2], 2)
        s.start_stepping()
        h = 1e-4
        for _ in range(30 * sub):
            t = s.t
            s.set(**{n: v + rate[n + "_rate"] * t for n, v in f0.items()}, **rate)
            s.step(h / sub)
        out.append(np.array(s.get("q_u_p", "v_u_p", "q_u_a", "W_excitation", "W_interface",
                                  "W_damping", "energy")))
        s.close()
    assert out[0] == pytest.approx(out[1], rel=STEP_RTOL, abs=1e-300)


def test_dissipation_per_cycle_is_the_analytic_one(specs, part_fmus):
    """At steady state W_damping over a period equals pi w U^H C U (U the complex amplitude)
    and W_excitation the same (no other input does work): the closed-form works."""
    b, _ = specs
    f = 430.0
    s = Slave(part_fmus["blade", 2], 2)
    s.set(frequency=f)
    s.start_stepping()
    T, n = 1.0 / f, 11
    for _ in range(1500 * n):
        s.step(T / n)
    e0 = np.array(s.get("W_damping", "W_excitation"))
    for _ in range(n):
        s.step(T / n)
    e1 = np.array(s.get("W_damping", "W_excitation"))
    s.close()
    w = 2 * np.pi * f
    U = np.linalg.solve(b.K + 1j * w * b.C - w * w * b.M, 30.0 * np.eye(b.n)[b.forced])
    D = np.pi * w * np.real(U.conj() @ b.C @ U)
    assert e1 - e0 == pytest.approx([D, D], rel=1e-6)


def _spec(M, K, C):
    n = M.shape[0]
    return BladeSpec(M, K, C, None, None, tuple(f"q{i}" for i in range(n)), {"left": (0, 1)}, 0,
                     0, np.zeros(n), {}, np.zeros(n))


def test_refuses_what_it_cannot_represent(tmp_path):
    M, K = np.diag([1.0, 2.0]), np.array([[2.0, -1.0], [-1.0, 2.0]])
    with pytest.raises(ValueError, match="positive definite"):
        check_spec(_spec(np.diag([1.0, 0.0]), K, 0 * K))
    with pytest.raises(ValueError, match="not symmetric"):
        check_spec(_spec(M, K + np.array([[0, 1.0], [0, 0]]), 0 * K))
    with pytest.raises(ValueError, match="defective"):  # a rigid-body mode: lambda = 0 twice
        modal_data(_spec(M, np.array([[1.0, -1.0], [-1.0, 1.0]]), 0 * K))
    with pytest.raises(ValueError, match="finite"):
        build_blade_fmu(_spec(M, K, 0 * K), tmp_path / "x.fmu", F0=np.nan, frequency=1.0)
    assert not (tmp_path / "x.fmu").exists()


@pytest.mark.parametrize("model", ["blade", "upd"])
def test_generated_sources_compile_without_warnings(specs, tmp_path, model):
    """The FMU build compiles without -Werror (users' compilers differ); CI compiles the
    blade's and the damper's generated sources with it, as CMake does the element's (FMI 2:
    the model and the layer are the same in both versions; CMake covers fmi3.c)."""
    from fmu_src import blade_fmu, fmu_build, upd_fmu

    b, d = specs
    itf = blade_fmu.interface(b, 30.0, 440.0, 0.0, 0.0)[0] if model == "blade" else upd_fmu.interface(d)
    src = tmp_path / model
    names = fmu_build._copy_sources(src, 2, model, itf)
    fmu_build.compile_binary(src, names, tmp_path / f"{model}.so", extra_flags=("-Werror",))
    # the binary loads and answers as an FMI 2 model
    lib = ctypes.CDLL(str(tmp_path / f"{model}.so"))
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    assert lib.fmi2GetVersion() == b"2.0"
