"""The normal approach curve file (contact_core.normal_curve) and ``damper normal
--normal-curve``: written from the FE solution, read back, refused when not monotone."""
from __future__ import annotations

import json

import numpy as np
import pytest

from contact_core.hertz import contact_modulus, sphere
from contact_core.normal_curve import NormalCurve, read_normal_curve, write_normal_curve
from damper.cli import main as damper

#: The coarse half-space grid's approach against Hertz (the CLI test of test_normal.py
#: uses the same model): within 5 %, the grid's own error.
HERTZ_RTOL = 0.05


def test_round_trip_keeps_every_number(tmp_path):
    c = NormalCurve([0.0, 1e-6, 2e-6], [0.0, 50.0, 140.0], load=140.0, k_n=[5e7, 5e7, 9e7],
                    provenance={"note": "kept"})
    back = read_normal_curve(write_normal_curve(c, tmp_path / "n.json"))
    assert np.array_equal(back.approach, c.approach) and np.array_equal(back.N, c.N)
    assert back.load == 140.0 and back.provenance == {"note": "kept"}


@pytest.mark.parametrize("p, N, message", [
    ([0, 1e-6, 2e-6], [0, 50, 40], "N must increase strictly"),
    ([0, 2e-6, 1e-6], [0, 50, 90], "approach must increase strictly"),
    ([1e-7, 2e-6], [0, 50], "start at"),
    ([0, np.nan], [0, 50], "finite"),
])
def test_bad_curves_are_refused(tmp_path, p, N, message):
    with pytest.raises(ValueError, match=message):
        NormalCurve(p, N)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"schema": "damper-normal-curve/1", "approach": p, "N": N}))
    with pytest.raises(ValueError, match=message):
        read_normal_curve(path)


def test_cli_writes_the_normal_curve(tmp_path, capsys):
    out = tmp_path / "normal.json"
    rc = damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "200", "--grid", "5",
                 "--model", "halfspace", "--json", "--cache-dir", str(tmp_path),
                 "--normal-curve", str(out)])
    assert rc == 0
    curve = read_normal_curve(out)
    assert curve.N[0] == 0.0 and curve.approach[0] == 0.0 and curve.N.size == 21
    assert curve.load == pytest.approx(200.0, rel=1e-8)
    hertz = sphere(200.0, 0.01, contact_modulus(200e9, 0.3, 200e9, 0.3))
    assert curve.approach[-1] == pytest.approx(hertz["approach"], rel=HERTZ_RTOL)


def test_cli_without_a_curve_writes_nothing(tmp_path, capsys, monkeypatch):
    """A result without an F-approach curve: exit 2 and neither file written."""
    import contact_core.api as api

    real = api.run_normal
    monkeypatch.setattr(api, "run_normal", lambda *a, **k: {**real(*a, **k), "curve": {}})
    out, res = tmp_path / "normal.json", tmp_path / "r.json"
    rc = damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "200", "--grid", "5",
                 "--model", "halfspace", "--cache-dir", str(tmp_path), "--out", str(res),
                 "--normal-curve", str(out)])
    assert rc == 2 and "F-approach curve" in capsys.readouterr().err
    assert not out.exists() and not res.exists()


def test_a_normal_curve_stiffer_than_any_contact_is_refused_as_a_unit_error():
    from contact_core.curve import MAX_STIFFNESS
    from contact_core.normal_curve import check_normal_table

    with pytest.raises(ValueError, match="points 1-2: a stiffness of .* N/m, above"):
        check_normal_table(np.array([0.0, 1e-6, 1e-6 * (1 + 1e-12)]), np.array([0.0, 50.0, 140.0]))
    check_normal_table(np.array([0.0, 1e-6, 2e-6]), np.array([0.0, 50.0, 50.0 + 1e-6 * MAX_STIFFNESS]))


def test_a_normal_curve_short_of_the_load_is_refused(tmp_path, capsys):
    """One curve point is 5 % of the load: the normal law written ended at 5 N for a 100 N load."""
    from contact_core.normal_curve import NormalCurve

    out = tmp_path / "normal.json"
    rc = damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "100", "--grid", "5",
                 "--model", "halfspace", "--curve", "1", "--normal-curve", str(out)])
    assert rc == 2 and "at least 2 points" in capsys.readouterr().err and not out.exists()
    short = {"force": 100.0, "curve": {"force": [5.0], "approach": [4.8e-7], "k_n": [2e7]}}
    with pytest.raises(ValueError, match="not at the load 100 N"):
        NormalCurve.from_result(short)
