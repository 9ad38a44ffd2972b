"""The hb benchmark's model classes: definitions, stored references, peak reading, and a
smoke run of one row (the whole benchmark and its peers run by hand, never in CI)."""
import json

import numpy as np
import pytest

from damper.bench import hb_classes, hb_reference, peer_pyharm, peers
from harmonic_balance import bench_models as bm
from harmonic_balance.model import load_model

#: The engine's single-DOF soft peak (H = 15, default AFT and steps) against the H = 45
#: dense reference: H truncation and the 256-sample AFT, measured 1.2e-5 (the trace at
#: H = 15 alone, 1.6e-5); 1e-4 leaves room for a coarser but sound step control.
SDOF_PEAK_RTOL = 1e-4
#: The same peak's frequency against the reference [rad/s] (measured 1.2e-4 apart: the
#: engine refines the peak of max |x|, the reference that of the first harmonic).
SDOF_OMEGA_ATOL = 1e-3


def test_chain3_is_nlvibs_chain_of_oscillators():
    """NLvib's ChainOfOscillators: K = diag(k_i + k_i+1) - offdiag(k_i+1), C = 0.02 K,
    Jenkins links on w = e_1 and w = e_2 - e_1 (stuck: + knl w w^T), force on mass 2."""
    c = bm.chain3(force=2.0, knl=200.0, down=True)
    ki = np.ones(4)
    K = np.diag(ki[:-1] + ki[1:]) - np.diag(ki[1:-1], -1) - np.diag(ki[1:-1], 1)
    np.testing.assert_array_equal(c.K, K)
    np.testing.assert_allclose(c.C, 0.02 * K)
    np.testing.assert_array_equal(c.force, [0.0, 2.0, 0.0])
    w1, w2 = np.array([1.0, 0, 0]), np.array([-1.0, 1, 0])
    np.testing.assert_allclose(c.model().stuck_stiffness(), K + 200.0 * (np.outer(w1, w1) + np.outer(w2, w2)))
    assert c.band == (2.0, 0.5) and c.response_dof == 1 and c.harmonics == 7


def test_case_names_are_unique_and_found():
    names = [c.name for c in bm.all_cases()]
    assert len(names) == len(set(names)) == 3 + 18 + 2
    assert bm.by_name("chain5 down").band == (2.2, 0.3)
    links = bm.chain5().links
    assert len(links) == 3 and len({j.k for j in links}) == 3 and len({j.fs for j in links}) == 3
    with pytest.raises(ValueError, match="known: sdof soft"):
        bm.by_name("chain4")


def test_every_reference_is_stored_for_its_model():
    """The benchmark reads its references, never recomputes them: every model has an entry
    whose fingerprint is that of the current definition (regenerate with
    ``python -m damper.bench.hb_reference --write`` after changing a model)."""
    stored = json.loads(hb_reference.REFERENCE_FILE.read_text())
    for key in hb_reference.keys():
        entry = stored[key]
        assert entry["fingerprint"] == hb_reference.fingerprint(key), key
        assert entry["amplitude"] > 0 and entry["error_estimate"] < 1e-2 and entry["how"], key
        assert hb_reference.load(key, compute_missing=False) == entry


def test_curve_peak_reads_the_vertex_of_a_parabola():
    w = np.linspace(0.9, 1.1, 11)
    a = 2.0 - 3.0 * (w - 1.013) ** 2
    amp, om, change = hb_reference.curve_peak(w[::-1], a[::-1])   # traced downwards alike
    assert amp == pytest.approx(2.0, rel=1e-12) and om == pytest.approx(1.013, rel=1e-12)
    assert 0 < change < 1e-3
    # the largest point at an end, or neighbours not monotone in omega (a fold): the point
    assert hb_reference.curve_peak(w, w)[:2] == (1.1, 1.1)
    assert hb_reference.curve_peak([1.0, 1.2, 1.1], [0.5, 1.0, 0.7])[:2] == (1.0, 1.2)
    assert np.isnan(hb_reference.curve_peak([], [])[0])


