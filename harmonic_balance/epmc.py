"""Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015).

The backbone of a friction-damped mode: frequency and modal damping against
amplitude (M. Krack, "Nonlinear modal analysis of nonconservative systems:
extension of the periodic motion concept", Computers & Structures 154, 2015).
The forcing is removed and an artificial negative mass-proportional damping
``-xi M x'`` makes the damped free motion periodic::

    M x'' + (C - xi M) x' + K x + f_nl(x) = 0

In harmonics, with the response normalised by its modal amplitude a
(x = a X~, so every unknown is O(1) over decades of a)::

    G = [A(omega) a X~ + F_nl(a X~) - xi omega (D_theta (x) M) a X~] / (a k_s) = 0
    sqrt(X~_1^T M X~_1) - 1 = 0        (mass-normalised fundamental: amplitude a)
    X~_1,sin[ref] = 0                   (phase: x_ref ~ cos(theta) in harmonic 1)

with k_s the largest stuck stiffness (makes G dimensionless). Unknowns
(X~, omega, xi), continuation parameter log10(a) through
:func:`continuation.continuation` (it knows only R(y, lam) and its derivatives).
The modal damping ratio is ``D = xi / (2 omega)``; at a given amplitude the
forced-response peak lies on the backbone when the excitation balances the
damping (phase resonance), which the tests check.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .continuation import ContinuationError, continuation
from .fourier import FourierBasis, parse_harmonics
from .model import Model
from .residual import FullResidual

#: Newton tolerance on the dimensionless residual.
TOL = 1e-10


class EPMCError(RuntimeError):
    """The backbone could not be completed; ``result`` holds the points so far."""

    def __init__(self, message, result):
        super().__init__(message)
        self.result = result


@dataclass
class Backbone:
    """Backbone (SI): modal amplitude a [m sqrt(kg)], omega [rad/s], xi [1/s], damping
    ratio D = xi / (2 omega), peak |x| of the response DOF [m], per point."""

    a: np.ndarray
    omega: np.ndarray
    xi: np.ndarray
    damping_ratio: np.ndarray
    amplitude: np.ndarray
    newton_iterations: int
    status: str = "complete"
    #: (n, N + 2) the solved unknowns (X~, omega, xi) per point (:class:`EPMCProblem`), for
    #: re-solving a point with more harmonics (:mod:`.epmc_accuracy`); not in the summary.
    y: np.ndarray | None = None

    def summary(self) -> dict:
        return {"modal_amplitude": self.a.tolist(), "omega": self.omega.tolist(),
                "xi": self.xi.tolist(), "damping_ratio": self.damping_ratio.tolist(),
                "amplitude": self.amplitude.tolist(), "points": int(self.a.size),
                "newton_iterations": self.newton_iterations, "status": self.status}


class EPMCProblem:
    """The EPMC residual R(y, log10 a) of one mode (module docstring)."""

    def __init__(self, model: Model, harmonics, n_t: int = 0, mode: int = 0):
        lin = model.linear
        if lin.M is None or lin.K is None:
            raise ValueError("EPMC needs a matrix model (M, C, K)")
        self.model, self.basis = model, FourierBasis(parse_harmonics(harmonics), n_t)
        if 1 not in self.basis.harmonics:
            raise ValueError("EPMC needs harmonic 1")
        self.full = FullResidual(model, self.basis)
        self.f = self.full.Fext.ravel()
        n, b = model.n, self.basis
        self.DM = np.kron(b.dtheta, lin.M)
        Ks = model.stuck_stiffness()
        lam, phi = sla.eigh(Ks, lin.M)
        if not 0 <= mode < n:
            raise ValueError(f"mode {mode} outside 0..{n - 1}")
        self.phi, self.w0 = phi[:, mode], float(np.sqrt(max(lam[mode], 0.0)))
        self.ref = int(np.argmax(np.abs(self.phi)))
        self.ks = float(np.abs(np.diag(Ks)).max())
        ic, isn = b.index(1)
        self.i_cos = ic * n + np.arange(n)
        self.i_sin = isn * n + np.arange(n)
        self.M = lin.M
        self.N = b.nb * n

    def start(self) -> np.ndarray:
        """Linear stuck mode: X~ = phi cos(theta), omega_0, xi = phi^T C phi."""
        y = np.zeros(self.N + 2)
        y[self.i_cos] = self.phi * np.sign(self.phi[self.ref])
        y[-2] = self.w0
        y[-1] = float(self.phi @ self.model.linear.C @ self.phi)
        return y

    def __call__(self, y, lam):
        a = 10.0**lam
        Xt, w, xi = y[:-2], y[-2], y[-1]
        R, J, dw = self.full(a * Xt, w)
        Nf = R + self.f - xi * w * (self.DM @ (a * Xt))
        JN = J - xi * w * self.DM
        G = Nf / (a * self.ks)
        x1 = np.concatenate([Xt[self.i_cos], Xt[self.i_sin]])
        M2 = sla.block_diag(self.M, self.M)
        q = float(np.sqrt(x1 @ M2 @ x1))
        Rf = np.concatenate([G, [q - 1.0, Xt[self.i_sin[self.ref]]]])
        Jf = np.zeros((self.N + 2, self.N + 2))
        Jf[:self.N, :self.N] = JN / self.ks
        Jf[:self.N, -2] = (dw - xi * (self.DM @ (a * Xt))) / (a * self.ks)
        Jf[:self.N, -1] = -w * (self.DM @ Xt) / self.ks
        g = (M2 @ x1) / max(q, 1e-300)
        Jf[self.N, self.i_cos] = g[:len(self.i_cos)]
        Jf[self.N, self.i_sin] = g[len(self.i_cos):]
        Jf[self.N + 1, self.i_sin[self.ref]] = 1.0
        dlam = np.zeros(self.N + 2)
        dlam[:self.N] = np.log(10.0) * (JN @ Xt - Nf / a) / self.ks
        return Rf, Jf, dlam

    def amplitude(self, y, lam) -> float:
        r = self.model.response_dof
        X = (10.0**lam * y[:-2]).reshape(self.basis.nb, self.model.n)
        return self.basis.peak_abs(X[:, r])


def compute_backbone(model: Model, harmonics, a_range, n_t: int = 0, mode: int = 0,
                     ds_max: float = 0.1, max_points: int = 2000) -> Backbone:
    """Backbone of mode ``mode`` (of the stuck linear system) over modal amplitudes
    ``a_range = (a_start, a_end)`` [m sqrt(kg)] (a_start small: the start is the linear mode).

    Raises
    ------
    ValueError for bad input; EPMCError (a RuntimeError) with the points computed so far.
    """
    a0, a1 = (float(v) for v in a_range)
    if not (np.isfinite(a0) and np.isfinite(a1)) or a0 <= 0 or a1 <= 0 or a0 == a1:
        raise ValueError(f"amplitude range must be two different positive numbers, got {a_range}")
    prob = EPMCProblem(model, harmonics, n_t, mode)
    try:
        br = continuation(prob, prob.start(), np.log10(a0), np.log10(a1), TOL, ds_max=ds_max,
                          max_points=max_points)
        status = "complete"
    except ContinuationError as err:
        br, status = err.branch, str(err)
    lam = np.asarray(br.lam)
    Y = np.array(br.x) if br.x else np.zeros((0, prob.N + 2))
    w = Y[:, -2] if len(Y) else np.zeros(0)
    xi = Y[:, -1] if len(Y) else np.zeros(0)
    amp = np.array([prob.amplitude(y, l) for y, l in zip(br.x, lam)])
    bb = Backbone(10.0**lam, w, xi, xi / (2.0 * np.where(w > 0, w, np.nan)), amp,
                  int(sum(br.iterations)), status, Y)
    if status != "complete":
        raise EPMCError(status, bb)
    return bb
