"""Per-point contact laws (UPDConfig.contacts): the plumbing that geometry-derived
contacts (contact_core virgin curves) use. A Jenkins law given as an explicit Iwan
element must reproduce the built-in Jenkins points exactly."""
import numpy as np
import pytest

from fmu_src.element import IwanElement
from harmonic_balance.bladed_disk.config import UPDConfig, load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.timeint import march_ring


def _jenkins_overrides(cfg):
    """The TOML's own Jenkins laws as explicit elements (slip force mu N: fs = mu at N_ref = 1)."""
    return {c.name: {"kn": c.kn, "friction": IwanElement.jenkins(c.kt, cfg.mu)}
            for c in cfg.contact_points()}


def test_explicit_jenkins_elements_reproduce_the_default_residual():
    cfg = load_config()
    ref = SectorHB(Sector(cfg), 3)
    over = SectorHB(Sector(UPDConfig(cfg.data, _jenkins_overrides(cfg))), 3)
    w = 2 * np.pi * 450.0
    x = ref.stuck_guess(w) * 1.3  # well into slip and partly lifted off
    R1, J1, _ = ref(x, w)
    R2, J2, _ = over(x, w)
    assert np.array_equal(R1, R2) and np.array_equal(J1, J2)


def test_explicit_jenkins_elements_reproduce_the_ring_time_integration():
    cfg = load_config()
    cfg2 = UPDConfig(cfg.data, _jenkins_overrides(cfg))
    w = [2 * np.pi * 450.0]
    a = march_ring(Sector(cfg), w, max_periods=3)
    b = march_ring(Sector(cfg2), w, max_periods=3)
    assert np.array_equal(a["amplitude"], b["amplitude"])


def test_override_changes_the_stuck_stiffness_and_survives_with_values():
    cfg = load_config()
    soft = {"left": {"kn": 2e7, "friction": IwanElement.jenkins(1e7, cfg.mu)}}
    cfg2 = UPDConfig(cfg.data, soft).with_values(load__cf=60.0)
    left = cfg2.contact_points()[0]
    assert (left.kn, left.kt) == (2e7, 1e7) and cfg2.cf == 60.0


@pytest.mark.parametrize("bad", [{"middle": {"kn": 1e8}}, {"left": {"kt": 1e8}},
                                 {"left": {"kn": -1.0}}, {"left": {"kn": float("nan")}}])
def test_bad_overrides_are_refused_with_the_point_named(bad):
    with pytest.raises(ValueError, match="contact override"):
        UPDConfig(load_config().data, bad).validate()
