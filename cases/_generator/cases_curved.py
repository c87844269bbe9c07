"""Curved and long (2-D-like) geometry by tessellation: V13, V14, V16-V19 of literature.md.
References are exact for the tessellated, float32-rounded geometry; the curved or 2-D
catalogue value is quoted in `source`."""
import math

import closed
import gltf
from casekit import Case, converged, point_estimates
from geom import rectangle, regular_polygon, ring_area, rule_1d, graded_cells, parallelogram_rule, point_to_ring, ring_normal
from cases_view import CF, AMB, X, Y, Z, neg, fan


# Exact shadow integration is O(blockers) per viewpoint. A closed convex mesh is summed over its
# faces instead (src/viewfactor/shadow/solid.rs); an open tessellated body is hundreds of blockers.
SLOW_SHADOW = ("exact shadowing treats each facet of an open tessellated body (not a closed convex solid) as its own "
               "blocker: > 100 s on 2 cores (validation/obstructed.md); auto and Monte Carlo cover this case")
SLOW_AUTO = ("at the full suite's 1e-6 goal auto shadow-integrates pairs behind hundreds of facet blockers: "
             "> 150 s on 2 cores (4.7 s at the default 1e-4; validation/obstructed.md); Monte Carlo covers this case")


def v13():
    c = Case("v13_concentric_spheres", "Concentric spheres r1/r2 = 0.5 (icospheres, 320 triangles each, glTF)", "Howell C-135 (cit.); literature.md V13",
             note="Exact for any convex inner body: F12 = 1, F21 = A1/A2, F22 = 1 − A1/A2 with the\nmeshes' own areas (float32 vertices as stored in the glTF).")
    c.quick = False
    inner = gltf.icosphere((0, 0, 0), 0.5, 2)
    outer = gltf.icosphere((0, 0, 0), 1.0, 2, inward=True)
    c.skips["auto"] = SLOW_AUTO
    c.model("spheres.gltf", [("inner", inner, {}), ("outer", outer, {})])
    a1, a2 = gltf.mesh_area(c.surface("inner").patches), gltf.mesh_area(c.surface("outer").patches)
    c.vf("inner", "outer", 1.0, "closure of a convex body inside an enclosure (exact)", bias=0.0)
    ce, ge = point_estimates(c.surface("outer").patches, c.surface("inner").patches, None)
    bias = max(abs(ce / a2 - a1 / a2), abs(ge / a2 - a1 / a2))
    c.vf("outer", "inner", a1 / a2, f"reciprocity A1/A2 with mesh areas {a1!r}, {a2!r} m² (curved: 0.25)", bias=bias)
    c.vf("outer", "outer", 1 - a1 / a2, "closure 1 − A1/A2 (curved: 0.75)", bias=bias)
    return c


def v14():
    n = 64
    c = Case("v14_sphere_to_disk", f"Sphere (icosphere r = 0.5, 1280 triangles) to a coaxial disk a = 1 at h = 1 ({n}-gon)", "Howell C-125 (cit.); literature.md V14", ambient=AMB,
             note="Reference: exact for the meshed sphere and the n-gon (1LI Gauss over every triangle);\nthe curved value 1/2·(1 − 1/√2) = 0.14644661 is independent of the sphere radius.")
    c.quick = False
    sphere = gltf.icosphere((0, 0, 0), 0.5, 3)
    c.model("sphere.gltf", [("sphere", sphere, {})])
    disk = regular_polygon((0, 0, 1), neg(Z), 1.0, n)
    c.poly("disk", disk)
    tris = c.surface("sphere").patches
    s, err = converged(tris, [disk], None, 0.2, 4)
    a = gltf.mesh_area(tris)
    curved = float(closed.sphere_to_disk(1, 1))
    c.vf("sphere", "disk", s / a, f"1LI Gauss over the mesh, converged to {err / a:.0e}; curved C-125 {curved:.10f}", uncertainty=2 * err / a + 1e-15)
    c.vf("disk", "sphere", s / ring_area(disk), f"reciprocity of the same integral; curved {curved * math.pi / math.pi * 4 * 0.25 / 1:.10f}·A_s/A_d", uncertainty=2 * err / ring_area(disk) + 1e-15)
    return c


