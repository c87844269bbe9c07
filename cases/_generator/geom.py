"""Vectors, polygon clipping, Lambert's point-to-polygon factor and Gauss rules (floats).

Independent of lambert's Rust code: the references of cases/ are computed here.
"""
import math

# ---------------------------------------------------------------- vectors


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def newell(ring):
    n = (0.0, 0.0, 0.0)
    for k in range(len(ring)):
        n = add(n, cross(ring[k], ring[(k + 1) % len(ring)]))
    return n


def ring_normal(ring):
    return unit(newell(ring))


def ring_area(ring):
    return 0.5 * norm(newell(ring))


def centroid(ring):
    o = ring[0]
    area2 = 0.0
    m = (0.0, 0.0, 0.0)
    nrm = ring_normal(ring)
    for k in range(1, len(ring) - 1):
        a2 = dot(cross(sub(ring[k], o), sub(ring[k + 1], o)), nrm)
        area2 += a2
        m = add(m, mul(add(add(o, ring[k]), ring[k + 1]), a2))
    return mul(m, 1.0 / (3.0 * area2))


# ---------------------------------------------------------------- clipping


def clip(ring, p, n):
    """Part of a convex ring with (x - p).n >= 0 (Sutherland-Hodgman)."""
    d = [dot(sub(v, p), n) for v in ring]
    out = []
    m = len(ring)
    for k in range(m):
        a, b, da, db = ring[k], ring[(k + 1) % m], d[k], d[(k + 1) % m]
        if da >= 0.0:
            out.append(a)
        if (da > 0.0 > db) or (da < 0.0 < db):
            out.append(add(a, mul(sub(b, a), da / (da - db))))
    return out


# ---------------------------------------------------------------- Lambert (V12)


def point_to_ring(p, n, ring):
    """F(dA -> ring): element at p with unit normal n, one-sided CCW ring clipped to the
    element's front half-space (Lambert 1760, literature V12)."""
    rn = ring_normal(ring)
    if dot(sub(p, ring[0]), rn) <= 0.0:
        return 0.0
    c = clip(ring, p, n)
    if len(c) < 3:
        return 0.0
    s = 0.0
    m = len(c)
    for k in range(m):
        a = sub(c[k], p)
        b = sub(c[(k + 1) % m], p)
        x = cross(a, b)
        ln = norm(x)
        if ln > 0.0:
            s += math.atan2(ln, dot(a, b)) * dot(n, x) / ln
    return max(0.0, -s / (2.0 * math.pi))


def point_to_rings(p, n, rings):
    return sum(point_to_ring(p, n, r) for r in rings)


# ---------------------------------------------------------------- Gauss rules


def gauss_legendre(n):
    """Nodes and weights on [0, 1]."""
    xs, ws = [0.0] * n, [0.0] * n
    for i in range((n + 1) // 2):
        z = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, z
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * z * p1 - (k - 1) * p0) / k
            if n == 1:
                p1, p0 = z, 1.0
            dp = n * (z * p1 - p0) / (z * z - 1.0)
            dz = p1 / dp
            z -= dz
            if abs(dz) < 1e-16:
                break
        w = 2.0 / ((1.0 - z * z) * dp * dp)
        xs[i], xs[n - 1 - i] = 0.5 * (1.0 - z), 0.5 * (1.0 + z)
        ws[i] = ws[n - 1 - i] = 0.5 * w
    return xs, ws


def graded_cells(grade_lo, grade_hi, levels=14, ratio=0.2, uniform=4):
    """Breakpoints of [0, 1], geometrically graded towards 0 and/or 1 (for x ln x ends)."""
    pts = set(i / uniform for i in range(uniform + 1))
    for k in range(1, levels + 1):
        h = (1.0 / uniform) * ratio ** k
        if grade_lo:
            pts.add(h)
        if grade_hi:
            pts.add(1.0 - h)
    return sorted(pts)


def rule_1d(breaks, order):
    xs, ws = gauss_legendre(order)
    out = []
    for a, b in zip(breaks[:-1], breaks[1:]):
        for x, w in zip(xs, ws):
            out.append((a + (b - a) * x, (b - a) * w))
    return out


def parallelogram_rule(o, u, v, su, sv):
    """Points and weights (summing to the area) of the tensor product of 1-D rules su, sv."""
    area = norm(cross(u, v))
    return [(add(o, add(mul(u, x), mul(v, y))), area * wx * wy) for x, wx in su for y, wy in sv]


def triangle_rule(a, b, c, order):
    """Collapsed (Duffy) Gauss rule on a triangle."""
    xs, ws = gauss_legendre(order)
    area = 0.5 * norm(cross(sub(b, a), sub(c, a)))
    pts = []
    for x, wx in zip(xs, ws):
        for y, wy in zip(xs, ws):
            s, t = x, y * (1.0 - x)
            pts.append((add(a, add(mul(sub(b, a), s), mul(sub(c, a), t))), 2.0 * area * wx * wy * (1.0 - x)))
    return pts


def polygon_rule(ring, order, cells=1):
    """Fan-triangulated Duffy rule on a convex ring; each triangle split into cells² pieces."""
    pts = []
    for k in range(1, len(ring) - 1):
        for tri in split_triangle(ring[0], ring[k], ring[k + 1], cells):
            pts.extend(triangle_rule(*tri, order))
    return pts


def split_triangle(a, b, c, m):
    """m² congruent sub-triangles."""
    if m == 1:
        return [(a, b, c)]
    P = lambda i, j: add(a, add(mul(sub(b, a), i / m), mul(sub(c, a), j / m)))
    out = []
    for i in range(m):
        for j in range(m - i):
            out.append((P(i, j), P(i + 1, j), P(i, j + 1)))
            if i + j < m - 1:
                out.append((P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)))
    return out


def exchange_area(rule, n, f):
    """Sum of w·f(p) over a rule: A_1 F_12 when f(p) = F(dA(p) -> A_2)."""
    return math.fsum(w * f(p) for p, w in rule)


# ---------------------------------------------------------------- shapes


def rectangle(o, u, v):
    """Corners o, o+u, o+u+v, o+v (normal u x v)."""
    return [o, add(o, u), add(add(o, u), v), add(o, v)]


def subdivide_rectangle(o, u, v, nu, nv):
    """nu x nv patches, as the scene loader's `subdivide = [nu, nv]`."""
    out = []
    for i in range(nu):
        for j in range(nv):
            po = add(o, add(mul(u, i / nu), mul(v, j / nv)))
            out.append(rectangle(po, mul(u, 1.0 / nu), mul(v, 1.0 / nv)))
    return out


def regular_polygon(center, normal, radius, n, phase=0.0):
    """Inscribed regular n-gon, CCW about `normal`."""
    nrm = unit(normal)
    helper = (1.0, 0.0, 0.0) if abs(nrm[0]) < 0.9 else (0.0, 1.0, 0.0)
    e1 = unit(cross(helper, nrm))
    e2 = cross(nrm, e1)
    return [
        add(center, add(mul(e1, radius * math.cos(phase + 2 * math.pi * k / n)), mul(e2, radius * math.sin(phase + 2 * math.pi * k / n))))
        for k in range(n)
    ]
