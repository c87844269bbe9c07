"""Case builder: scene.toml (and glTF) + reference.toml, with the point-sampling bias of every
reference view factor computed from the scene's own patches."""
import math
import os

from geom import (add, sub, mul, dot, cross, norm, unit, ring_normal, ring_area, centroid, clip, graded_cells,
                  rectangle, subdivide_rectangle, regular_polygon, gauss_legendre, rule_1d,
                  parallelogram_rule, triangle_rule, split_triangle)
from shadow import point_to_ring_shadowed
import gltf


def fmt(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, (int,)):
        return str(x)
    if isinstance(x, float):
        r = repr(x)
        return r if ("." in r or "e" in r or "inf" in r or "nan" in r) else r + ".0"
    if isinstance(x, str):
        return '"' + x.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(fmt(v) for v in x) + "]"
    if isinstance(x, dict):
        return "{ " + ", ".join(f"{k} = {fmt(v)}" for k, v in x.items()) + " }"
    return fmt(float(x))


def is_parallelogram(ring):
    if len(ring) != 4:
        return False
    a, b, c, d = ring
    return norm(sub(add(a, c), add(b, d))) < 1e-12 * (norm(sub(b, a)) + norm(sub(d, a)))


# ---------------------------------------------------------------- quadrature over patches


def area_rule(ring, h, order, grade_u=False):
    """Composite rule on a convex ring: tensor cells no wider than h on parallelograms (graded
    geometrically towards both ends of the first edge when `grade_u`, for edges touching
    another surface), otherwise a fan from the centroid with Duffy rules on split triangles."""
    if is_parallelogram(ring):
        o, u, v = ring[0], sub(ring[1], ring[0]), sub(ring[3], ring[0])
        nu, nv = max(1, math.ceil(norm(u) / h - 1e-9)), max(1, math.ceil(norm(v) / h - 1e-9))
        if grade_u:
            su = rule_1d(graded_cells(True, True, levels=12, uniform=nu), order)
        else:
            su = rule_1d([i / nu for i in range(nu + 1)], order)
        sv = rule_1d([i / nv for i in range(nv + 1)], order)
        return parallelogram_rule(o, u, v, su, sv)
    c = centroid(ring)
    pts = []
    for k in range(len(ring)):
        a, b = ring[k], ring[(k + 1) % len(ring)]
        size = max(norm(sub(a, c)), norm(sub(b, c)), norm(sub(b, a)))
        m = max(1, math.ceil(size / h - 1e-9))
        for tri in split_triangle(c, a, b, m):
            pts.extend(triangle_rule(*tri, order))
    return pts


def exchange_area(emitters, receivers, blocker, h, order, pairwise=False, grade_u=False):
    """Σ_i ∫_{A_i} Σ_j F(dA -> R_j) dA over emitter rings, receiver rings, one convex blocker.
    `pairwise` integrates each emitter only over the part in front of each receiver's plane,
    removing the one-sided kink where a receiver's plane cuts the emitter."""
    tot = []
    for e in emitters:
        n = ring_normal(e)
        if not pairwise:
            for p, w in area_rule(e, h, order, grade_u):
                tot.append(w * math.fsum(point_to_ring_shadowed(p, n, r, blocker) for r in receivers))
            continue
        for r in receivers:
            part = clip(e, r[0], ring_normal(r))
            if len(part) < 3 or ring_area(part) <= 1e-14 * ring_area(e):
                continue
            rule = area_rule(part, h, order, grade_u and is_parallelogram(part))
            tot.append(math.fsum(w * point_to_ring_shadowed(p, n, r, blocker) for p, w in rule))
    return math.fsum(tot)


def converged(emitters, receivers, blocker, h, order, **kw):
    """(fine value, |fine - coarse|): coarse (h, order), fine (h/2, order + 2)."""
    coarse = exchange_area(emitters, receivers, blocker, h, order, **kw)
    fine = exchange_area(emitters, receivers, blocker, h / 2, order + 2, **kw)
    return fine, abs(fine - coarse)


