"""Enclosure heat-exchange problems E1-E5 of literature.md 1.2, plus the subdivided cube
furnace (V15 view factors and a patch-level exact solve). Heat references come from the dense
net-radiation solve in radiation.py with CODATA σ (lambert::SIGMA)."""
import math

from mpmath import mp, mpf, findroot, pi

import closed
import radiation
from casekit import Case
from geom import subdivide_rectangle
from cases_view import CF, X, Y, Z

NRM = "dense net-radiation solve in mpmath (cases/_generator/radiation.py), CODATA σ"
SIGMA_RATIO = radiation.SIGMA / mpf("5.67e-8")


def standins(c, names_areas, props):
    """Stand-in squares of the right areas for cases whose factors come from a file."""
    for k, (name, area) in enumerate(names_areas):
        side = math.sqrt(float(area))
        c.rect(name, (3.0 * k, 0, 0), (side, 0, 0), (0, side, 0), **props[k])


def vf_rows(names, F):
    return [(names[i], names[j], float(F[i][j])) for i in range(len(names)) for j in range(len(names)) if F[i][j] != 0]


def e1():
    c = Case("e1_paint_oven", "Paint-baking oven: long equilateral triangular duct, W = 1 m, per metre", "Incropera et al., Fundamentals of Heat and Mass Transfer, Ch. 13 (oven example); literature.md E1",
             note="2-D enclosure: exact factors F_ij = 0.5 come from vf.csv (solve --viewfactors);\nthe scene's squares only carry the areas (1 m² per metre) and boundary conditions.")
    names = ["heater", "panels", "wall"]
    eps = [0.8, 0.4, 0.8]
    bc = [("T", 1200), ("T", 500), ("q", 0)]
    F = [[0 if i == j else mpf("0.5") for j in range(3)] for i in range(3)]
    props = [{"emissivity": 0.8, "temperature": 1200.0}, {"emissivity": 0.4, "temperature": 500.0}, {"emissivity": 0.8, "heat_flux": 0.0}]
    standins(c, [(n, 1) for n in names], props)
    out, _ = radiation.solve([1, 1, 1], eps, F, bc)
    assert abs(out[0]["heat_rate"] - mpf("36984.941")) < 2e-3 and abs(out[2]["temperature"] - mpf("1102.1734")) < 1e-3
    c.vf_file = ("vf.csv", vf_rows(names, F))
    c.heat("heater", NRM + " (literature: 36 984.941 W/m with CODATA σ)", heat_rate=out[0]["heat_rate"])
    c.heat("panels", NRM, heat_rate=out[1]["heat_rate"])
    c.heat("wall", NRM + " (literature: 1102.1734 K)", temperature=out[2]["temperature"])
    return c


def tubes(shield):
    D1, D2, D3 = mpf("0.020"), mpf("0.050"), mpf("0.035")
    name = "e2b_cryogenic_tubes_shield" if shield else "e2_cryogenic_tubes"
    title = "Evacuated concentric tubes D1 = 20 mm (77 K, ε 0.02) in D2 = 50 mm (300 K, ε 0.05), per metre" + (", with a thin shield D3 = 35 mm (ε 0.02 both sides)" if shield else "")
    c = Case(name, title, "Incropera et al., Ch. 13 (cryogenic fluid in concentric tubes); literature.md E2",
             note="2-D enclosure: exact factors of infinite concentric cylinders come from vf.csv;\nthe squares carry the areas π·D per metre." + ("\nThe shield's two faces are held at its equilibrium temperature T3 (zero net heat), found by the generator." if shield else ""))
    if not shield:
        names, areas, eps = ["inner", "outer"], [pi * D1, pi * D2], [0.02, 0.05]
        F = [[0, 1], [D1 / D2, 1 - D1 / D2]]
        bc = [("T", 77), ("T", 300)]
        out, _ = radiation.solve(areas, eps, F, bc)
        assert abs(out[0]["heat_rate"] / SIGMA_RATIO - mpf("-0.49881163")) < 1e-8
        lit = "-0.49881163 W/m with σ = 5.67e-8"
    else:
        names, areas, eps = ["inner", "shield_in", "shield_out", "outer"], [pi * D1, pi * D3, pi * D3, pi * D2], [0.02, 0.02, 0.02, 0.05]
        F = [[0, 1, 0, 0], [D1 / D3, 1 - D1 / D3, 0, 0], [0, 0, 0, 1], [0, 0, D3 / D2, 1 - D3 / D2]]

        def net(T3):
            o, _ = radiation.solve(areas, eps, F, [("T", 77), ("T", T3), ("T", T3), ("T", 300)])
            return o[1]["heat_rate"] + o[2]["heat_rate"]

        T3 = findroot(net, mpf(250))
        bc = [("T", 77), ("T", T3), ("T", T3), ("T", 300)]
        out, _ = radiation.solve(areas, eps, F, bc)
        assert abs(out[0]["heat_rate"] / SIGMA_RATIO - mpf("-0.25165272")) < 1e-8
        lit = "-0.25165272 W/m with σ = 5.67e-8"
    props = [{"emissivity": e, "temperature": float(b[1])} for e, b in zip(eps, bc)]
    standins(c, list(zip(names, areas)), props)
    c.vf_file = ("vf.csv", vf_rows(names, F))
    c.heat("inner", NRM + f" (literature: {lit})", heat_rate=out[0]["heat_rate"])
    c.heat("outer", NRM, heat_rate=out[-1]["heat_rate"])
    if shield:
        c.heat("shield_in", NRM + f"; shield at T3 = {float(T3):.10f} K", heat_rate=out[1]["heat_rate"])
    return c


