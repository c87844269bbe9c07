"""Irregular triangulations of flat faces: a grid whose inner points are jittered by up to
`JITTER` of a cell and whose quads are split along a random diagonal, so no two triangles are
alike and none lie on a regular grid (the way a CAD mesher's output looks to lambert)."""
import random

# Share of a cell by which inner points move: every jittered quad stays convex, so both
# diagonals give triangles of positive area.
JITTER = 0.2

# The irregular box of the CAD benchmarks: 1 x 1.3 x 0.7 m, (name, origin, u, v), u x v inward.
BOX = [
    ("floor", (0, 0, 0), (1, 0, 0), (0, 1.3, 0)),
    ("ceiling", (0, 0, 0.7), (0, 1.3, 0), (1, 0, 0)),
    ("wall_x0", (0, 0, 0), (0, 1.3, 0), (0, 0, 0.7)),
    ("wall_x1", (1, 0, 0), (0, 0, 0.7), (0, 1.3, 0)),
    ("wall_y0", (0, 0, 0), (0, 0, 0.7), (1, 0, 0)),
    ("wall_y1", (0, 1.3, 0), (1, 0, 0), (0, 0, 0.7)),
]
# The obstruction-only cuboid inside it.
BLOCK = ((0.35, 0.45, 0.2), (0.65, 0.85, 0.5))


def cell_for(triangles):
    """Cell size that gives about `triangles` triangles over the box's 5.82 m²."""
    area = 2 * (1 * 1.3 + 1 * 0.7 + 1.3 * 0.7)
    return (2 * area / triangles) ** 0.5


def face_triangles(rng, origin, u, v, h):
    """Triangles of the parallelogram (origin, u, v), cells about h wide, CCW about u x v."""
    lu = sum(c * c for c in u) ** 0.5
    lv = sum(c * c for c in v) ** 0.5
    nu, nv = max(1, round(lu / h)), max(1, round(lv / h))
    pts = {}
    for a in range(nu + 1):
        for b in range(nv + 1):
            s, t = a / nu, b / nv
            if 0 < a < nu:
                s += rng.uniform(-JITTER, JITTER) / nu
            if 0 < b < nv:
                t += rng.uniform(-JITTER, JITTER) / nv
            pts[a, b] = tuple(origin[k] + s * u[k] + t * v[k] for k in range(3))
    tris = []
    for a in range(nu):
        for b in range(nv):
            p00, p10, p11, p01 = pts[a, b], pts[a + 1, b], pts[a + 1, b + 1], pts[a, b + 1]
            if rng.random() < 0.5:
                tris += [(p00, p10, p11), (p00, p11, p01)]
            else:
                tris += [(p00, p10, p01), (p10, p11, p01)]
    return tris


def box_faces(triangles, seed):
    """(name, triangles) for the six faces of the irregular box."""
    rng = random.Random(seed)
    h = cell_for(triangles)
    return [(name, face_triangles(rng, o, u, v, h)) for name, o, u, v in BOX]
