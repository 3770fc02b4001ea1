"""fricbound from Python: the harmonic-balance solver for structures with dry-friction
contacts (turbine-blade wedge dampers, friction joints) and the limits of their response
among the multiple steady states friction allows (Ferhatoglu & Zucca, JSV 494, 2021).

The Rust library is the single implementation: this package converts numpy/scipy data, calls
the same library functions as the ``fricbound`` CLI and returns numpy arrays.

Main entry points (units SI, frequencies in Hz):

- :class:`Scene` (``from_toml``, ``from_matrices``, ``paper``, ``set``, ``check``);
- :func:`run` (one FRF), :func:`limits` (two-point limit analysis), :func:`sweep` (peaks of
  the limit cases over a scene field), :func:`modes`, :func:`reduce` (Craig-Bampton),
  :func:`verify` (time integration), :func:`linear`, :func:`accuracy_study` (what each
  solver setting costs in time and gives in accuracy);
- :mod:`fricbound.dask`: independent solves mapped over a Dask cluster.

Errors: bad input raises ``ValueError`` naming the file, the field (dotted path) and the
reason; an argument of the wrong type ``TypeError`` naming the function and the argument (a
complex matrix among them: fricbound's matrices are real); a failed solve raises
:class:`SolveError`; a problem too large for the machine ``MemoryError``. Solves release the
GIL; Ctrl-C stops them (``KeyboardInterrupt``) within about one continuation step.
"""

from __future__ import annotations

from typing import Any, Callable, Optional, Sequence

import numpy as np

from . import _args, _native
from ._native import SolveError
from ._results import (
    AccuracyStudy,
    ContinuationPath,
    Curve,
    FrfResult,
    LimitsResult,
    LinearResult,
    ModesResult,
    NonlinearMode,
    NonlinearModesResult,
    ReducedModel,
    SweepResult,
    VerifyResult,
)
from ._scene import MAX_INLINE_DOFS, Scene

__version__ = _native.__version__

# The extension defines SolveError in `_native`, which is not importable under that name:
# naming its module `fricbound` lets it pickle (a Dask task's error comes back as itself).
SolveError.__module__ = "fricbound"

__all__ = [
    "Scene",
    "accuracy_study",
    "AccuracyStudy",
    "run",
    "limits",
    "sweep",
    "modes",
    "nonlinear_modes",
    "reduce",
    "SolveError",
    "ContinuationPath",
    "Curve",
    "FrfResult",
    "LimitsResult",
    "LinearResult",
    "linear",
    "ModesResult",
    "NonlinearMode",
    "NonlinearModesResult",
    "ReducedModel",
    "SweepResult",
    "VerifyResult",
    "verify",
    "MAX_INLINE_DOFS",
    "dask",
]

Progress = Optional[Callable[[dict], Any]]


def _scene(where: str, scene: "Scene | str") -> Scene:
    """The ``scene`` argument of ``where``: a :class:`Scene`, or a path or TOML text read by
    :meth:`Scene.from_toml`."""
    if isinstance(scene, Scene):
        return scene
    _args.path_or_text(where, "scene", scene)
    return Scene.from_toml(scene)


def run(scene: "Scene | str", progress: Progress = None) -> FrfResult:
    """Solves the scene's nonlinear frequency response (what ``fricbound run`` solves for a
    scene without ``[limits]`` or ``[sweep]``; those tables are not run here: see
    :func:`limits` and :func:`sweep`).

    ``progress``, when given, is called with a dict per converged point: ``{"kind":
    "point", "freq_hz": ..., "amplitudes": [...], "points": count}``; an exception it raises
    stops the solve and is raised here.

    Returns an :class:`FrfResult`; a run that did not reach the end frequency is returned with
    ``status = "incomplete: <reason>"`` (``complete`` is False). Raises ``ValueError`` on a bad
    scene, :class:`SolveError` when the solve fails.
    """
    s = _scene("run", scene)
    return FrfResult(_native.run(*s._args(), _args.callback("run", "progress", progress)))


def limits(scene: "Scene | str", progress: Progress = None) -> LimitsResult:
    """The paper's two-point limit analysis (§3.3) with the scene's ``[limits]`` settings (the
    defaults when it has none): the limit curves (m = ±1 on every contact point), the
    intermediate curves, the band on a common grid, the bound scan, the variability.

    Curves are solved in parallel (rayon). ``progress`` is called with ``{"kind": "curve",
    "name": ..., "status": ...}`` as each curve ends.
    """
    s = _scene("limits", scene)
    return LimitsResult(_native.limits(*s._args(), _args.callback("limits", "progress", progress)))


