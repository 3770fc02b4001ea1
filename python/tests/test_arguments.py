"""Bad arguments: complex matrices are refused, and every error names the argument or the
field path inside it."""

import warnings

import numpy as np
import pytest

import fricbound
from fricbound import Scene

from conftest import PAPER

CONTACT = {"name": "c", "damper": ["a"], "body": [], "angle_deg": 0.0, "kt": 1e5, "kn": 1e5, "mu": 0.3}


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


def test_scene_values_name_their_field():
    with pytest.raises(ValueError, match=r"from_matrices: contacts\[0\]\.mu: must be a finite number, got nan"):
        _two_dofs(contacts=[dict(CONTACT, mu=float("nan"))])
    with pytest.raises(ValueError, match=r"contacts\[0\]\.kt: must be a finite number, got inf"):
        _two_dofs(contacts=[dict(CONTACT, kt=np.inf)])
    with pytest.raises(TypeError, match=r"loads\[0\]\.cos: complex value given"):
        _two_dofs(loads=[{"dof": "a", "harmonic": 1, "cos": 1.0 + 2.0j}])
    with pytest.raises(TypeError, match=r"contacts\[0\]: expected a dict, got int"):
        _two_dofs(contacts=[3])
    with pytest.raises(TypeError, match=r"from_matrices: freq_range_hz: expected \(start, end\)"):
        _two_dofs(freq_range_hz=(1.0,))
    with pytest.raises(ValueError, match=r"freq_range_hz\[1\]: must be a finite number, got nan"):
        _two_dofs(freq_range_hz=(1.0, float("nan")))
    with pytest.raises(ValueError, match=r"from_matrices: harmonics: must be >= 1, got 0"):
        _two_dofs(harmonics=0)
    with pytest.raises(ValueError, match=r"analysis\.max_step: must be a finite number, got nan"):
        _two_dofs(analysis={"max_step": float("nan")})
    with pytest.raises(TypeError, match=r"from_matrices: dofs\[1\]: expected a str, got int"):
        _two_dofs(dofs=["a", 2])
    with pytest.raises(TypeError, match=r"from_matrices: K: expected a matrix of real numbers"):
        _two_dofs(K=np.array([["a", "b"], ["c", "d"]]))
    scene = Scene.paper()
    with pytest.raises(TypeError, match=r"Scene.set: contacts.0.mu: complex value given"):
        scene.set("contacts.0.mu", 0.3 + 0.1j)
    with pytest.raises(TypeError, match=r"Scene.set: field: expected a str, got int"):
        scene.set(0, 0.3)
    assert scene.overrides == []
    with pytest.raises(TypeError, match=r"Scene.from_toml: path_or_text: expected a Scene, a path or TOML text, got int"):
        Scene.from_toml(42)


def test_function_arguments_name_themselves():
    scene = Scene.from_toml(PAPER / "zoom-2nd.toml")
    for f in (fricbound.run, fricbound.limits, fricbound.modes, fricbound.linear, fricbound.accuracy_study):
        with pytest.raises(TypeError, match=rf"{f.__name__}: scene: expected a Scene, a path or TOML text, got int"):
            f(42)
    with pytest.raises(TypeError, match=r"verify: scene: expected a Scene, a path or TOML text, got NoneType"):
        fricbound.verify(None, [120.0])
    with pytest.raises(ValueError, match=r"modes: count: must be >= 1, got -1"):
        fricbound.modes(scene, -1)
    with pytest.raises(TypeError, match=r"modes: count: must be an integer, got 2.5"):
        fricbound.modes(scene, 2.5)
    with pytest.raises(TypeError, match=r"modes: case: expected a str, got int"):
        fricbound.modes(scene, 3, case=1)
    with pytest.raises(ValueError, match=r"linear: points: must be >= 2, got -3"):
        fricbound.linear(scene, "open", points=-3)
    with pytest.raises(TypeError, match=r"verify: freqs_hz: expected a sequence of numbers, got float"):
        fricbound.verify(scene, 120.0)
    with pytest.raises(TypeError, match=r"verify: freqs_hz\[1\]: must be a number, got str"):
        fricbound.verify(scene, [120.0, "130"])
    with pytest.raises(ValueError, match=r"verify: steps_per_period: must be >= 8, got -1"):
        fricbound.verify(scene, [120.0], steps_per_period=-1)
    with pytest.raises(ValueError, match=r"verify: max_periods: must be >= 1, got 0"):
        fricbound.verify(scene, [120.0], max_periods=0)
    with pytest.raises(TypeError, match=r"run: progress: expected a callable or None, got int"):
        fricbound.run(scene, progress=5)
    with pytest.raises(TypeError, match=r"sweep: values\[1\]: must be a number, got str"):
        fricbound.sweep(scene, "contacts.0.mu", [0.3, "x"])
    with pytest.raises(ValueError, match=r"sweep: scale: must be a finite number, got nan"):
        fricbound.sweep(scene, "contacts.0.mu", [0.3], scale=float("nan"))
    with pytest.raises(TypeError, match=r"sweep: field: expected a str, got int"):
        fricbound.sweep(scene, 3, [0.3])
    with pytest.raises(TypeError, match=r"accuracy_study: quick: expected a bool, got str"):
        fricbound.accuracy_study(scene, quick="yes")
    with pytest.raises(ValueError, match=r'map_values: client: expected a dask.distributed.Client, "serial" or None'):
        fricbound.dask.sweep(scene, "contacts.0.mu", [0.3], client="local")
    with pytest.raises(TypeError, match=r"map_values: client: expected a dask.distributed.Client"):
        fricbound.dask.sweep(scene, "contacts.0.mu", [0.3], client=3)
    with pytest.raises(TypeError, match=r"map_values: values: expected a sequence of numbers, got float"):
        fricbound.dask.sweep(scene, "contacts.0.mu", 0.3, client="serial")


def test_reduce_arguments_name_themselves():
    sp = pytest.importorskip("scipy.sparse")
    K = sp.diags([2.0, 3.0, 4.0]).tocsc()
    M = sp.identity(3, format="csc")
    with pytest.raises(ValueError, match=r"reduce: boundary\[1\]: must be >= 0, got -1"):
        fricbound.reduce(K, M, boundary=[0, -1], modes=1)
    with pytest.raises(ValueError, match=r"reduce: modes: must be >= 0, got -2"):
        fricbound.reduce(K, M, boundary=[0], modes=-2)
    with pytest.raises(TypeError, match=r"reduce: recover\[0\]: must be an integer, got str"):
        fricbound.reduce(K, M, boundary=[0], modes=1, recover=["x"])
    with pytest.raises(ValueError, match=r"reduce: K: expected a square matrix, got shape \(3,\)"):
        fricbound.reduce(np.ones(3), M, boundary=[0], modes=1)
