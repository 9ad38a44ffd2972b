"""The path in CF (harmonic_balance.bladed_disk.load_path): its loads, halvings and failure.

A stand-in Newton that converges only over load steps of ratio at most REACH (the
solution is the load itself) checks the path's logic without a sector: the real models'
paths are checked in tests/upd/test_upd_surface_cli.py.
"""
import math

import numpy as np
import pytest

from harmonic_balance.bladed_disk import load_path
from harmonic_balance.bladed_disk.solve import SolverError
from harmonic_balance.newton import NewtonError

#: Largest load ratio the stand-in Newton crosses from its warm start.
REACH = 1.3


class _Model:
    def __init__(self, cf):
        self.cf = cf

    def stuck_guess(self, omega):
        return np.array([self.cf])   # the stuck start is the solution: the start always converges


def _newton(hb, omega, x0, max_iter):
    if abs(math.log(hb.cf / x0[0])) > math.log(REACH) + 1e-12:
        raise NewtonError("too far", x0, max_iter, 1.0)
    return np.array([hb.cf])


@pytest.fixture
def stand_in(monkeypatch):
    monkeypatch.setattr(load_path, "solve_point", _newton)


def test_path_halves_failed_steps_until_each_is_within_reach(stand_in):
    x, loads = load_path.cf_path(_Model, 1.0, 120.0, 815.0)
    ratios = np.array(loads[:-1]) / np.array(loads[1:])
    assert x[0] == 120.0 and loads[0] == 815.0 and loads[-1] == 120.0
    assert np.all(ratios > 1.0) and np.all(ratios <= REACH + 1e-12)
    # the default steps are the fewest of ratio at most STEP_RATIO, each halved in log CF
    # (k times) until within reach
    steps = math.ceil(math.log(815.0 / 120.0) / math.log(load_path.STEP_RATIO))
    k = math.ceil(math.log2(math.log(815.0 / 120.0) / steps / math.log(REACH)))
    assert len(loads) - 1 == steps * 2**k


def test_a_start_at_or_below_the_cf_is_newton_at_the_cf_alone(stand_in):
    x, loads = load_path.cf_path(_Model, 1.0, 120.0, 60.0)
    assert loads == [120.0] and x[0] == 120.0


def test_a_step_beyond_its_halvings_is_a_solver_error_naming_the_load(stand_in, monkeypatch):
    monkeypatch.setattr(load_path, "MAX_HALVINGS", 0)
    with pytest.raises(SolverError, match=r"from 815 N to 120 N at .* failed at 4\d\d\.?\d* N .*raise the CF"):
        load_path.cf_path(_Model, 2 * np.pi * 400.0, 120.0, 815.0)


def test_a_step_that_meets_a_wall_gives_up_after_its_failure_budget(stand_in, monkeypatch):
    """Below a wall no warm start converges: without a budget the step's halvings would try
    2^(MAX_HALVINGS + 1) - 1 Newton solves, each a few hundred evaluations on a real model."""
    wall, calls = 70.0, []

    def newton(hb, omega, x0, max_iter):
        calls.append(hb.cf)
        if hb.cf < wall:
            raise NewtonError("no equilibrium", x0, max_iter, 1.0)
        return _newton(hb, omega, x0, max_iter)
    monkeypatch.setattr(load_path, "solve_point", newton)
    with pytest.raises(SolverError, match=r"the last load solved: 7\d\.?\d* N"):
        load_path.cf_path(_Model, 2 * np.pi * 400.0, 40.0, 815.0)
    failures = sum(c < wall for c in calls)
    assert failures == load_path.MAX_STEP_FAILURES
