"""The contact-point FMU (damper fmu --normal / --k-n): fmpy validation, the array API
(fmu_src.contact_point) to round-off in fmpy and libcosim, the 1D FMU on a line, the
circle energy and its convergence order, directional derivatives, the CLI's refusals."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu
from fmu_helpers import N_CURVE, U_SLIP, Slave, curve_table

from contact_core.curve import VirginCurve, write_curve
from damper.cli import main as damper_main
from fmu_src import fmu_xml
from fmu_src.fmu_point import build_point_fmu, contact_point

#: Same C core, same flags: agreement to round-off.
EXACT_TOL = 1e-12
#: The required accuracy of the circle at 4000 steps a cycle (the polygon's own effect ~2e-7).
CIRCLE_RTOL = 1e-4
#: Central differences at 1e-6 of the slip distance, away from slider switches.
FD_RTOL = 1e-6
VR = {v.name: v.vr for v in fmu_xml.POINT_VARIABLES}
#: Hertz-like normal law, N(P_REF) = N_CURVE.
P_REF = 1e-6
P_TAB = np.linspace(0.0, 2 * P_REF, 7)
N_TAB = N_CURVE * (P_TAB / P_REF) ** 1.5


@pytest.fixture(scope="module")
def point_fmus(fmu_dir):
    u, T = curve_table()
    return {v: build_point_fmu(u, T, N_CURVE, P_TAB, N_TAB, fmu_dir / f"point{v}.fmu",
                               fmi_version=v) for v in (2, 3)}


@pytest.fixture(scope="module")
def ref_point():
    u, T = curve_table()
    return contact_point(u, T, N_CURVE, P_TAB, N_TAB)


class PointSlave:
    """One contact-point instance through fmpy's FMU2Slave / FMU3Slave."""

    def __init__(self, path, version: int, **params):
        md = read_model_description(path)
        cls, token = (FMU2Slave, md.guid) if version == 2 else (FMU3Slave, md.instantiationToken)
        self.fmu = cls(guid=token, unzipDirectory=extract(path),
                       modelIdentifier=md.coSimulation.modelIdentifier, instanceName="point")
        self.v, self.t = version, 0.0
        self.fmu.instantiate()
        if version == 2:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=0.0)
        if params:
            self.set(params)
        self.fmu.exitInitializationMode()

    def set(self, values: dict):
        (self.fmu.setReal if self.v == 2 else self.fmu.setFloat64)([VR[k] for k in values],
                                                                   list(values.values()))

    def get(self, names) -> np.ndarray:
        return np.array((self.fmu.getReal if self.v == 2 else self.fmu.getFloat64)(
            [VR[n] for n in names]))

    def step(self, q, names=("F_x", "F_y", "N", "W"), h=1e-3, **extra):
        self.set({"u_x": q[0], "u_y": q[1], "p": q[2], **extra})
        self.fmu.doStep(self.t, h)
        self.t += h
        return self.get(names)

    def dd(self, unknown: str, known: str) -> float:
        if self.v == 2:
            return self.fmu.getDirectionalDerivative([VR[unknown]], [VR[known]], [1.0])[0]
        return self.fmu.getDirectionalDerivative([VR[unknown]], [VR[known]], [1.0], 1)[0]


def history(n=150):
    """An ellipse in the plane with the penetration through lift-off and back."""
    t = 0.15 * np.arange(1, n + 1)
    return np.c_[1.2 * U_SLIP * np.cos(t), 0.6 * U_SLIP * np.sin(1.3 * t),
                 P_REF * (0.5 + 0.7 * np.sin(0.4 * t))]


