"""Bad arguments: complex matrices are refused, naming the argument."""

import warnings

import numpy as np
import pytest

import fricbound
from fricbound import Scene


def _two_dofs(M=None, C=None, K=None, **kw):
    args = dict(dofs=["a", "b"], freq_range_hz=(1.0, 2.0), loads=[{"dof": "a", "harmonic": 1, "cos": 1.0}])
    args.update(kw)
    return Scene.from_matrices(
        np.eye(2) if M is None else M, C, np.diag([2.0, 3.0]) if K is None else K, **args
    )


@pytest.mark.parametrize("which", ["M", "C", "K"])
def test_complex_dense_matrices_are_refused_naming_the_argument(which):
    z = np.diag([2.0, 3.0]).astype(complex)
    z[0, 1] = z[1, 0] = 0.5j
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: refused before any cast
        with pytest.raises(TypeError, match=rf"from_matrices: {which}: complex matrix given .*real stiffness, mass and damping"):
            _two_dofs(**{which: z})
    # A complex dtype is refused even when every imaginary part is 0, and as nested lists.
    with pytest.raises(TypeError, match=rf"{which}: complex matrix"):
        _two_dofs(**{which: np.diag([2.0, 3.0]).astype(np.complex64)})
    with pytest.raises(TypeError, match=rf"{which}: complex matrix"):
        _two_dofs(**{which: [[2.0 + 0j, 0.0], [0.0, 3.0]]})


@pytest.mark.parametrize("which", ["M", "C", "K"])
def test_complex_sparse_matrices_are_refused_naming_the_argument(which):
    sp = pytest.importorskip("scipy.sparse")
    z = sp.csr_matrix(np.diag([2.0 + 1j, 3.0]))
    with pytest.raises(TypeError, match=rf"from_matrices: {which}: complex matrix given"):
        _two_dofs(**{which: z})


def test_reduce_refuses_complex_matrices():
    sp = pytest.importorskip("scipy.sparse")
    K = sp.diags([2.0, 3.0, 4.0]).tocsc()
    M = sp.identity(3, format="csc")
    with pytest.raises(TypeError, match=r"reduce: K: complex matrix given"):
        fricbound.reduce(K * (1 + 0.1j), M, boundary=[0], modes=1)
    with pytest.raises(TypeError, match=r"reduce: M: complex matrix given"):
        fricbound.reduce(K, M.toarray() * (1 + 0j), boundary=[0], modes=1)
    assert fricbound.reduce(K, M, boundary=[0], modes=1).n_modes == 1


