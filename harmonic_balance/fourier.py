"""Real Fourier representation of periodic signals and the AFT time grid.

Symbols (used in the whole package)
-----------------------------------
theta = omega t          phase [rad], one period is 0 <= theta < 2 pi
H                        highest retained harmonic
h                        a retained harmonic index (0 = mean)
n_b                      number of real basis coefficients per DOF
n_t                      number of time samples per period in the AFT

Ordering (defined here once, used everywhere)
---------------------------------------------
A signal ``u(theta) = a_0 + sum_h (a_h cos(h theta) + b_h sin(h theta))`` is stored as
the coefficient vector ``[a_0, a_h1, b_h1, a_h2, b_h2, ...]`` for the retained
harmonics in increasing order (``a_0`` only when 0 is retained). A model with ``n``
DOFs stores its harmonics as an array ``X`` of shape ``(n_b, n)``: row = coefficient,
column = DOF; flattened row-major (``X.ravel()``), coefficient ``c`` of DOF ``d`` sits at
``c * n + d``.

The complex amplitude of harmonic h is ``U_h = a_h - i b_h`` so that
``u = Re(U_h exp(i h theta))``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Fewest AFT samples per period. A stick-slip loop sampled at n_t points has its
#: kinks (reversal, slip onset) located only to 2 pi / n_t in phase, so its harmonics
#: carry an O(n_t^-2) error: measured on the Jenkins describing function, 0.27 % at
#: 64, 0.068 % at 128, 0.017 % at 256, 0.0045 % at 512; 256 keeps a 6x margin on 0.1 %.
MIN_SAMPLES = 256
#: Samples per retained harmonic coefficient: keeps harmonics that alias onto the
#: retained band (those above n_t - H) far above H, where the friction force's
#: spectrum has decayed (it falls like 1/h^2 for a force with kinks).
SAMPLES_PER_HARMONIC = 16
#: Samples per coefficient of the grid on which :meth:`FourierBasis.peak_abs` locates the
#: maxima of |u| before Newton polishes them (a trigonometric polynomial of degree H has
#: at most 2 H maxima; at 8 samples per coefficient each lies within a few samples of
#: one on the grid).
PEAK_GRID = 8
#: Local maxima of the grid polished at most; more within the grid's error bound of the
#: largest (a nearly flat top) are left to the fine grid.
PEAK_CANDIDATES = 8
#: Entries (samples x coefficients) of the fine grid up to which :meth:`FourierBasis.peak_abs`
#: searches it directly: measured crossover of the two exact ways near H = 31 (0.18 ms each).
PEAK_FINE_MAX = 2**19


def parse_harmonics(spec) -> tuple[int, ...]:
    """Retained harmonics from an int H (0..H), 'odd:H' / 'all:H', or a sequence.

    Parameters
    ----------
    spec : int, str or sequence of int
        ``7`` -> 0..7; ``"odd:7"`` -> 1, 3, 5, 7; ``"all:7"`` -> 0..7; ``[1, 3]`` as given.

    Returns
    -------
    tuple of int, sorted, unique, non-negative.
    """
    if isinstance(spec, str):
        kind, _, num = spec.partition(":")
        if not num:
            kind, num = "all", kind
        try:
            H = int(num)
        except ValueError:
            raise ValueError(f"bad harmonic spec {spec!r}: use H, 'odd:H' or 'all:H'") from None
        if kind not in ("odd", "all"):
            raise ValueError(f"bad harmonic spec {spec!r}: use H, 'odd:H' or 'all:H'")
        if H < 1:
            raise ValueError(f"highest harmonic must be >= 1, got {H}")
        return tuple(range(1, H + 1, 2)) if kind == "odd" else tuple(range(H + 1))
    if isinstance(spec, (int, np.integer)):
        return parse_harmonics(f"all:{int(spec)}")
    hs = sorted({int(h) for h in spec})
    if not hs or hs[0] < 0 or hs[-1] < 1:
        raise ValueError(f"harmonics must be >= 0 with at least one >= 1, got {list(spec)}")
    return tuple(hs)


def default_samples(H: int) -> int:
    """Number of AFT samples for highest harmonic H: a power of two >= 16 (2H + 1), >= 256."""
    need = max(MIN_SAMPLES, SAMPLES_PER_HARMONIC * (2 * H + 1))
    return int(2 ** np.ceil(np.log2(need)))


@dataclass(frozen=True)
class FourierBasis:
    """Real Fourier basis with its sampling and (inverse) DFT matrices.

    Parameters
    ----------
    harmonics : tuple of int
        Retained harmonics (see :func:`parse_harmonics`).
    n_t : int, optional
        Samples per period; default :func:`default_samples`. Must exceed 2 H (Nyquist),
        otherwise the highest harmonic aliases onto lower ones (ValueError).

    Attributes
    ----------
    E : (n_t, n_b) array      inverse DFT: u(theta_j) = E @ coefficients
    D : (n_b, n_t) array      forward DFT: coefficients = D @ samples (D @ E = I)
    dtheta : (n_b, n_b) array d/dtheta in coefficient space
    order : (n_b,) int        harmonic of each coefficient
    """

    harmonics: tuple
    n_t: int = 0
    E: np.ndarray = field(init=False, repr=False)
    D: np.ndarray = field(init=False, repr=False)
    dtheta: np.ndarray = field(init=False, repr=False)
    order: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        hs = parse_harmonics(self.harmonics)
        object.__setattr__(self, "harmonics", hs)
        n_t = int(self.n_t) or default_samples(hs[-1])
        if n_t <= 2 * hs[-1]:
            raise ValueError(f"n_t = {n_t} samples alias harmonic {hs[-1]} (need n_t > {2 * hs[-1]})")
        object.__setattr__(self, "n_t", n_t)
        theta = 2.0 * np.pi * np.arange(n_t) / n_t
        cols, order = [], []
        for h in hs:
            if h == 0:
                cols.append(np.ones(n_t))
                order.append(0)
            else:
                cols += [np.cos(h * theta), np.sin(h * theta)]
                order += [h, h]
        E = np.column_stack(cols)
        # Discrete orthogonality on the uniform grid (h < n_t / 2): the mean weighs
        # 1/n_t, cosine and sine 2/n_t.
        w = np.where(np.asarray(order) == 0, 1.0, 2.0) / n_t
        object.__setattr__(self, "E", E)
        object.__setattr__(self, "D", E.T * w[:, None])
        object.__setattr__(self, "order", np.asarray(order))
        object.__setattr__(self, "dtheta", self._derivative(hs))

    @staticmethod
    def _derivative(hs) -> np.ndarray:
        """d/dtheta of (a cos h theta + b sin h theta) = h b cos - h a sin."""
        nb = sum(1 if h == 0 else 2 for h in hs)
        Dm = np.zeros((nb, nb))
        i = 0
        for h in hs:
            if h == 0:
                i += 1
                continue
            Dm[i, i + 1] = h
            Dm[i + 1, i] = -h
            i += 2
        return Dm

    @property
    def nb(self) -> int:
        """Number of real coefficients per DOF."""
        return self.E.shape[1]

    @property
    def H(self) -> int:
        """Highest retained harmonic."""
        return self.harmonics[-1]

    def index(self, h: int) -> tuple[int, int | None]:
        """Coefficient indices (cos, sin) of harmonic h (sin is None for h = 0)."""
        if h not in self.harmonics:
            raise ValueError(f"harmonic {h} is not retained ({self.harmonics})")
        i = 0
        for g in self.harmonics:
            if g == h:
                return (i, None) if h == 0 else (i, i + 1)
            i += 1 if g == 0 else 2
        raise AssertionError  # unreachable

    def magnitude(self, coeffs: np.ndarray, h: int) -> np.ndarray:
        """|U_h| = sqrt(a_h^2 + b_h^2) of coefficient rows ``coeffs`` (n_b, ...)."""
        ic, isn = self.index(h)
        c = np.asarray(coeffs)
        return np.abs(c[ic]) if isn is None else np.hypot(c[ic], c[isn])

    def peak_abs(self, coeffs: np.ndarray, oversample: int = 8) -> float:
        """max over the period of |u(theta)| for one DOF's coefficients (n_b,).

        Exact to round-off, not grid-limited. Up to PEAK_FINE_MAX grid entries (the
        cheaper way there), the largest |u| on ``oversample`` times H's default samples
        polished by Newton's method on du/dtheta = 0 (:meth:`_peak_abs_fine`). Above (a
        peak's truncation check at 1.5 H and 2.25 H: 14 ms a call at H = 70 on 32768
        samples, 0.15 ms this way): |u| on a grid of PEAK_GRID samples per coefficient
        (one inverse FFT), then every local maximum of the grid within the grid's error
        bound of its largest (``sum_h h^2 |U_h| dtheta^2 / 8``: the most |u| can exceed
        its nearest sample by) polished by Newton; where Newton leaves its grid cell, or
        more than PEAK_CANDIDATES maxima compete, the fine grid decides.
        """
        c = np.asarray(coeffs, dtype=float)
        if oversample * default_samples(self.H) * self.nb <= PEAK_FINE_MAX:
            return self._peak_abs_fine(c, oversample)
        n = int(2 ** np.ceil(np.log2(PEAK_GRID * (2 * self.H + 1))))
        a = np.abs(self._on_grid(c, n))
        d = np.column_stack([c, self.dtheta @ c, self.dtheta @ (self.dtheta @ c)])
        bound = float(np.sum(self.order.astype(float) ** 2 * np.abs(c))) * (2.0 * np.pi / n) ** 2 / 8.0
        top = a.max()
        cand = np.flatnonzero((a >= np.roll(a, 1)) & (a >= np.roll(a, -1)) & (a >= top - bound))
        best = top
        for j in cand[np.argsort(-a[cand])][:PEAK_CANDIDATES]:
            t = self._polish(d, 2.0 * np.pi * j / n, n)
            if t is None:
                return self._peak_abs_fine(c, oversample)
            best = max(best, abs(self.evaluate(c, t)))
        if cand.size > PEAK_CANDIDATES:
            return self._peak_abs_fine(c, oversample)
        return float(best)

    def _on_grid(self, c: np.ndarray, n: int) -> np.ndarray:
        """u at theta_j = 2 pi j / n (n,) by one inverse real FFT (n > 2 H)."""
        cache = self.__dict__.setdefault("_fine_cache", {})
        if "grid" not in cache:
            is_sin = np.zeros(self.nb, dtype=bool)
            is_sin[(2 if self.harmonics[0] == 0 else 1)::2] = True
            ic, isn = np.flatnonzero(~is_sin), np.flatnonzero(is_sin)
            # irfft's scaling: 1/n, the positive frequencies counted twice
            cache["grid"] = (ic, isn, self.order[ic], self.order[isn],
                             np.where(self.order[ic] == 0, 1.0, 0.5))
        ic, isn, hc, hs, w = cache["grid"]
        Z = np.zeros(n // 2 + 1, dtype=complex)
        Z[hc] = n * w * c[ic]
        Z[hs] -= 0.5j * n * c[isn]   # U_h = a_h - i b_h (each h retained once)
        return np.fft.irfft(Z, n)

    def _polish(self, d: np.ndarray, t: float, n: int):
        """Stationary point of u near t by Newton's method on du/dtheta (d: the coefficients
        of u, u', u'' as columns), or None when a step leaves the grid cell (2 pi / n)."""
        for _ in range(8):
            g0, g1, g2 = self.evaluate(d, t)
            if g2 == 0.0:
                return t
            step = -g1 / g2
            if abs(step) > 2.0 * np.pi / n:
                return None
            t += step
            if abs(step) < 1e-15:  # quadratic convergence reached round-off
                break
        return t

    def _peak_abs_fine(self, c: np.ndarray, oversample: int) -> float:
        """max |u| located on ``oversample`` times H's default samples (a displacement of
        harmonics up to H is smooth whatever the AFT grid), polished by Newton's method."""
        n = oversample * default_samples(self.H)
        u = self._fine(oversample) @ c
        j = int(np.argmax(np.abs(u)))
        t = 2.0 * np.pi * j / n
        d = np.column_stack([c, self.dtheta @ c, self.dtheta @ (self.dtheta @ c)])
        for _ in range(8):
            g0, g1, g2 = self.evaluate(d, t)
            if g2 == 0.0:
                break
            step = -g1 / g2
            if abs(step) > 2.0 * np.pi / n:  # left the grid cell: keep the grid value
                break
            t += step
            if abs(step) < 1e-15:
                break
        return float(max(abs(self.evaluate(c, t)), abs(u[j])))

    def _fine(self, oversample: int) -> np.ndarray:
        """Basis sampled at oversample * default_samples(H) points (cached)."""
        cache = self.__dict__.setdefault("_fine_cache", {})
        if oversample not in cache:
            # on a uniform grid h theta_j is 2 pi ((h j) mod n) / n: one table of n cosines
            # and sines gathered, instead of n n_b of each (0.4 s at H = 70, 32768 points)
            n = oversample * default_samples(self.H)
            ang = 2.0 * np.pi * np.arange(n) / n
            is_sin = np.zeros(self.nb, dtype=bool)
            is_sin[(2 if self.harmonics[0] == 0 else 1)::2] = True
            k = (np.arange(n)[:, None] * self.order[None, :]) % n + n * is_sin[None, :]
            cache[oversample] = np.concatenate([np.cos(ang), np.sin(ang)])[k]
        return cache[oversample]

    def evaluate(self, coeffs: np.ndarray, theta) -> np.ndarray:
        """u(theta) for coefficients (n_b,) or (n_b, n) at arbitrary phases."""
        th = np.atleast_1d(np.asarray(theta, dtype=float))
        arg = np.outer(th, self.order)
        is_sin = np.zeros(self.nb, dtype=bool)
        is_sin[1 if self.harmonics[0] == 0 else 0::2] = False
        is_sin[(2 if self.harmonics[0] == 0 else 1)::2] = True
        out = np.where(is_sin, np.sin(arg), np.cos(arg)) @ np.asarray(coeffs)
        return out[0] if np.ndim(theta) == 0 else out

    def weighted(self, k: np.ndarray) -> np.ndarray:
        """``D @ diag(k) @ E`` (n_b, n_b) for sample weights k (n_t,); (q, n_b, n_b) for k (q, n_t).

        From the 2H + 1 discrete Fourier coefficients of k by one FFT: entry (p, q) is
        ``w_p sum_t k_t psi_p(theta_t) phi_q(theta_t)`` and each product of two basis
        functions of orders a, b is half a sum of the cos or sin of orders ``a - b``
        and ``a + b`` (cos a cos b = (cos(a-b) + cos(a+b)) / 2, ...), exact on the grid:
        Toeplitz plus Hankel in the orders. O(n_t log n_t + n_b^2) instead of the
        O(n_t n_b^2) of the product; the same numbers to round-off.
        """
        k = np.asarray(k, dtype=float)
        L = 2 * self.H + 1
        X = (np.fft.rfft(k) if 2 * self.H <= self.n_t // 2 else np.fft.fft(k))[..., :L]
        # interleaved (re, im) = (C_j, -S_j), C_j = sum k cos(j theta), S_j = sum k sin
        V = np.ascontiguousarray(X).view(float).ravel()
        i_d, a_d, i_s, a_s = self._weighted_tables(1 if k.ndim == 1 else k.shape[0])
        return a_d * V[i_d] + a_s * V[i_s]

    def _weighted_tables(self, q: int):
        """Gather indices into the interleaved [C_0, -S_0, C_1, -S_1, ...] of q weight
        vectors and the weights of :meth:`weighted`, for the difference (``i_d``,
        ``a_d``) and sum (``i_s``, ``a_s``) orders; (n_b, n_b) for q = 1, else (q, n_b,
        n_b) (cached per q)."""
        cache = self.__dict__.setdefault("_fine_cache", {})
        if ("weighted", q) not in cache:
            a = self.order
            is_sin = np.zeros(self.nb, dtype=bool)
            is_sin[(2 if self.harmonics[0] == 0 else 1)::2] = True
            w = np.where(a == 0, 1.0, 2.0) / self.n_t / 2.0
            same = is_sin[:, None] == is_sin[None, :]
            dif, add = a[:, None] - a[None, :], a[:, None] + a[None, :]
            # cos cos: C_d + C_s; sin sin: C_d - C_s; cos_p sin_q: S_s - S_d; sin_p cos_q:
            # S_s + S_d; an S_j is read as -(-S_j)
            i_d = 2 * np.abs(dif) + ~same
            a_d = w[:, None] * np.where(same, 1.0, -np.sign(dif) * np.where(is_sin[:, None], 1.0, -1.0))
            i_s = 2 * add + ~same
            a_s = w[:, None] * np.where(same, np.where(is_sin[:, None], -1.0, 1.0), -1.0)
            if q > 1:
                shift = 2 * (2 * self.H + 1) * np.arange(q)[:, None, None]
                i_d, i_s = i_d + shift, i_s + shift
            cache["weighted", q] = (i_d, a_d, i_s, a_s)
        return cache["weighted", q]

    def project_terms(self, diag: np.ndarray, row: np.ndarray, col: np.ndarray,
                      coef: np.ndarray) -> np.ndarray:
        """``D @ S @ E`` (q, n_b, n_b) of sparse sample matrices S (n_t, n_t), one per
        row of diag (q, n_t) and coef (q, k): ``S = diag(diag) + sum_i coef[i] e_row[i]
        e_col[i]^T`` (row != col; e.g. the Jacobian of ``IwanElement.periodic_jac_terms``).
        The diagonal by :meth:`weighted`, the other columns J of S (few: where a stick
        episode began) as ``(D S[:, J]) E[J]``: O(n_t log n_t + k + (n_t + n_b) n_b |J|)
        instead of the O(n_t n_b^2) of the product over the samples."""
        n = self.n_t
        diag = np.asarray(diag, dtype=float).reshape(-1, n)
        out = self.weighted(diag)
        if len(row):
            used = np.zeros(n, dtype=bool)
            used[col] = True
            J = np.flatnonzero(used)
            idx = row + n * np.searchsorted(J, col)
            W = np.stack([np.bincount(idx, c, n * J.size) for c in np.reshape(coef, (len(diag), -1))])
            G = W.reshape(-1, n) @ self.D.T                   # rows of D S[:, J], per q
            out += G.reshape(len(diag), J.size, -1).transpose(0, 2, 1) @ self.E[J]
        return out

    def alias_ratio(self, samples: np.ndarray) -> float:
        """Aliasing indicator of a sampled periodic signal (n_t,) or (n_t, k).

        Ratio of the signal's spectral amplitude in the top half of the DFT band
        (harmonics n_t/4 .. n_t/2, which alias onto harmonics near n_t - H and
        show how much of the tail the grid cannot see) to its amplitude in the
        retained harmonics. Small (< 1e-3) means the grid resolves the force.
        """
        S = np.abs(np.fft.rfft(np.asarray(samples), axis=0))
        top = S[self.n_t // 4:].max() if S.ndim == 1 else S[self.n_t // 4:].max()
        kept = S[list(h for h in self.harmonics)].max()
        return float(top / kept) if kept > 0 else 0.0
