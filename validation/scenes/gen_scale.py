#!/usr/bin/env python3
"""The scaling-benchmark scenes, written to validation/scenes/scale/ (see bench_scale.sh):

- ebox_<tag>.toml + ebox_<tag>.gltf, tag in 1k 2k 5k 10k 20k 50k 100k: an electronics
  enclosure of about that many triangles. A closed 0.4 x 0.3 x 0.1 m box (six walls facing in,
  300 K, emissivity 0.85) holds two circuit boards (0.36 x 0.26 x 0.002 m cuboids at heights
  0.03 and 0.065 m, clear of the walls, 330 K, emissivity 0.9), each carrying 6-10 components
  (cuboids 0.02-0.05 m wide, 0.003-0.015 m tall, on 0.5 mm standoffs above the board top). Half of the
  components dissipate a heat_flux of 500-3000 W/m² (emissivity 0.9), the rest are held at
  340-380 K (emissivity 0.7-0.95). One glTF node (one lambert surface) per wall and per face
  of every board and component (a planar face blocks as one outline); every face irregularly triangulated (cases/_generator/irregular.py), with one
  cell size across the scene so that triangles have comparable sizes.
- room_<tag>.toml: validation/scenes/room_8472.toml with its `subdivide` values scaled so the
  patch count is near the tag (wall : block cells near 34 : 16).
- troom_<tag>.toml + troom_<tag>.gltf: the same room and block (all emissivity 0.8, floor
  1000 K, the rest 300 K), every face irregularly triangulated at one cell size (no grid, so
  no translated pairs), one glTF node per face.

Pure standard library, deterministic (fixed seed). Run: python3 validation/scenes/gen_scale.py
[FAMILY ...] (default: ebox room troom)
"""
import math
import os
import random
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "cases", "_generator"))

import gltf  # noqa: E402
import irregular  # noqa: E402
from geom import add, cross, dot, mul, norm, sub  # noqa: E402

OUT = os.path.join(HERE, "scale")
TAGS = [("1k", 1000), ("2k", 2000), ("5k", 5000), ("10k", 10000), ("20k", 20000), ("50k", 50000), ("100k", 100000)]
SEED = 11

# Enclosure, boards and components (metres).
BOX = (0.4, 0.3, 0.1)
BOARD_LO_XY, BOARD_HI_XY = (0.02, 0.02), (0.38, 0.28)  # 0.36 x 0.26, 0.02 clear of the walls
BOARD_Z = (0.03, 0.065)  # board bottoms
BOARD_T = 0.002
GAP = 5e-4  # component bottom above the board top (a 0.5 mm standoff)
SPACING = 0.006  # least clearance between components, and from the board edge


