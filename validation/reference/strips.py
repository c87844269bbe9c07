#!/usr/bin/env python3
"""Reference view factors between two directly opposed parallel rectangles L x 1 at unit gap
(long strips), for tests/viewfactor/analytic_scale.rs.

Howell's catalogue C-11 in mpmath at 60 significant digits, where its terms (of size L ln L)
cancel harmlessly:
F = 2/(pi X Y) [ ln sqrt((1+X^2)(1+Y^2)/(1+X^2+Y^2)) + X sqrt(1+Y^2) atan(X/sqrt(1+Y^2))
               + Y sqrt(1+X^2) atan(Y/sqrt(1+X^2)) - X atan X - Y atan Y ],  X = L, Y = 1.
Independent of lambert's contour integral and area cubature.

Usage: python3 strips.py > strips.csv   (pip install mpmath)
"""
import mpmath as mp

mp.mp.dps = 60


def c11(x, y):
    a = mp.log(mp.sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)))
    b = x * mp.sqrt(1 + y * y) * mp.atan(x / mp.sqrt(1 + y * y))
    c = y * mp.sqrt(1 + x * x) * mp.atan(y / mp.sqrt(1 + x * x))
    return 2 / (mp.pi * x * y) * (a + b + c - x * mp.atan(x) - y * mp.atan(y))


def main():
    print("L,factor")
    for e in range(0, 12):
        L = mp.mpf(10) ** e
        print(f"1e{e},{mp.nstr(c11(L, mp.mpf(1)), 20)}")


if __name__ == "__main__":
    main()
