"""Independent fricbound solves mapped over a ``dask.distributed`` cluster.

Each value of a sweep is one task: the scene (pickled as its text, label and overrides) is
sent to a worker, the field set there, the solve run, and one row of results sent back; the
rows are gathered into a pandas DataFrame in the order of ``values``. What scales is the
number of independent cases (values, Monte Carlo samples): one case is never split over
workers. Without a ``client``, a ``LocalCluster`` with one single-threaded worker process per
core is started for the call and closed after it.

On a real cluster, pass a client of it, e.g. with ``dask_jobqueue``::

    from dask_jobqueue import SLURMCluster
    from dask.distributed import Client
    cluster = SLURMCluster(cores=1, processes=1, memory="2GB", walltime="01:00:00",
                           job_script_prologue=["source ~/venvs/fricbound/bin/activate"])
    cluster.scale(jobs=64)
    df = fricbound.dask.limits_sweep(scene, "contacts.0.mu", mus, client=Client(cluster))

Every worker needs the ``fricbound`` package installed, and files the scene names (meshes,
Matrix Market files, relative to the scene file's absolute path) readable at the same path.
"""

from __future__ import annotations

import os
import pickle
from typing import Any, Callable, Dict, List, Optional, Sequence

import numpy as np

from . import _args
from . import limits as _limits
from . import run as _run
from . import sweep as _sweep
from ._scene import Scene

__all__ = ["sweep", "limits_sweep", "map_values", "frf_row", "limits_row", "peaks_row"]


def frf_row(scene: Scene, field: str, value: float) -> Dict[str, Any]:
    """One FRF with ``field`` set to ``value``, summarised: ``field``, ``value``, ``status``,
    ``points``, per output ``<dof>_max_amp`` (largest first-harmonic amplitude on the path, m)
    and ``<dof>_max_amp_hz``, ``elapsed_s``. What :func:`sweep` computes per task."""
    s = scene.copy().set(field, value)
    r = _run(s)
    row: Dict[str, Any] = {"field": field, "value": float(value), "status": r.status, "points": len(r)}
    for k, dof in enumerate(r.outputs):
        i = int(np.argmax(r.amplitudes[:, k])) if len(r) else None
        row[f"{dof}_max_amp"] = float(r.amplitudes[i, k]) if i is not None else float("nan")
        row[f"{dof}_max_amp_hz"] = float(r.freq_hz[i]) if i is not None else float("nan")
    row["elapsed_s"] = float(r.elapsed_s)
    return row


def peaks_row(scene: Scene, field: str, value: float) -> Dict[str, Any]:
    """The resonance peaks of the limit (and intermediate) cases with ``field`` at ``value``
    (:func:`fricbound.sweep` at one value): ``field``, ``value``, ``status``, then
    ``<case>_amp`` (m) and ``<case>_freq_hz`` per case, ``upper_peak``, ``lower_peak``."""
    r = _sweep(scene, field, [value])
    row: Dict[str, Any] = {"field": field, "value": float(value), "status": r.status}
    for k, c in enumerate(r.cases):
        row[f"{c}_amp"] = float(r.peak_amplitude[0, k])
        row[f"{c}_freq_hz"] = float(r.peak_freq_hz[0, k])
    upper, lower = r.limit_peaks()
    row["upper_peak"] = float(upper[0])
    row["lower_peak"] = float(lower[0])
    return row


def limits_row(scene: Scene, field: str, value: float) -> Dict[str, Any]:
    """The whole limit analysis with ``field`` at ``value``, summarised: ``field``, ``value``,
    ``status``, the limit curves' peaks (``<case>_amp``, ``<case>_freq_hz``) and the
    variability (``upper_peak``, ``lower_peak``, ``peak_ratio``, ``peak_freq_change_pct``,
    ``widest_band`` (m), ``widest_band_hz``, ``multiple_points``)."""
    s = scene.copy().set(field, value)
    r = _limits(s)
    row: Dict[str, Any] = {"field": field, "value": float(value), "status": r.status}
    for c in r.limits:
        peak = c.peak or {}
        row[f"{c.name}_amp"] = float(peak.get("amplitude", float("nan")))
        row[f"{c.name}_freq_hz"] = float(peak.get("freq_hz", float("nan")))
    for key in (
        "upper_peak",
        "lower_peak",
        "peak_ratio",
        "peak_freq_change_pct",
        "widest_band",
        "widest_band_hz",
        "multiple_points",
    ):
        row[key] = r.variability[key]
    return row


