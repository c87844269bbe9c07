"""Minimal glTF 2.0 writer: one node per surface (triangle mesh), embedded base64 buffer,
float32 positions. `f32` rounds vertices the way the file stores them, so references are
computed on exactly the geometry lambert reads."""
import base64
import json
import math
import struct

from geom import add, sub, mul, unit, cross, norm, dot


def f32(v):
    return tuple(struct.unpack("<3f", struct.pack("<3f", *v)))


def write(path, meshes):
    """meshes: list of (name, triangles [(a, b, c)], extras dict)."""
    buf = bytearray()
    accessors, views, gmeshes, nodes = [], [], [], []
    for name, tris, extras in meshes:
        verts, index = [], {}
        idx = []
        for t in tris:
            for v in t:
                v = f32(v)
                if v not in index:
                    index[v] = len(verts)
                    verts.append(v)
                idx.append(index[v])
        pos_off = len(buf)
        for v in verts:
            buf += struct.pack("<3f", *v)
        lo = [min(v[k] for v in verts) for k in range(3)]
        hi = [max(v[k] for v in verts) for k in range(3)]
        idx_off = len(buf)
        for i in idx:
            buf += struct.pack("<I", i)
        views.append({"buffer": 0, "byteOffset": pos_off, "byteLength": idx_off - pos_off, "target": 34962})
        views.append({"buffer": 0, "byteOffset": idx_off, "byteLength": 4 * len(idx), "target": 34963})
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"})
        gmeshes.append({"name": name + "_mesh", "primitives": [{"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1, "mode": 4}]})
        node = {"name": name, "mesh": len(gmeshes) - 1}
        if extras:
            node["extras"] = extras
        nodes.append(node)
    doc = {
        "asset": {"version": "2.0", "generator": "lambert cases/_generator"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": gmeshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buf)).decode()}],
    }
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def rounded(tris):
    return [tuple(f32(v) for v in t) for t in tris]


# ---------------------------------------------------------------- meshes


def icosphere(center, radius, subdivisions, inward=False):
    """Geodesic sphere: icosahedron split `subdivisions` times, vertices on the sphere."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [unit(p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
         (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    tris = [(v[a], v[b], v[c]) for a, b, c in f]
    for _ in range(subdivisions):
        nxt = []
        for a, b, c in tris:
            ab, bc, ca = unit(add(a, b)), unit(add(b, c)), unit(add(c, a))
            nxt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = nxt
    out = []
    for a, b, c in tris:
        a, b, c = (add(center, mul(p, radius)) for p in (a, b, c))
        out.append((a, c, b) if inward else (a, b, c))
    return out


def cylinder_mantle(c0, axis_len, radius, n, inward=False):
    """Mantle of a cylinder along +y from c0, n facets, outward (or inward) normals."""
    ring = [(c0[0] + radius * math.cos(2 * math.pi * k / n), c0[2] + radius * math.sin(2 * math.pi * k / n)) for k in range(n)]
    tris = []
    for k in range(n):
        (x0, z0), (x1, z1) = ring[k], ring[(k + 1) % n]
        a, b = (x0, c0[1], z0), (x1, c0[1], z1)
        c, d = (x1, c0[1] + axis_len, z1), (x0, c0[1] + axis_len, z0)
        # Outward: the facet normal (b - a) x (d - a) must point away from the axis.
        quad = [a, d, c, b]
        if dot(cross(sub(quad[1], quad[0]), sub(quad[3], quad[0])), sub(a, (c0[0], c0[1], c0[2]))) < 0:
            quad = quad[::-1]
        if inward:
            quad = quad[::-1]
        tris += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    return tris


def annulus(center_y, r1, r2, n, normal_y):
    """Flat annulus in the plane y = center_y (about the y axis through x = z = 0), n quads."""
    tris = []
    for k in range(n):
        a0, a1 = 2 * math.pi * k / n, 2 * math.pi * (k + 1) / n
        p = [(r1 * math.cos(a0), center_y, r1 * math.sin(a0)), (r2 * math.cos(a0), center_y, r2 * math.sin(a0)),
             (r2 * math.cos(a1), center_y, r2 * math.sin(a1)), (r1 * math.cos(a1), center_y, r1 * math.sin(a1))]
        nrm = cross(sub(p[1], p[0]), sub(p[3], p[0]))
        if nrm[1] * normal_y < 0:
            p = p[::-1]
        tris += [(p[0], p[1], p[2]), (p[0], p[2], p[3])]
    return tris


def mesh_area(tris):
    return math.fsum(0.5 * norm(cross(sub(b, a), sub(c, a))) for a, b, c in tris)


def box(lo, hi, n, inward=False):
    """Axis-aligned box surface, each face n×n quads as triangles, outward (or inward) normals."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    c = ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)
    faces = [((x0, y0, z0), (x1 - x0, 0, 0), (0, y1 - y0, 0)), ((x0, y0, z1), (x1 - x0, 0, 0), (0, y1 - y0, 0)),
             ((x0, y0, z0), (x1 - x0, 0, 0), (0, 0, z1 - z0)), ((x0, y1, z0), (x1 - x0, 0, 0), (0, 0, z1 - z0)),
             ((x0, y0, z0), (0, y1 - y0, 0), (0, 0, z1 - z0)), ((x1, y0, z0), (0, y1 - y0, 0), (0, 0, z1 - z0))]
    tris = []
    for o, u, v in faces:
        for i in range(n):
            for j in range(n):
                a = add(o, add(mul(u, i / n), mul(v, j / n)))
                q = [a, add(a, mul(u, 1 / n)), add(add(a, mul(u, 1 / n)), mul(v, 1 / n)), add(a, mul(v, 1 / n))]
                out = dot(cross(sub(q[1], q[0]), sub(q[3], q[0])), sub(q[0], c)) > 0
                if out == inward:
                    q = q[::-1]
                tris += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
    return tris
