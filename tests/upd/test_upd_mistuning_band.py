"""A pattern whose largest peak lies at the default band's end is searched on the band
widened there (damper.mistuning._solve_sample); a user's band is kept, and the pattern
fails with its message. The solves are stand-ins: the widening's logic alone."""
import numpy as np
import pytest

from damper import mistuning
from damper.mistuning import BAND_WIDENINGS, SampleModel, Study


def _model(band_hz=None, std=0.02):
    study = Study(std=std, samples=1, blades=4, engine_order=1, damper="free", band_hz=band_hz)
    return SampleModel(study, band_hz or [400.0, 500.0], 450.0)


def _stand_in(peaks_hz, seen):
    """_solve_on returning the largest peak at peaks_hz[i] [Hz] on its i-th call (None: at
    the band's upper end), recording each call's band [Hz]."""
    def solve_on(model, kappa, om):
        seen.append((om[0] / 2 / np.pi, om[-1] / 2 / np.pi))
        f = peaks_hz[len(seen) - 1]
        w = om[-1] if f is None else 2 * np.pi * f
        return {"peak_per_blade": [1.0], "evaluations": 1}, float(w)
    return solve_on


def test_a_peak_at_the_default_bands_end_is_searched_on_the_band_widened_there(monkeypatch):
    seen = []
    monkeypatch.setattr(mistuning, "_solve_on", _stand_in([None, 503.0], seen))
    model = _model()
    out = mistuning._solve_sample(model, np.ones(4))
    m = 1.0 + mistuning.BAND_MARGIN + mistuning.BAND_SIGMAS * 0.01   # sigma_f = std / 2
    assert seen[0] == pytest.approx((400.0, 500.0))
    assert seen[1] == pytest.approx((400.0, 500.0 * m))          # only the upper end moves
    assert out["band_widened"] == 1 and out["band_hz"] == pytest.approx([400.0, 500.0 * m])
    assert out["evaluations"] == 2   # both solves' (one each in the stand-in)


def test_the_widening_stops_after_its_limit_with_the_bands_message(monkeypatch):
    seen = []
    monkeypatch.setattr(mistuning, "_solve_on", _stand_in([None] * (BAND_WIDENINGS + 1), seen))
    with pytest.raises(RuntimeError, match="band's end"):
        mistuning._solve_sample(_model(), np.ones(4))
    assert len(seen) == BAND_WIDENINGS + 1


def test_a_users_band_is_not_widened(monkeypatch):
    seen = []
    monkeypatch.setattr(mistuning, "_solve_on", _stand_in([None, 503.0], seen))
    with pytest.raises(RuntimeError, match="give a wider --band"):
        mistuning._solve_sample(_model(band_hz=[400.0, 500.0]), np.ones(4))
    assert len(seen) == 1


def test_a_peak_inside_is_solved_once_on_the_band(monkeypatch):
    seen = []
    monkeypatch.setattr(mistuning, "_solve_on", _stand_in([450.0], seen))
    out = mistuning._solve_sample(_model(), np.ones(4))
    assert len(seen) == 1 and out["band_widened"] == 0 and out["band_hz"] == pytest.approx([400.0, 500.0])
