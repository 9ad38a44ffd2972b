"""The virgin-curve file: round trip, validation and clear errors."""
import json

import numpy as np
import pytest

from contact_core.curve import SCHEMA, VirginCurve, read_curve, write_curve


def _curve():
    u = np.linspace(0.0, 2e-6, 7)
    T = 100.0 * (1.0 - (1.0 - u / u[-1]) ** 1.5)  # Cattaneo-Mindlin shape, ends at mu N
    return VirginCurve(u=u, T=T, N=200.0, mu=0.5, k_t=1.5e8, load_case="CNF",
                       geometry={"body": "sphere", "radius": 0.01},
                       provenance={"command": "test"})


def test_curve_file_round_trips_identically(tmp_path):
    curve = _curve()
    path = write_curve(curve, tmp_path / "c.json")
    again = read_curve(path)
    assert np.array_equal(again.u, curve.u) and np.array_equal(again.T, curve.T)
    assert again.to_dict() == curve.to_dict()
    assert json.loads(path.read_text())["schema"] == SCHEMA


def test_file_with_only_u_and_T_is_read(tmp_path):
    path = tmp_path / "plain.json"
    path.write_text(json.dumps({"u": [0, 1e-6, 2e-6], "T": [0, 40.0, 50.0]}))
    curve = read_curve(path)
    assert curve.N is None and curve.mu is None
    assert curve.T[-1] == 50.0


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda d: d.pop("T"), "missing required array 'T'"),
        (lambda d: d.update(u=d["u"][:-1]), "differ in length"),
        (lambda d: d.update(u=[0.0, 2e-6, 1e-6, 3e-6, 4e-6, 5e-6, 6e-6]), "strictly increasing"),
        (lambda d: d.update(T=[0.0, -1.0] + d["T"][2:]), "non-negative"),
        (lambda d: d.update(u=[1e-9] + d["u"][1:]), "starts at (0, 0)"),
        (lambda d: d.update(N=-3.0), "N must be > 0"),
        (lambda d: d.update(mu=-0.1), "mu must be >= 0"),
        (lambda d: d.update(T=["a"] * 7), "list of numbers"),
        (lambda d: d.update(schema="damper-virgin-curve/9"), "newer"),
        (lambda d: d.update(u=[0.0]), "differ in length"),
    ],
)
def test_malformed_curve_file_gets_clear_error(tmp_path, mutate, message):
    data = _curve().to_dict()
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_curve(path)


def test_truncated_curve_file_gets_clear_error(tmp_path):
    text = json.dumps(_curve().to_dict())
    path = tmp_path / "cut.json"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(ValueError, match="not valid JSON"):
        read_curve(path)


def test_nonfinite_values_are_refused(tmp_path):
    path = tmp_path / "nan.json"
    path.write_text('{"u": [0, 1e-6, NaN], "T": [0, 1, 2]}')
    with pytest.raises(ValueError, match="finite"):
        read_curve(path)
