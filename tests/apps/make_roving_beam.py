#!/usr/bin/env python3
"""A roving-hammer test of a beam for frf-modes (issue #34 §2), made
independently of robomach (plain Python, no numpy, its own UFF58 writer).

A simply supported steel beam, 0.8 m, 40 x 12 mm, bent about its thin side:
omega_n = (n pi/L)^2 sqrt(EI/(rho A)), mass-normalised shapes
phi_n(x) = sqrt(2/(rho A L)) sin(n pi x/L) (Blevins, Formulas for natural
frequency and mode shape, Table 8-1). Modal damping zeta_n = 0.015 + 0.002 n,
modes 1-12 summed (those above the band act as its upper residual).

The accelerometer stays at node 4 (x = 4 L/14, +Z); the hammer roves over
nodes 1..13 (x_j = j L/14), node 4 included (the driving point). As a
measurement gives it: accelerance in (m/s^2)/N, 0.5 Hz lines from 5 Hz to
1.15 f_5 (modes 1-5 in the band), complex Gaussian noise of NOISE_REL of |A|
plus an additive floor of 1e-4 of the largest |A| (seeded).

Writes OUTDIR/beam.uff (13 dataset-58 records, response node 4, reference
node j; record 6 direction codes 3) and OUTDIR/analytic.csv
(mode,freq_hz,damping_ratio,point,phi_per_sqrt_kg).

usage: make_roving_beam.py OUTDIR [NOISE_REL]
"""
import cmath
import math
import os
import random
import sys

L, E, RHO, B, H = 0.8, 2.1e11, 7850.0, 0.04, 0.012
EI = E * B * H ** 3 / 12.0
RHOA = RHO * B * H
POINTS = list(range(1, 14))
FIXED = 4


def omega(n):
    return (n * math.pi / L) ** 2 * math.sqrt(EI / RHOA)


def phi(n, x):
    return math.sqrt(2.0 / (RHOA * L)) * math.sin(n * math.pi * x / L)


def x_of(node):
    return node * L / 14.0


def zeta(n):
    return 0.015 + 0.002 * n


def e13(v):
    return '%13.5E' % v


def record(resp_node, ref_node, f0, df, values):
    """One ASCII dataset 58 record: complex single (ordinate type 5), even abscissa."""
    lines = ['    -1', '    58',
             'roving hammer test, beam'.ljust(80), 'NONE'.ljust(80), '28-Nov-26 10:00:00'.ljust(80),
             'NONE'.ljust(80), 'NONE'.ljust(80)]
    lines.append('%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d' % (4, 0, 0, 0, 'BEAM', resp_node, 3, 'BEAM', ref_node, 3))
    lines.append('%10d%10d%10d%13.5E%13.5E%13.5E' % (5, len(values), 1, f0, df, 0.0))
    lines.append('%10d%5d%5d%5d %-20s %-20s' % (18, 0, 0, 0, 'Frequency', 'Hz'))
    lines.append('%10d%5d%5d%5d %-20s %-20s' % (12, 1, 0, 0, 'Acceleration', 'm/s^2'))
    lines.append('%10d%5d%5d%5d %-20s %-20s' % (13, 0, 1, 0, 'Force', 'N'))
    lines.append('%10d%5d%5d%5d %-20s %-20s' % (0, 0, 0, 0, 'NONE', 'NONE'))
    flat = []
    for v in values:
        flat += [v.real, v.imag]
    for k in range(0, len(flat), 6):
        lines.append(''.join(e13(v) for v in flat[k:k + 6]))
    lines.append('    -1')
    return '\n'.join(lines) + '\n'


def main():
    out = sys.argv[1]
    noise_rel = float(sys.argv[2]) if len(sys.argv) > 2 else 0.01
    os.makedirs(out, exist_ok=True)
    rng = random.Random(3434)
    f5 = omega(5) / (2 * math.pi)
    df, f0 = 0.5, 5.0
    n_lines = int((1.15 * f5 - f0) / df) + 1
    freqs = [f0 + k * df for k in range(n_lines)]
    xr = x_of(FIXED)
    clean = {}
    for j in POINTS:
        xj = x_of(j)
        row = []
        for f in freqs:
            w = 2 * math.pi * f
            h = 0j
            for n in range(1, 13):
                wn = omega(n)
                h += phi(n, xj) * phi(n, xr) / (wn * wn - w * w + 2j * zeta(n) * wn * w)
            row.append(-w * w * h)  # accelerance
        clean[j] = row
    floor = 1e-4 * max(abs(v) for row in clean.values() for v in row)
    text = ''
    for j in POINTS:
        noisy = []
        for a in clean[j]:
            g = complex(rng.gauss(0, 1), rng.gauss(0, 1)) / math.sqrt(2)
            g2 = complex(rng.gauss(0, 1), rng.gauss(0, 1)) / math.sqrt(2)
            noisy.append(a * (1 + noise_rel * g) + floor * g2)
        text += record(FIXED, j, f0, df, noisy)
    with open(os.path.join(out, 'beam.uff'), 'w') as f:
        f.write(text)
    with open(os.path.join(out, 'analytic.csv'), 'w') as f:
        f.write('mode,freq_hz,damping_ratio,point,phi_per_sqrt_kg\n')
        for n in range(1, 6):
            for j in POINTS:
                f.write('%d,%.9g,%.6g,%d,%.9g\n' % (n, omega(n) / (2 * math.pi), zeta(n), j, phi(n, x_of(j))))


if __name__ == '__main__':
    main()