def point_estimates(emitters, receivers, blocker):
    """Patch-centre and 2x2-Gauss-point estimates of A_I F_IJ (the hemicube's limits)."""
    centre, gauss = [], []
    for e in emitters:
        n = ring_normal(e)
        f = lambda p: math.fsum(point_to_ring_shadowed(p, n, r, blocker) for r in receivers)
        centre.append(ring_area(e) * f(centroid(e)))
        if is_parallelogram(e):
            o, u, v = e[0], sub(e[1], e[0]), sub(e[3], e[0])
            s = rule_1d([0.0, 1.0], 2)
            rule = parallelogram_rule(o, u, v, s, s)
        else:
            rule = []
            for k in range(1, len(e) - 1):
                rule += triangle_rule(e[0], e[k], e[k + 1], 2)
        gauss.append(math.fsum(w * f(p) for p, w in rule))
    return math.fsum(centre), math.fsum(gauss)


# ---------------------------------------------------------------- the case


class Surface:
    def __init__(self, name, fields, patches):
        self.name, self.fields, self.patches = name, fields, patches

    @property
    def area(self):
        return math.fsum(ring_area(p) for p in self.patches)


class Case:
    def __init__(self, name, title, citation, ambient=None, note=None):
        self.name, self.title, self.citation, self.ambient, self.note = name, title, citation, ambient, note
        self.surfaces, self.obstructions, self.models = [], [], []
        self.vfs, self.heats, self.skips, self.overrides = [], [], {}, {}
        self.vf_file = None
        self.defaults = None
        self.keep_scene = False
        self.quick = True
        self.auto_goal = None
        self.known = {}

    def surface(self, name):
        return next(s for s in self.surfaces if s.name == name)

    def rect(self, name, o, u, v, subdivide=None, **props):
        fields = {"rectangle": {"origin": list(map(float, o)), "u": list(map(float, u)), "v": list(map(float, v))}}
        patches = subdivide_rectangle(o, u, v, *subdivide) if subdivide else [rectangle(o, u, v)]
        if subdivide:
            props["subdivide"] = list(subdivide)
        fields.update(props)
        self.surfaces.append(Surface(name, fields, patches))
        return self

    def poly(self, name, ring, **props):
        fields = {"polygon": [list(map(float, v)) for v in ring]}
        fields.update(props)
        self.surfaces.append(Surface(name, fields, [list(ring)]))
        return self

    def disk(self, name, center, normal, radius, segments, **props):
        fields = {"disk": {"center": list(map(float, center)), "normal": list(map(float, normal)), "radius": float(radius), "segments": segments}}
        fields.update(props)
        self.surfaces.append(Surface(name, fields, [regular_polygon(center, normal, radius, segments)]))
        return self

    def model(self, file, meshes):
        """meshes: (name, triangles, extras); triangles are rounded to float32 as stored."""
        rounded = [(n, gltf.rounded(t), e) for n, t, e in meshes]
        self.models.append((file, rounded))
        for n, t, _ in rounded:
            self.surfaces.append(Surface(n, None, [list(tri) for tri in t]))
        return self

    def view3d(self, file, text, rings):
        """A View3D `.vs3` model: its text, and (name, ring) for every radiating surface."""
        self.models.append((file, text))
        for n, ring in rings:
            self.surfaces.append(Surface(n, None, [list(ring)]))
        return self

    def obstruction(self, name, ring):
        self.obstructions.append((name, ring))
        return self

    def vf(self, frm, to, value, source, uncertainty=0.0, blocker=None, bias=None, receiver=None):
        """A reference F(frm -> to); bias (if not given) from the emitter's patches, seen
        against `receiver` rings (default: the receiving surface's patches)."""
        value = float(value)
        if bias is None:
            I, J = self.surface(frm), self.surface(to)
            c, g = point_estimates(I.patches, receiver or J.patches, blocker)
            bias = max(abs(c / I.area - value), abs(g / I.area - value))
        self.vfs.append({"from": frm, "to": to, "value": value, "source": source, "uncertainty": float(uncertainty), "point_bias": float(bias)})
        return bias

    def heat(self, surface, source, heat_rate=None, temperature=None, uncertainty=0.0, sensitivity=None):
        """A reference heat rate or temperature; `sensitivity` lists d(quantity)/dF_IJ per
        surface pair (F_JI moved reciprocally), the error model for approximate factors."""
        h = {"surface": surface}
        if heat_rate is not None:
            h["heat_rate"] = float(heat_rate)
        if temperature is not None:
            h["temperature"] = float(temperature)
        h["source"] = source
        if uncertainty:
            h["uncertainty"] = float(uncertainty)
        if sensitivity:
            h["sensitivity"] = sensitivity
        self.heats.append(h)

    def write(self, root):
        d = os.path.join(root, self.name)
        os.makedirs(d, exist_ok=True)
        head = "# Generated by `python3 cases/_generator` (pure Python + mpmath, independent of lambert);\n# edit the generator, not this file.\n"
        s = [head, f"title = {fmt(self.title)}\n"]
        if self.ambient is not None:
            s.append(f"\n[ambient]\ntemperature = {fmt(float(self.ambient))}\n")
        if self.defaults:
            s.append("\n[defaults]\n" + "".join(f"{k} = {fmt(v)}\n" for k, v in self.defaults.items()))
        for file, meshes in self.models:
            s.append(f"\n[[model]]\nfile = {fmt(file)}\n")
            if isinstance(meshes, str):
                with open(os.path.join(d, file), "w") as f:
                    f.write(meshes)
            else:
                gltf.write(os.path.join(d, file), meshes)
        for srf in self.surfaces:
            if srf.fields is None:
                continue
            s.append(f"\n[[surface]]\nname = {fmt(srf.name)}\n" + "".join(f"{k} = {fmt(v)}\n" for k, v in srf.fields.items()))
        for name, ring in self.obstructions:
            s.append(f"\n[[surface]]\nname = {fmt(name)}\npolygon = {fmt([list(map(float, v)) for v in ring])}\nrole = \"obstruction\"\n")
        if not self.keep_scene:
            with open(os.path.join(d, "scene.toml"), "w") as f:
                f.write("".join(s))
        r = [head, f"title = {fmt(self.title)}\ncitation = {fmt(self.citation)}\n"]
        if self.vf_file:
            r.append(f"viewfactors_file = {fmt(self.vf_file[0])}\n")
            with open(os.path.join(d, self.vf_file[0]), "w") as f:
                f.write("from,to,factor\n")
                for a, b, x in self.vf_file[1]:
                    f.write(f"{a},{b},{x!r}\n")
        if self.note:
            r.insert(1, "".join(f"# {line}\n" for line in self.note.strip().splitlines()))
        if not self.quick:
            r.append("quick = false\n")
        if self.auto_goal is not None:
            r.append(f"auto_goal = {fmt(float(self.auto_goal))}\n")
        if self.known:
            r.append("\n[known_issue]\n" + "".join(f"{fmt(k)} = {fmt(v)}\n" for k, v in self.known.items()))
        if self.skips:
            r.append("\n[skip]\n" + "".join(f"{fmt(k)} = {fmt(v)}\n" for k, v in self.skips.items()))
        if self.overrides:
            r.append("\n[tolerance]\n" + "".join(f"{fmt(k)} = {fmt(v)}\n" for k, v in self.overrides.items()))
        for v in self.vfs:
            r.append("\n[[viewfactor]]\n" + "".join(f"{k} = {fmt(x)}\n" for k, x in v.items()))
        for h in self.heats:
            r.append("\n[[heat]]\n" + "".join(f"{k} = {fmt(x)}\n" for k, x in h.items()))
        with open(os.path.join(d, "reference.toml"), "w") as f:
            f.write("".join(r))
