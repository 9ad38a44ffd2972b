"""The virgin-curve file: round trip, validation and clear errors."""
import dataclasses
import json
import re

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
        (lambda d: d.pop("T"), "T: missing (required)"),
        (lambda d: d.update(u=d["u"][:-1]), "differ in length"),
        (lambda d: d.update(u=[0.0, 2e-6, 1e-6, 3e-6, 4e-6, 5e-6, 6e-6]), "strictly increasing"),
        (lambda d: d.update(T=[0.0, -1.0] + d["T"][2:]), "non-negative"),
        (lambda d: d.update(u=[1e-9] + d["u"][1:]), "starts at (0, 0)"),
        (lambda d: d.update(N=-3.0), "N: must be greater than 0"),
        (lambda d: d.update(mu=-0.1), "mu: must be greater than or equal to 0"),
        (lambda d: d.update(T=["a"] * 7), "T[0]: must be a valid number, got a string 'a'"),
        (lambda d: d.update(mu=True), "mu: must be a valid number, got a boolean True"),
        (lambda d: d.update(N="200"), "N: must be a valid number, got a string '200'"),
        (lambda d: d.update(note="x"), "note: unknown key"),
        (lambda d: d.update(T=[t * 1e300 for t in d["T"]]), "T[1]: must be less than or equal to"),
        (lambda d: d.update(N=60.0 / 0.5 / 3.0), "the curve contradicts its own mu and N"),
        (lambda d: d.update(schema="damper-virgin-curve/9"), "newer"),
        (lambda d: d.update(u=[0.0]), "differ in length"),
    ],
)
def test_malformed_curve_file_gets_clear_error(tmp_path, mutate, message):
    data = _curve().to_dict()
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=re.escape(message)):
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


def test_version_2_writes_and_reads_the_producers_tail(tmp_path):
    for tail in ("flat", "slope"):
        path = write_curve(dataclasses.replace(_curve(), tail=tail), tmp_path / f"{tail}.json")
        assert json.loads(path.read_text())["tail"] == tail
        assert read_curve(path).tail == tail     # stated, not guessed (T[-1] = mu N in both)


def test_version_2_without_a_tail_is_refused(tmp_path):
    data = _curve().to_dict()
    del data["tail"]
    path = tmp_path / "c.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="needs \"tail\""):
        read_curve(path)
    with pytest.raises(ValueError, match="tail must be one of"):
        VirginCurve(u=[0.0, 1.0], T=[0.0, 1.0], tail="up")


@pytest.mark.parametrize("schema", ["damper-virgin-curve/1", None])
def test_version_1_files_get_the_old_gross_slip_rule(tmp_path, schema):
    """Version 1 (or schema-less): flat iff mu and N are declared and T[-1] = mu N to 1e-6."""
    from contact_core.curve import V1_GROSS_SLIP_RTOL

    def tail_of(T_end, **meta):
        data = {"u": [0.0, 1e-6, 2e-6], "T": [0.0, 0.6 * T_end, T_end], **meta}
        if schema:
            data["schema"] = schema
        path = tmp_path / "v1.json"
        path.write_text(json.dumps(data))
        return read_curve(path).tail

    assert tail_of(50.0, mu=0.5, N=100.0) == "flat"
    assert tail_of(50.0 * (1 + 0.5 * V1_GROSS_SLIP_RTOL), mu=0.5, N=100.0) == "flat"
    assert tail_of(50.0 * (1 + 2 * V1_GROSS_SLIP_RTOL), mu=0.5, N=100.0) == "slope"
    assert tail_of(50.0, N=100.0) == "slope" and tail_of(50.0, mu=0.5) == "slope"
    assert tail_of(50.0, mu=0.0, N=100.0) == "slope"


def test_table_errors_name_the_point(tmp_path):
    for data, message in [({"u": [0, 1e-6, 1e-6], "T": [0, 1, 2]}, r"point 2: u = 1e-06 is not above u\[1\]"),
                          ({"u": [0, 1e-6, 2e-6], "T": [0, 1, -2]}, r"point 2: T = -2.0 is negative"),
                          ({"u": [], "T": []}, "empty")]:
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(data))
        with pytest.raises(ValueError, match=message):
            read_curve(path)


def test_a_curve_steeper_than_any_contact_is_refused_as_a_unit_error():
    """u in units 1e300 times too small: slopes of ~6e307 N/m (the element then bounded its
    input at 1e-297 m); the same table at MAX_STIFFNESS is accepted."""
    from contact_core.curve import MAX_STIFFNESS

    with pytest.raises(ValueError, match="points 0-1: a slope of .* N/m, above"):
        VirginCurve(u=[0.0, 1e-306, 2e-306], T=[0.0, 50.0, 60.0])
    VirginCurve(u=[0.0, 1e-6, 2e-6], T=[0.0, MAX_STIFFNESS * 1e-6, MAX_STIFFNESS * 1e-6])
