"""A radiator's tilt sweep with lambert's Python API.

A 1 m × 1 m panel at 350 K (ε = 0.9) hinged on the edge of a 2 m × 2 m floor at 300 K
(ε = 0.7), open to a 250 K sky. The panel is tilted from upright (0°) towards lying on the floor
in 10 steps; for each angle the net heat rate the panel loses is printed. Floor and panel are
gridded into patches (10 × 10 and 5 × 5), so each case is solved per patch.

With matplotlib installed, the heat rate against angle is plotted to tilt_sweep.png. The hottest
case (the one whose hottest floor patch receives the most irradiation) is saved for pyvista
(tilt_sweep.vtp) and, with pyvista installed, rendered off screen to tilt_sweep_hottest.png,
coloured by irradiation. Both images are in docs/python/.

Run: python examples/python/tilt_sweep.py [OUT_DIR]
"""

import os
import sys

import numpy as np

import lambert

FLOOR_CELLS = 10  # floor grid, cells per side (20 cm patches)
PANEL_CELLS = 5  # panel grid, cells per side (20 cm patches)


def grid(origin, u, v, n, first):
    """Vertices and quads (counter-clockwise seen along u × v) of an n × n grid on a parallelogram."""
    s = np.linspace(0.0, 1.0, n + 1)
    verts = [origin + a * u + b * v for b in s for a in s]
    quads = [
        [first + j * (n + 1) + i, first + j * (n + 1) + i + 1, first + (j + 1) * (n + 1) + i + 1, first + (j + 1) * (n + 1) + i]
        for j in range(n)
        for i in range(n)
    ]
    return verts, quads


def scene(tilt_deg: float) -> lambert.Scene:
    t = np.radians(tilt_deg)
    # The panel rises from the floor's edge y = 0 and leans over the floor (towards +y).
    up = np.array([0.0, np.sin(t), np.cos(t)])
    # Floor faces up (+z).
    fv, fq = grid(np.zeros(3), np.array([2.0, 0, 0]), np.array([0, 2.0, 0]), FLOOR_CELLS, 0)
    # Panel's front faces the floor side (+y before tilting): u = up, v = +x gives up × x.
    pv_, pq = grid(np.array([0.5, 0.0, 0.01]), up, np.array([1.0, 0, 0]), PANEL_CELLS, len(fv))
    ids = ["floor"] * len(fq) + ["panel"] * len(pq)
    return lambert.Scene.from_arrays(
        np.array(fv + pv_),
        fq + pq,
        ids,
        emissivity={"floor": 0.7, "panel": 0.9},
        temperature={"floor": 300.0, "panel": 350.0},
        ambient=250.0,
    )


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    angles = np.linspace(0.0, 80.0, 10)
    heat, results = [], []
    for a in angles:
        r = scene(a).solve()
        results.append(r)
        heat.append(r.surface["panel"]["heat_rate"])
        print(f"tilt {a:5.1f}°: panel loses {heat[-1]:8.2f} W")
    # The hottest case: the highest irradiation on any floor patch.
    peak = [r.patch.irradiation[r.patch.surface == r.surface.names.index("floor")].max() for r in results]
    k = int(np.argmax(peak))
    print(f"hottest case: tilt {angles[k]:.1f}°, floor irradiation up to {peak[k]:.1f} W/m²")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot(angles, heat, "o-")
        ax.set_xlabel("tilt from upright, °")
        ax.set_ylabel("panel heat rate, W")
        ax.set_title("Radiator panel 350 K over a 300 K floor, 250 K sky")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "tilt_sweep.png"), dpi=100)
        print("wrote tilt_sweep.png")
    except ImportError:
        print("matplotlib not installed: no plot")
    try:
        import pyvista as pv

        mesh = results[k].to_pyvista()
        mesh.save(os.path.join(out, "tilt_sweep.vtp"))
        print("wrote tilt_sweep.vtp (open with pyvista or ParaView)")
        pv.OFF_SCREEN = True
        plotter = pv.Plotter(off_screen=True, window_size=(640, 480))
        plotter.add_mesh(
            mesh, scalars="irradiation", cmap="inferno", show_edges=True,
            scalar_bar_args={"title": "irradiation, W/m²"},
        )
        plotter.add_text(f"tilt {angles[k]:.0f}°", font_size=10)
        # From the open side, low, to see the floor under the panel.
        plotter.camera_position = [(3.2, 4.2, 1.3), (1.0, 0.6, 0.0), (0.0, 0.0, 1.0)]
        plotter.screenshot(os.path.join(out, "tilt_sweep_hottest.png"))
        print("wrote tilt_sweep_hottest.png")
    except ImportError:
        print("pyvista not installed: no mesh")


if __name__ == "__main__":
    main()
