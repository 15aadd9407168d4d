#!/usr/bin/env python3
"""Overhead of one posture evaluation called from Python (issue #21 item 4).

Times PostureEvaluator.evaluate from Python with timeit (best of several
repeats) in CPU time (time.process_time, what Google Benchmark's "CPU"
column counts: on a shared machine the wall time also counts the other
processes' time slices) and, when the C++
bench_posture is given, runs its BM_EvaluatePosture_* cases on the same
model and postures; prints the per-call µs of both and the difference, the
cost of crossing into Python (target < 2 µs). Speed targets are measured by
Google Benchmark under bench/; this script only sets the Python side beside
it.

  PYTHONPATH=build/python python3 bench/python_posture_overhead.py \
      --bench build/bench/bench_posture
"""
import argparse
import json
import os
import subprocess
import sys
import time
import timeit

import numpy as np

import robomach as rm

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))


def python_us(fn, number, repeat):
    return min(timeit.repeat(fn, timer=time.process_time, number=number, repeat=repeat)) / number * 1e6


def cpp_us(bench):
    r = subprocess.run([bench, '--benchmark_filter=BM_EvaluatePosture_', '--benchmark_format=json',
                        '--benchmark_repetitions=5', '--benchmark_report_aggregates_only=true'],
                       capture_output=True, text=True, check=True)
    out = {}
    for b in json.loads(r.stdout)['benchmarks']:
        if b.get('aggregate_name') == 'median':
            scale = {'ns': 1e-3, 'us': 1.0, 'ms': 1e3}[b['time_unit']]
            out[b['run_name']] = b['cpu_time'] * scale
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--bench', help='path of the built bench_posture (C++ reference)')
    ap.add_argument('--number', type=int, default=20000)
    ap.add_argument('--repeat', type=int, default=7)
    a = ap.parse_args()

    model = rm.RobotConfig(os.path.join(ROOT, 'config', 'kr210.yaml')).build()
    ev = rm.PostureEvaluator(model)
    q = np.array([0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0])  # bench_posture's P1
    # Each Python call beside the C++ case that does the same work: a new
    # PostureDynamics per call with the same options (evaluate returns one
    # by value). Not BM_EvaluatePosture_MqJModes: since issue #23 that case
    # reuses its output and skips pose, cond J, static compliance, modal
    # masses and damping ratios, which cartesian=False still computes.
    cases = {
        'BM_EvaluatePosture_MqJModesByValue': lambda: ev.evaluate(q, cartesian=False),
        'BM_EvaluatePosture_Everything': lambda: ev.evaluate(q),
    }
    py = {name: python_us(fn, a.number, a.repeat) for name, fn in cases.items()}
    cpp = cpp_us(a.bench) if a.bench else {}
    print('CPU time per call')
    print(f'{"case":34s} {"python [us]":>12s} {"C++ [us]":>10s} {"overhead [us]":>14s}')
    for name in cases:
        c = cpp.get(name)
        line = f'{name:34s} {py[name]:12.3f}'
        line += f' {c:10.3f} {py[name] - c:14.3f}' if c is not None else f' {"-":>10s} {"-":>14s}'
        print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
