#!/usr/bin/env python3
"""Largest difference between two `viewfactors` CSVs (from,to,factor[,...]):
prints `max_abs <x> max_rel <y>` with max_rel over entries >= 1e-3 of the reference.
Usage: compare_vf.py REFERENCE.csv OTHER.csv"""
import csv
import sys


def read(path):
    with open(path) as f:
        return {(r["from"], r["to"]): float(r["factor"]) for r in csv.DictReader(f)}


ref, other = read(sys.argv[1]), read(sys.argv[2])
max_abs = max_rel = 0.0
for key in ref.keys() | other.keys():
    a, b = ref.get(key, 0.0), other.get(key, 0.0)
    max_abs = max(max_abs, abs(a - b))
    if abs(a) >= 1e-3:
        max_rel = max(max_rel, abs(a - b) / abs(a))
print(f"max_abs {max_abs:.2e} max_rel {max_rel:.2e}")
