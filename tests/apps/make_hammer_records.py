#!/usr/bin/env python3
"""Hammer records for the frf-estimate smoke tests, made independently of
robomach (plain Python, no numpy): a 3-DOF chain ground-k1-m1-k2-m2-k3-m3
struck on m1 with a 2 ms half-sine (a soft tip), integrated by classical
Runge-Kutta at 1/16 of the sample interval, sampled at 1024 Hz for 0.5 s
per hit, with seeded sensor noise. Five hits: 1-3 good, 4 a double hit
(rebound 15 ms later at 40 %), 5 a hard hit that clips the accelerometer at
+-90 m/s^2 (hits 1-3 peak at 53-77 m/s^2).

Writes to OUTDIR: hits.csv (hit column; tip_x_m = displacement of m1,
acc_y_m_per_s2 = acceleration of m3), hit_a.csv and hit_b.csv (hits 1 and
2, one file each), broken.csv (hits.csv with a NaN at line 9, column 4),
short.csv (four good hits of 96 samples, 94 ms: the 42 Hz mode, decay time
0.09 s, is still ringing at the end).

usage: make_hammer_records.py OUTDIR
"""
import math
import os
import random
import sys

M = [2.0, 1.5, 1.0]                 # kg
K = [4e5, 6e5, 5e5]                 # N/m
C = [150.0, 100.0, 60.0]            # N s/m
FS = 1024.0                         # Hz
N = 512                             # samples per hit
SUB = 16                            # integration steps per sample
PULSE = 0.002                       # s


def accel(x, v, f):
    """Accelerations of the chain for positions x, velocities v, force f on m1."""
    k1, k2, k3 = K
    c1, c2, c3 = C
    s1 = -k1 * x[0] - c1 * v[0] + k2 * (x[1] - x[0]) + c2 * (v[1] - v[0]) + f
    s2 = -k2 * (x[1] - x[0]) - c2 * (v[1] - v[0]) + k3 * (x[2] - x[1]) + c3 * (v[2] - v[1])
    s3 = -k3 * (x[2] - x[1]) - c3 * (v[2] - v[1])
    return [s1 / M[0], s2 / M[1], s3 / M[2]]


def force(t, hit):
    v = 0.0
    for start, peak in hit:
        if start <= t <= start + PULSE:
            v += peak * math.sin(math.pi * (t - start) / PULSE)
    return v


def simulate(hit, rng, clip=None, samples=N):
    h = 1.0 / (FS * SUB)
    x = [0.0, 0.0, 0.0]
    v = [0.0, 0.0, 0.0]
    rows = []
    for k in range(samples):
        t = k / FS
        f = force(t, hit)
        a = accel(x, v, f)
        acc = a[2] + rng.gauss(0.0, 0.01)
        if clip is not None:
            acc = max(-clip, min(clip, acc))
        rows.append((t, f + rng.gauss(0.0, 0.05), x[0] + rng.gauss(0.0, 2e-9), acc))
        for s in range(SUB):
            ts = t + s * h

            def deriv(xx, vv, tt):
                return vv, accel(xx, vv, force(tt, hit))

            k1x, k1v = deriv(x, v, ts)
            k2x, k2v = deriv([x[i] + 0.5 * h * k1x[i] for i in range(3)],
                             [v[i] + 0.5 * h * k1v[i] for i in range(3)], ts + 0.5 * h)
            k3x, k3v = deriv([x[i] + 0.5 * h * k2x[i] for i in range(3)],
                             [v[i] + 0.5 * h * k2v[i] for i in range(3)], ts + 0.5 * h)
            k4x, k4v = deriv([x[i] + h * k3x[i] for i in range(3)],
                             [v[i] + h * k3v[i] for i in range(3)], ts + h)
            x = [x[i] + h / 6 * (k1x[i] + 2 * k2x[i] + 2 * k3x[i] + k4x[i]) for i in range(3)]
            v = [v[i] + h / 6 * (k1v[i] + 2 * k2v[i] + 2 * k3v[i] + k4v[i]) for i in range(3)]
    return rows


def fmt(rows, hit_id=None):
    out = []
    for t, f, x, a in rows:
        cells = ([hit_id] if hit_id is not None else []) + ["%.7f" % t, "%.6g" % f, "%.6g" % x, "%.6g" % a]
        out.append(",".join(cells))
    return out


def main():
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    rng = random.Random(2026)
    hits = [
        ("1", [(0.020, 180.0)], None),
        ("2", [(0.031, 220.0)], None),
        ("3", [(0.017, 150.0)], None),
        ("4", [(0.022, 200.0), (0.037, 80.0)], None),
        ("5", [(0.025, 600.0)], 90.0),
    ]
    lines = ["# smoke-test hammer records (tests/apps/make_hammer_records.py)",
             "hit,time_s,force_N,tip_x_m,acc_y_m_per_s2"]
    sims = {}
    for hid, pulses, clip in hits:
        sims[hid] = simulate(pulses, rng, clip)
        lines += fmt(sims[hid], hid)
    with open(os.path.join(outdir, "hits.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")
    for name, hid in (("hit_a.csv", "1"), ("hit_b.csv", "2")):
        with open(os.path.join(outdir, name), "w") as f:
            f.write("\n".join(["time_s,force_N,tip_x_m,acc_y_m_per_s2"] + fmt(sims[hid])) + "\n")
    broken = list(lines)
    cells = broken[8].split(",")  # line 9 of the file
    cells[3] = "nan"
    broken[8] = ",".join(cells)
    with open(os.path.join(outdir, "broken.csv"), "w") as f:
        f.write("\n".join(broken) + "\n")
    short = ["hit,time_s,force_N,tip_x_m,acc_y_m_per_s2"]
    for hid, t0 in (("a", 0.010), ("b", 0.012), ("c", 0.011), ("d", 0.013)):
        short += fmt(simulate([(t0, 200.0)], rng, samples=96), hid)
    with open(os.path.join(outdir, "short.csv"), "w") as f:
        f.write("\n".join(short) + "\n")


if __name__ == "__main__":
    main()
