"""Radiant temperatures at sensor points in the cube furnace, from point view factors.

A small plate sensor at point p facing direction d receives the irradiation
G = sum_j F(p, d -> j) J_j from the diffuse surfaces j (radiosity J_j from the solve); its
plane radiant temperature is (G / sigma)^(1/4). The mean radiant temperature of a small
sphere is approximated by the six-direction method (ISO 7726): the plane irradiations facing
+-x, +-y, +-z averaged with equal weights. Each factor is exact (Lambert's formula with exact
shadows), and in this closed furnace every sensor's factors sum to 1.

    python examples/python/sensors_mrt.py
"""

from pathlib import Path

import numpy as np

import lambert

ROOT = Path(__file__).resolve().parents[2]
DIRECTIONS = {
    "+x": (1, 0, 0),
    "-x": (-1, 0, 0),
    "+y": (0, 1, 0),
    "-y": (0, -1, 0),
    "+z": (0, 0, 1),
    "-z": (0, 0, -1),
}
SENSORS = {
    "centre": (0.5, 0.5, 0.5),
    "above the floor": (0.5, 0.5, 0.1),
    "below the ceiling": (0.5, 0.5, 0.9),
    "corner": (0.15, 0.15, 0.5),
}


def main() -> None:
    scene = lambert.Scene.load(ROOT / "cases" / "cube_furnace" / "scene.toml")
    result = scene.solve(patches=True)
    radiosity = result.patch.radiosity  # W/m², one per patch
    # One row per sensor and direction: six small plates at every sensor point.
    points = np.array([p for p in SENSORS.values() for _ in DIRECTIONS], dtype=float)
    normals = np.array([d for _ in SENSORS for d in DIRECTIONS.values()], dtype=float)
    factors = scene.point_view_factors(points, normals, patches=True)  # (sensors × 6, patches)
    assert np.allclose(factors.sum(axis=1), 1.0, atol=1e-12), "every sensor sees the whole furnace"
    irradiation = (factors @ radiosity).reshape(len(SENSORS), len(DIRECTIONS))
    plane = (irradiation / lambert.SIGMA) ** 0.25
    mrt = (irradiation.mean(axis=1) / lambert.SIGMA) ** 0.25
    print(f"{'sensor':>18}  " + "  ".join(f"{d:>6}" for d in DIRECTIONS) + "   MRT [K]")
    for name, row, t in zip(SENSORS, plane, mrt):
        print(f"{name:>18}  " + "  ".join(f"{x:6.1f}" for x in row) + f"   {t:7.1f}")


if __name__ == "__main__":
    main()
