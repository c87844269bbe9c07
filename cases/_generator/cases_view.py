"""Unobstructed view-factor cases: V1-V12 and V15 of literature.md (planar closed forms)."""
import math

import closed
from casekit import Case, converged, exchange_area
from geom import rectangle, regular_polygon, ring_area

CF = "closed form in mpmath at 40 digits (cases/_generator/closed.py)"
AMB = 300.0
X, Y, Z = (1, 0, 0), (0, 1, 0), (0, 0, 1)


def neg(v):
    return tuple(-c for c in v)


def v01(name, gap):
    c = Case(name, f"Parallel opposed unit squares at gap {gap}", "Howell C-11; literature.md V1", ambient=AMB)
    c.rect("bottom", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("top", (0, 0, gap), Y, X, subdivide=(4, 4))
    f = float(closed.c11(1, 1, gap))
    c.vf("bottom", "top", f, "C-11 " + CF)
    c.vf("top", "bottom", f, "C-11 " + CF)
    return c


def v02():
    c = Case("v02_perpendicular_squares", "Perpendicular unit squares with a common edge", "Howell C-14; literature.md V2", ambient=AMB)
    c.rect("floor", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("wall", (0, 0, 0), Y, Z, subdivide=(4, 4))
    f = float(closed.c14(1, 1, 1))
    c.vf("floor", "wall", f, "C-14 " + CF)
    c.vf("wall", "floor", f, "C-14 " + CF)
    return c


def v03():
    c = Case("v03_perpendicular_unequal", "Perpendicular rectangles with a common edge, l = 1, w = 1, h = 2", "Howell C-14; literature.md V3", ambient=AMB)
    c.rect("floor", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("wall", (0, 0, 0), Y, (0, 0, 2), subdivide=(4, 8))
    c.vf("floor", "wall", float(closed.c14(1, 2, 1)), "C-14 " + CF)
    c.vf("wall", "floor", float(closed.c14(2, 1, 1)), "C-14 " + CF)
    return c


def v04():
    c = Case("v04_perpendicular_strips", "Perpendicular strips not sharing the edge: floor [0,1] and [1,2], wall [1,2]", "Howell C-14 algebra; literature.md V4", ambient=AMB)
    c.rect("floor_near", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("floor_far", (1, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("wall", (0, 0, 1), Y, Z, subdivide=(4, 4))
    c.vf("floor_near", "wall", float(closed.strips(0, 1, 1, 2, 1)), "C-14 bilinear strip algebra " + CF)
    c.vf("floor_far", "wall", float(closed.strips(1, 2, 1, 2, 1)), "C-14 bilinear strip algebra " + CF)
    return c


def v05():
    c = Case("v05_corner_touch", "Perpendicular unit squares touching at one corner point", "C-14 offset algebra; literature.md V5", ambient=AMB)
    c.rect("floor", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("wall", (0, 1, 0), Y, Z, subdivide=(4, 4))
    f = float(closed.perpendicular_general(0, 1, 0, 1, (0, 1), (1, 2)))
    c.vf("floor", "wall", f, "C-14 offset algebra ½[Gl(2) − 2Gl(1)] " + CF)
    c.vf("wall", "floor", f, "C-14 offset algebra (reciprocity, equal areas) " + CF)
    return c


def v06():
    c = Case("v06_half_shared_edge", "Perpendicular unit squares sharing half an edge (wall y in [0.5, 1.5])", "C-14 offset algebra; literature.md V6", ambient=AMB)
    c.rect("floor", (0, 0, 0), X, Y, subdivide=(4, 4))
    c.rect("wall", (0, 0.5, 0), Y, Z, subdivide=(4, 4))
    f = float(closed.perpendicular_general(0, 1, 0, 1, (0, 1), (0.5, 1.5)))
    c.vf("floor", "wall", f, "C-14 offset algebra ½[Gl(1.5) − Gl(0.5)] " + CF)
    return c


def v07():
    c = Case("v07_parallel_offset", "Parallel rectangles in general position: [0,1]×[0,2] to [0.5,2]×[1,1.5] at z = 0.7", "Howell C-13 corner sum (EES F3D_14); literature.md V7", ambient=AMB)
    c.rect("lower", (0, 0, 0), X, (0, 2, 0), subdivide=(4, 8))
    c.rect("upper", (0.5, 1, 0.7), (0, 0.5, 0), (1.5, 0, 0), subdivide=(6, 2))
    s = closed.parallel_general((0, 1, 0, 2), (0.5, 2, 1, 1.5), 0.7)
    c.vf("lower", "upper", float(s / 2), "C-13 corner sum " + CF)
    c.vf("upper", "lower", float(s / 0.75), "C-13 corner sum " + CF)
    return c


def v07b():
    c = Case("v07b_nonconvex_parallel", "Non-convex L-shaped polygon under a parallel square at gap 1", "C-13 corner sum over the L's two rectangles; literature.md V7", ambient=AMB)
    L = [(0, 0, 0), (2, 0, 0), (2, 1, 0), (1, 1, 0), (1, 2, 0), (0, 2, 0)]
    c.poly("ell", L)
    c.rect("square", (0.5, 0.5, 1), Y, X)
    s = closed.parallel_general((0, 2, 0, 1), (0.5, 1.5, 0.5, 1.5), 1) + closed.parallel_general((0, 1, 1, 2), (0.5, 1.5, 0.5, 1.5), 1)
    # The L's patch is the whole polygon; its centroid (7/18·(…)) drives the hemicube bias.
    c.vf("ell", "square", float(s / 3), "C-13 corner sums, L = [0,2]×[0,1] ∪ [0,1]×[1,2] " + CF)
    c.vf("square", "ell", float(s / 1), "C-13 corner sums " + CF)
    return c


def disk_rings(n, h):
    return regular_polygon((0, 0, 0), Z, 1.0, n), regular_polygon((0, 0, h), neg(Z), 1.0, n)


def fan(ring):
    """Fan triangles from the centroid (well-shaped pieces for the integration rule)."""
    cx = tuple(sum(v[k] for v in ring) / len(ring) for k in range(3))
    return [[cx, ring[k], ring[(k + 1) % len(ring)]] for k in range(len(ring))]


def v08():
    n = 64
    c = Case("v08_coaxial_disks", f"Coaxial parallel disks r1 = r2 = h = 1 as explicit {n}-gons", "Howell C-40/C-41; literature.md V8",
             ambient=AMB, note=f"Reference: exact for the two inscribed {n}-gons (1LI Gauss of Lambert's formula);\nthe curved-disk value (3 − √5)/2 = 0.38196601 differs by the tessellation error.")
    b, t = disk_rings(n, 1.0)
    c.poly("bottom", b)
    c.poly("top", t)
    s, err = converged(fan(b), [t], None, 0.5, 6)
    f = s / ring_area(b)
    curved = float(closed.coaxial_disks(1, 1, 1))
    src = f"1LI composite Gauss of Lambert's formula over the {n}-gon, converged to {err / ring_area(b):.1e} (curved C-41: {curved:.10f})"
    c.vf("bottom", "top", f, src, uncertainty=2 * err / ring_area(b) + 1e-15)
    c.vf("top", "bottom", f, src, uncertainty=2 * err / ring_area(b) + 1e-15)
    return c


def v09():
    n = 128
    c = Case("v09_coaxial_disks_unequal", f"Coaxial parallel disks r1 = 1, r2 = 2, h = 1 (`disk` shapes, {n} segments)", "Howell C-40/C-41; literature.md V9", ambient=AMB,
             note="Reference: the curved-disk closed form; its uncertainty is the tessellation error,\nthe larger of the inscribed and circumscribed n-gon deviations (computed, 1LI Gauss).")
    c.disk("small", (0, 0, 0), Z, 1.0, n)
    c.disk("large", (0, 0, 1), neg(Z), 2.0, n)
    f12, f21 = float(closed.coaxial_disks(1, 2, 1)), float(closed.coaxial_disks(2, 1, 1))
    dev12, dev21 = 0.0, 0.0
    for scale in (1.0, 1.0 / math.cos(math.pi / n)):
        a = regular_polygon((0, 0, 0), Z, scale, n)
        b = regular_polygon((0, 0, 1), neg(Z), 2 * scale, n)
        s = exchange_area(fan(a), [b], None, 1.0, 5)
        dev12 = max(dev12, abs(s / ring_area(a) - f12))
        dev21 = max(dev21, abs(s / ring_area(b) - f21))
    c.vf("small", "large", f12, f"C-41 {CF}; uncertainty = tessellation deviation", uncertainty=1.5 * dev12)
    c.vf("large", "small", f21, f"C-41 {CF}; uncertainty = tessellation deviation", uncertainty=1.5 * dev21)
    return c


def tiny_square(center, side=0.01):
    h = side / 2
    return rectangle((center[0] - h, center[1] - h, center[2]), (side, 0, 0), (0, side, 0))


def v10():
    c = Case("v10_element_to_rectangle", "Small square (0.01) parallel to a rectangle, normal through a corner: a = b = c = 1 and a = 2, b = c = 1", "Howell B-section; literature.md V10", ambient=AMB,
             note="Reference: exact for the 0.01 square (1LI Gauss); the differential value is quoted in `source`.")
    ea, eb = tiny_square((0, 0, 0)), tiny_square((10, 0, 0))
    ra, rb = rectangle((0, 0, 1), Y, X), rectangle((10, 0, 1), Y, (2, 0, 0))
    c.poly("element_a", ea).poly("element_b", eb).poly("rect_a", ra).poly("rect_b", rb)
    for e, r, name, ab in ((ea, ra, "a", (1, 1)), (eb, rb, "b", (2, 1))):
        s, err = converged([e], [r], None, 0.01, 4)
        f = s / ring_area(e)
        diff = float(closed.element_corner(ab[0], ab[1], 1))
        c.vf(f"element_{name}", f"rect_{name}", f, f"1LI Gauss over the square, converged to {err / ring_area(e):.0e}; differential B-section value {diff:.10f}", uncertainty=2 * err / ring_area(e) + 1e-15)
    return c


def v11():
    n = 128
    c = Case("v11_element_to_disk", f"Small squares (0.01) under a disk r = 1 at h = 1 ({n}-gon): on the axis and offset a = 0.5", "Howell B-section; literature.md V11", ambient=AMB,
             note=f"Reference: exact for the 0.01 squares and the inscribed {n}-gon (1LI Gauss);\nthe curved differential values are quoted in `source`.")
    disk = regular_polygon((0, 0, 1), neg(Z), 1.0, n)
    ea, eb = tiny_square((0, 0, 0)), tiny_square((0.5, 0, 0))
    c.poly("on_axis", ea).poly("offset", eb).poly("disk", disk)
    for e, name, curved in ((ea, "on_axis", 0.5), (eb, "offset", float(closed.element_disk_offset(1, 1, 0.5)))):
        s, err = converged([e], [disk], None, 0.01, 4)
        f = s / ring_area(e)
        c.vf(name, "disk", f, f"1LI Gauss over the square, converged to {err / ring_area(e):.0e}; curved differential value {curved:.10f}", uncertainty=2 * err / ring_area(e) + 1e-15)
    return c


def v12():
    c = Case("v12_point_to_triangle", "Small square (0.01) at the origin facing +z to the V12 triangle", "Lambert (1760) point-to-polygon; literature.md V12", ambient=AMB,
             note="Reference: exact for the 0.01 square (1LI Gauss); the point value 0.131969942498 is quoted.")
    e = tiny_square((0, 0, 0))
    tri = [(0.1, 1.2, 1.6), (1.5, 0.4, 0.7), (0.2, -0.3, 1.0)]
    c.poly("element", e).poly("triangle", tri)
    s, err = converged([e], [tri], None, 0.01, 4)
    f = s / ring_area(e)
    c.vf("element", "triangle", f, f"1LI Gauss over the square, converged to {err / ring_area(e):.0e}; point value 0.131969942498", uncertainty=2 * err / ring_area(e) + 1e-15)
    return c


CASES = [
    ("v01_parallel_squares", lambda: v01("v01_parallel_squares", 1.0)),
    ("v01b_parallel_squares_close", lambda: v01("v01b_parallel_squares_close", 0.5)),
    ("v02_perpendicular_squares", v02), ("v03_perpendicular_unequal", v03), ("v04_perpendicular_strips", v04),
    ("v05_corner_touch", v05), ("v06_half_shared_edge", v06), ("v07_parallel_offset", v07),
    ("v07b_nonconvex_parallel", v07b), ("v08_coaxial_disks", v08), ("v09_coaxial_disks_unequal", v09),
    ("v10_element_to_rectangle", v10), ("v11_element_to_disk", v11), ("v12_point_to_triangle", v12),
]