def cuboid_faces(name, lo, hi, inward=False):
    """(face name, origin, u, v) of an axis-aligned cuboid, u x v outward (or inward)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    faces = [
        ("z0", (x0, y0, z0), (0, dy, 0), (dx, 0, 0)),
        ("z1", (x0, y0, z1), (dx, 0, 0), (0, dy, 0)),
        ("x0", (x0, y0, z0), (0, 0, dz), (0, dy, 0)),
        ("x1", (x1, y0, z0), (0, dy, 0), (0, 0, dz)),
        ("y0", (x0, y0, z0), (dx, 0, 0), (0, 0, dz)),
        ("y1", (x0, y1, z0), (0, 0, dz), (dx, 0, 0)),
    ]
    return [(f"{name}_{f}", o, v, u) if inward else (f"{name}_{f}", o, u, v) for f, o, u, v in faces]


def place_components(rng, board, z_top):
    """Non-overlapping components on a board: [(lo, hi)]."""
    (bx0, by0), (bx1, by1) = BOARD_LO_XY, BOARD_HI_XY
    want = rng.randint(6, 10)
    comps = []
    tries = 0
    while len(comps) < want:
        tries += 1
        assert tries < 100000, "cannot place components"
        wx, wy = round(rng.uniform(0.02, 0.05), 4), round(rng.uniform(0.02, 0.05), 4)
        hz = round(rng.uniform(0.003, 0.015), 4)
        x = round(rng.uniform(bx0 + SPACING, bx1 - SPACING - wx), 4)
        y = round(rng.uniform(by0 + SPACING, by1 - SPACING - wy), 4)
        if any(x < c[1][0] + SPACING and c[0][0] < x + wx + SPACING and y < c[1][1] + SPACING and c[0][1] < y + wy + SPACING
               for c in comps):
            continue
        z = z_top + GAP
        comps.append(((x, y, z), (x + wx, y + wy, z + hz)))
    return comps


def ebox_layout(seed):
    """[(surface name, [(face name, origin, u, v)], extras)] of the enclosure."""
    rng = random.Random(seed)
    X, Y, Z = BOX
    walls = {"z0": "floor", "z1": "ceiling", "x0": "wall_x0", "x1": "wall_x1", "y0": "wall_y0", "y1": "wall_y1"}
    bodies = []
    for fname, o, u, v in cuboid_faces("box", (0, 0, 0), BOX, inward=True):
        bodies.append((walls[fname[4:]], [(fname, o, u, v)], {"emissivity": 0.85, "temperature": 300.0}))
    comps = []
    for b, z in enumerate(BOARD_Z):
        lo, hi = (BOARD_LO_XY[0], BOARD_LO_XY[1], z), (BOARD_HI_XY[0], BOARD_HI_XY[1], z + BOARD_T)
        bodies.append((f"board{b + 1}", cuboid_faces(f"board{b + 1}", lo, hi), {"emissivity": 0.9, "temperature": 330.0}))
        for k, (clo, chi) in enumerate(place_components(rng, b, z + BOARD_T)):
            comps.append((f"board{b + 1}_c{k + 1}", clo, chi))
    # Half of the components dissipate (heat_flux), the rest are held at a temperature.
    flux = set(rng.sample(range(len(comps)), len(comps) // 2))
    for i, (name, lo, hi) in enumerate(comps):
        if i in flux:
            extras = {"emissivity": 0.9, "heat_flux": float(round(rng.uniform(500, 3000), -1))}
        else:
            extras = {"emissivity": round(rng.uniform(0.7, 0.95), 2), "temperature": float(round(rng.uniform(340, 380)))}
        bodies.append((name, cuboid_faces(name, lo, hi), extras))
    return bodies


def cells(length, h):
    """irregular.face_triangles' cell count along a side."""
    return max(1, round(length / h))


def count(bodies, h):
    return sum(2 * cells(norm(u), h) * cells(norm(v), h) for _, faces, _ in bodies for _, _, u, v in faces)


def cell_for(bodies, target):
    """The cell size whose triangle count is closest to target."""
    area = sum(norm(cross(u, v)) for _, faces, _ in bodies for _, _, u, v in faces)
    h0 = math.sqrt(2 * area / target)
    best = None
    for i in range(3001):
        h = h0 * 0.6 * (2.5 ** (i / 3000))
        n = count(bodies, h)
        if best is None or abs(n - target) < abs(best[1] - target):
            best = (h, n)
    return best


def check_closed(name, tris, inward):
    """A closed surface: area vectors cancel and the enclosed volume has the right sign."""
    area = math.fsum(0.5 * norm(cross(sub(b, a), sub(c, a))) for a, b, c in tris)
    flux = [math.fsum(0.5 * cross(sub(b, a), sub(c, a))[k] for a, b, c in tris) for k in range(3)]
    vol = math.fsum(dot(a, cross(b, c)) for a, b, c in tris) / 6
    assert norm(flux) < 1e-9 * area, f"{name}: not closed"
    assert (vol < 0) == inward and vol != 0, f"{name}: wrong orientation"


def write_mesh_scene(stem, meshes, n, h, title):
    """stem.gltf (one node per mesh) and stem.toml loading it; returns the triangle count."""
    total = sum(len(t) for _, t, _ in meshes)
    assert total == n
    gltf.write(os.path.join(OUT, stem + ".gltf"), meshes)
    with open(os.path.join(OUT, stem + ".toml"), "w") as f:
        f.write(f"# Generated by validation/scenes/gen_scale.py: {total} triangles, cell {h:.4g} m\n"
                f'title = "{title}, {total} triangles"\n\n'
                f'[[model]]\nfile = "{stem}.gltf"\n')
    return total


