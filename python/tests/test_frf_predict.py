"""Tool-tip FRF prediction. The acceptance test: a ten-line script predicts
the FRF of config/kr210.yaml at a posture and it equals the frf-predict
tool's --out file to 1e-12. Then a second method (direct solve against modal
superposition) and the static limit."""
import csv
import os

import numpy as np
import pytest

import robomach as rm
from conftest import KR210, run_tool


def read_tool_csv(path, pose_id):
    """frf-predict's --out (docs/formats.md §3) parsed with Python's csv module."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith('#'))][1:]
    freq = sorted({float(r[3]) for r in rows if r[0] == pose_id})
    H = np.zeros((len(freq), 3, 3), complex)
    index = {f: i for i, f in enumerate(freq)}
    for pose, resp, exc, f, re, im in rows:
        if pose == pose_id:
            H[index[float(f)], 'xyz'.index(resp), 'xyz'.index(exc)] = complex(float(re), float(im))
    return np.array(freq), H


def test_module_comes_from_where_it_was_put():
    # Set by run_installed.py (ctest python.installed): the module must be the
    # one `cmake --install` wrote under the scratch prefix, not the build tree's.
    expected = os.environ.get('ROBOMACH_EXPECT_MODULE_DIR')
    if expected is None:
        pytest.skip('not run from an install prefix')
    assert os.path.dirname(os.path.realpath(rm.__file__)) == os.path.realpath(expected)


@pytest.mark.parametrize('method', ['modal', 'direct'])
def test_ten_line_script_equals_frf_predict(tmp, method):
    (tmp / 'p.csv').write_text('pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP7,20,-75,105,-10,35,60\n')
    (tmp / 'f.csv').write_text('freq_hz\n' + '\n'.join(repr(0.5 * k) for k in range(1, 1001)) + '\n')
    run_tool('frf-predict', '--robot', KR210, '--postures', tmp / 'p.csv', '--freq-file', tmp / 'f.csv',
             '--method', method, '--out', tmp / 'tool.csv')

    # --- the ten-line script ---------------------------------------------
    import numpy as np
    import robomach as rm
    model = rm.RobotConfig(KR210).build()
    pose = rm.read_posture_file(str(tmp / 'p.csv'), model.num_joints)[0]
    freq_hz = 0.5 * np.arange(1, 1001)
    H = model.predict_frf(pose.q, freq_hz, method=method)        # (1000, 3, 3) [m/N]
    rm.write_predicted_frf_csv(str(tmp / 'py.csv'), [(pose.id, freq_hz, H)])
    # ----------------------------------------------------------------------

    f_tool, H_tool = read_tool_csv(tmp / 'tool.csv', 'P7')
    np.testing.assert_array_equal(freq_hz, f_tool)
    # 1e-12 of each FRF's largest |H|: the acceptance figure (same library
    # code; the tool's file keeps 17 significant digits).
    scale = np.abs(H_tool).max(axis=0)
    assert np.all(np.abs(H - H_tool) <= 1e-12 * scale)
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()


def test_direct_and_modal_agree_and_the_static_limit():
    cfg = rm.RobotConfig(KR210, add=['tip_mass', 'joint_damping'])
    d = rm.PostureEvaluator(cfg.build()).evaluate(np.radians([-15, -80, 110, 30, 60, -20]))
    f = np.concatenate([[0.0], np.linspace(1, 400, 799)])
    Hm = d.receptance(f)
    Hd = rm.receptance(d, f, method='direct')
    # Two methods (modal superposition, complex modes if the damping is not
    # proportional; direct solve per line): 1e-8 of the peak, the round-off
    # of the eigen-decomposition at the lightly damped peaks.
    assert np.abs(Hm - Hd).max() <= 1e-8 * np.abs(Hd).max()
    # At 0 Hz the direct solve is K^-1: the static compliance to round-off.
    np.testing.assert_allclose(Hd[0].real, d.static_compliance, rtol=0,
                               atol=1e-12 * np.abs(d.static_compliance).max())
    with pytest.raises(ValueError, match="method 'exact'"):
        d.receptance(f, method='exact')


def test_threads_get_the_same_answer():
    """predict_frf releases the GIL; four threads on one shared model give
    the answer of one call each (no shared evaluator state)."""
    from concurrent.futures import ThreadPoolExecutor
    model = rm.RobotConfig(KR210).build()
    f = np.linspace(1, 300, 600)
    qs = [np.radians([10 * k, -80, 100, 5 * k, 40, -10 * k]) for k in range(4)]
    ref = [model.predict_frf(q, f) for q in qs]
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(lambda q: model.predict_frf(q, f), qs))
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)


def test_predict_frfs_is_frf_predicts_workflow(tmp):
    """predict_frfs: frf-predict's run in one call. Its FRFs written with
    write_predicted_frf_csv are the tool's --out byte for byte, and its status
    is the tool's exit code: a joint outside its limits and the wrist
    singularity (q5 = 0) flag the run (exit 3), with the posture file's line."""
    (tmp / 'p.csv').write_text('pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n'
                               'A,20,-75,105,-10,35,60\n'
                               'OUT,20,-75,105,-10,35,400\n'
                               'W,0,-90,90,0,0,0\n')
    r = run_tool('frf-predict', '--robot', KR210, '--postures', tmp / 'p.csv', '--fmax-hz', 100,
                 '--out', tmp / 'tool.csv', expect_rc=3)
    model = rm.RobotConfig(KR210).build()
    postures = rm.read_posture_file(str(tmp / 'p.csv'), model.num_joints)
    freq_hz = 0.625 * np.arange(1, 161)
    p = rm.predict_frfs(model, postures, freq_hz)
    rm.write_predicted_frf_csv(str(tmp / 'py.csv'), [(x['id'], freq_hz, x['H_m_per_N']) for x in p['postures']])
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    assert p['status'] == 'flagged'
    assert [x['id'] for x in p['postures']] == ['A', 'OUT', 'W']
    assert p['postures'][1]['joints_outside_limits'] == [5]
    assert len(p['findings']) == 2
    assert p['findings'][0].startswith('line 3: posture OUT: joint 6 at 400 deg is outside its limits')
    assert p['findings'][1].startswith('line 4: posture W is near a singularity')
    for f in p['findings']:  # the tool says the same, after the file name
        assert f.split(': ', 1)[1] in r.stderr
    ok = rm.predict_frfs(model, postures[:1], freq_hz, method='direct')
    assert ok['status'] == 'ok' and ok['findings'] == []
