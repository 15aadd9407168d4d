"""frf-modes' call from Python (analyse_modes, modal_assurance_criterion).
References: the frf-modes tool's summary JSON on the same file (the C++
tool), and the model's natural frequencies from frf-predict --modes (the
eigen-solution, no modal fit); for a roving test, the analytic modes of a
simply supported beam (tests/apps/make_roving_beam.py, plain Python) and
the tool's --mode-shapes output."""
import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, KR210, SOURCE_DIR, run_tool

POSTURES = DATA + '/calibration/postures_two.csv'


@pytest.fixture(scope='module')
def tap(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('modes')
    run_tool('frf-synth', '--robot', KR210, '--postures', POSTURES, '--directions', 'xx,yy,xy',
             '--noise-rel', '0.01', '--seed', '34', '--out', tmp / 'tap.csv')
    run_tool('frf-modes', '--measured', tmp / 'tap.csv', '--out', tmp / 'modes.csv', '--summary', tmp / 's.json')
    run_tool('frf-predict', '--robot', KR210, '--postures', POSTURES, '--modes', tmp / 'model_modes.csv',
             '--out', tmp / 'pred.csv')
    return tmp


def test_analyse_modes_equals_the_tool_and_the_model(tap):
    frfs = rm.read_frf_file(str(tap / 'tap.csv'))['frfs']
    poses = rm.analyse_modes(frfs, rm.estimate_noise(frfs, rm.NoiseOptions(global_modal_fit=True)))
    summary = json.loads((tap / 's.json').read_text())
    assert [p['pose_id'] for p in poses] == [p['pose_id'] for p in summary['postures']]
    model = {}
    with open(tap / 'model_modes.csv') as f:
        for row in csv.DictReader(f):
            model.setdefault(row['pose_id'], []).append(float(row['freq_hz']))
    for p, s in zip(poses, summary['postures']):
        ours = [m['freq_hz'] for m in p['tip_modes']]
        tool = [m['freq_hz'] for m in s['tip_modes']]
        assert ours == pytest.approx(tool, rel=1e-9)
        for f in ours:  # every fitted mode is a mode of the model
            assert min(abs(f - g) / g for g in model[p['pose_id']]) < 0.003
        for fit in p['fits']:
            assert fit['ok']
            for frf in fit['frfs']:
                assert frf['misfit_noise_sigmas'] < 1.5


def test_run_frf_synth_equals_the_tools_summary(tmp_path):
    """Issue #36 acceptance: frf-synth's JSON summary and FRF file and the
    Python call's (workflows::PrepareFrfSynth, RunFrfSynth) on the shipped
    robot with the tool's defaults (the two postures of the fixture above, to
    keep it fast)."""
    r = run_tool('frf-synth', '--robot', KR210, '--postures', POSTURES, '--out', tmp_path / 'tool.csv',
                 '--summary', tmp_path / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 'tool.json').read_text())
    run = rm.run_frf_synth(KR210, POSTURES, out=str(tmp_path / 'py.csv'))
    assert run['flagged'] == (r.returncode == 3)
    assert run['status'] == ('flagged' if r.returncode == 3 else 'ok')
    for key in ('tool', 'out', 'format', 'quantity', 'exit_code', 'warnings', 'robomach_version'):  # only the tool's
        tool.pop(key, None)
    assert run['summary'] == tool
    assert (tmp_path / 'py.csv').read_text() == (tmp_path / 'tool.csv').read_text()
    assert f"frf-synth: wrote {len(run['frfs'])} FRFs of {run['lines']} lines" in r.stderr
    assert run['sample_rate_hz'] == tool['sample_rate_hz']


def test_mac_of_known_vectors():
    a = np.array([[1, 0], [2, 1], [3, 0]], dtype=complex)
    mac = rm.modal_assurance_criterion(a, -2j * a[:, :1])
    assert mac[0, 0] == pytest.approx(1.0, abs=1e-14)
    assert mac[1, 0] == pytest.approx(4.0 / 14.0, abs=1e-14)


def test_bad_weights_are_refused():
    frfs = rm.FrfSet()
    with pytest.raises(ValueError, match='weights'):
        rm.analyse_modes(frfs, weights='uniform')