def v16a():
    L = 10.0
    c = Case("v16a_long_parallel_plates", f"Long parallel plates, width 1, gap 1, length {L:g} (C-1 in 3-D)", "Hottel crossed strings C-1 (2-D); Howell C-11 (3-D); literature.md V16", ambient=AMB)
    c.rect("lower", (0, 0, 0), X, (0, L, 0), subdivide=(2, 10))
    c.rect("upper", (0, 0, 1), (0, L, 0), X, subdivide=(10, 2))
    f = float(closed.c11(1, L, 1))
    c.vf("lower", "upper", f, f"C-11 {CF}; 2-D crossed strings √2 − 1 = {float(closed.strings_parallel(1, 1)):.10f}")
    return c


def v16b():
    L = 10.0
    c = Case("v16b_long_common_edge", f"Long perpendicular plates with a common edge, widths 1, length {L:g} (C-3 in 3-D)", "Hottel crossed strings C-3 (2-D); Howell C-14 (3-D); literature.md V16", ambient=AMB)
    c.rect("floor", (0, 0, 0), X, (0, L, 0), subdivide=(2, 10))
    c.rect("wall", (0, 0, 0), (0, L, 0), Z, subdivide=(10, 2))
    f = float(closed.c14(1, 1, L))
    c.vf("floor", "wall", f, f"C-14 {CF}; 2-D crossed strings 1 − √2/2 = {float(closed.strings_common_edge(1, 1)):.10f}")
    return c


def v16c():
    L, alpha = 10.0, math.pi / 3
    c = Case("v16c_long_wedge", f"Long equal plates at 60° with a common edge, width 1, length {L:g} (C-4 in 3-D)", "Hottel crossed strings C-4 (2-D); literature.md V16", ambient=AMB,
             note="Reference: 1LI Gauss of Lambert's formula, graded geometrically towards the shared edge\nand the plate ends (x·ln x behaviour), checked on C-14 to 1e-16.")
    d = (math.cos(alpha), 0.0, math.sin(alpha))
    c.rect("floor", (0, 0, 0), X, (0, L, 0), subdivide=(2, 10))
    c.rect("tilted", (0, 0, 0), (0, L, 0), d, subdivide=(10, 2))
    recv = rectangle((0, 0, 0), (0, L, 0), d)
    vals = []
    for levels, order in ((10, 8), (16, 10)):
        su = rule_1d(graded_cells(True, False, levels=levels), order)
        sv = rule_1d(graded_cells(True, True, levels=levels, uniform=20), order)
        rule = parallelogram_rule((0, 0, 0), X, (0, L, 0), su, sv)
        vals.append(math.fsum(w * point_to_ring(p, Z, recv) for p, w in rule) / L)
    c.vf("floor", "tilted", vals[1], f"graded 1LI Gauss, converged to {abs(vals[1] - vals[0]):.0e}; 2-D crossed strings 1 − sin 30° = 0.5", uncertainty=2 * abs(vals[1] - vals[0]) + 1e-15)
    return c


def facets(tris):
    """Pair the mantle's triangles back into quads (for faster reference integration)."""
    return [[t[0], t[1], t[2], u[2]] for t, u in zip(tris[0::2], tris[1::2])]


