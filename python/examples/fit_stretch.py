#!/usr/bin/env python3
"""Fit the hanging cloth's stretch compliance to a target sag with scipy.optimize.

The sag is how far the top edge of assets/scenes/hanging.toml hangs below its two pinned
corners after a fixed time. Given a target (say, measured on a fabric sample), a bounded scalar
search over log10(compliance) finds the compliance whose simulated sag matches it. Without
--target the target is made by a run at a known compliance, which the fit should recover.

    python python/examples/fit_stretch.py                 # recovers α = 0.02 m/N
    python python/examples/fit_stretch.py --target 0.012  # the α that sags 12 mm
    python python/examples/fit_stretch.py --quick         # coarse cloth, 1 s
"""

import argparse
from pathlib import Path

from scipy.optimize import minimize_scalar

import weft

SCENE = Path(__file__).resolve().parents[2] / "assets" / "scenes" / "hanging.toml"


def sag(compliance, frames, resolution):
    """The top edge's sag below its pins (m) after `frames` frames at `compliance` (m/N)."""
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
    return x0[edge, 1].max() - sim.positions("cloth")[edge, 1].min()


def fit(target, frames, resolution, bounds=(-4.0, 0.0)):
    """The compliance (m/N) whose sag is `target` (m), and how many runs it took."""
    result = minimize_scalar(
        lambda e: (sag(10.0**e, frames, resolution) - target) ** 2,
        bounds=bounds,
        method="bounded",
        options={"xatol": 1e-3},
    )
    return 10.0**result.x, result.nfev


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", type=float, help="the sag to match (m)")
    parser.add_argument("--truth", type=float, default=0.02, help="α making the target (m/N)")
    parser.add_argument("--quick", action="store_true", help="16² particles, 1 s")
    args = parser.parse_args()
    frames, resolution = (60, 16) if args.quick else (120, 32)
    target = args.target
    if target is None:
        target = sag(args.truth, frames, resolution)
        print(f"target: the sag at α = {args.truth:g} m/N, {1e3 * target:.3f} mm")
    alpha, runs = fit(target, frames, resolution)
    got = sag(alpha, frames, resolution)
    print(f"fitted stretch compliance α = {alpha:.4g} m/N in {runs} runs")
    print(f"its sag {1e3 * got:.3f} mm against the target {1e3 * target:.3f} mm")


if __name__ == "__main__":
    main()