def test_cli_files_pose_the_same_model(tmp_path):
    """The .npz / .toml written for ``damper frf`` load into the case's own model."""
    case = bm.chain5(down=True)
    argv = hb_classes._write_model(case, tmp_path)
    m = load_model(argv[argv.index("--model") + 1], argv[argv.index("--elements") + 1])
    ref = case.model()
    np.testing.assert_array_equal(m.stuck_stiffness(), ref.stuck_stiffness())
    np.testing.assert_array_equal(m.linear.C, ref.linear.C)
    np.testing.assert_array_equal(m.forcing[1], ref.forcing[1])
    assert m.response_dof == 2 and argv[argv.index("--omega") + 1:][:2] == ["2.2", "0.3"]


def test_peer_inputs_pose_the_same_model():
    spec = {**bm.chain3(1.0, 20.0, down=True).spec(), **hb_classes.PEER_SETTINGS, "x0": "stuck"}
    d = peer_pyharm.idata(spec)
    jen = [v for v in d["connectors"].values() if v["type"] == "Jenkins"]
    assert [j["connect"] for j in jen] == [{"chain": [0]}, {"chain": [1], "INTERNAL": [0]}]
    assert all(j["mu"] * j["N0"] == 1.0 and j["k"] == 20.0 for j in jen)
    frf = d["analysis"]["FRF"]
    assert (frf["puls_inf"], frf["puls_sup"], frf["sign_ds"]) == (0.5, 2.0, -1)
    assert d["system"]["nh"] == 7
    # NLvib's case file: -1 is the ground (Octave's JSON arrays have no null)
    assert peers._spec(bm.chain3(), "nlvib", {}, "free")["links"][0] == [0, -1, 20.0, 1.0]


def test_missing_peers_say_what_to_give(tmp_path):
    assert "give --pyharm" in peers.available("pyharm", None)
    assert "no interpreter" in peers.available("pyharm", str(tmp_path / "python"))
    assert "not an NLvib folder" in peers.available("nlvib", str(tmp_path))


def test_smoke_row_sdof_soft(tmp_path):
    """One cheap row end to end (the CLI in a child, the stored reference): complete, and
    its first-harmonic peak within SDOF_PEAK_RTOL of the dense reference."""
    rows = [r.as_dict() for r in hb_classes.run(True, tmp_path, log=lambda s: None)]
    assert [r["case"] for r in rows] == ["sdof soft [damper]"]
    r = rows[0]
    ref = r["reference"]
    assert r["complete"] and not r["gaps"] and r["points"] > 10 and r["evaluations"] >= r["points"]
    assert r["error"] < SDOF_PEAK_RTOL and r["trace_error"] < SDOF_PEAK_RTOL
    assert abs(r["peak_omega"] - ref["omega"]) < SDOF_OMEGA_ATOL
    assert r["time_s"] > 0 and r["cpu_s"] > 0 and r["memory_mb"] > 0
    assert (r["dofs"], r["harmonics"], r["size"]) == (1, 15, 31.0)
    text = hb_classes.table(rows)
    assert "sdof soft" in text and "own error" in text


def test_cli_files_of_cases_with_dotted_names_stay_apart(tmp_path):
    """A case named with a decimal ("F=0.5") keeps its whole name in its files' names, so two
    such cases never write to one file."""
    import dataclasses

    a = bm.chain3(1.0, 20.0, down=True)
    b = dataclasses.replace(a, name="chain3 F=0.5 knl=2000")
    c = dataclasses.replace(a, name="chain3 F=0.5 knl=20")
    files = {}
    for case in (b, c):
        argv = hb_classes._write_model(case, tmp_path)
        files[case.name] = (argv[argv.index("--model") + 1], argv[argv.index("--elements") + 1])
    assert files[b.name][0] != files[c.name][0] and files[b.name][1] != files[c.name][1]
    assert files[b.name][0].endswith("chain3_F0.5_knl2000.npz")
