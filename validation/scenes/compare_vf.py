#!/usr/bin/env python3
"""Largest difference between two `viewfactors` CSVs (from,to,factor[,...]):
prints `max_abs <x> max_rel <y>` with max_rel over entries >= 1e-3 of the reference.
Usage: compare_vf.py REFERENCE.csv OTHER.csv
       compare_vf.py REFERENCE.csv VIEW3D.vf NAMES (View3D's text output, its polygons summed into
       surfaces by area; NAMES holds each radiating polygon's surface name, one per line)"""
import csv
import sys


def read(path):
    with open(path) as f:
        return {(r["from"], r["to"]): float(r["factor"]) for r in csv.DictReader(f)}


def read_view3d(path, names_path):
    """Surface factors F_IJ = sum over i in I, j in J of A_i F_ij / A_I from a View3D output."""
    names = open(names_path).read().split()
    lines = open(path).read().split("\n")
    areas = [float(x) for x in lines[1].split()]
    if len(areas) != len(names):
        sys.exit(f"{path}: {len(areas)} polygons, {names_path}: {len(names)} names")
    exchange, area = {}, {}
    for i, name in enumerate(names):
        area[name] = area.get(name, 0.0) + areas[i]
        for j, f in enumerate(lines[2 + i].split()):
            key = (name, names[j])
            exchange[key] = exchange.get(key, 0.0) + areas[i] * float(f)
    return {k: v / area[k[0]] for k, v in exchange.items()}


ref = read(sys.argv[1])
other = read_view3d(sys.argv[2], sys.argv[3]) if len(sys.argv) > 3 else read(sys.argv[2])
max_abs = max_rel = 0.0
for key in ref.keys() | other.keys():
    a, b = ref.get(key, 0.0), other.get(key, 0.0)
    max_abs = max(max_abs, abs(a - b))
    if abs(a) >= 1e-3:
        max_rel = max(max_rel, abs(a - b) / abs(a))
print(f"max_abs {max_abs:.2e} max_rel {max_rel:.2e}")
