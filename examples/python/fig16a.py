"""Fig. 16a of Ferhatoglu & Zucca (JSV 2021) from Python: the resonance-peak amplitude of the
two limit curves (m = +1 and m = -1 on every contact point) against the damper pre-load F0,
for the apical angle beta = 120 deg, around the 3rd resonance.

The scene is meshes/paper-wedge/fig16a-d.toml (the one `fricbound paper` runs for Figs. 16a
and 16d); its [sweep] table moves the pre-load (static_loads.0.value = -F0) over 10-500 N.
The values are solved in parallel on this machine (rayon); for a cluster see
fricbound.dask.limits_sweep.

    python examples/python/fig16a.py                 # 50 pre-loads, writes fig16a.png
    python examples/python/fig16a.py --quick         # 12 pre-loads
    python examples/python/fig16a.py --out my.png --csv fig16a.csv
"""

import argparse
import pathlib
import sys
import time

import numpy as np

import fricbound

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="12 pre-loads instead of 50")
    parser.add_argument("--out", default="fig16a.png", help="figure file (PNG, SVG, PDF)")
    parser.add_argument("--csv", default=None, help="also write the peaks as CSV")
    args = parser.parse_args()

    scene = fricbound.Scene.from_toml(ROOT / "meshes" / "paper-wedge" / "fig16a-d.toml")
    if args.quick:
        scene.set("sweep.values", [10.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 160.0, 200.0, 300.0, 400.0, 500.0])

    def progress(event):
        print(f"  F0 = {event['value']:g} N done", file=sys.stderr)

    started = time.perf_counter()
    result = fricbound.sweep(scene, progress=progress)
    elapsed = time.perf_counter() - started
    upper, lower = result.limit_peaks()
    print(f"{len(result.value)} pre-loads in {elapsed:.1f} s; status: {result.status}")
    if args.csv:
        result.to_pandas().to_csv(args.csv, index=False)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(result.value, upper * 1e3, "o-", ms=3, label="upper limit (larger limit-curve peak)")
    ax.plot(result.value, lower * 1e3, "s-", ms=3, label="lower limit (smaller limit-curve peak)")
    ax.fill_between(result.value, lower * 1e3, upper * 1e3, alpha=0.2, label="possible peaks")
    ratio = upper / lower
    k = int(np.nanargmax(ratio))
    ax.annotate(
        f"{ratio[k]:.2f}x at F0 = {result.value[k]:g} N",
        (result.value[k], lower[k] * 1e3),
        textcoords="offset points",
        xytext=(-5, -16),
        ha="right",
    )
    ax.set_xlabel(f"pre-load {result.parameter} ({result.unit})")
    ax.set_ylabel("y2 resonance-peak amplitude (mm)")
    ax.set_title("Fig. 16a: optimal-curve limits, beta = 120 deg")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center")
    fig.tight_layout()
    fig.savefig(args.out, dpi=150)
    print(f"figure written to {args.out}")
    return 0 if result.complete else 3


if __name__ == "__main__":
    sys.exit(main())
