"""Reference checks that the documentation's validation table lists.

A test compares a computed quantity with an independent reference (a closed-form
solution, a different method, a published value) through :func:`check`, which asserts
and records the comparison: the quantity, the reference's source, our value, the
reference value, the tolerance and the test that made it. ``tests/conftest.py`` writes
the records of a run to ``$DAMPER_VALIDATION_JSON`` when it is set; ``make validation``
runs the tests that call :func:`check` and keeps the result as
``docs/data/validation.json``, from which the documentation renders its table. So the
table holds exactly the checks the tests make, with the values of the last run, and
the check cannot drift from the assert: it is the assert.

Arrays are compared element by element; the record keeps the element that uses the
largest share of its tolerance, its error ``|value - reference|`` and its bound
``atol + rtol |reference|``. ``docs/tools/validation_check.py`` fails when a run's error
grows past ``growth`` times the recorded one, so a regression well inside a tolerance
still shows.

Each check states its ``kind``: ``"independent"`` when the reference owes nothing to this
code (a closed form, a published value, an independent implementation), or
``"self-consistency"`` when the reference is another part of the same code (a time
integration through the same friction element, the linear limit from the same sector
matrices, the EPMC backbone of the same model). The validation page lists the two apart.
"""
from __future__ import annotations

import os

import numpy as np

#: Records of this session (appended by :func:`check`, written by the conftest hook).
RECORDS: list[dict] = []
#: The kinds of reference (see the module docstring).
KINDS = ("independent", "self-consistency")
#: Default growth factor of the recorded error before docs/tools/validation_check.py fails:
#: errors move with the code by round-off or by a discretisation's small changes; a
#: tenfold growth is a change of method or a regression.
GROWTH = 10.0


def _test_id() -> str:
    """The running test's node id (pytest sets ``PYTEST_CURRENT_TEST``: 'path::name (call)')."""
    return os.environ.get("PYTEST_CURRENT_TEST", "?").rsplit(" (", 1)[0]


def check(quantity: str, value, reference, *, rtol: float = 0.0, atol: float = 0.0, source: str,
          kind: str = "independent", growth: float = GROWTH) -> None:
    """Assert ``|value - reference| <= atol + rtol |reference|`` (elementwise) and record it.

    Parameters
    ----------
    quantity : str
        What is compared, with its unit, e.g. ``"contact radius a [m], sphere R = 10 mm, 200 N"``.
    value, reference : float or array_like
        Our result and the reference (same shape, or a scalar reference).
    rtol, atol : float
        Relative and absolute tolerance (the test's named constants); at least one > 0.
    source : str
        Where the reference comes from, e.g. ``"Hertz (Johnson 1985, eq. 4.22)"``.
    kind : {"independent", "self-consistency"}
        Whether the reference is independent of this code or another part of it.
    growth : float
        Factor by which the error may grow over the recorded one before the validation
        check fails (> 1; larger for errors that move with unrelated changes).
    """
    if not (rtol > 0.0 or atol > 0.0):
        raise ValueError("refcheck.check needs rtol > 0 or atol > 0")
    if kind not in KINDS:
        raise ValueError(f"refcheck.check: kind must be one of {KINDS}, not {kind!r}")
    if not growth > 1.0:
        raise ValueError(f"refcheck.check: growth must be > 1, not {growth!r}")
    v = np.atleast_1d(np.asarray(value, dtype=float))
    r = np.broadcast_to(np.atleast_1d(np.asarray(reference, dtype=float)), v.shape)
    bound = atol + rtol * np.abs(r)
    dev = np.abs(v - r)
    share = np.where(bound > 0, dev / np.where(bound > 0, bound, 1.0), np.inf)
    share = np.where(np.isnan(dev), np.inf, share)
    i = int(np.argmax(share))
    passed = bool(np.all(dev <= bound))
    tol = " + ".join(t for t in (f"rel {rtol:g}" if rtol else "", f"abs {atol:g}" if atol else "") if t)
    RECORDS.append({"test": _test_id(), "quantity": quantity, "source": source, "kind": kind,
                    "value": float(v[i]), "reference": float(r[i]), "tolerance": tol,
                    "error": float(dev[i]), "bound": float(bound[i]), "growth": float(growth),
                    "elements": int(v.size), "passed": passed})
    assert passed, (f"{quantity}: {v[i]:.6g} against {source} {r[i]:.6g} (element {i} of {v.size}), "
                    f"off by {dev[i]:.3g} > {bound[i]:.3g} ({tol})")
