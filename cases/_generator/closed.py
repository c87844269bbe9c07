"""Howell-catalogue closed forms at 40 digits (mpmath), from literature.md section 1.1."""
from mpmath import mp, mpf, sqrt, atan, log, pi, acos, asin

mp.dps = 40


def c11(a, b, c):
    """C-11 (V1): identical parallel opposed rectangles a x b at gap c."""
    X, Y = mpf(a) / c, mpf(b) / c
    t = (log(sqrt((1 + X**2) * (1 + Y**2) / (1 + X**2 + Y**2)))
         + X * sqrt(1 + Y**2) * atan(X / sqrt(1 + Y**2)) + Y * sqrt(1 + X**2) * atan(Y / sqrt(1 + X**2))
         - X * atan(X) - Y * atan(Y))
    return 2 / (pi * X * Y) * t


def c14(w, h, l):
    """C-14 (V2): perpendicular rectangles, common edge l, from A1 (width w) to A2 (height h)."""
    W, H = mpf(w) / l, mpf(h) / l
    S = W**2 + H**2
    lt = log((1 + W**2) * (1 + H**2) / (1 + S))
    lt += W**2 * log(W**2 * (1 + S) / ((1 + W**2) * S)) if W else 0
    lt += H**2 * log(H**2 * (1 + S) / ((1 + H**2) * S)) if H else 0
    return (W * atan(1 / W) + H * atan(1 / H) - sqrt(S) * atan(1 / sqrt(S)) + lt / 4) / (pi * W)


def strips(a, b, c, d, l):
    """V4 algebra: A1F12, floor x in [a, b], wall z in [c, d], length l, common line."""
    def G(w, h):
        return 0 if (w == 0 or h == 0) else mpf(w) * l * c14(w, h, l)
    return G(b, d) - G(a, d) - G(b, c) + G(a, c)


def corner_g(x, y, eta, xi, z):
    u, v = mpf(x) - xi, mpf(y) - eta
    z = mpf(z)
    s = 0
    if v != 0:
        s += v * sqrt(u**2 + z**2) * atan(v / sqrt(u**2 + z**2))
    if u != 0:
        s += u * sqrt(v**2 + z**2) * atan(u / sqrt(v**2 + z**2))
    s -= z**2 / 2 * log(u**2 + v**2 + z**2)
    return s / (2 * pi)


def parallel_general(r1, r2, z):
    """V7 (C-13 corner sum): A1F12 of parallel rectangles [x0,x1]x[y0,y1] and
    [xi0,xi1]x[eta0,eta1] in planes a distance z apart."""
    (x0, x1, y0, y1), (k0, k1, e0, e1) = r1, r2
    tot = 0
    for i, x in enumerate((x0, x1)):
        for j, y in enumerate((y0, y1)):
            for k, e in enumerate((e0, e1)):
                for l_, k_ in enumerate((k0, k1)):
                    tot += (-1) ** (i + j + k + l_) * corner_g(x, y, e, k_, z)
    return tot


def coaxial_disks(r1, r2, h):
    """C-40/C-41 (V8, V9): F12 between coaxial parallel disks."""
    R1, R2 = mpf(r1) / h, mpf(r2) / h
    S = 1 + (1 + R2**2) / R1**2
    return (S - sqrt(S**2 - 4 * (R2 / R1) ** 2)) / 2


def element_corner(a, b, c):
    """Section B (V10): element parallel to an a x b rectangle, normal through a corner."""
    X, Y = mpf(a) / c, mpf(b) / c
    return (X / sqrt(1 + X**2) * atan(Y / sqrt(1 + X**2)) + Y / sqrt(1 + Y**2) * atan(X / sqrt(1 + Y**2))) / (2 * pi)


def element_disk_offset(r, h, a):
    """V11: element parallel to a disk of radius r at height h, offset a from the axis."""
    H, R = mpf(h) / a, mpf(r) / a
    return (1 - (1 + H**2 - R**2) / sqrt((1 + H**2 + R**2) ** 2 - 4 * R**2)) / 2


def sphere_to_disk(a, h):
    """C-125 (V14): sphere to a coaxial disk of radius a whose plane is h from the centre."""
    return (1 - 1 / sqrt(1 + (mpf(a) / h) ** 2)) / 2


def strings_parallel(w, h):
    """C-1 (V16): infinitely long parallel plates w at gap h (crossed strings)."""
    H = mpf(h) / w
    return sqrt(1 + H**2) - H