def ebox():
    bodies = ebox_layout(SEED)
    ncomp = len(bodies) - 8
    for tag, target in TAGS:
        h, n = cell_for(bodies, target)
        rng = random.Random(SEED)
        meshes, walls = [], []
        for name, faces, extras in bodies:
            per_face = [(fname, irregular.face_triangles(rng, o, u, v, h)) for fname, o, u, v in faces]
            tris = [t for _, ft in per_face for t in ft]
            if len(faces) == 6:
                check_closed(name, tris, inward=False)
                # One surface per planar face, as CAD exports faces: a face blocks as one outline.
                meshes += [(fname, ft, extras) for fname, ft in per_face]
            else:
                walls += tris
                meshes.append((name, tris, extras))
        check_closed("enclosure", walls, inward=True)
        total = write_mesh_scene(f"ebox_{tag}", meshes, n, h, f"Electronics enclosure, 2 boards, {ncomp} components")
        print(f"ebox_{tag}: {total} triangles (target {target}, {len(meshes)} surfaces, cell {h * 1000:.2f} mm)")


def troom():
    hot = {"emissivity": 0.8, "temperature": 1000.0}
    cold = {"emissivity": 0.8, "temperature": 300.0}
    room_faces = cuboid_faces("room", (0.0, 0.0, 0.0), (3.0, 3.0, 3.0), inward=True)
    block_faces = cuboid_faces("block", (1.0, 1.0, 1.0), (2.0, 2.0, 2.0))
    bodies = [("room", room_faces, None), ("block", block_faces, cold)]
    for tag, target in TAGS:
        h, n = cell_for(bodies, target)
        rng = random.Random(SEED)
        meshes = []
        for name, faces, _ in bodies:
            per_face = [(fname, irregular.face_triangles(rng, o, u, v, h)) for fname, o, u, v in faces]
            check_closed(name, [t for _, ft in per_face for t in ft], inward=name == "room")
            meshes += [(fname, ft, hot if fname == "room_z0" else cold) for fname, ft in per_face]
        total = write_mesh_scene(f"troom_{tag}", meshes, n, h, "Obstructed room, irregular triangles")
        print(f"troom_{tag}: {total} triangles (target {target}, cell {h * 1000:.1f} mm)")


def room():
    with open(os.path.join(HERE, "room_8472.toml")) as f:
        src = f.read()
    assert src.count("subdivide = [34, 34]") == 6 and src.count("subdivide = [16, 16]") == 6
    for tag, target in TAGS:
        best = None
        for a in range(2, 400):  # block cells within one of the 34 : 16 ratio
            for b in range(max(1, round(a * 16 / 34) - 1), round(a * 16 / 34) + 2):
                n = 6 * (a * a + b * b)
                if best is None or abs(n - target) < abs(best[2] - target):
                    best = (a, b, n)
        a, b, n = best
        s = src.replace("subdivide = [34, 34]", "subdivide = WALL").replace("subdivide = [16, 16]", "subdivide = BLOCK")
        s = s.replace("subdivide = WALL", f"subdivide = [{a}, {a}]").replace("subdivide = BLOCK", f"subdivide = [{b}, {b}]")
        s = s.replace("34x34 patches per face", f"{a}x{a} patches per face").replace("16x16 per face", f"{b}x{b} per face")
        s = re.sub(r"N = 8,?472", f"N = {n}", s)
        s = "# Generated by validation/scenes/gen_scale.py from room_8472.toml\n" + s
        with open(os.path.join(OUT, f"room_{tag}.toml"), "w") as f:
            f.write(s)
        print(f"room_{tag}: {n} patches (target {target}, walls {a}x{a}, block {b}x{b})")


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    families = {"ebox": ebox, "room": room, "troom": troom}
    for name in sys.argv[1:] or families:
        families[name]()
