#!/usr/bin/env python3
"""Independent references for concave parts in a room: surface-to-surface view factors by
Monte Carlo ray casting in numpy, with no lambert code involved.

Method: for each emitting surface, points uniform by area over its triangles (a wall is its
rectangle split in two), directions cosine-weighted about the triangle's normal (Malley), the
nearest hit among all triangles of the scene (Moller-Trumbore, both sides, t > 1e-9 m). F(i -> j)
is the fraction of rays from i whose first hit is a front face of j. A ray that hits a back face
first, or nothing, is counted as lost (a leak; 0 for a closed, outward part in the room). The
rays are independent, so the count is binomial and the standard error of an entry is
sqrt(F (1 - F) / N) for N rays. (The rays are cast in B batches; the spread of the batch means
is printed as a check, but its estimate of the error is itself uncertain by about 1/sqrt(2 (B - 1)),
18 % for B = 16, so it is not the one stored.) The seed is fixed, so a rerun gives the same
numbers.

usage: reference.py OUT_DIR [RAYS_PER_SURFACE [PART,...]]  (default 4,000,000; writes OUT_DIR/<part>/scene.toml,
part0.stl and reference.csv for l_bracket, u_channel and heat_sink, coarse meshes from parts.py)
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

# The reference scenes: a 1 m closed room (half-width 0.5 m), the part scaled to 0.4 m.
HALF = (0.5, 0.5, 0.5)
SIZE_M = 0.4
BATCHES = 16
CHUNK = 16384  # rays per numpy chunk (memory about CHUNK x triangles x 8 bytes per array)
T_MIN = 1e-9  # m: hits closer than this to a ray's origin are its own surface


def scene_triangles(parts_m):
    """All triangles (metres) with their surface index: walls 0..5 (two triangles each), parts after."""
    tris, sid = [], []
    for k, quad in enumerate(scenes.wall_patches(HALF, 1)):
        tris += [quad[[0, 1, 2]], quad[[0, 2, 3]]]
        sid += [k, k]
    for p, t in enumerate(parts_m):
        tris += list(t)
        sid += [6 + p] * len(t)
    return np.array(tris), np.array(sid)


def first_hits(orig, dirs, tris):
    """Index of the nearest triangle hit by each ray (-1: none) and whether it was hit on its front."""
    v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    normal = np.cross(e1, e2)
    p = np.cross(dirs[:, None, :], e2[None, :, :])
    det = np.einsum("mkc,kc->mk", p, e1)
    ok = np.abs(det) > 1e-300
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = orig[:, None, :] - v0[None, :, :]
    u = np.einsum("mkc,mkc->mk", s, p) * inv
    q = np.cross(s, e1[None, :, :])
    v = np.einsum("mc,mkc->mk", dirs, q) * inv
    t = np.einsum("kc,mkc->mk", e2, q) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > T_MIN)
    t = np.where(hit, t, np.inf)
    k = t.argmin(axis=1)
    none = ~np.isfinite(t[np.arange(len(k)), k])
    front = np.einsum("mc,mc->m", dirs, normal[k]) < 0
    k[none] = -1
    return k, front


def sample_rays(rng, tris, m):
    """m points uniform by area on the triangles, with cosine-weighted directions about their normals."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    nrm = np.cross(e1, e2)
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    nrm /= (2 * area)[:, None]
    idx = rng.choice(len(tris), size=m, p=area / area.sum())
    a, b = rng.random(m), rng.random(m)
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    orig = tris[idx, 0] + a[:, None] * e1[idx] + b[:, None] * e2[idx]
    n = nrm[idx]
    # an orthonormal frame about n
    helper = np.where(np.abs(n[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    t1 = np.cross(n, helper)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(n, t1)
    r, phi = np.sqrt(rng.random(m)), 2 * np.pi * rng.random(m)
    z = np.sqrt(np.maximum(0.0, 1 - r * r))
    dirs = (r * np.cos(phi))[:, None] * t1 + (r * np.sin(phi))[:, None] * t2 + z[:, None] * n
    return orig, dirs


def view_factors(tris, sid, nsurf, rays, seed):
    """F (nsurf x nsurf), its standard error, and the lost fraction per row."""
    f = np.zeros((nsurf, nsurf))
    se = np.zeros((nsurf, nsurf))
    lost = np.zeros(nsurf)
    per_batch = rays // BATCHES
    for i in range(nsurf):
        rng = np.random.default_rng([seed, i])
        mine = tris[sid == i]
        means = np.zeros((BATCHES, nsurf + 1))
        for b in range(BATCHES):
            counts = np.zeros(nsurf + 1)
            left = per_batch
            while left > 0:
                m = min(CHUNK, left)
                left -= m
                o, d = sample_rays(rng, mine, m)
                k, front = first_hits(o, d, tris)
                target = np.where((k >= 0) & front, sid[np.maximum(k, 0)], nsurf)
                counts += np.bincount(target, minlength=nsurf + 1)
            means[b] = counts / per_batch
        f[i] = means[:, :nsurf].mean(0)
        se[i] = np.sqrt(f[i] * (1 - f[i]) / (per_batch * BATCHES))
        spread = means[:, :nsurf].std(0, ddof=1) / np.sqrt(BATCHES)
        ratio = spread[se[i] > 0] / se[i][se[i] > 0]
        print(f"  row {i}: batch spread / binomial error {ratio.min():.2f} to {ratio.max():.2f}")
        lost[i] = means[:, nsurf].mean()
    return f, se, lost


def main():
    out = sys.argv[1]
    rays = int(float(sys.argv[2])) if len(sys.argv) > 2 else 4_000_000
    here = os.path.dirname(os.path.abspath(__file__))
    coarse = tempfile.mkdtemp(prefix="lambert-coarse-parts-")
    subprocess.run([sys.executable, os.path.join(here, "parts.py"), coarse, "--coarse"], check=True)
    only = sys.argv[3].split(",") if len(sys.argv) > 3 else None
    for seed, name in enumerate(["l_bracket", "u_channel", "heat_sink"]):
        if only and name not in only:
            continue
        t0 = time.time()
        part = scenes.place(scenes.read_stl(os.path.join(coarse, f"{name}.stl")), SIZE_M, 1)
        d = os.path.join(out, name)
        scenes.write_scene(d, part, HALF, 1, f"{name} (parts.py --coarse) scaled to {SIZE_M} m in a 1 m room")
        os.remove(os.path.join(d, "scene.vs3"))
        tris, sid = scene_triangles([p * 1e-3 for p in part])
        names = scenes.WALLS + ["part0"]
        f, se, lost = view_factors(tris, sid, len(names), rays, seed=1800 + seed)
        with open(os.path.join(d, "reference.csv"), "w") as w:
            w.write("from,to,factor,std_error\n")
            for i, a in enumerate(names):
                for j, b in enumerate(names):
                    if f[i, j] > 0:
                        w.write(f"{a},{b},{float(f[i, j])!r},{float(se[i, j])!r}\n")
        print(f"{name}: {len(part[0])} triangles, {rays} rays per surface, lost {lost.max():.2e}, "
              f"largest std_error {se.max():.2e}, {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