def strings_common_edge(w, h):
    """C-3 (V16): infinitely long plates with a common edge at 90 degrees, widths w (from) and h."""
    H = mpf(h) / w
    return (1 + H - sqrt(1 + H**2)) / 2


def strings_wedge(alpha):
    """C-4 (V16): equal infinitely long plates at angle alpha with a common edge."""
    return 1 - mp.sin(mpf(alpha) / 2)


def cylinders_equal(r, s):
    """C-68 (V17): infinite parallel cylinders of radius r, surface gap s."""
    X = 1 + mpf(s) / (2 * r)
    return (sqrt(X**2 - 1) + asin(1 / X) - X) / pi


def cylinders_unequal(r1, r2, s):
    """C-69 (V18): F12, cylinder radii r1 (from), r2, surface gap s."""
    R, S = mpf(r2) / r1, mpf(s) / r1
    C = 1 + R + S
    return (pi + sqrt(C**2 - (R + 1) ** 2) - sqrt(C**2 - (R - 1) ** 2) + (R - 1) * acos((R - 1) / C) - (R + 1) * acos((R + 1) / C)) / (2 * pi)


def coaxial_cylinders(r1, r2, L):
    """V19 (Siegel & Howell 4th ed. p. 847 per EES): returns F12, F21, F22, F2->both ends."""
    R, H = mpf(r2) / r1, mpf(L) / r1
    A, B = H**2 + R**2 - 1, H**2 - R**2 + 1
    F21 = 1 / R - (1 / (pi * R)) * (acos(B / A) - (1 / (2 * H)) * (sqrt((A + 2) ** 2 - 4 * R**2) * acos(B / (R * A)) + B * asin(1 / R) - pi * A / 2))
    F22 = (1 - 1 / R + (2 / (pi * R)) * atan(2 * sqrt(R**2 - 1) / H)
           - (H / (2 * pi * R)) * ((sqrt(4 * R**2 + H**2) / H) * asin((4 * (R**2 - 1) + (H**2 / R**2) * (R**2 - 2)) / (H**2 + 4 * (R**2 - 1)))
                                   - asin((R**2 - 2) / R**2) + (pi / 2) * (sqrt(4 * R**2 + H**2) / H - 1)))
    return R * F21, F21, F22, 1 - F21 - F22


def selftest():
    """Each closed form against the printed literature value."""
    checks = [
        (c11(1, 1, 1), "0.199824895698"), (c11(1, 1, 0.5), "0.41525328"),
        (c14(1, 1, 1), "0.200043776075"), (c14(1, 2, 1), "0.232852602795"), (c14(2, 1, 1), "0.11642630"),
        (strips(0, 1, 1, 2, 1), "0.0328088267"), (strips(1, 2, 1, 2, 1), "0.0329381623"),
        (parallel_general((0, 1, 0, 2), (0.5, 2, 1, 1.5), 0.7) / 2, "0.0934134915"),
        (coaxial_disks(1, 1, 1), "0.38196601"), (coaxial_disks(1, 2, 1), "0.76393202"),
        (element_corner(1, 1, 1), "0.13853161"), (element_corner(2, 1, 1), "0.16737501"),
        (element_disk_offset(1, 1, 0.5), "0.43798263"), (sphere_to_disk(1, 1), "0.14644661"),
        (strings_parallel(1, 1), "0.41421356"), (strings_common_edge(1, 1), "0.29289322"),
        (strings_wedge(pi / 3), "0.50000000"), (cylinders_equal(1, 1), "0.11069597"),
        (cylinders_unequal(1, 2, 1), "0.16938446"),
    ]
    F12, F21, F22, Fe = coaxial_cylinders(0.5, 1, 2)
    checks += [(F12, "0.82525582"), (F21, "0.41262791"), (F22, "0.32859825"), (Fe, "0.25877384")]
    for got, printed in checks:
        digits = len(printed.split(".")[1])
        assert abs(got - mpf(printed)) <= 0.6 * mpf(10) ** -digits, (got, printed)


def perpendicular_general(a, b, c, d, y1, y2):
    """Exchange area of perpendicular rectangles whose planes meet in a common line: floor at
    distances [a, b] from the line, wall at [c, d], spans y1 and y2 along the line (V5/V6
    algebra: the kernel depends on y - y' only, K(L) = Gl(|L|)/2 with Gl the aligned value)."""
    def K(L):
        L = abs(mpf(L))
        return 0 if L == 0 else strips(a, b, c, d, L) / 2
    (p0, p1), (q0, q1) = y1, y2
    return K(q1 - p0) - K(q0 - p0) - K(q1 - p1) + K(q0 - p1)