def e5():
    r1, r2 = mpf("0.1"), mpf("0.2")
    c = Case("e5_concentric_spheres", "Concentric spheres r1 = 0.1 m (400 K, ε 0.3) and r2 = 0.2 m (300 K, ε 0.5)", "Constructed; literature.md E5 (Incropera Eq. 13.26 form)",
             note="Curved enclosure: exact sphere factors come from vf.csv; the squares carry the areas 4πr².")
    names, areas, eps = ["inner", "outer"], [4 * pi * r1**2, 4 * pi * r2**2], [0.3, 0.5]
    F = [[0, 1], [(r1 / r2) ** 2, 1 - (r1 / r2) ** 2]]
    bc = [("T", 400), ("T", 300)]
    out, _ = radiation.solve(areas, eps, F, bc)
    assert abs(out[0]["heat_rate"] - mpf("34.799455")) < 1e-5, out[0]["heat_rate"]
    standins(c, list(zip(names, areas)), [{"emissivity": 0.3, "temperature": 400.0}, {"emissivity": 0.5, "temperature": 300.0}])
    c.vf_file = ("vf.csv", vf_rows(names, F))
    c.heat("inner", NRM + " (literature: 34.799455 W)", heat_rate=out[0]["heat_rate"])
    c.heat("outer", NRM, heat_rate=out[1]["heat_rate"])
    return c


CUBE = [  # name, origin, u, v (inward normals u × v)
    ("floor", (0, 0, 0), X, Y), ("ceiling", (0, 0, 1), Y, X),
    ("wall_y0", (0, 0, 0), Z, X), ("wall_y1", (0, 1, 0), X, Z),
    ("wall_x0", (0, 0, 0), Y, Z), ("wall_x1", (1, 0, 0), Z, Y),
]


def cube_factors(open_top):
    fo, fa = closed.c11(1, 1, 1), closed.c14(1, 1, 1)
    names = [n for n, *_ in CUBE if not (open_top and n == "ceiling")]
    opp = {"floor": "ceiling", "ceiling": "floor", "wall_y0": "wall_y1", "wall_y1": "wall_y0", "wall_x0": "wall_x1", "wall_x1": "wall_x0"}
    F = [[0 if a == b else (fo if opp[a] == b else fa) for b in names] for a in names]
    return names, F, fo, fa


def e3(open_top):
    name = "e4_cube_open_top" if open_top else "e3_cube_furnace"
    title = "Unit-cube furnace, one surface per face: floor 1000 K ε 0.8, " + ("ceiling open to black space (ambient 0 K)" if open_top else "ceiling 400 K ε 0.6") + ", adiabatic walls ε 0.5"
    c = Case(name, title, "Constructed; literature.md " + ("E4" if open_top else "E3") + " (uses V1 and V2)", ambient=0.0 if open_top else None)
    names, F, fo, fa = cube_factors(open_top)
    props = {"floor": {"emissivity": 0.8, "temperature": 1000.0}, "ceiling": {"emissivity": 0.6, "temperature": 400.0}}
    for n, o, u, v in CUBE:
        if n in names:
            c.rect(n, o, u, v, **props.get(n, {"emissivity": 0.5, "heat_flux": 0.0}))
    eps = [props.get(n, {"emissivity": 0.5})["emissivity"] for n in names]
    bc = [("T", props[n]["temperature"]) if n in props else ("q", 0) for n in names]
    t_amb = 0 if open_top else None
    out, amb = radiation.solve([1] * len(names), eps, F, bc, t_amb=t_amb)
    # Every surface pair is referenced: the heat tolerances of approximate methods propagate
    # their view-factor tolerances through these pairs.
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            if i != j:
                c.vf(a, b, float(F[i][j]), ("C-11 " if F[i][j] == fo else "C-14 ") + CF)
    if not open_top:
        assert abs(out[0]["heat_rate"] - mpf("21385.907")) < 1e-3
    else:
        assert abs(out[0]["heat_rate"] - mpf("29580.808")) < 1e-3, out[0]["heat_rate"]

    def sensitivity(pick):
        """d(quantity)/dF_IJ with F_JI moved reciprocally (equal areas), per surface pair, after
        the solve's enforcement: closure by symmetric scaling in the closed furnace (the
        perturbation is projected back onto closed rows), none beyond reciprocity when open."""
        rows = []
        h = mpf("1e-15")
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                vals = []
                for sgn in (1, -1):
                    G = [row[:] for row in F]
                    G[i][j] += sgn * h
                    G[j][i] += sgn * h
                    if not open_top:
                        G = radiation.close_symmetric([1] * len(names), G)
                    o, a = radiation.solve([1] * len(names), eps, G, bc, t_amb=t_amb)
                    vals.append(pick(o, a))
                d = (vals[0] - vals[1]) / (2 * h)
                rows.append({"from": names[i], "to": names[j], "d": float(d)})
        return rows

    lit = "29 580.808 W at 0 K" if open_top else "21 385.907 W"
    src = f" with exact C-11/C-14 factors (literature: {lit})"
    c.heat("floor", NRM + src, heat_rate=out[0]["heat_rate"], sensitivity=sensitivity(lambda o, a: o[0]["heat_rate"]))
    for i, n in enumerate(names):
        if n.startswith("wall"):
            c.heat(n, NRM, temperature=out[i]["temperature"], sensitivity=sensitivity(lambda o, a, i=i: o[i]["temperature"]))
    if open_top:
        c.heat("ambient", NRM + ": net heat the environment gives the scene", heat_rate=amb, sensitivity=sensitivity(lambda o, a: a))
    else:
        c.heat("ceiling", NRM, heat_rate=out[1]["heat_rate"], sensitivity=sensitivity(lambda o, a: o[1]["heat_rate"]))
    return c