@pytest.mark.parametrize("version", [2, 3])
def test_an_overflowing_penetration_or_step_end_is_refused_at_the_call(point_fmus, version, capfd):
    """SetReal(p = 1e300) is refused (the normal energy would overflow at the next call),
    the instance keeps its inputs; DoStep whose end t + h is not finite is refused, the
    time unchanged; a representable deep penetration and the next step still work."""
    from fmpy.fmi1 import FMICallException

    fmu = PointSlave(point_fmus[version], version)
    p0 = fmu.get(["p"])[0]
    with pytest.raises(FMICallException):
        fmu.set({"p": 1e300})
    assert "beyond the bound" in capfd.readouterr().out and fmu.get(["p"])[0] == p0
    deep = fmu.step([0.0, 0.0, 1e3 * P_REF], names=("N", "stored_energy"))
    assert np.all(np.isfinite(deep)) and deep[0] > N_CURVE
    fmu.fmu.doStep(fmu.t, 1e308)                            # t + h = 1e308: finite, accepted
    with pytest.raises(FMICallException):
        fmu.fmu.doStep(1e308, 1e308)
    assert "overflows" in capfd.readouterr().out
    fmu.fmu.doStep(1e308, 1.0)                              # still at t = 1e308
    fmu.fmu.terminate()
    fmu.fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_fmpy_validates_the_point_fmu(point_fmus, version):
    assert validate_fmu(str(point_fmus[version])) == []


@pytest.mark.parametrize("version", [2, 3])
def test_fmu_equals_the_array_api(point_fmus, ref_point, version):
    fmu = PointSlave(point_fmus[version], version)
    p0 = fmu.get(["p"])[0]
    assert math.isclose(ref_point.normal(p0)[0], N_CURVE, rel_tol=1e-12)   # start at N_ref
    st = ref_point.initial_state(p0)
    names = ("F_x", "F_y", "N", "W", "stored_energy", "state", "slip", "K_xx", "K_xp", "K_yx")
    for q in history():
        got = fmu.step(q, names)
        o = ref_point.step(st, q)
        want = [*o.f, o.W, o.E, o.state, o.slip, o.K[0, 0], o.K[0, 2], o.K[1, 0]]
        assert np.allclose(got, want, rtol=EXACT_TOL, atol=EXACT_TOL * N_CURVE * 1e-6)
    assert st.W > 0 and (history()[:, 2] < 0).any()


def test_fmu_on_a_line_is_the_1d_fmu(point_fmus, fmus, ref_point):
    """Slip along a fixed direction at constant p (N = N(p)): the 1D FMU at that N."""
    p = 0.8 * P_REF
    N = ref_point.normal(p)[0]
    s = 1.3 * U_SLIP * np.sin(0.21 * np.arange(120)) * (1 + 0.4 * np.sin(0.9 * np.arange(120)))
    t = np.array([0.6, -0.8])
    point, line = PointSlave(point_fmus[2], 2), Slave(fmus[2], 2).initialize(0.0, N)
    for sk in s:
        Fx, Fy, _, W = point.step([sk * t[0], sk * t[1], p])
        F1, _, W1, _ = line.step(sk, N)
        assert abs(Fx * t[0] + Fy * t[1] - F1) <= EXACT_TOL * N_CURVE
        assert abs(-Fx * t[1] + Fy * t[0]) <= EXACT_TOL * N_CURVE
        assert math.isclose(W, W1, rel_tol=EXACT_TOL, abs_tol=1e-20)


@pytest.fixture(scope="module")
def jenkins_fmu(fmu_dir):
    """A Jenkins slider (k = 1e8 N/m, f_s = 100 N at N_ref = 200 N) with a penalty law."""
    r = 1e-6
    return build_point_fmu([0.0, r, 2 * r], [0.0, 100.0, 100.0], N_CURVE, [0.0, 1.0],
                           [0.0, 1e8], fmu_dir / "jenkins_point.fmu"), r


def circle_cycle_energy(path, a, n, p):
    fmu = PointSlave(path, 2)
    t = 2 * np.pi * np.arange(6 * n + 1) / n
    W = [fmu.step([a * math.cos(x), a * math.sin(x), p], ("W",))[0] for x in t]
    return W[-1] - W[-1 - n]


def test_fmu_circle_energy_and_convergence_order(jenkins_fmu):
    """Steady circle: 2 pi f_s sqrt(a^2 - (f_s/k)^2) per cycle, within 1e-4 at 4000
    communication steps a cycle, converging at order 2 (the inscribed polygon)."""
    path, r = jenkins_fmu
    a, fs, p = 3 * r, 100.0, N_CURVE / 1e8
    want = 2 * np.pi * fs * math.sqrt(a * a - r * r)
    errs = [abs(circle_cycle_energy(path, a, n, p) / want - 1) for n in (1000, 2000, 4000)]
    assert errs[-1] < CIRCLE_RTOL
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.05), orders


