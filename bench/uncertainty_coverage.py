#!/usr/bin/env python3
"""Full coverage run of issue #37 (the test, python/tests/test_uncertainty.py,
runs a smaller one): N simulated tracker campaigns with fresh noise, each
identified by robomach and predicted at three postures; how often the 95 %
intervals of the lowest mode's frequency and of the smallest ZOA critical
depth contain the NumPy truth (python/tests/coverage_sim.py).

    PYTHONPATH=build/python python3 bench/uncertainty_coverage.py [N] [seed] [samples]
"""
import math
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'python', 'tests'))
import numpy as np  # noqa: E402

import coverage_sim  # noqa: E402


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    samples = int(sys.argv[3]) if len(sys.argv) > 3 else 2000
    source = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
    t0 = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        res = coverage_sim.run_campaigns(n, seed, tmp, source, samples=samples)
    cov_f, cov_d, lines = coverage_sim.summary(res)
    for line in lines:
        print(line)
    k = len(cov_f)
    print(f'binomial 1-sigma of a coverage over {n} campaigns: {math.sqrt(0.95 * 0.05 / n):.3f}')
    z = (res['f1'] - res['f1_true']) / res['f1_sd']
    print(f'(estimate - truth) / std_dev of the lowest frequency: mean {z.mean():.3f}, std {z.std(ddof=1):.3f}')
    for name in ('f1', 'd'):
        methods, counts = np.unique(res[name + '_method'], return_counts=True)
        print(f'{name}: methods ' + ', '.join(f'{m} {c}' for m, c in zip(methods, counts)))
    print(f'mean relative half-width: frequency {np.mean((res["f1_hi"] - res["f1_lo"]) / 2 / res["f1"]):.4f}, '
          f'depth {np.mean((res["d_hi"] - res["d_lo"]) / 2 / res["d"]):.4f}')
    print(f'{k} predictions in {time.time() - t0:.0f} s')


if __name__ == '__main__':
    main()
