"""Every available sparse back end gives the same condensed compliance.

The reference is an independent dense computation: the rows and columns of the
contact DOFs of K^-1 from numpy's dense inverse of a small FE stiffness.
"""
import numpy as np
import pytest

from contact_core import assembly, condense, linsolve, mesh
from contact_core.spec import ContactSpec

#: Agreement with the dense inverse, relative to max|C|: round-off of a factorisation of a
#: 4380-DOF matrix (measured 2.6e-16 cholmod, 8.6e-16 pardiso, 9.3e-16 superlu); 1e-12 leaves
#: room for other BLAS builds and still fails on any wrong block or ordering.
RTOL = 1e-12


@pytest.fixture(scope="module")
def small_body():
    spec = ContactSpec(body="sphere", model="real", grid=5, radius=0.01, load_hint=200.0)
    b1, _b2, meta = mesh.build(spec)
    K = assembly.stiffness(b1.p, b1.t, spec.E1, spec.nu1)
    free = np.setdiff1d(np.arange(K.shape[0]), condense._fixed_dofs(b1, "z", meta["symmetry"]))
    local = np.full(K.shape[0], -1)
    local[free] = np.arange(free.size)
    dofs = local[3 * b1.contact + 2]
    Kff = K[free][:, free].tocsc()
    C_ref = np.linalg.inv(Kff.toarray())[np.ix_(dofs, dofs)]
    return Kff, dofs, C_ref


def test_superlu_always_available():
    assert "superlu" in linsolve.available_backends()


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
@pytest.mark.parametrize("name", linsolve.BACKENDS)
def test_backends_agree_with_dense_inverse(name, small_body, monkeypatch):
    if name not in linsolve.available_backends():
        pytest.skip(f"{name} is not installed here")
    monkeypatch.setenv("DAMPER_SOLVER", name)
    Kff, dofs, C_ref = small_body
    # reversed DOFs: the block must follow the order asked for
    C = linsolve.compliance_block(Kff, dofs[::-1])
    np.testing.assert_allclose(C, C_ref[::-1, ::-1], rtol=0, atol=RTOL * np.abs(C_ref).max())
    solve = linsolve.factorize(Kff)
    B = np.zeros((Kff.shape[0], 2))
    B[dofs[:2], [0, 1]] = 1.0
    np.testing.assert_allclose(np.asarray(solve(B))[dofs[:2]], C_ref[:2, :2], atol=RTOL * np.abs(C_ref).max())


def test_unknown_or_missing_backend_is_an_error(monkeypatch):
    monkeypatch.setenv("DAMPER_SOLVER", "magic")
    with pytest.raises(ValueError, match="use one of"):
        linsolve.backend()


#: A 3D Laplacian-like SPD matrix (n^3 DOFs) and 40 right-hand sides: large enough that
#: MKL PARDISO's forward/backward solves run in parallel on two threads and their last
#: bits then differ from one thread (seen without the pinned thread count).
_THREADS_SCRIPT = """
import hashlib, numpy as np, scipy.sparse as sp
from contact_core import linsolve
n = 20
I = sp.identity(n)
D = sp.diags([-np.ones(n - 1), 2.05 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
K = (sp.kron(sp.kron(D, I), I) + sp.kron(sp.kron(I, D), I) + sp.kron(sp.kron(I, I), D)).tocsr()
K = K + sp.diags(np.random.default_rng(20261127).random(K.shape[0]))
B = np.random.default_rng(11).standard_normal((K.shape[0], 40))
X = linsolve.factorize(K)(B)
C = linsolve.compliance_block(K, np.arange(0, n * n, 3))
print(hashlib.sha1(X.tobytes() + C.tobytes()).hexdigest())
"""


@pytest.mark.slow
def test_pardiso_bits_do_not_depend_on_mkl_thread_count():
    """A serial run (MKL: one thread per core) and a Dask worker (MKL_NUM_THREADS=1) give the
    same bits: every PARDISO call runs on linsolve.SOLVER_THREADS_DEFAULT threads."""
    import os
    import subprocess
    import sys

    if "pardiso" not in linsolve.available_backends():
        pytest.skip("pypardiso is not installed here")
    digests = set()
    for threads in ("1", "2"):
        env = dict(os.environ, MKL_NUM_THREADS=threads, MKL_DYNAMIC="FALSE", DAMPER_SOLVER="pardiso")
        env.pop("DAMPER_SOLVER_THREADS", None)
        out = subprocess.run([sys.executable, "-c", _THREADS_SCRIPT], env=env, capture_output=True, text=True,
                             check=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1


def test_solver_threads_setting_is_checked(monkeypatch):
    monkeypatch.setenv("DAMPER_SOLVER_THREADS", "two")
    with pytest.raises(ValueError, match="DAMPER_SOLVER_THREADS='two': give a whole number"):
        linsolve.solver_threads()
    monkeypatch.setenv("DAMPER_SOLVER_THREADS", "3")
    assert linsolve.solver_threads() == 3
    monkeypatch.delenv("DAMPER_SOLVER_THREADS")
    assert linsolve.solver_threads() == linsolve.SOLVER_THREADS_DEFAULT
