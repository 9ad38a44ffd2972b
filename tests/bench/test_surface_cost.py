"""The surface stage's cost rows (damper.bench.surface_cost): one row per model, node count
and H, with the evaluation's own figures and the derived costs per node and per coefficient."""
import pytest

from damper.bench import report, surface_cost
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector


@pytest.mark.slow
def test_surface_rows_report_each_model_with_its_unknowns_and_costs():
    lines = []
    rows = [r.as_dict() for r in surface_cost.run(True, lines.append)]
    assert lines[0] == surface_cost.HEAD and len(lines) == 1 + len(surface_cost.QUICK_CASES)
    by = {r["case"]: r for r in rows}
    cond, nodes = by["cost surface condensed H 1"], by["cost surface nodes H 1"]
    n_dof = Sector(load_config(None)).n_dof
    # the condensed model's unknowns are the sector's alone (2 H + 1 coefficients each);
    # the node-DOF model adds its nodes' DOFs
    assert cond["unknowns"] == n_dof * 3
    assert nodes["unknowns"] > cond["unknowns"] + cond["surface_nodes"]
    for r in rows:
        assert r["size"] == 5 and r["error"] is None and r["time_s"] == r["eval_jac_s"] > 0
        assert r["time_per_node_s"] == pytest.approx(r["time_s"] / r["surface_nodes"])
        assert r["time_per_coefficient_s"] == pytest.approx(r["time_s"] / 3)
    md = surface_cost.markdown(rows)
    assert len(md) == 2 + len(rows) and md[0].count("|") == len(surface_cost.COLUMNS) + 1
    assert "ms" not in md[2] and len(report._plot("surface", rows)) > 100
