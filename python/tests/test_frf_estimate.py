"""frf-estimate's call from Python (estimate_frf). References: hammer records
simulated in plain Python by tests/apps/make_hammer_records.py (a 3-DOF
chain integrated by Runge-Kutta, independent of robomach), the chain's
analytic receptance inv(K - w^2 M + i w C), and the frf-estimate tool on the
same records."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import robomach as rm
from conftest import SOURCE_DIR, run_tool, tool_path

# The chain of make_hammer_records.py: masses [kg], springs [N/m], dampers [N s/m].
M = np.diag([2.0, 1.5, 1.0])
k1, k2, k3 = 4e5, 6e5, 5e5
c1, c2, c3 = 150.0, 100.0, 60.0
K = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
C = np.array([[c1 + c2, -c2, 0.0], [-c2, c2 + c3, -c3], [0.0, -c3, c3]])


def chain_receptance(f_hz):
    """H[i, 0](f): displacement of mass i per force on mass 1 [m/N]."""
    out = []
    for f in f_hz:
        w = 2 * np.pi * f
        out.append(np.linalg.solve(K - w * w * M + 1j * w * C, np.array([1.0, 0.0, 0.0])))
    return np.array(out)


@pytest.fixture(scope='module')
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp('hammer')
    subprocess.run([sys.executable, os.path.join(SOURCE_DIR, 'tests', 'apps', 'make_hammer_records.py'), str(d)],
                   check=True, timeout=300)
    return d


def test_estimate_equals_the_chains_dynamics(records):
    r = rm.estimate_frf([str(records / 'hits.csv')])
    assert r['status'] == 'ok', r['findings']
    assert r['averages'] == 3
    statuses = {h['id']: h['status'] for h in r['summary']['hits']}
    assert statuses == {'1': 'accepted', '2': 'accepted', '3': 'accepted', '4': 'double hit', '5': 'overload'}
    frfs = r['frfs']
    assert sorted(frfs.keys()) == [('P1', 'x', 'x'), ('P1', 'y', 'x')]
    # tip_x is mass 1's displacement (Hxx); acc_y is mass 3's acceleration,
    # returned as receptance (Hyx).
    hxx, hyx = frfs['P1', 'x', 'x'], frfs['P1', 'y', 'x']
    f = np.asarray(hxx.freq_hz)
    ref = chain_receptance(f)
    # 1. The recorded force is the half-sine sampled at about two points per
    # 2 ms pulse (no anti-aliasing filter in the simulation), so its
    # spectrum, and with it each FRF's level, is off by several per cent
    # (the sampled impulse of hit 1 is 11 % above the integral). The ratio
    # of two responses to the same hits does not depend on the force:
    # sum |F|^2 H_3 / sum |F|^2 H_1 = H_3 / H_1. It is compared with the
    # chain's where both responses are within 40 dB of their peak: there the
    # sensor noise of the records (0.01 m/s^2 and 2e-9 m rms per sample, 512
    # samples, 3 hits) is at most about 1 % of the signal per line, so 5 %
    # is a bound with margin; further down (above about 250 Hz, where the
    # third mass moves 60 dB less) the noise floor takes over, as it would
    # on a real tap test. The coherence of 3 averages is biased towards 1
    # and cannot stand in for that floor.
    h1, h3 = np.asarray(hxx.receptance), np.asarray(hyx.receptance)
    use = ((f >= 20) & (np.abs(ref[:, 0]) > 0.01 * np.abs(ref[:, 0]).max())
           & (np.abs(ref[:, 2]) > 0.01 * np.abs(ref[:, 2]).max()))
    assert use.sum() > 50
    err = np.abs((h3[use] / h1[use]) / (ref[use, 2] / ref[use, 0]) - 1)
    assert np.median(err) < 0.01, np.median(err)
    assert err.max() < 0.05, (err.max(), f[use][np.argmax(err)])
    # 2. The resonances: the estimate's peaks of |Hxx| lie on the line of the
    # chain's peak or the next one (line spacing 2 Hz).
    mag, mag_ref = np.abs(np.asarray(hxx.receptance)), np.abs(ref[:, 0])
    peaks = [k for k in range(1, len(f) - 1) if mag_ref[k] > mag_ref[k - 1] and mag_ref[k] > mag_ref[k + 1]]
    assert len(peaks) == 3, f[peaks]
    for k in peaks:
        window = slice(k - 3, k + 4)
        assert abs(int(np.argmax(mag[window])) - 3) <= 1, (f[k], f[window][np.argmax(mag[window])])


def test_equals_the_tool(records, tmp_path):
    if tool_path('frf-estimate') is None:
        pytest.skip('frf-estimate is not built')
    out = tmp_path / 'frf.csv'
    summary = tmp_path / 'summary.json'
    run_tool('frf-estimate', records / 'hits.csv', '--out', out, '--summary', summary)
    tool = rm.read_frf_csv(str(out))['frfs']
    py = rm.estimate_frf([str(records / 'hits.csv')])
    for key in tool.keys():
        # The tool's CSV keeps 11 significant digits (formats.md §3).
        a, b = np.asarray(tool[key].receptance), np.asarray(py['frfs'][key].receptance)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max()
    s = json.load(open(summary))
    for k in ('hits', 'channels', 'averages', 'sample_rate_hz', 'block_samples', 'warnings'):
        assert s[k] == py['summary'][k], k


def test_few_hits_are_flagged_and_every_rejected_hit_gives_no_estimate(records):
    r = rm.estimate_frf([str(records / 'hit_a.csv'), str(records / 'hit_b.csv')], estimator='h2')
    assert r['status'] == 'flagged'
    assert any('fewer than min_hits 3' in f for f in r['findings']), r['findings']
    none = rm.estimate_frf([str(records / 'hits.csv')], force_range_N=50.0)
    assert none['status'] == 'no_estimate' and none['frfs'] is None
    # Every hit reaches the 50 N range; hit 4 is named a double hit first.
    assert {h['id']: h['status'] for h in none['summary']['hits']} == {
        '1': 'overload', '2': 'overload', '3': 'overload', '4': 'double hit', '5': 'overload'}


def test_response_range_rejects_the_hits_that_reach_it_as_the_tool_does(records, tmp_path):
    # The accelerometer's peak per hit, read from the file with numpy: a range
    # just under the largest peak of hits 1-3 makes that hit an overload and
    # leaves the others accepted.
    lines = [x for x in open(records / 'hits.csv') if not x.startswith('#')]
    names = lines[0].strip().split(',')
    rows = np.array([[float(v) for v in x.split(',')] for x in lines[1:]])
    hit, acc = rows[:, names.index('hit')], rows[:, names.index('acc_y_m_per_s2')]
    peaks = {h: np.abs(acc[hit == h]).max() for h in (1, 2, 3)}
    loudest = max(peaks, key=peaks.get)
    limit = 0.999 * peaks[loudest]
    assert sorted(peaks.values())[1] < limit, 'the two largest peaks are too close for this test'
    r = rm.estimate_frf([str(records / 'hits.csv')], min_hits=2, response_range={'acc_y': limit})
    statuses = {h['id']: h['status'] for h in r['summary']['hits']}
    expected = {str(h): ('overload' if h == loudest else 'accepted') for h in (1, 2, 3)}
    assert {k: statuses[k] for k in expected} == expected and r['averages'] == 2
    if tool_path('frf-estimate') is not None:
        summary = tmp_path / 'summary.json'
        run_tool('frf-estimate', records / 'hits.csv', '--min-hits', 2, '--out', tmp_path / 'frf.csv', '--summary',
                 summary, '--response-range', f'acc_y={limit!r}')
        assert json.load(open(summary))['hits'] == r['summary']['hits']
    with pytest.raises(ValueError, match="acc=50: no response channel 'acc'"):
        rm.estimate_frf([str(records / 'hits.csv')], response_range={'acc': 50.0})
    with pytest.raises(ValueError, match='tip_x=-1: expected a finite range >= 0'):
        rm.estimate_frf([str(records / 'hits.csv')], response_range={'tip_x': -1.0})


def test_bad_input_raises_with_the_message(records):
    with pytest.raises(ValueError, match="acc=z: no response channel 'acc'"):
        rm.estimate_frf([str(records / 'hits.csv')], directions={'acc': 'z'})
    with pytest.raises(ValueError, match="tip_x: direction 'w': expected x, y or z"):
        rm.estimate_frf([str(records / 'hits.csv')], directions={'tip_x': 'w'})
    with pytest.raises(FileNotFoundError):
        rm.estimate_frf([str(records / 'no_such.csv')])
    with pytest.raises(rm.InputError, match=r'broken.csv:9:4'):
        rm.estimate_frf([str(records / 'broken.csv')])
