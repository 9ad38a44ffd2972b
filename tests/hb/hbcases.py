"""Small models shared by the harmonic-balance tests.

Friction elements come from the C core (``fmu_src.element``). Setting the
environment variable ``HB_TEST_ORACLE=1`` swaps in the slow Python oracle
(:mod:`jenkins_ref`), for debugging the HB code independently of the C build.
"""
from __future__ import annotations

import os

import numpy as np

from harmonic_balance.aft import FrictionLink
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model

#: Seed of every random draw in these tests (written out, as the guide asks).
SEED = 20261122


def jenkins(k: float, fs: float):
    """A Jenkins element: the C core's, or the oracle when HB_TEST_ORACLE=1."""
    if os.environ.get("HB_TEST_ORACLE") == "1":
        from jenkins_ref import JenkinsRef

        return JenkinsRef(k, fs)
    from fmu_src.element import IwanElement

    return IwanElement.jenkins(k, fs)


def sdof(m=1.0, k=1.0, c=0.01, kt=1.0, fs=0.05, P=0.05) -> Model:
    """m x'' + c x' + k x + F_jenkins(x; kt, fs) = P cos(omega t), element to ground."""
    lin = LinearModel(M=[[m]], C=[[c]], K=[[k]])
    return Model(lin, [FrictionLink(jenkins(kt, fs), 0)], {1: np.array([P])})


def two_dof(c_prop=True, fs=0.04, P=0.05) -> Model:
    """Two masses on springs, a Jenkins element between them and one to the ground.

    With ``c_prop`` the damping is Rayleigh (modal receptance); otherwise a dashpot
    on DOF 0 only (non-proportional: direct receptance).
    """
    M = np.diag([1.0, 0.5])
    K = np.array([[2.0, -1.0], [-1.0, 1.5]])
    C = 0.01 * M + 0.005 * K if c_prop else np.diag([0.02, 0.0])
    links = [FrictionLink(jenkins(0.8, fs), 0, 1, "between"),
             FrictionLink(jenkins(0.5, 2.0 * fs), 1, None, "ground")]
    return Model(LinearModel(M=M, C=C, K=K), links, {1: np.array([P, 0.0])}, response_dof=0)


def condensed_flat_face(cache, normal_load: float, mu: float, penalty: float):
    """A small flat face (5 x 5 grid, 15 contact nodes, planar: z and x) condensed onto its
    rigid inputs, preloaded by ``normal_load`` [N]: (CondensedSurface, q_static (r,), surface)."""
    from contact_core.condense import condense
    from contact_core.spec import ContactSpec
    from harmonic_balance import surface as sf
    from harmonic_balance import surface_static as ss
    from harmonic_balance.kinematics import Kinematics
    from harmonic_balance.surface_condensed import CondensedSurface

    cc = condense(ContactSpec(body="flat", width=1.2e-3, length=1.2e-3, grid=5), directions=("z", "x"),
                  cache=cache)
    surface = sf.build(cc, mu, penalty=penalty, tangents=("x",))
    x = ss.preload(surface, normal_load).x
    slips = [x[surface.d * i] for i in range(surface.n)]
    kin = Kinematics(list(range(len(surface.inputs))), np.eye(len(surface.inputs)))
    return CondensedSurface(surface, kin, x[surface.n_w:], x[:surface.n_w], slips), x[surface.n_w:], surface
