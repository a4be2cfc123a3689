#!/usr/bin/env python3
"""Richardson extrapolation of a quantity measured on three grids:

  python3 tools/richardson.py h1 f1 h2 f2 h3 f3      (h1 > h2 > h3, any unit)

Assumes f(h) = f0 + C h^p and solves the three equations for the observed order p (by bisection
on (f2 - f1)/(f3 - f2) = (h1^p - h2^p)/(h2^p - h3^p), which allows unequal refinement ratios), then
prints p, f0 and the remaining error estimate f0 - f3. Where the increments do not shrink
fast enough for any p in (0.01, 10) (not yet in the asymptotic range) it says so and prints no f0.

docs/results.md (S4) uses it on the wheel's `hub_height_final` at h = 13.3, 10, 6.7 mm:
  python3 tools/richardson.py 13.333 0.463 10 0.488 6.667 0.509
"""
import sys


def richardson(h, f):
    (h1, h2, h3), (f1, f2, f3) = h, f
    if f3 == f2:
        return None
    target = (f2 - f1) / (f3 - f2)

    def g(p):
        return target - (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p)

    lo, hi = 0.01, 10.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    c = (f3 - f2) / (h3 ** p - h2 ** p)
    return p, f3 - c * h3 ** p


def main():
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    v = [float(x) for x in sys.argv[1:]]
    h, f = (v[0], v[2], v[4]), (v[1], v[3], v[5])
    print(f"increments: {f[1] - f[0]:+.4g} ({h[0]:g} -> {h[1]:g}), {f[2] - f[1]:+.4g} ({h[1]:g} -> {h[2]:g})")
    r = richardson(h, f)
    if r is None:
        print("no order p in (0.01, 10) fits: the sequence is not in the asymptotic range; no extrapolation")
        return
    p, f0 = r
    print(f"observed order p = {p:.3g}; extrapolated f0 = {f0:.4g} (f0 - f3 = {f0 - f[2]:+.3g})")


if __name__ == "__main__":
    main()
