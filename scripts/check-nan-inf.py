#!/usr/bin/env python3
"""NaN and inf in every reader (issue #22 item 1): each numeric field of the
shipped configs and test files is replaced, one at a time, by "nan", "inf"
and "-inf"; the tool that reads the file must exit 65 and name the file and
the line ("file:line"). Prints one line per failure and a summary per file.

  scripts/check-nan-inf.py BUILD_DIR [--max-fields N] [--only SUBSTRING]

Files referenced by a mutated file (a URDF next to a robot YAML) are copied
beside it. Not a ctest: it runs the tools a few hundred times (minutes).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SRC = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.abspath(sys.argv[1])
MAX_FIELDS = int(sys.argv[sys.argv.index('--max-fields') + 1]) if '--max-fields' in sys.argv else 40
ONLY = sys.argv[sys.argv.index('--only') + 1] if '--only' in sys.argv else ''
C, T, D = SRC + '/config', SRC + '/tests/data', SRC + '/tests/data'

# (file, extra files to copy beside it, command with {f} for the mutated file and {o} for an output folder)
CASES = [
    (C + '/kr210.yaml', [C + '/kr210_r2700_2.urdf'],
     'frf-predict --robot {f} --postures ' + C + '/postures_demo.csv --fmax-hz 5 --out {o}/frf.csv'),
    (C + '/kr210_dh.yaml', [],
     'frf-predict --robot {f} --postures ' + C + '/postures_demo.csv --fmax-hz 5 --out {o}/frf.csv'),
    (C + '/kr210_r2700_2.urdf', [C + '/kr210.yaml'],
     'frf-predict --robot {d}/kr210.yaml --postures ' + C + '/postures_demo.csv --fmax-hz 5 --out {o}/frf.csv'),
    (C + '/postures_demo.csv', [],
     'frf-predict --robot ' + C + '/kr210.yaml --postures {f} --fmax-hz 5 --out {o}/frf.csv'),
    (C + '/cut_demo.yaml', [],
     'stability-lobes --modal-table ' + T + '/stability/modal_benchmark.csv --cut {f} --method zoa --out {o}/l.csv'),
    (T + '/stability/modal_benchmark.csv', [],
     'stability-lobes --modal-table {f} --cut ' + T + '/stability/cut_benchmark_slot.yaml --method zoa --out {o}/l.csv'),
    (T + '/kr210_P1_receptance.csv', [],
     'stability-lobes --frf {f} --cut ' + C + '/cut_demo.yaml --method zoa --out {o}/l.csv'),
    (T + '/kr210_P1_receptance.uff', [],
     'stability-lobes --frf {f} --cut ' + C + '/cut_demo.yaml --method zoa --out {o}/l.csv'),
    (C + '/region_demo.yaml', [],
     'stability-map --robot ' + C + '/kr210.yaml --cut ' + C + '/cut_demo.yaml --region {f} --out {o}/m.csv'),
    (T + '/stability/path_demo.csv', [],
     'stability-map --robot ' + C + '/kr210.yaml --cut ' + C + '/cut_demo.yaml --region ' + C + '/region_demo.yaml --path {f} --out {o}/m.csv'),
    (C + '/demo/hammer.csv', [],
     'model-audit --robot ' + C + '/kr210.yaml --postures ' + C + '/demo/postures.csv --measured {f} --report {o}/r'),
    (C + '/demo/postures.csv', [],
     'model-audit --robot ' + C + '/kr210.yaml --postures {f} --measured ' + C + '/demo/hammer.csv --report {o}/r'),
    (T + '/tracker_campaign.csv', [],
     'kq-identify --robot ' + C + '/kr210.yaml --tracker {f} --out {o}/kq.yaml'),
    (C + '/drilling/q235_hss.csv', [],
     'drill-force-fit --table {f} --drill ' + C + '/drilling/drill_5mm.yaml --out {o}/m.yaml'),
    (D + '/drilling/predict_rows.csv', [],
     'drill-force-fit --table ' + C + '/drilling/q235_hss.csv --drill ' + C + '/drilling/drill_5mm.yaml --out {o}/m.yaml'
     ' --predict {f} --predictions {o}/p.csv'),
    (C + '/drilling/drill_5mm.yaml', [],
     'drill-sim --robot ' + C + '/drilling/planar3r.yaml --drill {f} --material ' + C + '/drilling/q235.yaml'
     ' --controller pid --out {o}/r.csv'),
    (C + '/drilling/planar3r.yaml', [],
     'drill-sim --robot {f} --drill ' + C + '/drilling/drill_5mm.yaml --material ' + C + '/drilling/q235.yaml'
     ' --controller pid --out {o}/r.csv'),
    # Only `material:` is read; std_dev, fit and table are a record of the fit.
    (C + '/drilling/q235.yaml', [],
     'drill-sim --robot ' + C + '/drilling/planar3r.yaml --drill ' + C + '/drilling/drill_5mm.yaml --material {f}'
     ' --controller pid --out {o}/r.csv', 'std_dev:'),
    (C + '/machine/dmu80p.yaml', [],
     'axis-acquire --machine {f} --counts ' + T + '/machine/counts_tiny.csv --out {o}/a.csv'),
    (T + '/machine/counts_tiny.csv', [],
     'axis-acquire --machine ' + C + '/machine/dmu80p.yaml --counts {f} --out {o}/a.csv'),
    (C + '/machine/dmu80p_comp.mpf', [],
     'axis-acquire --machine ' + C + '/machine/dmu80p.yaml --counts ' + T + '/machine/counts_tiny.csv'
     ' --compensation {f} --out {o}/a.csv'),
    (C + '/machine/dmu80p_temperature.csv', [],
     'axis-acquire --machine ' + C + '/machine/dmu80p.yaml --counts ' + T + '/machine/counts_tiny.csv'
     ' --compensation ' + C + '/machine/dmu80p_comp.mpf --temperature {f} --out {o}/a.csv'),
    (T + '/machine/cone_arc.csv', [],
     'axis-acquire --machine ' + C + '/machine/dmu80p.yaml --counts ' + T + '/machine/counts_tiny.csv'
     ' --program {f} --out {o}/a.csv'),
    (T + '/machine/x_runs_hand.csv', [],
     'axis-accuracy --runs {f} --out {o}/iso.json'),
    (T + '/polishing/plane_80x50.yaml', [],
     'polish-plan --surface {f} --process ' + T + '/polishing/process_small_margin.yaml --pattern cycloid'
     ' --guides parallel --target-removal-um 2 --path {o}/p.csv'),
    (T + '/polishing/process_small_margin.yaml', [],
     'polish-plan --surface ' + T + '/polishing/plane_80x50.yaml --process {f} --pattern cycloid'
     ' --guides parallel --target-removal-um 2 --path {o}/p.csv'),
    (T + '/polishing/path_straight.csv', [],
     'polish-sim --surface ' + T + '/polishing/plane_80x50.yaml --process ' + T + '/polishing/process_small_margin.yaml'
     ' --path {f} --removal {o}/r.csv'),
]

# Hammer records (frf-estimate) are made by the plain-Python simulation of
# the frf-estimate smoke tests.
REC = tempfile.mkdtemp(prefix='naninf_records')
import atexit
atexit.register(shutil.rmtree, REC, True)
subprocess.run(['python3', SRC + '/tests/apps/make_hammer_records.py', REC], check=True, capture_output=True)
CASES.append((REC + '/hit_a.csv', [], 'frf-estimate {f} ' + REC + '/hit_b.csv --out {o}/frf.csv'))

NUM = r'[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?'


def fields(path):
    """(line index, start, end) of each number that is a data value."""
    out = []
    lines = open(path, errors='replace').read().split('\n')
    ext = os.path.splitext(path)[1]
    header_seen = False
    for i, l in enumerate(lines):
        s = l.split('#', 1)[0] if ext in ('.yaml', '.csv', '.mpf') else l
        if ext == '.csv':
            if not s.strip():
                continue
            if not header_seen:
                header_seen = True
                continue
        if ext == '.mpf' and s.lstrip().startswith(';'):
            continue
        if ext == '.urdf' and s.lstrip().startswith('<?'):
            continue  # the XML declaration
        if ext == '.yaml':
            m = re.match(r'^\s*(?:- )?[A-Za-z_][\w]*:\s*', s)
            if not m and not s.strip().startswith(('-', '[')):
                continue
        for m in re.finditer(NUM, s):
            a, b = m.start(), m.end()
            if a > 0 and s[a - 1].isalnum() or s[a - 1:a] == '_':
                continue  # part of a name (AX1, joint_3)
            if ext == '.urdf' and s[:a].count('"') % 2 == 0:
                continue  # URDF: attribute values only (not comments)
            if ext == '.mpf' and s[a - 1:a] != '=':
                continue  # Siemens tables: values follow '=' (not indices, CHANDATA(1))
            if b < len(s) and (s[b].isalpha() or s[b] == '_'):
                continue
            out.append((i, a, b))
    return lines, out


def pick(items, n):
    if len(items) <= n:
        return items
    step = len(items) / n
    return [items[int(k * step)] for k in range(n)]


def main():
    bad = 0
    for case in CASES:
        path, extra, cmd = case[:3]
        if ONLY and ONLY not in path:
            continue
        lines, fs = fields(path)
        if len(case) > 3:  # fields before the line starting with case[3] only
            stop = next(i for i, l in enumerate(lines) if l.startswith(case[3]))
            fs = [x for x in fs if x[0] < stop]
        fs = pick(fs, MAX_FIELDS)
        failures = 0
        for (i, a, b) in fs:
            for text in ('nan', 'inf', '-inf'):
                d = tempfile.mkdtemp(prefix='naninf')
                try:
                    for e in extra:
                        shutil.copy(e, d)
                    f = os.path.join(d, os.path.basename(path))
                    mutated = list(lines)
                    mutated[i] = lines[i][:a] + text + lines[i][b:]
                    open(f, 'w').write('\n'.join(mutated))
                    os.makedirs(d + '/out')
                    argv = cmd.format(f=f, o=d + '/out', d=d).split()
                    argv[0] = os.path.join(BUILD, 'apps', argv[0])
                    try:
                        r = subprocess.run(argv, capture_output=True, text=True, timeout=120)
                        rc, err = r.returncode, r.stderr
                    except subprocess.TimeoutExpired:
                        rc, err = 'timeout', ''
                    name = os.path.basename(path)
                    located = re.search(re.escape(name) + r':\d+', err) is not None
                    if rc != 65 or not located:
                        failures += 1
                        print('FAIL %s:%d field %r -> %s: exit %s; %s' %
                              (name, i + 1, lines[i][a:b], text, rc, (err.strip().splitlines() or [''])[-1][:240]))
                finally:
                    shutil.rmtree(d, ignore_errors=True)
        bad += failures
        print('%-40s %3d fields x 3: %d failures' % (os.path.relpath(path, SRC), len(fs), failures), flush=True)
    sys.exit(1 if bad else 0)


main()
