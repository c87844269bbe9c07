#!/usr/bin/env python3
"""Writes the malformed glTF corpus of tests/scene/gltf_malformed.rs (run from the repo root:
`python3 tests/data/make_malformed_gltf.py`). Standard library only; deterministic output.

grid.gltf / grid.glb are valid: node "Grid" with mesh "GridMesh", the unit square split into
8 triangles (9 float VEC3 positions, 24 unsigned-short indices) in one buffer. Every file in
malformed/ breaks one glTF 2.0 rule of grid.gltf; the test's table says which and what the
error must name. Some are the files that used to be misread or to panic inside the reader.
"""
import base64
import copy
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "gltf")
BAD = os.path.join(OUT, "malformed")

POS = [(x / 2, y / 2, 0.0) for y in range(3) for x in range(3)]
IDX = []
for y in range(2):
    for x in range(2):
        a = 3 * y + x
        IDX += [a, a + 1, a + 4, a, a + 4, a + 3]
POS_BYTES = b"".join(struct.pack("<3f", *p) for p in POS)  # 108 bytes
IDX_BYTES = struct.pack("<%dH" % len(IDX), *IDX)  # 48 bytes
DATA = POS_BYTES + IDX_BYTES


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()


BASE = {
    "asset": {"version": "2.0", "generator": "lambert tests/data/make_malformed_gltf.py"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "Grid", "mesh": 0}],
    "meshes": [{"name": "GridMesh", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 9, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 24, "type": "SCALAR"},
    ],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 108, "target": 34962},
        {"buffer": 0, "byteOffset": 108, "byteLength": 48, "target": 34963},
    ],
    "buffers": [{"byteLength": len(DATA), "uri": data_uri(DATA)}],
}


def write(path, doc):
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_glb(path, doc, data):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bn = bytes(data) + b"\0" * (-len(data) % 4)
    total = 12 + 8 + len(js) + 8 + len(bn)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)
        f.write(struct.pack("<I4s", len(bn), b"BIN\0") + bn)


def variant(edit):
    doc = copy.deepcopy(BASE)
    edit(doc)
    return doc


def acc(k, **kw):
    return lambda d: d["accessors"][k].update(kw)


def view(k, **kw):
    return lambda d: d["bufferViews"][k].update(kw)


def uri(u):
    return lambda d: d["buffers"][0].update(uri=u)


def raw_indices(values, fmt="<%dH"):
    data = POS_BYTES + struct.pack(fmt % len(values), *values)

    def edit(d):
        d["buffers"][0].update(byteLength=len(data), uri=data_uri(data))
        d["bufferViews"][1]["byteLength"] = len(data) - 108
        d["accessors"][1]["count"] = len(values)

    return edit


def both(*edits):
    def edit(d):
        for e in edits:
            e(d)

    return edit


