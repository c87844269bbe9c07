"""Obstructed cases: shadows of one convex blocker, integrated exactly (shadow.py)."""
import math

import closed
from casekit import Case, converged
from geom import rectangle
from shadow import plate, box
from cases_view import CF, AMB, X, Y, Z

SHADOW = "1LI Gauss of Lambert's formula minus the blocker's exact central-projection shadow (cases/_generator/shadow.py), cells split at the shadow's kinks"


def squares(c, blocker_ring):
    c.rect("bottom", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("top", (0, 0, 1), Y, X, subdivide=(4, 4))
    bottom, top = rectangle((0, 0, 0), X, Y), rectangle((0, 0, 1), Y, X)
    # Quadrant cells: the shadow's edges cross the receiver's at x, y = 1/2.
    s, err = converged([rectangle((x, y, 0), (0.5, 0, 0), (0, 0.5, 0)) for x in (0, 0.5) for y in (0, 0.5)], [top], plate(blocker_ring), 0.5, 8)
    return s, err, bottom, top


def o1():
    c = Case("o1_squares_centred_blocker", "Parallel unit squares at gap 1 with a centred 0.5×0.5 obstruction midway", "Obstructed C-11 (literature.md, issue reference 0.0995062946); View3D-style shadow test", ambient=AMB)
    blk = rectangle((0.25, 0.25, 0.5), (0, 0.5, 0), (0.5, 0, 0))
    s, err, _, _ = squares(c, blk)
    c.obstruction("blocker", blk)
    u = 2 * err + 1e-15
    c.vf("bottom", "top", s, f"{SHADOW}; converged to {err:.0e}", uncertainty=u, blocker=plate(blk))
    c.vf("top", "bottom", s, "reciprocity and symmetry of the same integral", uncertainty=u, blocker=plate(blk))
    return c


def o2():
    c = Case("o2_squares_plate_between", "The o1 geometry with the blocker as a two-sided exchanging plate (two coincident one-sided surfaces)", "Obstructed C-11 and C-13 corner sums; SPEC 'a thin plate is two surfaces'", ambient=AMB)
    blk = rectangle((0.25, 0.25, 0.5), (0, 0.5, 0), (0.5, 0, 0))
    s, err, _, _ = squares(c, blk)
    c.rect("plate_down", (0.25, 0.25, 0.5), (0, 0.5, 0), (0.5, 0, 0), subdivide=(2, 2))
    c.rect("plate_up", (0.25, 0.25, 0.5), (0.5, 0, 0), (0, 0.5, 0), subdivide=(2, 2))
    u = 2 * err + 1e-15
    c.vf("bottom", "top", s, f"{SHADOW}; converged to {err:.0e}", uncertainty=u, blocker=plate(blk))
    sp = closed.parallel_general((0, 1, 0, 1), (0.25, 0.75, 0.25, 0.75), 0.5)
    c.vf("bottom", "plate_down", float(sp), "C-13 corner sum " + CF)
    c.vf("plate_up", "top", float(sp / 0.25), "C-13 corner sum " + CF)
    c.vf("plate_down", "bottom", float(sp / 0.25), "C-13 corner sum " + CF)
    return c


def o3():
    nr, nb = 12, 6
    c = Case("o3_obstructed_room", f"Room 3 m cube ({nr}×{nr} patches per face) around a block [1,2]³ ({nb}×{nb} per face)", "Obstructed-room benchmark of the issue (coarse version); exact shadows of the convex block",
             note="The full benchmark is 34×34 per face + 16×16 per block face (N = 8472); this case keeps it fast.\nThe reference row F(floor→·) closes to 1 within 4e-12 (opposite + 4 walls + block bottom + 4 block sides).")
    c.quick = False
    L = 3.0
    c.rect("floor", (0, 0, 0), (L, 0, 0), (0, L, 0), subdivide=(nr, nr))
    c.rect("ceiling", (0, 0, L), (0, L, 0), (L, 0, 0), subdivide=(nr, nr))
    c.rect("wall_x0", (0, 0, 0), (0, L, 0), (0, 0, L), subdivide=(nr, nr))
    c.rect("wall_x1", (L, 0, 0), (0, 0, L), (0, L, 0), subdivide=(nr, nr))
    c.rect("wall_y0", (0, 0, 0), (0, 0, L), (L, 0, 0), subdivide=(nr, nr))
    c.rect("wall_y1", (0, L, 0), (L, 0, 0), (0, 0, L), subdivide=(nr, nr))
    c.rect("block_bottom", (1, 1, 1), Y, X, subdivide=(nb, nb))
    c.rect("block_top", (1, 1, 2), X, Y, subdivide=(nb, nb))
    c.rect("block_x0", (1, 1, 1), Z, Y, subdivide=(nb, nb))
    c.rect("block_x1", (2, 1, 1), Y, Z, subdivide=(nb, nb))
    c.rect("block_y0", (1, 1, 1), X, Z, subdivide=(nb, nb))
    c.rect("block_y1", (1, 2, 1), Z, X, subdivide=(nb, nb))
    blk = box((1, 1, 1), (2, 2, 2))
    floor_cells = []
    br = [0, 1, 1.5, 2, 3]
    for x0, x1 in zip(br[:-1], br[1:]):
        for y0, y1 in zip(br[:-1], br[1:]):
            floor_cells.append(rectangle((x0, y0, 0), (x1 - x0, 0, 0), (0, y1 - y0, 0)))
    ring = lambda n: c.surface(n).patches
    whole = {n: [rectangle(*args)] for n, args in {
        "ceiling": ((0, 0, L), (0, L, 0), (L, 0, 0)), "wall_x0": ((0, 0, 0), (0, L, 0), (0, 0, L)),
        "block_bottom": ((1, 1, 1), Y, X), "block_x0": ((1, 1, 1), Z, Y), "block_top": ((1, 1, 2), X, Y)}.items()}
    total = 0.0
    for to, w in (("ceiling", 1), ("wall_x0", 4), ("block_bottom", 1), ("block_x0", 4), ("block_top", 1)):
        s, err = converged(floor_cells, whole[to], blk if to in ("ceiling", "wall_x0") else None, 0.25, 6)
        f = s / (L * L)
        total += w * f
        src = (SHADOW if to in ("ceiling", "wall_x0") else "1LI Gauss of Lambert's formula (a convex block's faces never hide each other)") + f"; converged to {err / 9:.0e}"
        c.vf("floor", to, f, src, uncertainty=2 * err / 9 + 1e-14, blocker=blk, receiver=whole[to])
    assert abs(total - 1) < 1e-10, total
    f = float(closed.parallel_general((1, 2, 1, 2), (0, 3, 0, 3), 1))
    c.vf("block_x0", "wall_x0", f, "C-13 corner sum " + CF, receiver=[rectangle((0, 0, 0), (0, L, 0), (0, 0, L))])
    return c


def o4():
    c = Case("o4_squares_side_blocker", "Parallel unit squares at gap 1 with an obstruction beside them that cuts no sight line", "Howell C-11 (unchanged); no-false-occlusion test", ambient=AMB)
    c.rect("bottom", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("top", (0, 0, 1), Y, X, subdivide=(4, 4))
    c.obstruction("side_blocker", rectangle((1.2, 0.25, 0.5), (0, 0.5, 0), (0.5, 0, 0)))
    f = float(closed.c11(1, 1, 1))
    c.vf("bottom", "top", f, "C-11 " + CF)
    return c


def o5():
    c = Case("o5_squares_corner_blocker", "Parallel unit squares at gap 1 with a 0.5×0.5 obstruction in a corner at z = 0.5", "View3D's shipped square-obstruction.vs3 (research/view3d.md §5: exact 0.1498686718)", ambient=AMB)
    c.rect("bottom", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("top", (0, 0, 1), Y, X, subdivide=(4, 4))
    blk = rectangle((0, 0, 0.5), (0, 0.5, 0), (0.5, 0, 0))
    c.obstruction("blocker", blk)
    s, err = converged([rectangle((0, 0, 0), X, Y)], [rectangle((0, 0, 1), Y, X)], plate(blk), 0.5, 8)
    u = 2 * err + 1e-15
    c.vf("bottom", "top", s, f"{SHADOW}; converged to {err:.0e}", uncertainty=u, blocker=plate(blk))
    c.vf("top", "bottom", s, "reciprocity of the same integral (equal areas)", uncertainty=u, blocker=plate(blk))
    return c


def o6():
    c = Case("o6_concentric_cubes", "Outward cube of side 0.5 centred in an inward cube of side 2 (glTF, one node each)", "Enclosure algebra (exact for a convex inner body): F12 = 1, F21 = A1/A2 = 0.0625, F22 = 0.9375",
             note="The outer box sees itself past the inner one: obstructed self-view.")
    import gltf
    inner = gltf.box((-0.25, -0.25, -0.25), (0.25, 0.25, 0.25), 2)
    outer = gltf.box((-1, -1, -1), (1, 1, 1), 2, inward=True)
    c.model("boxes.gltf", [("inner", inner, {}), ("outer", outer, {})])
    from casekit import point_estimates
    a1, a2 = gltf.mesh_area(c.surface("inner").patches), gltf.mesh_area(c.surface("outer").patches)
    ce, ge = point_estimates(c.surface("outer").patches, c.surface("inner").patches, None)
    bias = max(abs(ce / a2 - a1 / a2), abs(ge / a2 - a1 / a2))
    c.vf("inner", "outer", 1.0, "closure of a convex body inside an enclosure (exact)", bias=0.0)
    c.vf("outer", "inner", a1 / a2, "reciprocity A1/A2 (exact)", bias=bias)
    c.vf("outer", "outer", 1 - a1 / a2, "closure 1 − A1/A2 (exact)", bias=bias)
    return c


def o7():
    import gltf
    import irregular
    c = Case("o7_irregular_box_block", "Closed 1 × 1.3 × 0.7 m box, faces triangulated at random (572 triangles, glTF), an obstruction-only cuboid inside",
             "CAD benchmark box_500_block (validation/cad.md); exact shadows of the convex block",
             note="Whole-face factors do not depend on the triangulation: the references integrate the faces\nas rectangles (float32 corners, as lambert reads them) past the float32 block.")
    c.quick = False
    lo, hi = irregular.BLOCK
    faces = irregular.box_faces(500, 7)
    c.model("box.gltf", [(name, tris, {}) for name, tris in faces] + [("block", gltf.box(lo, hi, 1), {"role": "obstruction"})])
    for name, f, err, blk, r in irregular_box_references():
        c.vf("floor", name, f, f"{SHADOW}; converged to {err:.0e}", uncertainty=2 * err + 1e-14, blocker=blk, receiver=[r])
    return c


def irregular_box_references():
    """(receiver, F(floor -> receiver), convergence, blocker, receiver ring) of the irregular box
    past its block: whole faces (float32 corners, as lambert reads them), so the values hold for
    every triangulation (also validation/scenes/gen_cad.py --reference)."""
    import gltf
    import irregular
    lo, hi = irregular.BLOCK
    f = lambda x: gltf.f32((x, 0.0, 0.0))[0]
    X, Y, Z = f(1.0), f(1.3), f(0.7)
    blk = box(gltf.f32(lo), gltf.f32(hi))
    floor = rectangle((0, 0, 0), (X, 0, 0), (0, Y, 0))
    out = []
    for name, r in (("ceiling", rectangle((0, 0, Z), (0, Y, 0), (X, 0, 0))),
                    ("wall_x0", rectangle((0, 0, 0), (0, Y, 0), (0, 0, Z))),
                    ("wall_y1", rectangle((0, Y, 0), (X, 0, 0), (0, 0, Z)))):
        s, err = converged([floor], [r], blk, 0.05, 6)
        out.append((name, s / (X * Y), err / (X * Y), blk, r))
    return out


def o8():
    import gltf
    from shadow import ConvexBlocker
    n = 8
    c = Case("o8_sphere_in_room", f"1,280-facet sphere (r = 0.6, glTF, facing out) centred in a 4 m cube room ({n}×{n} patches per wall)",
             "CAD benchmark sphere_room (validation/cad.md): symmetry, reciprocity and exact shadows of the convex facetted sphere",
             note="The icosphere keeps the coordinate mirrors and the cyclic axis permutation (float32 rounding\nkeeps them too), which map the walls onto each other: F(sphere -> each wall) = 1/6 exactly.")
    c.quick = False
    # At the suite's 1e-6 goal auto integrates the wall pairs behind the sphere (> 240 s).
    c.auto_goal = 1e-4
    sphere = gltf.icosphere((0, 0, 0), 0.6, 3)
    c.model("sphere.gltf", [("sphere", sphere, {})])
    L, o = 4.0, -2.0
    # (origin, u, v) with u × v facing into the room.
    walls = {"floor": ((o, o, o), (L, 0, 0), (0, L, 0)), "ceiling": ((o, o, -o), (0, L, 0), (L, 0, 0)),
             "wall_x0": ((o, o, o), (0, L, 0), (0, 0, L)), "wall_x1": ((-o, o, o), (0, 0, L), (0, L, 0)),
             "wall_y0": ((o, o, o), (0, 0, L), (L, 0, 0)), "wall_y1": ((o, -o, o), (L, 0, 0), (0, 0, L))}
    for name, (org, u, v) in walls.items():
        c.rect(name, org, u, v, subdivide=(n, n))
    tris = c.surface("sphere").patches
    a_s = gltf.mesh_area(tris)
    for name in ("floor", "wall_x1", "wall_y0"):
        c.vf("sphere", name, 1 / 6, "symmetry of the icosphere and the room (exact); row sum 1 for a convex body", bias=0.0)
    # The facetted sphere as one convex blocker: its float32 vertices and the facets' edges.
    verts = sorted({v for t in tris for v in t})
    index = {v: k for k, v in enumerate(verts)}
    edges = sorted({tuple(sorted((index[t[k]], index[t[(k + 1) % 3]]))) for t in tris for k in range(3)})
    ball = ConvexBlocker(verts, edges)
    floor = rectangle(*walls["floor"])
    ceiling = rectangle(*walls["ceiling"])
    s, err = converged([floor], [ceiling], ball, 0.5, 6)
    c.vf("floor", "ceiling", s / (L * L), f"{SHADOW}; converged to {err / (L * L):.0e}",
         uncertainty=2 * err / (L * L) + 1e-14, blocker=ball, receiver=[ceiling])
    c.vf("floor", "sphere", a_s / (6 * L * L), f"reciprocity with F(sphere -> floor) = 1/6 and the mesh area {a_s!r} m² (exact)",
         receiver=tris)
    return c


CASES = [
    ("o1_squares_centred_blocker", o1), ("o2_squares_plate_between", o2),
    ("o3_obstructed_room", o3), ("o4_squares_side_blocker", o4), ("o5_squares_corner_blocker", o5),
    ("o6_concentric_cubes", o6), ("o7_irregular_box_block", o7), ("o8_sphere_in_room", o8),
]
