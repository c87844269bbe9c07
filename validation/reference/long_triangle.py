#!/usr/bin/env python3
"""Reference view factors F(square -> long triangle) for tests/viewfactor/analytic_scale.rs.

The unit square [0,1]^2 at z = 1 faces down (-z); the triangle (0,0,0.5), (L,0,0.5),
(0,0.5,0.5) faces up. F = (1/A_sq) * integral over the square of Lambert's point-to-polygon
factor (Lambert 1760: F = (1/2pi) sum_k beta_k n.(R_k x R_k+1)/|R_k x R_k+1|), computed in
mpmath at 30 significant digits with 2-D tanh-sinh quadrature. This route (area integral of a
point factor) is independent of lambert's double contour integral. The integrand is analytic
on the square (the triangle lies 0.5 below it), so tanh-sinh converges fast; the printed
error estimate is mpmath's.

Usage: python3 long_triangle.py > long_triangle.csv   (pip install mpmath)
"""
import mpmath as mp

mp.mp.dps = 30


def point_factor(a, b, L):
    x = mp.matrix([a, b, 1])
    n = mp.matrix([0, 0, -1])
    verts = [mp.matrix([0, 0, mp.mpf('0.5')]), mp.matrix([L, 0, mp.mpf('0.5')]),
             mp.matrix([0, mp.mpf('0.5'), mp.mpf('0.5')])]
    r = [v - x for v in verts]
    total = mp.mpf(0)
    for k in range(3):
        p, q = r[k], r[(k + 1) % 3]
        c = mp.matrix([p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]])
        cn = mp.sqrt(c[0] ** 2 + c[1] ** 2 + c[2] ** 2)
        beta = mp.atan2(cn, p[0] * q[0] + p[1] * q[1] + p[2] * q[2])
        total += beta * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / cn
    return abs(total) / (2 * mp.pi)


def main():
    print("L,factor,quad_error_estimate")
    for e in range(0, 12):
        L = mp.mpf(10) ** e
        value, err = mp.quad(lambda a, b: point_factor(a, b, L), [0, 1], [0, 1], error=True)
        print(f"1e{e},{mp.nstr(value, 20)},{mp.nstr(err, 3)}", flush=True)


if __name__ == "__main__":
    main()