def test_fmu_iwan_circle_energy_is_the_sum_over_sliders(point_fmus, ref_point):
    el = ref_point.tangential
    r = el.slip_radii()
    a, n = 0.5 * U_SLIP, 4000
    W = circle_cycle_energy(point_fmus[2], a, n, P_REF)
    slips = r < a
    want = np.sum(2 * np.pi * el.fs[slips] * np.sqrt(a * a - r[slips] ** 2))
    assert abs(W / want - 1) < CIRCLE_RTOL


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivatives_are_central_differences(point_fmus, version):
    fmu = PointSlave(point_fmus[version], version)
    for q in history(40):
        fmu.step(q)
    checked = 0
    for q in history(48)[40:]:
        q = q + np.array([0.1 * U_SLIP, -0.05 * U_SLIP, 0.02 * P_REF])   # trial point
        fmu.set(dict(zip(("u_x", "u_y", "p"), q)))
        J = np.array([[fmu.dd(f, k) for k in ("u_x", "u_y", "p")] for f in ("F_x", "F_y", "N")])
        K = fmu.get([f"K_{a}{b}" for a in "xyp" for b in "xyp"]).reshape(3, 3)
        assert np.array_equal(J, K)
        fd = np.empty((3, 3))
        for j, (name, h) in enumerate((("u_x", 1e-6 * U_SLIP), ("u_y", 1e-6 * U_SLIP),
                                       ("p", 1e-6 * P_REF))):
            fmu.set({name: q[j] + h})
            fp = fmu.get(["F_x", "F_y", "N"])
            fmu.set({name: q[j] - h})
            fm = fmu.get(["F_x", "F_y", "N"])
            fmu.set({name: q[j]})
            fd[:, j] = (fp - fm) / (2 * h)
        checked += np.abs(fd - J).max() <= FD_RTOL * np.abs(J).max()
        fmu.fmu.doStep(fmu.t, 1e-3)
        fmu.t += 1e-3
    assert checked >= 7


def test_dashpots_and_input_derivatives(point_fmus, ref_point):
    fmu = PointSlave(point_fmus[2], 2, c_t=50.0, c_n=80.0)
    q = np.array([0.2 * U_SLIP, 0.1 * U_SLIP, P_REF])
    F = fmu.step(q, ("F_x", "F_y", "N"), v_x=1e-3, v_y=0.0, v_n=-2e-3)
    st = ref_point.initial_state(fmu.get(["p"])[0])
    want = ref_point.step(st, q).f + np.array([50.0 * 1e-3, 0.0, 80.0 * -2e-3])
    assert np.allclose(F, want, rtol=EXACT_TOL)
    assert fmu.dd("N", "v_n") == 80.0 and fmu.dd("F_x", "v_x") == 50.0
    # FMI 2 input derivatives: the inputs move on straight lines within the step
    a, b = PointSlave(point_fmus[2], 2), PointSlave(point_fmus[2], 2)
    q1 = np.array([0.5 * U_SLIP, -0.3 * U_SLIP, 0.7 * P_REF])
    a.fmu.setRealInputDerivatives([VR["u_x"], VR["u_y"], VR["p"]], [1, 1, 1],
                                  list((q1 - a.get(["u_x", "u_y", "p"])) / 1e-3))
    a.fmu.doStep(0.0, 1e-3)
    assert np.array_equal(a.get(["F_x", "F_y", "N", "W"]), b.step(q1))


def test_libcosim_runs_the_point_fmu(point_fmus, ref_point):
    pytest.importorskip("libcosimpy", reason="libcosimpy (PyPI) is a test dependency")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(1_000_000)
    idx = ex.add_local_slave(CosimLocalSlave(fmu_path=str(point_fmus[2]), instance_name="pt"))
    override, last = CosimManipulator.create_override(), CosimObserver.create_last_value()
    ex.add_manipulator(override)
    ex.add_observer(last)
    st = ref_point.initial_state(ref_point.penetration(N_CURVE))
    for q in history(80):
        override.slave_real_values(idx, [VR["u_x"], VR["u_y"], VR["p"]], list(q))
        assert ex.step()
        got = last.last_real_values(idx, [VR["F_x"], VR["F_y"], VR["N"], VR["W"]])
        o = ref_point.step(st, q)
        assert np.allclose(got, [*o.f, o.W], rtol=EXACT_TOL, atol=EXACT_TOL * 1e-3)


