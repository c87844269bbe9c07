"""A radiator's tilt sweep with lambert's Python API.

A 1 m × 1 m panel at 350 K (ε = 0.9) hinged on the edge of a 2 m × 2 m floor at 300 K
(ε = 0.7), open to a 250 K sky. The panel is tilted from upright (0°) towards lying on the floor
in 10 steps; for each angle the net heat rate the panel loses is printed and, when matplotlib is
installed, plotted to tilt_sweep.png. The last case is also saved for pyvista (tilt_sweep.vtp).

Run: python examples/python/tilt_sweep.py
"""

import numpy as np

import lambert


def scene(tilt_deg: float) -> lambert.Scene:
    t = np.radians(tilt_deg)
    # The panel rises from the floor's edge y = 0 and leans over the floor (towards +y).
    up = np.array([0.0, np.sin(t), np.cos(t)])
    base = [np.array([0.5, 0.0, 0.01]), np.array([1.5, 0.0, 0.01])]
    vertices = np.array(
        [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], base[0], base[1], base[1] + up, base[0] + up],
        dtype=float,
    )
    # Floor faces up; the panel's front faces the floor side (+y before tilting).
    faces = [[0, 1, 2, 3], [4, 7, 6, 5]]
    return lambert.Scene.from_arrays(
        vertices,
        faces,
        ["floor", "panel"],
        emissivity={"floor": 0.7, "panel": 0.9},
        temperature={"floor": 300.0, "panel": 350.0},
        ambient=250.0,
    )


def main() -> None:
    angles = np.linspace(0.0, 80.0, 10)
    heat = []
    for a in angles:
        r = scene(a).solve()
        heat.append(r.surface["panel"]["heat_rate"])
        print(f"tilt {a:5.1f}°: panel loses {heat[-1]:8.2f} W")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        plt.plot(angles, heat, "o-")
        plt.xlabel("tilt from upright, °")
        plt.ylabel("panel heat rate, W")
        plt.savefig("tilt_sweep.png", dpi=120)
        print("wrote tilt_sweep.png")
    except ImportError:
        print("matplotlib not installed: no plot")
    try:
        r.to_pyvista().save("tilt_sweep.vtp")
        print("wrote tilt_sweep.vtp (open with pyvista or ParaView)")
    except ImportError:
        print("pyvista not installed: no mesh")


if __name__ == "__main__":
    main()