def sweep(
    scene: "Scene | str",
    field: Optional[str] = None,
    values: Optional[Sequence[float]] = None,
    *,
    scale: float = 1.0,
    offset: float = 0.0,
    parameter: Optional[str] = None,
    unit: str = "",
    progress: Progress = None,
) -> SweepResult:
    """Resonance peaks of the limit (and intermediate) cases at each value of a scene field:
    the paper's optimal curves (Figs. 15-19), ``fricbound run`` of a scene with ``[sweep]``.

    With ``field`` and ``values``, the field (dotted path, as :meth:`Scene.set`) is set to
    ``offset + scale * value`` for each value (e.g. ``sweep(scene, "static_loads.0.value",
    f0, scale=-1.0, parameter="F0", unit="N")``); without them the scene's own ``[sweep]``
    table is run. Values are solved in parallel (rayon). ``progress`` is called with
    ``{"kind": "sweep", "value": ..., "failures": count}`` as each value finishes.
    """
    s = _scene("sweep", scene)
    progress = _args.callback("sweep", "progress", progress)
    if field is not None or values is not None:
        if field is None or values is None:
            raise ValueError("sweep: give both field and values (or neither, to run the scene's [sweep])")
        field = _args.text("sweep", "field", field)
        s = s.copy().set(
            "sweep",
            {
                "parameter": _args.text("sweep", "parameter", parameter) if parameter is not None else field,
                "unit": _args.text("sweep", "unit", unit),
                "values": _args.numbers_list("sweep", "values", values),
                "targets": [
                    {
                        "field": field,
                        "scale": _args.number("sweep", "scale", scale),
                        "offset": _args.number("sweep", "offset", offset),
                    }
                ],
            },
        )
    return SweepResult(_native.sweep(*s._args(), progress))


def verify(
    scene: "Scene | str",
    freqs_hz: Sequence[float],
    steps_per_period: Optional[int] = None,
    max_periods: Optional[int] = None,
) -> VerifyResult:
    """Checks harmonic-balance points by time integration (``fricbound verify``, started from
    the HBM state): at each frequency (Hz) the point is solved from the stuck (else open)
    linear guess, its Hill stability computed, and the equations of motion integrated
    (Newmark, ``steps_per_period`` default 256·H, at most ``max_periods`` default 300) at dt and
    dt/2 until periodic. A stable point's motion stays at the HBM amplitude
    (``hbm_difference`` < 1e-3); an unstable one drifts away. Dense models up to 2000 DOFs.
    """
    s = _scene("verify", scene)
    freqs = _args.numbers_list("verify", "freqs_hz", freqs_hz)
    steps = _args.optional_integer("verify", "steps_per_period", steps_per_period, 8)
    periods = _args.optional_integer("verify", "max_periods", max_periods, 1)
    result = _native.verify(*s._args(), freqs, steps, periods)
    return VerifyResult(result["cases"], s.check()["outputs"], result["status"])


def accuracy_study(scene: "Scene | str", quick: bool = False, progress: Progress = None) -> AccuracyStudy:
    """What accuracy costs in time (``fricbound study accuracy`` without its files): one
    setting at a time is changed from the scene as given (harmonics H = 1 … 15 and odd-only
    sets, AFT samples per period, Newton tolerance, Craig-Bampton interior modes on reduced
    scenes, each effect switch) and each setting's FRF is compared with the most refined
    setting, whose convergence is checked against the next refinement down. A limit scene is
    studied per limit curve (m = +1, m = −1 and its ``[[limits.cases]]``). ``quick`` uses the
    short lists (seconds on the paper case). Settings are solved in parallel (rayon);
    ``progress`` is called with ``{"kind": "setting", "curve": ..., "setting": ..., "done":
    n, "total": total}`` as each setting finishes.

    Returns an :class:`AccuracyStudy`. Raises ``ValueError`` on a bad scene and
    :class:`SolveError` when a curve's reference does not solve (no error can be measured
    then); a setting that fails is a row with its ``setting_status``.
    """
    s = _scene("accuracy_study", scene)
    if not isinstance(quick, (bool, np.bool_)):
        raise TypeError(f"accuracy_study: quick: expected a bool, got {_args.type_name(quick)}")
    progress = _args.callback("accuracy_study", "progress", progress)
    return AccuracyStudy(_native.accuracy_study(*s._args(), bool(quick), progress))


def linear(scene: "Scene | str", case: str = "open", points: Optional[int] = None) -> LinearResult:
    """The linear reference of the scene with its contacts ``"open"`` (removed) or ``"stuck"``
    (replaced by their kt, kn springs): first-harmonic amplitude of each output on ``points``
    uniformly spaced frequencies of the analysis range (default ``analysis.linear_points``),
    as the CLI's ``linear_open.csv`` and ``linear_stuck.csv``."""
    s = _scene("linear", scene)
    case = _args.text("linear", "case", case)
    points = _args.optional_integer("linear", "points", points, 2)
    return LinearResult(_native.linear(*s._args(), case, points))


def modes(scene: "Scene | str", count: int = 10, case: str = "stuck") -> ModesResult:
    """The lowest ``count`` natural frequencies and mass-normalised shapes of the scene's
    structure with its contacts ``"open"`` (removed) or ``"stuck"`` (replaced by their kt, kn
    springs), as ``fricbound modes`` (dense below a few thousand DOFs, shift-invert Lanczos
    above)."""
    s = _scene("modes", scene)
    count = _args.integer("modes", "count", count, 1)
    case = _args.text("modes", "case", case)
    return ModesResult(_native.modes(*s._args(), count, case))