def _single_threaded(task: Callable[..., Dict[str, Any]], *args: Any) -> "tuple[bool, Any]":
    """Runs a task on a worker: ``(True, row)``, or ``(False, exception)`` when the task
    raised. The exception is returned, not raised, so that the worker logs nothing and every
    task ends normally; :func:`map_values` raises it once all tasks are in and the cluster it
    started is closed. Each worker process runs one case at a time on one core: the library's
    rayon pool (used by limit analyses and sweeps) is kept to the worker's threads unless
    ``RAYON_NUM_THREADS`` is already set (it must be set before the first solve of the
    process)."""
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    try:
        return True, task(*args)
    except Exception as e:  # noqa: BLE001 - every error goes back to the caller
        try:
            pickle.loads(pickle.dumps(e))
        except Exception:  # noqa: BLE001 - an exception that cannot travel is sent as text
            e = RuntimeError(f"{type(e).__name__}: {e}")
        return False, e


def _gather(client: Any, task: Callable[..., Dict[str, Any]], scene: Scene, field: str, values: List[float]):
    """Sends one task per value to ``client`` and waits for all of them (each returns its row
    or its exception, see :func:`_single_threaded`). If the wait is interrupted (Ctrl-C), the
    tasks not started are cancelled before the exception goes on."""
    futures = client.map(
        _single_threaded,
        [task] * len(values),
        [scene] * len(values),
        [field] * len(values),
        values,
        pure=False,
    )
    try:
        return client.gather(futures)
    except BaseException:
        client.cancel(futures)
        raise


def map_values(
    task: Callable[[Scene, str, float], Dict[str, Any]],
    scene: Scene,
    field: str,
    values: Sequence[float],
    client: Any = None,
):
    """Maps ``task(scene, field, value)`` over ``values`` on a Dask cluster and gathers the rows
    into a DataFrame in the order of ``values``. ``client``: a ``dask.distributed.Client``;
    None starts a ``LocalCluster`` (one single-threaded worker process per core, no dashboard)
    for the call and closes it once every task has ended. ``client="serial"`` runs the same
    tasks in this process, one after the other (the reference the distributed result equals).

    A task that fails does not stop the others: once all have ended (and the cluster started
    here is closed), the first failure in the order of ``values`` is raised with its own type
    (``ValueError``, :class:`fricbound.SolveError`, ...)."""
    import pandas as pd

    if isinstance(scene, (str, os.PathLike)):
        scene = Scene.from_toml(scene)
    elif not isinstance(scene, Scene):
        raise TypeError(f"map_values: scene: expected a Scene, a path or TOML text, got {type(scene).__name__}")
    field = _args.text("map_values", "field", field)
    values = _args.numbers_list("map_values", "values", values)
    if values:
        # A bad field is reported here, naming the override, before any task is sent.
        scene.copy().set(field, values[0])
    if isinstance(client, str):
        if client != "serial":
            raise ValueError(f'map_values: client: expected a dask.distributed.Client, "serial" or None, got {client!r}')
        return pd.DataFrame([task(scene, field, v) for v in values])
    if client is None:
        from dask.distributed import Client, LocalCluster

        workers = os.cpu_count() or 1
        # Closed in this order on the way out (client, then cluster), after every task ended.
        with LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster, Client(cluster) as own:
            outcomes = _gather(own, task, scene, field, values)
    elif callable(getattr(client, "map", None)) and callable(getattr(client, "gather", None)):
        outcomes = _gather(client, task, scene, field, values)
    else:
        raise TypeError(
            f'map_values: client: expected a dask.distributed.Client, "serial" or None, got {type(client).__name__}'
        )
    for ok, outcome in outcomes:
        if not ok:
            raise outcome
    return pd.DataFrame([row for _, row in outcomes])


def sweep(scene: Scene, field: str, values: Sequence[float], client: Any = None):
    """One nonlinear FRF per value of ``field`` (dotted path, as :meth:`Scene.set`), on a Dask
    cluster: a DataFrame of :func:`frf_row` rows (status, points, largest amplitude of each
    output and its frequency), in the order of ``values``. See :func:`map_values` for
    ``client``."""
    return map_values(frf_row, scene, field, values, client)


def limits_sweep(
    scene: Scene,
    field: str,
    values: Sequence[float],
    client: Any = None,
    output: str = "peaks",
):
    """A limit analysis per value of ``field``, on a Dask cluster. ``output="peaks"``: the
    resonance peaks of the limit and intermediate cases (:func:`peaks_row`, the same numbers
    as :func:`fricbound.sweep`, whose values run in parallel on one machine);
    ``output="limits"``: the whole analysis, summarised (:func:`limits_row`). See
    :func:`map_values` for ``client``."""
    if output not in ("peaks", "limits"):
        raise ValueError(f'limits_sweep: output: must be "peaks" or "limits", got {output!r}')
    return map_values(peaks_row if output == "peaks" else limits_row, scene, field, values, client)
