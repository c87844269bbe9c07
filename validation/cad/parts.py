#!/usr/bin/env python3
"""Parametric machined parts built with a CAD kernel (build123d, `pip install build123d`) and
exported as binary STL in millimetres, as a CAD tool would.

Parts (all concave):
- heat_sink: a 60 x 40 x 5 mm base with straight fins 2 mm thick and 25 mm tall;
- l_bracket: an L of two 40 x 30 mm legs, 4 mm thick, each leg with two 6 mm holes;
- u_channel: a 60 mm long U, 30 mm wide, 20 mm tall, walls 3 mm;
- boards: two 100 x 80 x 1.6 mm circuit boards with a few components (boxes) on them, the
  contents of the enclosure scene.

usage: parts.py OUT_DIR [--coarse]   (--coarse: coarse tessellation and no holes, the small
meshes of the reference scenes in validation/reference/real_parts/)
"""
import os
import sys

from build123d import Align, Box, Cylinder, Location, Pos, export_stl

# Tessellation of curved faces: chord tolerance in mm and angle in radians (fine, coarse).
TESS = {False: (0.05, 0.2), True: (0.5, 0.6)}


def heat_sink(fins=6, coarse=False):
    """A finned heat sink: base 60 x 40 x 5 mm, `fins` fins 2 x 40 x 25 mm on top."""
    base = Box(60, 40, 5, align=(Align.CENTER, Align.CENTER, Align.MIN))
    pitch = (60 - 2) / (fins - 1)
    body = base
    for k in range(fins):
        fin = Box(2, 40, 25, align=(Align.CENTER, Align.CENTER, Align.MIN))
        body = body + Pos(-29 + k * pitch, 0, 5) * fin
    return body


def l_bracket(coarse=False):
    """An L-bracket: a 40 x 30 x 4 mm foot and a 40 x 30 x 4 mm upright, two 6 mm holes in each."""
    foot = Box(40, 30, 4, align=(Align.MIN, Align.CENTER, Align.MIN))
    upright = Box(4, 30, 40, align=(Align.MIN, Align.CENTER, Align.MIN))
    body = foot + upright
    if not coarse:
        for y in (-8, 8):
            body = body - Pos(26, y, 0) * Cylinder(3, 20)
            body = body - Location((0, y, 26), (0, 90, 0)) * Cylinder(3, 20)
    return body


def u_channel(coarse=False):
    """A U-channel 60 mm long (y), 30 mm wide (x), 20 mm tall, walls 3 mm thick."""
    outer = Box(30, 60, 20, align=(Align.CENTER, Align.CENTER, Align.MIN))
    inner = Pos(0, 0, 3) * Box(24, 62, 20, align=(Align.CENTER, Align.CENTER, Align.MIN))
    return outer - inner


def boards(coarse=False):
    """Two circuit boards 100 x 80 x 1.6 mm, 30 mm apart, with chips and a tall capacitor-like block."""
    parts = []
    for z in (10.0, 40.0):
        board = Pos(0, 0, z) * Box(100, 80, 1.6, align=(Align.CENTER, Align.CENTER, Align.MIN))
        top = z + 1.6
        chips = [(-25, -15, 20, 20, 3), (20, 10, 30, 15, 2), (30, -25, 10, 10, 12)]
        for x, y, w, d, h in chips:
            board = board + Pos(x, y, top) * Box(w, d, h, align=(Align.CENTER, Align.CENTER, Align.MIN))
        parts.append(board)
    return parts[0] + parts[1]


PARTS = {"heat_sink": heat_sink, "l_bracket": l_bracket, "u_channel": u_channel, "boards": boards}


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    coarse = "--coarse" in sys.argv
    os.makedirs(out, exist_ok=True)
    tol, ang = TESS[coarse]
    for name, make in PARTS.items():
        if coarse and name == "boards":
            continue
        shape = make(coarse=coarse)
        path = os.path.join(out, f"{name}.stl")
        export_stl(shape, path, tolerance=tol, angular_tolerance=ang)
        n = (os.path.getsize(path) - 84) // 50
        print(f"{path}: {n} triangles, volume {shape.volume:.1f} mm3")


if __name__ == "__main__":
    main()