def nonlinear_modes(
    scene: "Scene | str",
    mode: Optional[int] = None,
    mode_freq_hz: Optional[float] = None,
    dof: Optional[str] = None,
    amplitude: Optional[Sequence[float]] = None,
    max_points: Optional[int] = None,
) -> NonlinearModesResult:
    """The scene's nonlinear mode by EPMC (what ``fricbound run`` computes for a scene with
    ``analysis.kind = "nonlinear-modes"``; with ``[limits]``, one mode per initial tangential
    state and their band): frequency (Hz), modal damping ratio D = ξ/2ω and shape against the
    vibration level, from the linear mode at rest (contacts stuck) to the highest amplitude.

    The keyword arguments set the scene's fields of the same name (``analysis.mode``: the
    mode's number among the elastic modes at rest, see :func:`modes`; ``analysis.mode_freq_hz``:
    the mode nearest this frequency, Hz; ``analysis.dof``: the DOF that fixes the phase and at
    which ``analysis.amplitude`` = [low, high], the first-harmonic amplitude range (m), is
    given; ``analysis.max_points``), and ``analysis.kind`` to ``"nonlinear-modes"``.

    Returns a :class:`NonlinearModesResult`; raises ``ValueError`` naming the field on bad
    input, :class:`SolveError` when the mode cannot be computed.
    """
    s = _scene("nonlinear_modes", scene).copy()
    s.set("analysis.kind", "nonlinear-modes")
    if mode is not None:
        s.set("analysis.mode", _args.integer("nonlinear_modes", "mode", mode, 1))
        _remove(s, "analysis.mode_freq_hz")
    if mode_freq_hz is not None:
        s.set("analysis.mode_freq_hz", float(mode_freq_hz))
        _remove(s, "analysis.mode")
    if dof is not None:
        s.set("analysis.dof", _args.text("nonlinear_modes", "dof", dof))
    if amplitude is not None:
        low, high = (float(v) for v in amplitude)
        s.set("analysis.amplitude", [low, high])
    if max_points is not None:
        s.set("analysis.max_points", _args.integer("nonlinear_modes", "max_points", max_points, 1))
    return NonlinearModesResult(_native.nonlinear_modes(*s._args()))


def _remove(scene: Scene, field: str) -> None:
    """Removes ``field`` from ``scene`` where the scene has it (the other way of choosing the
    mode, replaced by the keyword given)."""
    try:
        scene.set(field, None)
    except ValueError:
        pass


def reduce(
    K: Any,
    M: Any,
    boundary: Sequence[int],
    modes: int,
    recover: Optional[Sequence[int]] = None,
) -> ReducedModel:
    """Craig-Bampton reduction of a sparse symmetric model (the library's reduction crate, as
    a scene's ``[reduction]`` table uses).

    Parameters
    ----------
    K, M : scipy.sparse matrix or array_like, (n, n)
        Stiffness (N/m) and mass (kg), real (a complex dtype raises ``TypeError``), symmetric
        with both triangles stored. ``K`` with the boundary DOFs held must be positive
        definite.
    boundary : sequence of int
        DOF indices kept physical (contacts, loads, outputs), in the order of the reduced
        coordinates.
    modes : int
        Fixed-interface modes kept (a repeated last eigenvalue is kept whole).
    recover : sequence of int, optional
        DOFs whose recovery rows are returned (default: none).
    """
    K = _args.real_matrix("reduce", "K", K)
    M = _args.real_matrix("reduce", "M", M)
    if len(np.shape(K)) != 2 or np.shape(K)[0] != np.shape(K)[1]:
        raise ValueError(f"reduce: K: expected a square matrix, got shape {np.shape(K)}")
    n = np.shape(K)[0]
    k_csc = _csc_arrays("K", K, n)
    m_csc = _csc_arrays("M", M, n)
    return ReducedModel(
        _native.reduce(
            n,
            *k_csc,
            *m_csc,
            _args.indices("reduce", "boundary", boundary),
            _args.integer("reduce", "modes", modes, 0),
            _args.indices("reduce", "recover", recover if recover is not None else []),
        )
    )


def _csc_arrays(name: str, a: Any, n: int):
    """``indptr``, ``indices``, ``data`` of a matrix in compressed sparse columns."""
    try:
        import scipy.sparse as sp
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("reduce() needs scipy: pip install scipy") from e
    m = sp.csc_matrix(a)
    if m.dtype.kind == "c":  # refused before; kept here so no imaginary part is ever dropped
        raise TypeError(f"reduce: {name}: complex matrix given (dtype {m.dtype}); {_args._REAL_ONLY}")
    if m.shape != (n, n):
        raise ValueError(f"reduce: {name}: shape {m.shape}, expected ({n}, {n})")
    m.sum_duplicates()
    return (
        np.ascontiguousarray(m.indptr, dtype=np.int64),
        np.ascontiguousarray(m.indices, dtype=np.int64),
        np.ascontiguousarray(m.data, dtype=np.float64),
    )


# Last: the module uses the functions above (it imports dask.distributed only when called).
from . import dask  # noqa: E402