# ---------------------------------------------------------------- the CLI
@pytest.fixture(scope="module")
def curve_file(tmp_path_factory):
    u, T = curve_table(21)
    path = tmp_path_factory.mktemp("cli") / "curve.json"
    write_curve(VirginCurve(u, T, N=N_CURVE, mu=0.5, tail="flat"), path)
    return path


def normal_file(path, N, load=None):
    data = {"schema": "damper-normal-curve/1", "approach": list(P_TAB), "N": list(N)}
    if load is not None:
        data["load"] = load
    path.write_text(json.dumps(data))
    return path


def test_cli_builds_point_fmus(curve_file, tmp_path, capsys):
    out = tmp_path / "p.fmu"
    nf = normal_file(tmp_path / "n.json", N_TAB, load=N_CURVE)
    assert damper_main(["fmu", "--curve", str(curve_file), "--normal", str(nf), "-o", str(out)]) == 0
    assert validate_fmu(str(out)) == []
    assert read_model_description(out).coSimulation.modelIdentifier == "contact_point"
    out2 = tmp_path / "k.fmu"
    assert damper_main(["fmu", "--curve", str(curve_file), "--k-n", "2e8", "--preload", "150",
                        "-o", str(out2), "--fmi-version", "3"]) == 0
    fmu = PointSlave(out2, 3)
    assert math.isclose(fmu.get(["N"])[0], 150.0, rel_tol=1e-12)


def test_cli_json_describes_the_fmu_written(curve_file, tmp_path, capsys):
    """``--json``: one object on stdout whose path, model and preload are those of the file."""
    out = tmp_path / "j.fmu"
    assert damper_main(["fmu", "--curve", str(curve_file), "--k-n", "2e8", "--preload", "150",
                        "-o", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["fmu"] == str(out) and info["model"] == "contact_point" and info["preload_N"] == 150.0
    assert read_model_description(out).coSimulation.modelIdentifier == info["model"]
    assert info["points"] <= info["curve_points"] == 21


@pytest.mark.parametrize("args, N, load, message", [
    ([], N_TAB[[0, 1, 2, 3, 2, 5, 6]], None, "increase strictly"),           # not monotone
    ([], N_TAB, 0.5 * N_CURVE, "--preload"),                                  # other load
    (["--preload", "nan"], N_TAB, None, "--preload must be finite"),
    (["--preload", "-5"], N_TAB, None, "--preload must be finite"),
])
def test_cli_refuses_bad_normal_laws(curve_file, tmp_path, capsys, args, N, load, message):
    out = tmp_path / "bad.fmu"
    nf = normal_file(tmp_path / "n.json", N, load)
    code = damper_main(["fmu", "--curve", str(curve_file), "--normal", str(nf), "-o", str(out), *args])
    assert code == 2 and message in capsys.readouterr().err and not out.exists()


@pytest.mark.parametrize("args, message", [
    (["--k-n", "-1"], "--k-n must be finite and > 0"),
    (["--k-n", "inf"], "--k-n must be finite and > 0"),
    (["--preload", "100"], "--preload needs a normal law"),
    (["--k-n", "1e-310"], "N/m is outside"),                             # p at N_ref: inf
    (["--k-n", "1e8", "--preload", "1e300"], "N is outside"),           # stored energy: inf
])
def test_cli_refuses_bad_penalty_options(curve_file, tmp_path, capsys, args, message):
    out = tmp_path / "bad.fmu"
    code = damper_main(["fmu", "--curve", str(curve_file), "-o", str(out), *args])
    assert code == 2 and message in capsys.readouterr().err and not out.exists()


def test_cli_refuses_two_normal_laws(curve_file, tmp_path):
    with pytest.raises(SystemExit) as err:
        damper_main(["fmu", "--curve", str(curve_file), "--k-n", "1e8", "--normal", "x.json",
                     "-o", str(tmp_path / "x.fmu")])
    assert err.value.code == 2
