"""View3D input files (`.vs3`, format F 3) as `[[model]]`s of TOML scenes: the unit cube and
View3D's square-obstruction layout (a radiating plate that also blocks), against the same
closed forms and shadow integrals as the TOML cases."""
import closed
from casekit import Case, converged
from geom import rectangle
from shadow import plate
from cases_view import CF, AMB, X, Y
from cases_obstructed import SHADOW


def vs3(title, rings, emit):
    """F 3 text: shared vertices, one `S` record per (name, ring), View3D's column layout."""
    verts = []
    for _, ring in rings:
        for p in ring:
            if p not in verts:
                verts.append(p)
    out = [f"T {title}", "C encl=0 list=0", "F 3", "!  #   x   y   z"]
    out += [f"V {k + 1:>3}  " + "  ".join(repr(float(x)) for x in p) for k, p in enumerate(verts)]
    out.append("!  #  v1  v2  v3  v4 base cmb emit name")
    for k, (name, ring) in enumerate(rings):
        ix = [verts.index(p) + 1 for p in ring] + [0] * (4 - len(ring))
        out.append(f"S {k + 1:>3}  " + "  ".join(f"{i:>3}" for i in ix) + f"  0  0  {emit}  {name}")
    out.append("End of data")
    return "\n".join(out) + "\n"


def x1():
    c = Case("x1_view3d_cube", "The unit cube as a View3D F 3 file, faces facing in", "Howell C-11 and C-14 (literature.md V1, V2) through the .vs3 reader")
    faces = [
        ("floor", rectangle((0, 0, 0), X, Y)), ("ceiling", rectangle((0, 0, 1), Y, X)),
        ("wall_y0", rectangle((0, 0, 0), (0, 0, 1), X)), ("wall_y1", rectangle((0, 1, 0), X, (0, 0, 1))),
        ("wall_x0", rectangle((0, 0, 0), Y, (0, 0, 1))), ("wall_x1", rectangle((1, 0, 0), (0, 0, 1), Y)),
    ]
    c.view3d("cube.vs3", vs3("The unit cube", faces, 0.5), faces)
    c.vf("floor", "ceiling", float(closed.c11(1, 1, 1)), "C-11 " + CF)
    c.vf("floor", "wall_x0", float(closed.c14(1, 1, 1)), "C-14 " + CF)
    c.vf("wall_y1", "ceiling", float(closed.c14(1, 1, 1)), "C-14 " + CF)
    return c


def x2():
    c = Case("x2_view3d_square_obstruction", "View3D's square-obstruction layout: unit squares at gap 1, a radiating 0.5×0.5 plate facing up in a corner at z = 0.5", "View3D's shipped square-obstruction.vs3 (research/view3d.md §5: exact 0.1498686718); the plate both exchanges and blocks", ambient=AMB)
    bottom, top = rectangle((0, 0, 0), X, Y), rectangle((0, 0, 1), Y, X)
    blk = rectangle((0, 0, 0.5), (0.5, 0, 0), (0, 0.5, 0))
    c.view3d("squares.vs3", vs3("Two squares with a radiating square between", [("zeq0", bottom), ("zeq1", top), ("zeq05", blk)], 0.5),
             [("zeq0", bottom), ("zeq1", top), ("zeq05", blk)])
    s, err = converged([bottom], [top], plate(blk), 0.5, 8)
    u = 2 * err + 1e-15
    c.vf("zeq0", "zeq1", s, f"{SHADOW}; converged to {err:.0e}", uncertainty=u, blocker=plate(blk))
    c.vf("zeq1", "zeq0", s, "reciprocity of the same integral (equal areas)", uncertainty=u, blocker=plate(blk))
    return c


CASES = [("x1_view3d_cube", x1), ("x2_view3d_square_obstruction", x2)]