@pytest.fixture(scope='module')
def beam(tmp_path_factory):
    """make_roving_beam.py's 13-point roving-hammer test (1 % noise), and
    frf-modes --mode-shapes on it."""
    tmp = tmp_path_factory.mktemp('roving')
    subprocess.run([sys.executable, os.path.join(SOURCE_DIR, 'tests', 'apps', 'make_roving_beam.py'), str(tmp),
                    '0.01'], check=True, capture_output=True)
    run_tool('frf-modes', '--measured', tmp / 'beam.uff', '--out', tmp / 'modes.csv', '--mode-shapes',
             tmp / 'shapes.csv')
    return tmp


def test_a_roving_test_keeps_its_points_and_gives_the_tools_shapes(beam):
    """Issue #34: Python reads roving tests (keys with point numbers) and
    analyse_modes gives frf-modes' shapes, which match the beam's analytic
    ones (MAC >= 0.99, mass-normalised scale within 3 %)."""
    # Without keep_points a posture must hold one point pair (the tool-tip tools).
    with pytest.raises(ValueError, match='frf-modes'):
        rm.read_frf_file(str(beam / 'beam.uff'))
    frfs = rm.read_frf_file(str(beam / 'beam.uff'), keep_points=True)['frfs']
    keys = frfs.keys()
    assert len(keys) == 13
    assert all(len(k) == 5 for k in keys)
    assert sorted(k[4] for k in keys) == list(range(1, 14))  # the hammer roves over nodes 1..13
    assert {k[3] for k in keys} == {4}                        # the accelerometer at node 4
    assert keys[0] in frfs and frfs[keys[0]] is not None      # a 5-tuple key finds its FRF
    poses = rm.analyse_modes(frfs, rm.estimate_noise(frfs, rm.NoiseOptions(global_modal_fit=True)))
    assert len(poses) == 1 and len(poses[0]['fits']) == 1
    fit = poses[0]['fits'][0]
    shapes = fit['shapes']
    assert shapes is not None, fit.get('shapes_why_not')
    assert shapes['roving'] == 'excitation' and shapes['fixed_point'] == 4
    assert shapes['mass_normalised']
    points = shapes['points']
    freqs = [m['freq_hz'] for m in fit['modes']]
    phi = np.asarray(shapes['shapes'])
    assert phi.shape == (13, len(freqs))
    # The tool's --mode-shapes rows: the same numbers.
    tool = {}
    with open(beam / 'shapes.csv') as f:
        for r in csv.DictReader(f):
            tool[(int(r['mode']), int(r['point']))] = complex(float(r['shape_re']), float(r['shape_im']))
    tool_modes = sorted({m for m, _ in tool})
    assert len(tool_modes) == len(freqs)
    for j, m in enumerate(tool_modes):
        for i, p in enumerate(points):
            assert phi[i, j] == pytest.approx(tool[(m, p)], rel=1e-9, abs=1e-12)
    # The analytic beam (Blevins): every mode found, MAC and scale.
    ref = {}
    with open(beam / 'analytic.csv') as f:
        for r in csv.DictReader(f):
            e = ref.setdefault(int(r['mode']), [float(r['freq_hz']), {}])
            e[1][int(r['point'])] = float(r['phi_per_sqrt_kg'])
    for n, (fn, shape) in ref.items():
        j = int(np.argmin([abs(f - fn) for f in freqs]))
        assert freqs[j] == pytest.approx(fn, rel=0.005), n
        a = np.array([shape[p] for p in points], dtype=complex)
        b = phi[:, j]
        mac = rm.modal_assurance_criterion(a.reshape(-1, 1), b.reshape(-1, 1))[0, 0]
        assert mac >= 0.99, (n, mac)
        scale = abs(np.vdot(a, b) / np.vdot(a, a))
        assert scale == pytest.approx(1.0, abs=0.03), (n, scale)


def test_a_key_with_a_bad_direction_is_named():
    frfs = rm.FrfSet()
    with pytest.raises(ValueError, match="direction 'w': expected x, y or z"):
        frfs[('P1', 'w', 'x')]
    with pytest.raises(TypeError):
        frfs[('P1', 'x')]
