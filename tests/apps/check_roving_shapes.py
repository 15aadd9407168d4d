#!/usr/bin/env python3
"""Checks frf-modes' --mode-shapes output of make_roving_beam.py's test
against the beam's analytic modes (plain Python): every analytic mode found
within 0.5 % in frequency and 5 % in damping, its shape's MAC with the
analytic shape at least 0.99 (issue #34 acceptance, at 1 % noise), the
shapes mass-normalised (the test has a driving point) with a scale within
3 % of the analytic one, and MAC between different modes below 0.1.

usage: check_roving_shapes.py SHAPES_CSV ANALYTIC_CSV
"""
import csv
import sys


def mac(a, b):
    num = abs(sum(x * y.conjugate() for x, y in zip(a, b))) ** 2
    den = sum(abs(x) ** 2 for x in a) * sum(abs(y) ** 2 for y in b)
    return num / den


def main():
    shapes, analytic = sys.argv[1], sys.argv[2]
    fitted = {}  # mode -> (freq, zeta, {point: complex}, unit)
    with open(shapes) as f:
        for r in csv.DictReader(f):
            m = int(r['mode'])
            e = fitted.setdefault(m, [float(r['freq_hz']), float(r['damping_ratio']), {}, r['shape_unit']])
            e[2][int(r['point'])] = complex(float(r['shape_re']), float(r['shape_im']))
    ref = {}
    with open(analytic) as f:
        for r in csv.DictReader(f):
            m = int(r['mode'])
            e = ref.setdefault(m, [float(r['freq_hz']), float(r['damping_ratio']), {}])
            e[2][int(r['point'])] = float(r['phi_per_sqrt_kg'])
    failures = []
    matched = {}
    for n, (fn, zn, phi) in sorted(ref.items()):
        best = min(fitted.items(), key=lambda kv: abs(kv[1][0] - fn)) if fitted else None
        if best is None or abs(best[1][0] - fn) > 0.005 * fn:
            failures.append('mode %d (%.2f Hz): not found within 0.5 %%' % (n, fn))
            continue
        m, (f_fit, z_fit, sh, unit) = best
        matched[n] = m
        if abs(z_fit - zn) > 0.05 * zn:
            failures.append('mode %d: damping ratio %.5f, analytic %.5f' % (n, z_fit, zn))
        pts = sorted(phi)
        if sorted(sh) != pts:
            failures.append('mode %d: points %s, expected %s' % (n, sorted(sh), pts))
            continue
        a = [complex(phi[p]) for p in pts]
        b = [sh[p] for p in pts]
        value = mac(a, b)
        if value < 0.99:
            failures.append('mode %d: MAC %.4f < 0.99' % (n, value))
        if unit != '1/sqrt(kg)':
            failures.append('mode %d: shape unit %s, expected 1/sqrt(kg) (a driving point is in the test)' % (n, unit))
        # Least-squares scale of the fitted shape onto the analytic one (the
        # sign of a shape is arbitrary).
        scale = abs(sum(x.conjugate() * y for x, y in zip(a, b)) / sum(abs(x) ** 2 for x in a))
        if abs(scale - 1.0) > 0.03:
            failures.append('mode %d: mass-normalised scale %.4f of the analytic shape' % (n, scale))
        print('mode %d: %.3f Hz (analytic %.3f), zeta %.5f (%.5f), MAC %.5f, scale %.4f' %
              (n, f_fit, fn, z_fit, zn, value, scale))
    for n1, m1 in matched.items():
        for n2, m2 in matched.items():
            if n1 < n2:
                pts = sorted(fitted[m1][2])
                v = mac([fitted[m1][2][p] for p in pts], [fitted[m2][2][p] for p in pts])
                if v >= 0.1:
                    failures.append('modes %d and %d: cross MAC %.3f >= 0.1' % (n1, n2, v))
    if failures:
        print('\n'.join(failures))
        return 1
    print('all %d analytic modes found; shapes match' % len(ref))
    return 0


if __name__ == '__main__':
    sys.exit(main())
