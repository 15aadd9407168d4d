#!/usr/bin/env python3
"""Does a targeted plan give the band it promises? (issue #37 §5)

kq-identify --plan N --target-postures ... prints each target's expected
95 % half-width of the smallest ZOA critical depth (first order, at the
configured stiffnesses). This script simulates M campaigns of that plan with
fresh tracker noise (tracker-synth --plan-file, seeds 1..M), identifies each
(kq-identify), predicts the smallest critical depth at every target posture
with the identified stiffnesses (robomach.zoa_lobe_band) and compares the
campaigns' spread with the promise: 1.96 x the relative standard deviation
over the campaigns against the printed half-width, and how often the
prediction falls within the promised band around the truth.

tracker-synth simulates with the library's own model: this checks the
planner's variance formula against the identification's actual scatter, not
the physics (python/tests/coverage_sim.py does that with NumPy).

    PYTHONPATH=build/python python3 bench/plan_width_check.py [N] [M]
"""
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

import robomach as rm

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
APPS = os.path.join(ROOT, 'build', 'apps')
ROBOT = os.path.join(ROOT, 'config', 'kr210.yaml')
CUT = os.path.join(ROOT, 'config', 'cut_demo.yaml')
POSTURES = os.path.join(ROOT, 'config', 'postures_demo.csv')


def run(*args):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if r.returncode not in (0, 3):
        sys.exit(f'{args[0]} failed ({r.returncode}): {r.stderr}')
    return r.stderr


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
    m = int(sys.argv[2]) if len(sys.argv) > 2 else 60
    cfg = rm.load_robot_config(ROBOT)
    cut = rm.read_cut_file(CUT)
    targets = rm.read_posture_file(POSTURES, 6)
    with tempfile.TemporaryDirectory() as tmp:
        plan = os.path.join(tmp, 'plan.csv')
        err = run(os.path.join(APPS, 'kq-identify'), '--robot', ROBOT, '--plan', n, '--load-point-mm', '150,0,100',
                  '--target-mm', '0,120,50', '--target-postures', POSTURES, '--target-quantity', 'safe-depth',
                  '--cut', CUT, '--out', plan)
        line = next(x for x in err.splitlines() if 'expected 95 % half-width' in x)
        promised = {k: float(v) / 100 for k, v in re.findall(r'(P\d+) ±([0-9.]+) %', line.split('(worst')[0])}
        # The truth: the configured stiffnesses, which tracker-synth simulates.
        u_true = rm.ParameterUncertainty(
            [(f'kq{j + 1}_Nm_per_rad', cfg.parameters[f'kq{j + 1}_Nm_per_rad'], 'log') for j in range(6)],
            np.eye(6) * 1e-12, 'truth')
        truth = {p.id: rm.zoa_lobe_band(cfg, cut, u_true, p.q, method='first-order')['min_critical_depth_mm']
                 for p in targets}
        pred = {p.id: [] for p in targets}
        for seed in range(1, m + 1):
            camp = os.path.join(tmp, 'campaign.csv')
            unc = os.path.join(tmp, 'kq_unc.yaml')
            run(os.path.join(APPS, 'tracker-synth'), '--robot', ROBOT, '--plan-file', plan, '--seed', seed,
                '--out', camp)
            run(os.path.join(APPS, 'kq-identify'), '--robot', ROBOT, '--tracker', camp,
                '--out', os.path.join(tmp, 'kq.yaml'), '--uncertainty-out', unc)
            u = rm.read_parameter_uncertainty([unc])
            for p in targets:
                b = rm.zoa_lobe_band(cfg, cut, u, p.q, method='first-order')
                pred[p.id].append(b['min_critical_depth_mm'])
            print(f'\rcampaigns {seed}/{m}', end='', file=sys.stderr)
        print(file=sys.stderr)
    print(f'plan of {n} postures (load 150,0,100 mm, target 0,120,50 mm), {m} simulated campaigns')
    print('target  promised  measured 1.96 sd/truth  within promised band')
    for pid, hw in promised.items():
        d = np.array(pred[pid])
        rel = 1.96 * d.std(ddof=1) / truth[pid]
        inside = np.mean(np.abs(d / truth[pid] - 1) <= hw)
        print(f'{pid:6}  ±{100 * hw:5.1f} %   ±{100 * rel:5.1f} % (ratio {rel / hw:.2f})   {100 * inside:5.1f} %')
    print(f'a sample sd over {m} campaigns is within ±{100 * 1.96 / math.sqrt(2 * (m - 1)):.0f} % of the true one '
          f'(95 %)')


if __name__ == '__main__':
    main()
