"""Posture evaluation: the matrices and modes returned as NumPy arrays.
References: frf-predict's --summary JSON and --modes table at the same
postures (the C++ tool's output), and analytic identities checked with
NumPy's own linear algebra (generalised eigenproblem, static compliance)."""
import csv
import json
import os

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, KR210, SOURCE_DIR, run_tool

# Same library code on the same inputs (the postures are read by the same
# reader); JSON and the CSV keep 17 significant digits, so agreement is
# exact up to instruction selection (FMA contraction): 1e-12 relative.
REL = 1e-12

POSTURES = 'pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-90,90,0,45,0\nP2,30,-60,100,20,-50,70\n'


def close(a, b, rel=REL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    scale = np.max(np.abs(b))
    np.testing.assert_allclose(a, b, rtol=0, atol=rel * scale)


@pytest.fixture(scope='module')
def tool_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('posture')
    (tmp / 'p.csv').write_text(POSTURES)
    run_tool('frf-predict', '--robot', KR210, '--postures', tmp / 'p.csv', '--out', tmp / 'h.csv',
             '--summary', tmp / 's.json', '--modes', tmp / 'modes.csv', '--fmax-hz', '2')
    summary = json.loads((tmp / 's.json').read_text())
    with open(tmp / 'modes.csv') as f:
        modes = list(csv.DictReader(f))
    return tmp, summary, modes


def test_matrices_equal_the_tools_summary(tool_run):
    tmp, summary, _ = tool_run
    model = rm.RobotConfig(KR210).build()
    ev = rm.PostureEvaluator(model)
    for pose, ref in zip(rm.read_posture_file(str(tmp / 'p.csv'), model.num_joints), summary['postures']):
        d = ev.evaluate(pose.q)
        assert ref['pose_id'] == pose.id
        for name in ('M_q', 'K_q', 'C_q'):
            close(getattr(d, name), ref[name])
        close(d.J, ref['J_BT'])
        close(d.X_BT[:3, 3], ref['tcp_position_m'])
        close(d.X_BT[:3, :3], ref['tcp_rotation'])
        close(d.static_compliance, ref['static_compliance_m_per_N'])
        for name in ('M_X', 'K_X', 'C_X'):
            close(getattr(d, name), ref['cartesian'][name])
        assert d.jacobian_condition == pytest.approx(ref['jacobian_condition'], rel=REL)
        assert len(d.modes) == len(ref['modes'])
        close(d.freq_hz, [m['freq_hz'] for m in ref['modes']])
        close(d.damping_ratio, [m['damping_ratio'] for m in ref['modes']])
        close(d.modal_mass_kg, [m['modal_mass_kg'] for m in ref['modes']])
        close(d.shapes_T, [m['shape_T'] for m in ref['modes']])


def test_modes_equal_the_tools_modal_table(tool_run):
    tmp, _, rows = tool_run
    model = rm.RobotConfig(KR210).build()
    for pose in rm.read_posture_file(str(tmp / 'p.csv'), 6):
        d = model.evaluate(pose.q)
        mine = [r for r in rows if r['pose_id'] == pose.id]
        close(d.freq_hz, [float(r['freq_hz']) for r in mine])
        close(d.modal_mass_kg, [float(r['modal_mass_kg']) for r in mine])
        close(d.shapes_T, [[float(r['ux']), float(r['uy']), float(r['uz'])] for r in mine])


def test_modes_solve_the_generalised_eigenproblem():
    d = rm.RobotConfig(KR210, add=['tip_mass']).build().evaluate(np.radians([10, -70, 95, 15, 40, -30]))
    M, K, phi = d.M, d.K, d.phi
    assert M.shape == (d.M.shape[0],) * 2 and phi.shape == (M.shape[0], len(d.modes))
    w2 = (2 * np.pi * d.freq_hz) ** 2
    # Mass normalisation and K phi = w^2 M phi; 1e-9: the eigensolver's
    # residual on matrices whose entries span ~10 decades (kg·m² to N·m/rad).
    np.testing.assert_allclose(phi.T @ M @ phi, np.eye(len(w2)), atol=1e-9)
    np.testing.assert_allclose(phi.T @ K @ phi, np.diag(w2), rtol=0, atol=1e-9 * w2.max())
    # NumPy's own eigenvalues of M^-1 K; relative 1e-9 (conditioning of M^-1 K).
    ref = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    np.testing.assert_allclose(w2, ref, rtol=1e-9)
    # Static compliance B K^-1 B^T (NumPy's LU against the library's LDLT:
    # 1e-9, the conditioning of K); Rayleigh damping C = alpha K + beta M
    # (two products and a sum: 1e-12 of the largest entry).
    np.testing.assert_allclose(d.static_compliance, d.B @ np.linalg.solve(K, d.B.T), rtol=1e-9,
                               atol=1e-12 * np.abs(d.static_compliance).max())
    p = rm.RobotConfig(KR210).parameters
    np.testing.assert_allclose(d.C - d.C_extra, p['alpha_s'] * K + p['beta_per_s'] * M, rtol=1e-12,
                               atol=1e-12 * np.abs(d.C).max())


def test_options_and_errors():
    model = rm.RobotConfig(KR210).build()
    ev = rm.PostureEvaluator(model)
    d = ev.evaluate(np.zeros(6) + 0.3, cartesian=False, modes=False)
    assert np.isnan(d.M_X).all() and d.modes == [] and d.freq_hz.shape == (0,)
    with pytest.raises(ValueError):
        ev.evaluate(np.zeros(5))
    with pytest.raises(ValueError):
        ev.evaluate(np.array([0, 0, np.nan, 0, 0, 0.0]))
    # Without the real modes, 'modal' superposes the complex modes: the
    # same receptance to round-off of the two decompositions (1e-9 of |H|).
    f = np.array([5.0, 10.5, 40.0])
    h0, h1 = d.receptance(f), ev.evaluate(d.q).receptance(f)
    assert np.abs(h0 - h1).max() <= 1e-9 * np.abs(h1).max()


# Issue #35: evaluate took degrees silently. The angles' unit is in the
# argument's name (q_rad, or q_deg=), and angles that fit the other unit far
# better are a robomach.UnitWarning, by the posture files' rule (exit 3 in
# the tools): more than a turn in q_rad; all within 2 pi, with fractions,
# in q_deg.
DEMO_DEG = np.array([0.0, -90.0, 90.0, 0.0, 45.0, 0.0])


def test_angles_in_degrees_by_name_equal_radians():
    ev = rm.PostureEvaluator(rm.RobotConfig(KR210).build())
    # The conversion is one multiplication by pi/180, as numpy.radians does.
    close(ev.evaluate(q_deg=DEMO_DEG).K_X, ev.evaluate(np.radians(DEMO_DEG)).K_X, rel=1e-15)
    close(ev.evaluate(q_rad=np.radians(DEMO_DEG)).q, np.radians(DEMO_DEG), rel=1e-15)
    close(rm.Posture('P1', q_deg=DEMO_DEG).q, np.radians(DEMO_DEG), rel=1e-15)


def test_degrees_passed_as_radians_are_named():
    model = rm.RobotConfig(KR210).build()
    ev = rm.PostureEvaluator(model)
    msg = r'evaluate: q_rad has an angle of 90 rad = 5157 deg, more than a turn: these look like degrees'
    for call in (lambda: ev.evaluate(DEMO_DEG), lambda: model.evaluate(DEMO_DEG)):
        with pytest.warns(rm.UnitWarning, match=msg):
            call()
    with pytest.warns(rm.UnitWarning, match='predict_frf: q_rad has an angle of 90 rad'):
        model.predict_frf(DEMO_DEG, np.array([10.0]))
    with pytest.warns(rm.UnitWarning, match='Posture: q_rad'):
        rm.Posture('P1', DEMO_DEG)
    assert issubclass(rm.UnitWarning, UserWarning)
    # Radians passed as degrees (the demo posture in radians: 1.5708 ...).
    with pytest.warns(rm.UnitWarning, match=r'every angle of q_deg is within 2 pi = 6.28 \(largest 1.571\).*'
                                             r'these look like radians'):
        ev.evaluate(q_deg=np.radians(DEMO_DEG))


def test_plausible_angles_do_not_warn_and_one_unit_is_required():
    ev = rm.PostureEvaluator(rm.RobotConfig(KR210).build())
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        ev.evaluate(np.radians(DEMO_DEG))
        ev.evaluate(q_deg=DEMO_DEG)
        ev.evaluate(q_deg=np.array([0.0, -2.0, 3.0, 0.0, 1.0, 0.0]))  # small whole degrees
        ev.evaluate(np.full(6, 0.3))
    with pytest.raises(ValueError, match='give the joint angles once, as q_rad'):
        ev.evaluate()
    with pytest.raises(ValueError, match='not both'):
        ev.evaluate(np.zeros(6), q_deg=np.zeros(6))


def test_read_posture_file_warns_of_radians_under_deg_headers(tmp_path):
    # The posture files' rule, as frf-predict's exit 3: every angle within
    # 2 pi and some fractional under _deg headers are radians.
    ok = tmp_path / 'deg.csv'
    ok.write_text(POSTURES)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        degrees = rm.read_posture_file(str(ok), 6)
    rad = tmp_path / 'rad.csv'
    rad.write_text('pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\n'
                   + ''.join(f'{p.id},' + ','.join(f'{x:.4f}' for x in p.q) + '\n' for p in degrees))
    with pytest.warns(rm.UnitWarning, match=r'rad\.csv.*radians'):
        rm.read_posture_file(str(rad), 6)


def test_read_posture_file_takes_the_joint_count_from_the_file(tmp_path):
    # num_joints is optional (a new user had to know it before reading the
    # file): None reads as many joints as the file's q columns, the same
    # postures as with the robot's count; a wrong count is still an error.
    ok = tmp_path / 'deg.csv'
    ok.write_text(POSTURES)
    given = rm.read_posture_file(str(ok), 6)
    inferred = rm.read_posture_file(str(ok))
    assert [p.id for p in inferred] == [p.id for p in given]
    for a, b in zip(inferred, given):
        assert np.array_equal(a.q, b.q)
    three = tmp_path / 'three.csv'
    three.write_text('pose_id,q1_deg,q3_rad,q2_deg\nA,10,0.5,20\n')
    (p,) = rm.read_posture_file(str(three))
    assert np.allclose(p.q, [np.radians(10), np.radians(20), 0.5])
    gap = tmp_path / 'gap.csv'
    gap.write_text('pose_id,q1_deg,q3_deg\nA,10,20\n')
    with pytest.raises(rm.InputError, match=r'gap\.csv:1: missing column q2_deg \(or q2_rad\): the file has columns up to q3'):
        rm.read_posture_file(str(gap))
    with pytest.raises(rm.InputError, match=r'up to q6 but the robot has 5 joints'):
        rm.read_posture_file(str(ok), 5)
    with pytest.raises(ValueError, match='num_joints'):
        rm.read_posture_file(str(ok), 0)


@pytest.mark.parametrize('case', ['defaults', 'uncertainty_and_set'])
def test_run_frf_predict_equals_the_tools_summary(tmp_path, case):
    """Issue #36 acceptance: frf-predict's JSON summary and the Python call's
    result (workflows::RunFrfPredict) on the shipped defaults, and with a
    parameter set, an effect added and the modes' intervals from a
    parameter-uncertainty file; the predicted receptance equals the tool's
    CSV."""
    postures = os.path.join(SOURCE_DIR, 'config', 'postures_demo.csv')
    args = ['--robot', KR210, '--postures', postures, '--out', tmp_path / 'h.csv', '--summary', tmp_path / 't.json',
            '--fmax-hz', '50']
    kwargs = {}
    if case == 'uncertainty_and_set':
        unc = os.path.join(DATA, 'uncertainty', 'kq_demo.yaml')
        args += ['--set', 'm6_kg=31', '--add', 'tip_mass', '--uncertainty', unc, '--samples', '200']
        kwargs = dict(sets={'m6_kg': 31.0}, adds=['tip_mass'], uncertainty=[unc], intervals=True, samples=200)
    r = run_tool('frf-predict', *args, expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 't.json').read_text())
    run = rm.run_frf_predict(KR210, postures, fmax_hz=50, **kwargs)
    assert run['flagged'] == (r.returncode == 3)
    for key in ('tool', 'exit_code', 'robomach_version', 'warnings'):
        tool.pop(key, None)
    assert run['summary'] == tool
    if case == 'uncertainty_and_set':
        assert 'mode_intervals' in run['summary']['postures'][0]
        assert run['summary']['parameters']['m6_kg'] == 31.0
        # As the tool refuses --uncertainty without an output that carries it.
        with pytest.raises(ValueError, match=r'intervals=True'):
            rm.run_frf_predict(KR210, postures, fmax_hz=50, uncertainty=[unc])
    with open(tmp_path / 'h.csv') as f:
        rows = [row for row in csv.DictReader(line for line in f if not line.startswith('#'))
                if row['response'] == 'y' and row['excitation'] == 'y']
    p0 = run['predictions'][0]
    mine = [row for row in rows if row['pose_id'] == p0['pose_id']]
    assert len(mine) == len(p0['freq_hz'])
    h = np.array([complex(float(x['re']), float(x['im'])) for x in mine])
    close(np.abs(h), np.abs(p0['receptance'][:, 1, 1]), rel=1e-9)
