#!/usr/bin/env python3
"""Sweep the stretch compliance of the hanging cloth, one run per process; write a CSV and a plot.

Each run loads assets/scenes/hanging.toml (a cloth pinned at its two top corners) with its own
`cloth.cloth.stretch_compliance`, steps it, and measures the sag of the top edge between the
pins. The runs go to a `concurrent.futures.ProcessPoolExecutor`; any engine that maps a
function over processes (Ray, Dask, a Slurm array) runs the same `run` function.

    python python/examples/sweep_compliance.py --out sweep/          # 13 compliances, 2 s each
    python python/examples/sweep_compliance.py --out sweep/ --quick  # 4 compliances, coarse

Workers are started with "spawn": Weft steps its frames on a thread pool, which a process forked
from one that already stepped would not have. Each worker keeps to one thread
(RAYON_NUM_THREADS=1), so the processes share the cores instead of fighting for them.
"""

import argparse
import csv
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

SCENE = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "hanging.toml"


def one_thread_each():
    """Worker initializer: one solver thread per process (read when the first frame runs)."""
    os.environ["RAYON_NUM_THREADS"] = "1"


def top_edge_sag(sim, edge, pin_height):
    """How far the top edge hangs below its pinned corners (m)."""
    return pin_height - sim.positions("cloth")[edge, 1].min()


def run(job):
    """One run: (compliance m/N, frames, resolution) → a row of the CSV."""
    import weft

    compliance, frames, resolution = job
    sim = weft.Simulation(
        SCENE,
        overrides={
            "cloth.cloth.stretch_compliance": compliance,
            "cloth.cloth.resolution": [resolution, resolution],
            # Strong air damping: the cloth comes to rest within a second, so the sag is
            # the one at rest rather than a moment of its swing.
            "sim.damping": 5.0,
        },
    )
    x0 = sim.positions("cloth")
    edge = x0[:, 1] == x0[:, 1].max()
    sim.step(frames)
    stats = sim.stats()
    return {
        "stretch_compliance": compliance,
        "sag_m": top_edge_sag(sim, edge, x0[edge, 1].max()),
        "residual_max_m": stats["residual_max"],
        "kinetic_energy_j": stats["kinetic_energy"],
        "time_s": sim.time,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("sweep"), help="output folder")
    parser.add_argument("--quick", action="store_true", help="4 compliances, 16², 1 s")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    if args.quick:
        compliances, frames, resolution = np.logspace(-4, 0, 4), 60, 16
    else:
        compliances, frames, resolution = np.logspace(-6, 0, 13), 120, 32
    jobs = [(float(c), frames, resolution) for c in compliances]
    args.out.mkdir(parents=True, exist_ok=True)
    with ProcessPoolExecutor(
        max_workers=min(args.workers, len(jobs)),
        mp_context=multiprocessing.get_context("spawn"),
        initializer=one_thread_each,
    ) as pool:
        rows = list(pool.map(run, jobs))

    table = args.out / "sweep.csv"
    with open(table, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogx([r["stretch_compliance"] for r in rows], [1e3 * r["sag_m"] for r in rows], "o-")
    ax.set_xlabel("stretch compliance α (m/N)")
    ax.set_ylabel(f"top-edge sag after {rows[0]['time_s']:.1f} s (mm)")
    ax.set_title(f"Hanging cloth, XPBD, {resolution}² particles")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    plot = args.out / "sweep.png"
    fig.savefig(plot, dpi=120)
    for r in rows:
        print(f"α = {r['stretch_compliance']:.3g} m/N: sag {1e3 * r['sag_m']:.2f} mm")
    print(f"wrote {table} and {plot}")


if __name__ == "__main__":
    main()