def rect_exchange(p, q):
    """Exact exchange area between axis-aligned rectangles on different faces of the unit cube
    (C-13 corner sum when parallel, the V5/V6 offset algebra when perpendicular)."""
    (ap, vp, bp), (aq, vq, bq) = p, q  # normal axis, plane value, bounds [(lo, hi)] * 3
    if ap == aq:
        if vp == vq:
            return mpf(0)
        o = [k for k in range(3) if k != ap]
        return closed.parallel_general((bp[o[0]][0], bp[o[0]][1], bp[o[1]][0], bp[o[1]][1]), (bq[o[0]][0], bq[o[0]][1], bq[o[1]][0], bq[o[1]][1]), abs(vp - vq))
    line = 3 - ap - aq
    dp = sorted(abs(x - vq) for x in bp[aq])  # p's distances from the common line, along q's normal axis
    dq = sorted(abs(x - vp) for x in bq[ap])
    return closed.perpendicular_general(dp[0], dp[1], dq[0], dq[1], bp[line], bq[line])


def cube_furnace():
    c = Case("cube_furnace", "Unit-cube furnace with 4×4 patches per face (the shipped example): view factors and patch-level heat rates", "Howell C-11/C-14 (V15); literature.md E3 geometry",
             note="Heat references are exact for the patched model: every patch is its own radiosity node (adiabatic walls\nper patch), solved with exact patch-pair factors (C-13 corner sums and the V5/V6 offset algebra).")
    c.keep_scene = True
    n = 4
    eps = {"floor": 0.8, "ceiling": 0.6}
    temp = {"floor": 1000, "ceiling": 400}
    patches = []
    for name, o, u, v in CUBE:
        c.rect(name, o, u, v, subdivide=(n, n))
        axis = [k for k in range(3) if u[k] == 0 and v[k] == 0][0]
        for ring in subdivide_rectangle(o, u, v, n, n):
            bounds = [(min(p[k] for p in ring), max(p[k] for p in ring)) for k in range(3)]
            patches.append((name, (axis, o[axis], bounds)))
    mp.dps = 25
    N = len(patches)
    area = mpf(1) / (n * n)
    S = [[rect_exchange(patches[i][1], patches[j][1]) if patches[i][0] != patches[j][0] else mpf(0) for j in range(N)] for i in range(N)]
    F = [[S[i][j] / area for j in range(N)] for i in range(N)]
    rowerr = max(abs(sum(F[i]) - 1) for i in range(N))
    assert rowerr < 1e-15, rowerr
    e = [eps.get(p[0], 0.5) for p in patches]
    bc = [("T", temp[p[0]]) if p[0] in temp else ("q", 0) for p in patches]
    out, _ = radiation.solve([area] * N, e, F, bc)
    mp.dps = 40
    q = {}
    for (name, _), o in zip(patches, out):
        q[name] = q.get(name, 0) + o["heat_rate"]
    fo, fa = closed.c11(1, 1, 1), closed.c14(1, 1, 1)
    c.vf("floor", "ceiling", float(fo), "C-11 " + CF)
    c.vf("floor", "wall_y0", float(fa), "C-14 " + CF)
    c.vf("wall_x0", "wall_x1", float(fo), "C-11 " + CF)
    c.vf("wall_y0", "wall_x1", float(fa), "C-14 " + CF)
    src = f"{NRM}, {N} patches with exact patch-pair factors (max |row sum − 1| = {float(rowerr):.0e})"
    c.heat("floor", src, heat_rate=q["floor"])
    c.heat("ceiling", src, heat_rate=q["ceiling"])
    return c


CASES = [
    ("e1_paint_oven", e1), ("e2_cryogenic_tubes", lambda: tubes(False)), ("e2b_cryogenic_tubes_shield", lambda: tubes(True)),
    ("e3_cube_furnace", lambda: e3(False)), ("e4_cube_open_top", lambda: e3(True)), ("e5_concentric_spheres", e5),
    ("cube_furnace", cube_furnace),
]
