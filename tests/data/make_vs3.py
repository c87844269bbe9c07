#!/usr/bin/env python3
"""Writes the View3D test inputs under tests/data/vs3/: `python3 tests/data/make_vs3.py`.

- cube.vs3: the unit cube as a closed enclosure (F 3), faces facing in (Howell C-11, C-14);
- blocked_squares.vs3: parallel unit squares 1 apart and a radiating 0.5 x 0.5 plate in a
  corner at half height, which also blocks (F 3, open);
- l_room.vs3 / l_room_f3a.vs3: one L-shaped room written in both geometry formats, with
  combined surfaces (a two-piece floor and ceiling, a wall made of two triangles).
Pure standard library; the F 3a form is derived from the same polygons by inverting View3D's
placement (x axis (-cos a, sin a, 0), y axis (-cos t sin a, -cos t cos a, sin t)).
"""
import math
import os

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vs3")


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a)


def rect(o, u, v):
    """Corners o, o+u, o+u+v, o+v: u x v is the facing side."""
    return [o, add(o, u), add(add(o, u), v), add(o, v)]


def num(x):
    r = repr(float(x))
    return "0." if r in ("0.0", "-0.0") else r


def write_f3(name, title, control, surfaces):
    """surfaces: (name, ring, emit, cmb, kind) with kind 'S' or 'O'."""
    verts, lines = [], []
    for _, ring, _, _, _ in surfaces:
        for p in ring:
            if p not in verts:
                verts.append(p)
    lines += [f"T {title}", f"C {control}", "F 3", "!  #   x   y   z"]
    lines += [f"V {k + 1:>3}  {num(p[0])}  {num(p[1])}  {num(p[2])}" for k, p in enumerate(verts)]
    lines.append("!  #  v1  v2  v3  v4 base cmb emit name")
    for k, (sname, ring, emit, cmb, kind) in enumerate(surfaces):
        ix = [verts.index(p) + 1 for p in ring] + ([0] if len(ring) == 3 else [])
        tail = f"  0  {cmb}  {emit}  {sname}" if kind == "S" else ""
        lines.append(f"{kind} {k + 1:>3}  " + "  ".join(f"{i:>3}" for i in ix) + tail)
    lines.append("End of data")
    open(os.path.join(OUT, name), "w").write("\n".join(lines) + "\n")


def blast(ring):
    """(origin, azimuth, tilt, local points) of a planar ring whose first edge is horizontal."""
    o = ring[0]
    x = unit(sub(ring[1], ring[0]))
    assert abs(x[2]) < 1e-12, "the first edge must be horizontal"
    n = unit(cross(sub(ring[1], ring[0]), sub(ring[-1], ring[0])))
    y = cross(n, x)
    a = math.atan2(x[1], -x[0])
    t = math.atan2(y[2], -(y[0] * math.sin(a) + y[1] * math.cos(a)))
    local = [(dot(sub(p, o), x), dot(sub(p, o), y)) for p in ring]
    return o, math.degrees(a) % 360.0, math.degrees(t), local


def write_f3a(name, title, control, surfaces):
    lines = [f"T {title}", f"C {control}", "F 3a", "!  #  shape base cmb emit name"]
    for k, (sname, ring, emit, cmb, _) in enumerate(surfaces):
        o, a, t, local = blast(ring)
        shape = "T" if len(ring) == 3 else "Q"
        lines.append(f"S {k + 1:>3}  {shape}  0  {cmb}  {emit}  {sname}")
        lines.append(f"   {num(o[0])} {num(o[1])} {num(o[2])}   {num(a)} {num(t)}")
        lines.append("   " + "   ".join(f"{num(px)} {num(py)}" for px, py in local))
    lines.append("End of data")
    open(os.path.join(OUT, name), "w").write("\n".join(lines) + "\n")


def cube():
    faces = [
        ("floor", rect((0, 0, 0), (1, 0, 0), (0, 1, 0))),
        ("ceiling", rect((0, 0, 1), (0, 1, 0), (1, 0, 0))),
        ("wall_y0", rect((0, 0, 0), (0, 0, 1), (1, 0, 0))),
        ("wall_y1", rect((0, 1, 0), (1, 0, 0), (0, 0, 1))),
        ("wall_x0", rect((0, 0, 0), (0, 1, 0), (0, 0, 1))),
        ("wall_x1", rect((1, 0, 0), (0, 0, 1), (0, 1, 0))),
    ]
    surfaces = [(n, r, 0.8, 0, "S") for n, r in faces]
    write_f3("cube.vs3", "Unit cube, closed", "encl=1 eps=1e-6 list=0", surfaces)


def blocked_squares():
    surfaces = [
        ("bottom", rect((0, 0, 0), (1, 0, 0), (0, 1, 0)), 0.5, 0, "S"),
        ("top", rect((0, 0, 1), (0, 1, 0), (1, 0, 0)), 0.5, 0, "S"),
        ("plate", rect((0, 0, 0.5), (0.5, 0, 0), (0, 0.5, 0)), 0.5, 0, "S"),
    ]
    write_f3("blocked_squares.vs3", "Parallel squares, radiating plate in a corner between", "encl=0", surfaces)


def l_room():
    """Footprint [0,4] x [0,3] without the notch [2.5,4] x [1.5,3]; height 2.5; faces facing in."""
    h = 2.5
    z = (0, 0, h)
    s = [
        ("floor", rect((0, 0, 0), (4, 0, 0), (0, 1.5, 0)), 0.9, 0),
        ("ceiling", rect((0, 1.5, h), (4, 0, 0), (0, -1.5, 0)), 0.9, 0),
        ("wall_south", rect((4, 0, 0), (-4, 0, 0), z), 0.9, 0),
        ("wall_east", rect((4, 1.5, 0), (0, -1.5, 0), z), 0.7, 0),
        ("notch_south", rect((2.5, 1.5, 0), (1.5, 0, 0), z), 0.7, 0),
        ("notch_east", rect((2.5, 3, 0), (0, -1.5, 0), z), 0.7, 0),
        ("wall_north", rect((0, 3, 0), (2.5, 0, 0), z), 0.9, 0),
        ("wall_west_a", [(0, 0, 0), (0, 3, 0), (0, 3, h)], 0.9, 0),
        ("floor_b", rect((0, 1.5, 0), (2.5, 0, 0), (0, 1.5, 0)), 0.9, 1),
        ("ceiling_b", rect((0, 3, h), (2.5, 0, 0), (0, -1.5, 0)), 0.9, 2),
        ("wall_west_b", [(0, 3, h), (0, 0, h), (0, 0, 0)], 0.9, 8),
    ]
    surfaces = [(n, r, e, c, "S") for n, r, e, c in s]
    for k, (n, r, _, _, _) in enumerate(surfaces):
        nrm = cross(sub(r[1], r[0]), sub(r[-1], r[0]))
        inside = (1.0, 0.75, 1.0)
        assert dot(nrm, sub(inside, r[0])) > 0, n
    write_f3("l_room.vs3", "L-shaped room", "encl=1 eps=1e-6", surfaces)
    write_f3a("l_room_f3a.vs3", "L-shaped room", "encl=1 eps=1e-6", surfaces)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    cube()
    blocked_squares()
    l_room()
