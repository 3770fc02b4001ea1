"""Measures the speed-up of fricbound.dask on a local cluster: the pre-load sweep of Fig. 16a
(resonance peaks of the two limit curves, one task per pre-load) run serially in this process,
on a LocalCluster of N single-threaded worker processes, and with the library's own parallel
sweep (rayon threads in one process).

    python examples/python/dask_speedup.py --values 16 --workers 2
"""

import argparse
import os
import pathlib
import time

import numpy as np

import fricbound
import fricbound.dask

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--values", type=int, default=16, help="pre-loads swept")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()

    from dask.distributed import Client, LocalCluster

    scene = fricbound.Scene.from_toml(ROOT / "meshes" / "paper-wedge" / "fig16a-d.toml")
    values = list(-np.linspace(40.0, 500.0, args.values))  # static_loads.0.value = -F0
    field = "static_loads.0.value"

    t = time.perf_counter()
    serial = fricbound.dask.limits_sweep(scene, field, values, client="serial")
    t_serial = time.perf_counter() - t

    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(lambda: None)  # workers up before the clock starts
        t = time.perf_counter()
        distributed = fricbound.dask.limits_sweep(scene, field, values, client=client)
        t_dask = time.perf_counter() - t
    assert distributed.equals(serial), "the distributed sweep differs from the serial one"

    t = time.perf_counter()
    fricbound.sweep(scene, field, values)
    t_rayon = time.perf_counter() - t

    print(f"{args.values} pre-loads, {os.cpu_count()} cores")
    print(f"serial (one process, one value at a time): {t_serial:6.2f} s")
    print(f"Dask LocalCluster, {args.workers} workers:        {t_dask:6.2f} s  (speed-up {t_serial / t_dask:.2f})")
    print(f"fricbound.sweep (rayon, one process):      {t_rayon:6.2f} s  (speed-up {t_serial / t_rayon:.2f})")


if __name__ == "__main__":
    main()
