#!/usr/bin/env python3
"""Derives the fully symmetric quadrature rules of cpp/element/symmetric_quadrature.cpp.

A fully symmetric rule on a simplex is a sum of orbits: every permutation of a barycentric
tuple (the centroid; (a, a, a, 1-3a); (a, a, 1/2-a, 1/2-a); (a, a, b, 1-2a-b); and, on the
triangle, (a, a, 1-2a) and (a, b, 1-a-b)), each orbit with one weight. A rule exact to degree d
needs as many free parameters as there are polynomials of degree <= d invariant under the
simplex's symmetries (Molien series 1/((1-t^2)(1-t^3)) on the triangle, 1/((1-t^2)(1-t^3)(1-t^4))
on the tetrahedron); the orbit structures below have exactly that many. The moment equations
(every monomial of degree <= d integrated exactly) are solved by least squares from random
starts until a root has every weight positive and every point strictly inside, then polished
by Gauss-Newton in 60-digit arithmetic, so that the printed values are the root rounded to
double. Run it to regenerate the table (it prints C++); the unit tests check every rule's
exactness independently.

    /usr/bin/python3 scripts/symmetric-quadrature.py

It needs Debian's python3-scipy and python3-mpmath; neither the build nor the tests run it.
"""
import itertools
from math import factorial

import mpmath
import numpy as np
from scipy.optimize import least_squares

# (shape, degree, orbit counts, seed). Tetrahedron orbits: centroid, S31, S22, S211;
# triangle orbits: centroid, S21, S111. Points: tetrahedron 1, 4, 6, 12; triangle 1, 3, 6.
RULES = [
    ("tetrahedron", 5, (0, 2, 1, 0), 0),  # 14 points (the collapsed rule: 27)
    ("tetrahedron", 7, (1, 1, 1, 2), 0),  # 35 points (64)
    # ("triangle", 8, (1, 3, 1), 0) finds 16 points (25): not used, see the header.
]

PARAMETERS = {"tetrahedron": [0, 1, 1, 2], "triangle": [0, 1, 2]}


def base_tuple(shape, kind, p, one):
    half = one / 2
    if shape == "tetrahedron":
        if kind == 0:
            return (one / 4,) * 4
        if kind == 1:
            return (p[0], p[0], p[0], one - 3 * p[0])
        if kind == 2:
            return (p[0], p[0], half - p[0], half - p[0])
        return (p[0], p[0], p[1], one - 2 * p[0] - p[1])
    if kind == 0:
        return (one / 3,) * 3
    if kind == 1:
        return (p[0], p[0], one - 2 * p[0])
    return (p[0], p[1], one - p[0] - p[1])


def orbits(shape, counts, x, one=1.0):
    """(weight, base tuple) per orbit from the unknowns x."""
    out, i = [], 0
    for kind, count in enumerate(counts):
        for _ in range(count):
            n = PARAMETERS[shape][kind]
            out.append((x[i], base_tuple(shape, kind, x[i + 1:i + 1 + n], one)))
            i += 1 + n
    return out


def points(orbit_list):
    pts, wts = [], []
    for w, b in orbit_list:
        for perm in sorted(set(itertools.permutations(b))):
            pts.append(perm[1:])  # Cartesian coordinates: the last barycentrics
            wts.append(w)
    return pts, wts


def monomials(dim, degree):
    return [m for m in itertools.product(range(degree + 1), repeat=dim) if sum(m) <= degree]


def exact(m, one=1.0):
    """Integral of x^i y^j (z^k) over the unit simplex."""
    num = 1
    for e in m:
        num *= factorial(e)
    return one * num / factorial(sum(m) + len(m))


def residual(shape, counts, degree, x, one=1.0, power=pow):
    pts, wts = points(orbits(shape, counts, x, one))
    mons = monomials(len(pts[0]), degree)
    out = []
    for m in mons:
        s = 0 * one
        for p, w in zip(pts, wts):
            term = w
            for c, e in zip(p, m):
                term = term * power(c, e)
            s += term
        out.append(s - exact(m, one))
    return out


def random_start(shape, counts, rng):
    x = []
    for kind, count in enumerate(counts):
        for _ in range(count):
            x.append(rng.uniform(0.002, 0.05))
            if PARAMETERS[shape][kind] == 1:
                x.append(rng.uniform(0.0, 0.33 if shape == "tetrahedron" else 0.5))
            elif PARAMETERS[shape][kind] == 2:
                a = rng.uniform(0.0, 0.5)
                x += [a, rng.uniform(0.0, 1.0 - 2.0 * a)] if shape == "tetrahedron" else list(
                    rng.dirichlet([1, 1, 1])[:2])
    return np.array(x)


def solve(shape, degree, counts, seed):
    rng = np.random.default_rng(seed)
    for _ in range(20000):
        fit = least_squares(lambda x: residual(shape, counts, degree, x),
                            random_start(shape, counts, rng), xtol=1e-15, ftol=1e-15,
                            gtol=1e-15, max_nfev=2000)
        pts, wts = points(orbits(shape, counts, fit.x))
        bary = [1.0 - sum(p) for p in pts] + [c for p in pts for c in p]
        if (max(abs(r) for r in residual(shape, counts, degree, fit.x)) < 1e-14
                and min(wts) > 0.0 and min(bary) > 1e-6):
            return polish(shape, degree, counts, fit.x)
    raise RuntimeError(f"no positive interior rule of degree {degree} on the {shape}")


def polish(shape, degree, counts, x):
    mpmath.mp.dps = 60
    one = mpmath.mpf(1)
    x = mpmath.matrix([mpmath.mpf(float(v)) for v in x])
    for _ in range(12):
        r = mpmath.matrix(residual(shape, counts, degree, x, one, mpmath.power))
        jac = mpmath.matrix(len(r), len(x))
        for j in range(len(x)):
            h = mpmath.mpf(10)**-35
            xh = x.copy()
            xh[j] += h
            rh = mpmath.matrix(residual(shape, counts, degree, xh, one, mpmath.power))
            for i in range(len(r)):
                jac[i, j] = (rh[i] - r[i]) / h
        step = mpmath.lu_solve(jac.T * jac, jac.T * r)
        x -= step
    worst = max(abs(v) for v in residual(shape, counts, degree, x, one, mpmath.power))
    assert worst < mpmath.mpf(10)**-25, worst
    return orbits(shape, counts, x, one)


def main():
    for shape, degree, counts, seed in RULES:
        orbit_list = solve(shape, degree, counts, seed)
        pts, _ = points(orbit_list)
        print(f"// {shape}, degree {degree}, {len(pts)} points")
        for w, b in orbit_list:
            values = ", ".join(mpmath.nstr(v, 17, min_fixed=-1, max_fixed=1) for v in b[:-1])
            print(f"    {{{mpmath.nstr(w, 17)}, {{{values}}}}},")


if __name__ == "__main__":
    main()
