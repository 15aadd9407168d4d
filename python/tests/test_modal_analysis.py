"""frf-modes' call from Python (analyse_modes, modal_assurance_criterion).
References: the frf-modes tool's summary JSON on the same file (the C++
tool), and the model's natural frequencies from frf-predict --modes (the
eigen-solution, no modal fit)."""
import csv
import json

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, KR210, run_tool

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


def test_mac_of_known_vectors():
    a = np.array([[1, 0], [2, 1], [3, 0]], dtype=complex)
    mac = rm.modal_assurance_criterion(a, -2j * a[:, :1])
    assert mac[0, 0] == pytest.approx(1.0, abs=1e-14)
    assert mac[1, 0] == pytest.approx(4.0 / 14.0, abs=1e-14)


def test_bad_weights_are_refused():
    frfs = rm.FrfSet()
    with pytest.raises(ValueError, match='weights'):
        rm.analyse_modes(frfs, weights='uniform')