CASES = {
    # An index accessor longer than its buffer view (was read as "no indices").
    "indices_past_view": acc(1, count=30),
    # POSITION declared as something other than VEC3 of FLOAT (was read as f32 triples).
    "position_vec2": acc(0, type="VEC2"),
    "position_ushort": acc(0, componentType=5123),
    "position_mat4": acc(0, type="MAT4"),
    # A buffer-view index of 2^40 (wrapped to 0).
    "view_index_2_40": acc(0, bufferView=2**40),
    # Malformed accessors that panicked inside the glTF crate.
    "position_accessor_out_of_range": lambda d: d["meshes"][0]["primitives"][0]["attributes"].update(POSITION=7),
    "indices_accessor_out_of_range": lambda d: d["meshes"][0]["primitives"][0].update(indices=5),
    "no_accessors": lambda d: d.pop("accessors"),
    "stride_below_element": view(0, byteStride=8),
    "float_indices": acc(1, componentType=5126),
    "signed_indices": acc(1, componentType=5122),
    "byte_indices": acc(1, componentType=5120),
    "vec2_indices": acc(1, type="VEC2", count=12),
    # Buffer URIs outside the folder, devices and file: URIs (were followed and read).
    "uri_dev_urandom": uri("/dev/urandom"),
    "uri_dev_zero": uri("/dev/zero"),
    "uri_etc_passwd": uri("/etc/passwd"),
    "uri_dotdot_hostname": uri("../../../../etc/hostname"),
    "uri_file_scheme": uri("file:///etc/passwd"),
    "uri_http": uri("http://localhost/grid.bin"),
    "uri_bad_percent": uri("grid%FF.bin"),
    "uri_missing": uri("missing.bin"),
    # Other rules of the accessors, views and buffers.
    "index_past_vertices": raw_indices(IDX[:-1] + [99]),
    "restart_index": raw_indices(IDX[:-1] + [65535]),
    "triangles_not_in_threes": raw_indices(IDX[:-2]),
    "view_past_buffer": view(1, byteLength=400),
    "view_offset_2_64": view(1, byteOffset=2**64 - 1),
    "buffer_shorter_than_declared": lambda d: d["buffers"][0].update(byteLength=400),
    "stride_not_multiple_of_4": view(0, byteStride=13),
    "stride_on_indices": view(1, byteStride=4),
    "offset_misaligned": both(view(0, byteLength=112), acc(0, byteOffset=2)),
    "count_zero": acc(0, count=0),
    "count_huge": acc(0, count=2**62),
    "count_negative": acc(0, count=-9),
    "count_float": acc(0, count=9.5),
    "unknown_component_type": acc(0, componentType=5124),
    "unknown_type": acc(0, type="VEC5"),
    "attribute_counts_differ": lambda d: (
        d["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3"}),
        d["meshes"][0]["primitives"][0]["attributes"].update(NORMAL=2),
    ),
    # Read as u32, the first two u16 indices (0, 1) give the sparse index 65536, past the count 9.
    "sparse_index_past_count": lambda d: d["accessors"][0].update(
        sparse={"count": 1, "indices": {"bufferView": 1, "componentType": 5125}, "values": {"bufferView": 0}}
    ),
    "mode_9": lambda d: d["meshes"][0]["primitives"][0].update(mode=9),
    "matrix_and_trs": lambda d: d["nodes"][0].update(matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], scale=[2, 2, 2]),
    "child_out_of_range": lambda d: d["nodes"][0].update(children=[4]),
    "scene_node_out_of_range": lambda d: d["scenes"][0].update(nodes=[2**40]),
    "required_extension": lambda d: d.update(extensionsRequired=["KHR_draco_mesh_compression"]),
    "version_1": lambda d: d["asset"].update(version="1.0"),
    "mesh_without_primitives": lambda d: d["meshes"][0].update(primitives=[]),
    "name_not_string": lambda d: d["nodes"][0].update(name=7),
}


def main():
    os.makedirs(BAD, exist_ok=True)
    write(os.path.join(OUT, "grid.gltf"), BASE)
    glb_doc = copy.deepcopy(BASE)
    del glb_doc["buffers"][0]["uri"]
    write_glb(os.path.join(OUT, "grid.glb"), glb_doc, DATA)
    for name, edit in CASES.items():
        write(os.path.join(BAD, name + ".gltf"), variant(edit))
    # Valid: a sparse accessor lifts the centre vertex (index 4) to z = 0.25.
    sparse = struct.pack("<HH", 4, 0) + struct.pack("<3f", 0.5, 0.5, 0.25)
    data = DATA + sparse
    doc = copy.deepcopy(BASE)
    doc["buffers"][0].update(byteLength=len(data), uri=data_uri(data))
    doc["bufferViews"] += [
        {"buffer": 0, "byteOffset": len(DATA), "byteLength": 2},
        {"buffer": 0, "byteOffset": len(DATA) + 4, "byteLength": 12},
    ]
    doc["accessors"][0]["max"] = [1, 1, 0.25]
    doc["accessors"][0]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": 2, "componentType": 5123},
        "values": {"bufferView": 3},
    }
    write(os.path.join(OUT, "grid_sparse.gltf"), doc)
    # GLB files whose BIN chunk is shorter than the buffer, or missing.
    write_glb(os.path.join(BAD, "glb_bin_short.glb"), glb_doc, DATA[:100])
    with open(os.path.join(BAD, "glb_no_bin.glb"), "wb") as f:
        js = json.dumps(glb_doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js)))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)


if __name__ == "__main__":
    main()