def cylinder_pair(name, r1, r2, s, n, L, title, citation, curved):
    c = Case(name, title, citation, ambient=AMB,
             note=f"Reference: exact for the two {n}-facet prisms of length {L:g} (float32 vertices): the sum over\nfacet pairs of 1LI Gauss integrals (two convex bodies never shadow each other).")
    a = gltf.cylinder_mantle((0, 0, 0), L, r1, n)
    b = gltf.cylinder_mantle((r1 + s + r2, 0, 0), L, r2, n)
    c.model("cylinders.gltf", [("cyl_1", a, {}), ("cyl_2", b, {})])
    qa, qb = facets(c.surface("cyl_1").patches), facets(c.surface("cyl_2").patches)
    sab, err = converged(qa, qb, None, 0.5, 6, pairwise=True)
    a1, a2 = gltf.mesh_area(c.surface("cyl_1").patches), gltf.mesh_area(c.surface("cyl_2").patches)
    c.vf("cyl_1", "cyl_2", sab / a1, f"facet-pair 1LI Gauss, converged to {err / a1:.0e}; 2-D {citation.split(';')[0]} {curved:.10f}", uncertainty=2 * err / a1 + 1e-15)
    if r1 != r2:
        c.vf("cyl_2", "cyl_1", sab / a2, "reciprocity of the same integral", uncertainty=2 * err / a2 + 1e-15)
    return c


def v17():
    return cylinder_pair("v17_parallel_cylinders", 1.0, 1.0, 1.0, 32, 10.0, "Parallel cylinders r = 1, gap 1, length 10 (32-facet prisms, glTF)", "Howell C-68; literature.md V17", float(closed.cylinders_equal(1, 1)))


def v18():
    return cylinder_pair("v18_unequal_cylinders", 1.0, 2.0, 1.0, 32, 10.0, "Parallel cylinders r1 = 1, r2 = 2, gap 1, length 10 (32-facet prisms, glTF)", "Howell C-69 (cit.); literature.md V18", float(closed.cylinders_unequal(1, 2, 1)))


def v19():
    n, r1, r2, L = 32, 0.5, 1.0, 2.0
    c = Case("v19_coaxial_cylinders", f"Coaxial cylinders r1 = 0.5, r2 = 1, L = 2 with annular ends ({n}-facet prisms, glTF)", "Siegel & Howell p. 847 (EES); literature.md V19",
             note="Exact for the prisms: the inner body sees the ends unobstructed, so F(inner→outer) = 1 − 2·F(inner→end)\nby closure; the outer-to-outer factors need shadowing by the inner body and are not referenced here.")
    c.quick = False
    inner = gltf.cylinder_mantle((0, 0, 0), L, r1, n)
    outer = gltf.cylinder_mantle((0, 0, 0), L, r2, n, inward=True)
    c.skips["analytic"] = SLOW_SHADOW
    bottom = gltf.annulus(0.0, r1, r2, n, +1)
    top = gltf.annulus(L, r1, r2, n, -1)
    c.model("coaxial.gltf", [("inner", inner, {}), ("outer", outer, {}), ("end_bottom", bottom, {}), ("end_top", top, {})])
    qi = facets(c.surface("inner").patches)
    ends = c.surface("end_bottom").patches
    s_end, err = converged(qi, ends, None, 0.25, 4, grade_u=True)
    ai, ao = gltf.mesh_area(c.surface("inner").patches), gltf.mesh_area(c.surface("outer").patches)
    f_end = s_end / ai
    F12, F21, F22, _ = (float(x) for x in closed.coaxial_cylinders(r1, r2, L))
    u = 2 * err / ai + 1e-15
    c.vf("inner", "end_bottom", f_end, f"1LI Gauss over the inner facets, converged to {err / ai:.0e}", uncertainty=u)
    c.vf("inner", "outer", 1 - 2 * f_end, f"closure 1 − 2·F(inner→end) (curved V19: {F12:.10f})", uncertainty=2 * u)
    c.vf("outer", "inner", (1 - 2 * f_end) * ai / ao, f"reciprocity (curved V19: {F21:.10f})", uncertainty=2 * u * ai / ao)
    return c


CASES = [
    ("v13_concentric_spheres", v13), ("v14_sphere_to_disk", v14), ("v16a_long_parallel_plates", v16a),
    ("v16b_long_common_edge", v16b), ("v16c_long_wedge", v16c), ("v17_parallel_cylinders", v17),
    ("v18_unequal_cylinders", v18), ("v19_coaxial_cylinders", v19),
]
