#!/usr/bin/env python3
"""Writes the glTF fixtures of tests/scene/scene_gltf.rs and cases/box_interior (run from the repo root:
`python3 tests/data/make_gltf.py`). Standard library only; the output is deterministic.

hierarchy.{gltf,glb} and external.gltf + external.bin hold the same document:

  scene 0 (default): Frame (translation 10,0,5) -> PanelA, PanelB, node3, Mirror;  Shield;  StripPanel
  scene 1:           Ghost (must not be loaded)

  PanelA   scale 2, mesh Quad, extras {emissivity 0.7, temperature 350, blender_prop 1}
  PanelB   translation 1,0,0 then rotation +90 deg about X, mesh Quad, extras {heat_flux 0}
  node3    (no name) mesh without a name: one triangle and one degenerate triangle
  Mirror   translation 0,3,0, scale -1,1,1 (mirrors: winding must be reversed), mesh Quad
  Shield   mesh Plate (unit quad at z = 1), extras {role: obstruction}
  StripPanel translation 0,0,-2, mesh Strip (TRIANGLE_STRIP unit quad)

The bad_*.gltf files each break one rule.
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "gltf")


class Buf:
    """Packs accessors into one buffer."""

    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def _view(self, raw, target):
        while len(self.data) % 4:
            self.data.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw), "target": target})
        self.data += raw
        return len(self.views) - 1

    def positions(self, pts):
        raw = b"".join(struct.pack("<3f", *p) for p in pts)
        view = self._view(raw, 34962)
        finite = [p for p in pts if all(math.isfinite(c) for c in p)] or [(0, 0, 0)]
        lo = [min(p[k] for p in finite) for k in range(3)]
        hi = [max(p[k] for p in finite) for k in range(3)]
        self.accessors.append({"bufferView": view, "componentType": 5126, "count": len(pts), "type": "VEC3", "min": lo, "max": hi})
        return len(self.accessors) - 1

    def indices(self, idx):
        raw = struct.pack("<%dH" % len(idx), *idx)
        view = self._view(raw, 34963)
        self.accessors.append({"bufferView": view, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
        return len(self.accessors) - 1


def document(buf, meshes, nodes, scenes, scene=0):
    doc = {
        "asset": {"version": "2.0", "generator": "lambert tests/data/make_gltf.py"},
        "scene": scene,
        "scenes": scenes,
        "nodes": nodes,
        "meshes": meshes,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": len(buf.data)}],
    }
    if scene is None:
        del doc["scene"]
    return doc


def write_embedded(name, doc, data):
    doc = json.loads(json.dumps(doc))
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_external(name, bin_name, doc, data):
    doc = json.loads(json.dumps(doc))
    doc["buffers"][0]["uri"] = bin_name
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    with open(os.path.join(OUT, bin_name), "wb") as f:
        f.write(bytes(data))


def write_glb(path, doc, data):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bn = bytes(data) + b"\0" * (-len(data) % 4)
    total = 12 + 8 + len(js) + 8 + len(bn)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)
        f.write(struct.pack("<I4s", len(bn), b"BIN\0") + bn)


QUAD = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
QUAD_IDX = [0, 1, 2, 0, 2, 3]


def hierarchy():
    b = Buf()
    quad_pos, quad_idx = b.positions(QUAD), b.indices(QUAD_IDX)
    tri_pos = b.positions([(0, 0, 0), (1, 0, 0), (0, 0, 1), (0, 0, 0), (1, 0, 0), (2, 0, 0)])
    plate_pos = b.positions([(x, y, 1.0) for (x, y, _) in QUAD])
    strip_pos = b.positions([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)])
    meshes = [
        {"name": "Quad", "primitives": [{"attributes": {"POSITION": quad_pos}, "indices": quad_idx}]},
        {"primitives": [{"attributes": {"POSITION": tri_pos}}]},
        {"name": "Plate", "primitives": [{"attributes": {"POSITION": plate_pos}, "indices": quad_idx}]},
        {"name": "Strip", "primitives": [{"attributes": {"POSITION": strip_pos}, "mode": 5}]},
    ]
    s = math.sqrt(0.5)
    nodes = [
        {"name": "Frame", "translation": [10, 0, 5], "children": [1, 2, 3, 4]},
        {"name": "PanelA", "scale": [2, 2, 2], "mesh": 0, "extras": {"emissivity": 0.7, "temperature": 350.0, "blender_prop": 1}},
        {"name": "PanelB", "translation": [1, 0, 0], "rotation": [s, 0, 0, s], "mesh": 0, "extras": {"heat_flux": 0.0}},
        {"mesh": 1},
        {"name": "Mirror", "translation": [0, 3, 0], "scale": [-1, 1, 1], "mesh": 0},
        {"name": "Shield", "mesh": 2, "extras": {"role": "obstruction"}},
        {"name": "StripPanel", "translation": [0, 0, -2], "mesh": 3},
        {"name": "Ghost", "mesh": 0},
    ]
    scenes = [{"nodes": [0, 5, 6]}, {"nodes": [7]}]
    doc = document(b, meshes, nodes, scenes)
    write_embedded("hierarchy.gltf", doc, b.data)
    write_external("external.gltf", "external.bin", doc, b.data)
    write_glb(os.path.join(OUT, "hierarchy.glb"), doc, b.data)


def one_mesh(name, pts, idx=None, mode=None, nodes=None, scenes=None, extra=None):
    """A small document with one mesh; `extra` edits it before writing."""
    b = Buf()
    prim = {"attributes": {"POSITION": b.positions(pts)}}
    if idx is not None:
        prim["indices"] = b.indices(idx)
    if mode is not None:
        prim["mode"] = mode
    nodes = nodes or [{"name": "Panel", "mesh": 0}]
    doc = document(b, [{"name": "M", "primitives": [prim]}], nodes, scenes or [{"nodes": list(range(len(nodes)))}])
    if extra:
        extra(doc)
    write_embedded(name, doc, b.data)


def bad_files():
    one_mesh("bad_lines.gltf", QUAD, mode=1)
    one_mesh("bad_degenerate.gltf", [(0, 0, 0), (1, 1, 1), (2, 2, 2)])
    one_mesh("bad_nan.gltf", [(0, 0, 0), (1, 0, 0), (float("nan"), 1, 0)])
    one_mesh("bad_index.gltf", QUAD, idx=[0, 1, 2, 0, 2, 9])
    one_mesh("bad_duplicate.gltf", QUAD, idx=QUAD_IDX, nodes=[{"name": "Panel", "mesh": 0}, {"name": "Panel", "mesh": 0, "translation": [0, 0, 1]}])
    one_mesh("bad_cycle.gltf", QUAD, idx=QUAD_IDX, nodes=[{"name": "A", "mesh": 0, "children": [1]}, {"name": "B", "children": [0]}], scenes=[{"nodes": [0]}])
    one_mesh("bad_extras.gltf", QUAD, idx=QUAD_IDX, nodes=[{"name": "Panel", "mesh": 0, "extras": {"emissivity": 1.5}}])
    one_mesh("bad_role.gltf", QUAD, idx=QUAD_IDX, nodes=[{"name": "Panel", "mesh": 0, "extras": {"role": "obstruction", "temperature": 300}}])

    # Two unnamed nodes instancing the mesh "M": surfaces "M_node0" and "M_node1".
    one_mesh("instanced.gltf", QUAD, idx=QUAD_IDX, nodes=[{"mesh": 0}, {"mesh": 0, "translation": [0, 0, 1]}])

    def no_position(doc):
        prim = doc["meshes"][0]["primitives"][0]
        prim["attributes"] = {"NORMAL": prim["attributes"]["POSITION"]}

    one_mesh("bad_no_position.gltf", QUAD, idx=QUAD_IDX, extra=no_position)

    def no_scene(doc):
        del doc["scene"]
        doc["scenes"] = []

    one_mesh("bad_no_scene.gltf", QUAD, idx=QUAD_IDX, extra=no_scene)


def box_interior():
    """cases/box_interior/box.glb: the inside of a unit cube as one mesh, normals inward."""
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    # Faces as corner indices, counter-clockwise seen from inside the box.
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    idx = []
    for a, b_, c, d in faces:
        idx += [a, b_, c, a, c, d]
    b = Buf()
    prim = {"attributes": {"POSITION": b.positions(corners)}, "indices": b.indices(idx)}
    doc = document(b, [{"name": "Box", "primitives": [prim]}], [{"name": "box", "mesh": 0}], [{"nodes": [0]}])
    out = os.path.join(HERE, "..", "..", "cases", "box_interior")
    os.makedirs(out, exist_ok=True)
    write_glb(os.path.join(out, "box.glb"), doc, b.data)


def outward_box():
    """gltf/outward_box.gltf: a unit cube as one mesh with every normal facing outward, the
    wrong winding for an enclosure (the leak hint of tests/cli/cli_rough_edges.rs)."""
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    # The box_interior faces with their winding reversed: counter-clockwise seen from outside.
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    idx = []
    for a, b_, c, d in faces:
        idx += [a, c, b_, a, d, c]
    one_mesh("outward_box.gltf", corners, idx, nodes=[{"name": "room", "mesh": 0}])


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    hierarchy()
    bad_files()
    box_interior()
    outward_box()
