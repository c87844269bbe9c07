#!/usr/bin/env python3
"""Parts placed in a closed box room of gridded walls, written for lambert (TOML + binary STL in
mm, read through `[[model]] unit = "mm"`) and for View3D (.vs3, the same float32 vertices in
metres, the same patch order).

Patch order (both files): the six walls floor, ceiling, wall_x0, wall_x1, wall_y0, wall_y1, each
n x n patches with k = j*n + i (i along the rectangle's u, j along v: lambert's `wall#k`), then
each part's triangles in file order (`partP#k`). Walls face into the room; parts keep the
outward winding of their STL.

Used by bench.py and reference.py; no command line of its own.
"""
import os
import struct

import numpy as np

WALLS = ["floor", "ceiling", "wall_x0", "wall_x1", "wall_y0", "wall_y1"]


def read_stl(path):
    """Triangles of a binary STL as an (n, 3, 3) float64 array of its float32 coordinates."""
    b = open(path, "rb").read()
    n = struct.unpack("<I", b[80:84])[0]
    if len(b) != 84 + 50 * n:
        return read_ascii_stl(path)
    rec = np.frombuffer(b, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), offset=84, count=n)
    return rec["v"].astype(np.float64)


def read_ascii_stl(path):
    """Triangles of an ASCII STL."""
    pts = [list(map(float, line.split()[1:4])) for line in open(path) if line.strip().startswith("vertex")]
    return np.array(pts, dtype=np.float64).reshape(-1, 3, 3)


def write_stl(path, tris):
    """Binary STL of (n, 3, 3) triangles (stored as float32, normals left zero)."""
    rec = np.zeros(len(tris), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rec["v"] = tris.astype(np.float32)
    with open(path, "wb") as f:
        f.write(b"binary STL written by validation/cad/scenes.py".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        f.write(rec.tobytes())


def room_walls(half):
    """(name, origin, u, v) of the six walls of the box [-hx, hx] x [-hy, hy] x [-hz, hz], u x v inward."""
    hx, hy, hz = half
    walls = [  # (name, origin, v, u)
        ("floor", (-hx, -hy, -hz), (0, 2 * hy, 0), (2 * hx, 0, 0)),
        ("ceiling", (-hx, -hy, hz), (2 * hx, 0, 0), (0, 2 * hy, 0)),
        ("wall_x0", (-hx, -hy, -hz), (0, 0, 2 * hz), (0, 2 * hy, 0)),
        ("wall_x1", (hx, -hy, -hz), (0, 2 * hy, 0), (0, 0, 2 * hz)),
        ("wall_y0", (-hx, -hy, -hz), (2 * hx, 0, 0), (0, 0, 2 * hz)),
        ("wall_y1", (-hx, hy, -hz), (0, 0, 2 * hz), (2 * hx, 0, 0)),
    ]
    return [(name, o, u, v) for name, o, v, u in walls]


def wall_patches(half, n):
    """Wall patches as (4, 3) corner arrays in lambert's order (walls, then j along v, i along u)."""
    out = []
    for _, o, u, v in room_walls(half):
        o, u, v = (np.array(x, dtype=np.float64) for x in (o, u, v))
        for j in range(n):
            for i in range(n):
                q = lambda a, b: o + u * (a / n) + v * (b / n)
                out.append(np.array([q(i, j), q(i + 1, j), q(i + 1, j + 1), q(i, j + 1)]))
    return out


def place(tris_mm, size_m, count):
    """The part centred at the origin, scaled so that its largest extent is size_m metres (None:
    its own size, the file being in mm), in `count` copies along x, 1.67 extents apart centre to
    centre (0.5 m for a 0.3 m part); odd copies are turned 180 degrees about z, facing the even
    ones. Returns a list of (n, 3, 3) arrays in mm, exactly representable in float32."""
    pts = tris_mm.reshape(-1, 3)
    lo, hi = pts.min(0), pts.max(0)
    extent = (hi - lo).max()
    scale = 1.0 if size_m is None else size_m * 1e3 / extent
    base = (tris_mm - (lo + hi) / 2) * scale
    spacing = 5.0 / 3.0 * extent * scale
    copies = []
    for p in range(count):
        t = base.copy()
        if p % 2 == 1:
            t[..., 0] *= -1
            t[..., 1] *= -1
        t[..., 0] += (p - (count - 1) / 2) * spacing
        copies.append(drop_degenerate(t.astype(np.float32).astype(np.float64)))
    return copies


# Corners closer than this fraction of the bounding-box diagonal are one point (lambert's default
# weld tolerance), so a triangle with such an edge, or with zero area, is left out of both files.
WELD_FRACTION = 1e-6


def drop_degenerate(tris):
    """The triangles without a welded-together edge or zero area, so both codes see the same list."""
    pts = tris.reshape(-1, 3)
    tol = WELD_FRACTION * np.linalg.norm(pts.max(0) - pts.min(0))
    edges = np.stack([tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 1], tris[:, 0] - tris[:, 2]], axis=1)
    short = (np.linalg.norm(edges, axis=2) <= tol).any(axis=1)
    flat = np.linalg.norm(np.cross(edges[:, 0], edges[:, 1]), axis=1) == 0
    return tris[~(short | flat)]


def write_scene(d, parts_mm, half, n, title, part_eps=0.85, part_t=400.0):
    """d/scene.toml with d/partP.stl (surfaces partP) for lambert and d/scene.vs3 for View3D (raw
    factors: encl=0, so View3D does not normalise its rows); returns the patch count."""
    os.makedirs(d, exist_ok=True)
    s = [f'title = "{title}"\n']
    for p, tris in enumerate(parts_mm):
        write_stl(os.path.join(d, f"part{p}.stl"), tris)
        s.append(f'\n[[model]]\nfile = "part{p}.stl"\nunit = "mm"\nemissivity = {part_eps}\n'
                 f'temperature = {part_t}\n')
    for name, o, u, v in room_walls(half):
        s.append(f'\n[[surface]]\nname = "{name}"\nrectangle = {{ origin = {list(map(float, o))}, '
                 f'u = {list(map(float, u))}, v = {list(map(float, v))} }}\n'
                 f'emissivity = 0.8\ntemperature = 300.0\n' + (f"subdivide = [{n}, {n}]\n" if n > 1 else ""))
    open(os.path.join(d, "scene.toml"), "w").write("".join(s))
    # View3D: the same geometry in metres, vertices listed per surface.
    verts, surfs = [], []

    def vid(p):
        verts.append(p)
        return len(verts)

    for quad in wall_patches(half, n):
        surfs.append([vid(tuple(c)) for c in quad])
    for tris in parts_mm:
        for t in tris:
            surfs.append([vid(tuple(c * 1e-3)) for c in t] + [0])
    with open(os.path.join(d, "scene.vs3"), "w") as f:
        f.write(f"T {title}\nC encl=0 list=0 eps=1.0e-4\nF 3\n")
        for k, p in enumerate(verts, 1):
            f.write(f"V {k} {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
        for k, c in enumerate(surfs, 1):
            f.write(f"S {k} {c[0]} {c[1]} {c[2]} {c[3]} 0 0 0.9 s{k}\n")
        f.write("End of data\n")
    return len(surfs)


def patch_names(nparts_tris, n):
    """lambert's `--patches` row names in the patch order above."""
    names = [f"{w}#{k}" for w in WALLS for k in range(n * n)]
    for p, nt in enumerate(nparts_tris):
        names += [f"part{p}#{k}" for k in range(nt)]
    return names
