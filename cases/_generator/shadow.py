"""Exact shadows of one convex blocker: F(dA -> receiver seen past the blocker) =
F(dA -> R) - F(dA -> R ∩ S), S the blocker's central projection onto R's plane (convex)."""
from geom import add, sub, mul, dot, cross, unit, clip, point_to_ring, ring_normal


class ConvexBlocker:
    """A convex polytope given by its vertices and edges (index pairs)."""

    def __init__(self, vertices, edges):
        self.vertices = vertices
        self.edges = edges


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    e = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    return ConvexBlocker(v, e)


def plate(ring):
    """A flat convex polygon as a blocker."""
    m = len(ring)
    return ConvexBlocker(list(ring), [(k, (k + 1) % m) for k in range(m)])


# Fraction of p's height above the receiver plane kept between p and the plane: blocker parts
# closer to p's level than this project more than 1e9 sizes away, far outside any receiver.
SLAB = 1.0 - 1e-9


def shadow_ring(p, blocker, q0, rn):
    """The blocker's shadow from p on the plane (q0, rn), as a ring CCW about rn, or None."""
    hp = dot(sub(p, q0), rn)
    if hp <= 0.0:
        return None
    lim = hp * SLAB
    h = [dot(sub(v, q0), rn) for v in blocker.vertices]
    # Keep the part strictly between the receiver plane (h > 0) and p's level (h < lim).
    pts = [v for v, hv in zip(blocker.vertices, h) if 0.0 < hv < lim]
    for i, j in blocker.edges:
        a, b, ha, hb = blocker.vertices[i], blocker.vertices[j], h[i], h[j]
        for cut in (0.0, lim):
            if (ha - cut) * (hb - cut) < 0.0:
                x = add(a, mul(sub(b, a), (ha - cut) / (ha - hb)))
                hx = dot(sub(x, q0), rn)
                if -1e-12 <= hx <= lim * (1 + 1e-12):
                    pts.append(x)
    if len(pts) < 3:
        return None
    # Central projection onto the receiver plane.
    proj = []
    for v in pts:
        hv = dot(sub(v, q0), rn)
        t = hp / (hp - hv)
        proj.append(add(p, mul(sub(v, p), t)))
    return hull_in_plane(proj, rn)


def hull_in_plane(points, n):
    """Convex hull (monotone chain) of coplanar points, CCW about n."""
    helper = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    e1 = unit(cross(helper, n))
    e2 = cross(n, e1)
    pts = sorted(set((dot(q, e1), dot(q, e2), q) for q in points))
    if len(pts) < 3:
        return None

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for q in pts:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    for q in reversed(pts):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    hull = lower[:-1] + upper[:-1]
    return [q[2] for q in hull] if len(hull) >= 3 else None


def intersect_convex(ring, convex, n):
    """ring ∩ convex (both convex, coplanar, convex CCW about n)."""
    out = ring
    m = len(convex)
    for k in range(m):
        a, b = convex[k], convex[(k + 1) % m]
        inward = cross(n, sub(b, a))
        out = clip(out, a, inward)
        if len(out) < 3:
            return []
    return out


def point_to_ring_shadowed(p, n, ring, blocker):
    """F(dA -> ring) with one convex blocker's shadow removed."""
    f = point_to_ring(p, n, ring)
    if f == 0.0 or blocker is None:
        return f
    rn = ring_normal(ring)
    s = shadow_ring(p, blocker, ring[0], rn)
    if s is None:
        return f
    vis = clip(ring, p, n)
    if len(vis) < 3:
        return f
    hidden = intersect_convex(vis, s, rn)
    if len(hidden) < 3:
        return f
    return max(0.0, f - point_to_ring(p, n, hidden))
