"""Calibration against hammer FRFs and joint-stiffness identification from a
load test. References: the frf-calibrate and kq-identify tools' summary
JSON on the same inputs (the C++ tools), and the true values behind the
data, which other code made (frf-synth's hammer data from a model with m6
+10 % and d6 -5 %; tests/data/tracker_campaign.csv from tracker-synth, its
truth in the header)."""
import json
import os
import re

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, KR210, run_tool

POSTURES = os.path.join(DATA, 'calibration', 'postures_two.csv')
TRUTH = {'m6_kg': 31.955, 'd6_m': 0.5225, 'kq3_Nm_per_rad': 4.2895e6}
FREE = ['kq3_Nm_per_rad', 'm6_kg', 'd6_m']
# The same library calls on the same data (Ceres single-threaded, central
# numeric differences): the tool and Python agree to round-off; 1e-10 of the
# value leaves room for a different instruction selection (FMA) only.
REL = 1e-10


@pytest.fixture(scope='module')
def hammer(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('calibration')
    run_tool('frf-synth', '--robot', KR210, '--postures', POSTURES, '--out', tmp / 'hammer.csv',
             '--set', f'm6_kg={TRUTH["m6_kg"]}', '--set', f'd6_m={TRUTH["d6_m"]}', '--noise-rel', '0.01',
             '--seed', '5', '--coherence')
    args = ['--robot', KR210, '--postures', POSTURES, '--measured', tmp / 'hammer.csv', '--only-free']
    for f in FREE:
        args += ['--free', f]
    run_tool('frf-calibrate', *args, '--out', tmp / 'cal.yaml', '--report', tmp / 'report')
    return tmp, json.loads((tmp / 'report' / 'summary.json').read_text())


def test_calibrate_equals_frf_calibrate_and_finds_the_truth(hammer):
    tmp, summary = hammer
    cfg = rm.RobotConfig(KR210)
    postures = {p.id: p.q for p in rm.read_posture_file(POSTURES, cfg.num_joints)}
    read = rm.read_frf_csv(str(tmp / 'hammer.csv'))
    noise = rm.estimate_noise(read['frfs'], rm.NoiseOptions(averages=read['averages']))
    data = rm.usable_data(read['frfs'], noise)
    result = rm.calibrate(cfg, postures, data, free_parameters=FREE)

    assert result.status == summary['status'] == 'converged'
    tool = {p['name']: p for p in summary['parameters']}
    assert [e.name for e in result.estimates] == FREE
    for e in result.estimates:
        assert e.value == pytest.approx(tool[e.name]['value'], rel=REL)
        # The covariance is a product of numeric derivatives (central
        # differences): it repeats less tightly than the values, 1e-6.
        assert e.std_dev == pytest.approx(tool[e.name]['std_dev'], rel=1e-6)
        assert e.unit == tool[e.name]['unit'] and e.stage == tool[e.name]['stage']
        # The truth within 3 sigma (0.3 % false alarm per parameter; the data's seed is fixed).
        assert abs(e.value - TRUTH[e.name]) < 3 * e.std_dev, e
    # A sum over 8000 residual pairs at parameters equal to REL: 1e-9.
    assert result.misfit_final == pytest.approx(summary['misfit']['calibrated'], rel=1e-9)
    assert result.misfit_final < result.misfit_start
    assert result.parameters['m6_kg'] == result.estimates[1].value
    # The calibrated config written by the tool reads back with the same values.
    written = rm.RobotConfig(str(tmp / 'cal.yaml'))
    for name in FREE:
        assert written.get(name) == pytest.approx(result.parameters[name], rel=REL)
    # The tool's verdict (it exited 0, so ok) and its rms in noise units.
    verdict = rm.judge_calibration(result, data)
    assert verdict['status'] == 'ok' and verdict['findings'] == summary['misfit']['flags'] == []
    assert verdict['rms_per_residual_in_noise_units'] == pytest.approx(
        summary['misfit']['rms_per_residual_in_noise_units'], rel=1e-9)
    # Data the model cannot represent (the measured FRFs 1.5 times larger at
    # every line: no mass or tool length does that without moving the
    # modes): calibrated, the model misses them by far more than the noise.
    scaled = rm.FrfSet()
    for k, f in data.items():
        scaled[k] = rm.Frf(f.freq_hz, 1.5 * f.receptance, f.coherence).with_noise(1.5 * f.noise_sigma)
    poor = rm.calibrate(cfg, postures, scaled, free_parameters=FREE)
    bad = rm.judge_calibration(poor, scaled)
    assert bad['status'] == 'flagged'
    assert any('misses the data by' in m for m in bad['findings']), bad['findings']
    assert bad['rms_per_residual_in_noise_units'] > 1.3


def test_calibration_uncertainty_equals_frf_calibrate_uncertainty_out(hammer, tmp_path):
    """Issue #37: result.uncertainty() is what frf-calibrate --uncertainty-out
    writes (same fit, same covariance), on the log scale; the file reads back."""
    tmp, _ = hammer
    out = tmp_path / 'cal_unc.yaml'
    args = ['--robot', KR210, '--postures', POSTURES, '--measured', tmp / 'hammer.csv', '--only-free']
    for f in FREE:
        args += ['--free', f]
    run_tool('frf-calibrate', *args, '--out', tmp_path / 'cal.yaml', '--report', tmp_path / 'report',
             '--uncertainty-out', out)
    cfg = rm.RobotConfig(KR210)
    postures = {p.id: p.q for p in rm.read_posture_file(POSTURES, cfg.num_joints)}
    read = rm.read_frf_csv(str(tmp / 'hammer.csv'))
    data = rm.usable_data(read['frfs'], rm.estimate_noise(read['frfs'], rm.NoiseOptions(averages=read['averages'])))
    result = rm.calibrate(cfg, postures, data, free_parameters=FREE)
    u, left_out = result.uncertainty()
    assert left_out == []
    assert u.names == FREE
    cov = np.asarray(result.covariance)
    for i, e in enumerate(result.estimates):
        assert np.sqrt(cov[i, i]) == pytest.approx(e.std_dev, rel=1e-12)
    written = rm.read_parameter_uncertainty([str(out)])
    assert written.names == u.names
    assert np.allclose(written.values, u.values, rtol=1e-10)
    # Numeric derivatives repeat to about 1e-6 (as the std_dev above).
    assert np.allclose(written.covariance, u.covariance, rtol=1e-5, atol=0)


def test_calibrate_rejects_unknown_parameters_and_postures(hammer):
    tmp, _ = hammer
    cfg = rm.RobotConfig(KR210)
    frfs = rm.read_frf_csv(str(tmp / 'hammer.csv'))['frfs']
    postures = {p.id: p.q for p in rm.read_posture_file(POSTURES, 6)}
    with pytest.raises(ValueError, match='m7_kg'):
        rm.calibrate(cfg, postures, frfs, free_parameters=['m7_kg'])
    with pytest.raises(ValueError):
        rm.calibrate(cfg, {'P1': postures['P1']}, frfs)  # P2 measured, not given
    with pytest.raises(ValueError, match="objective"):
        rm.calibrate(cfg, postures, frfs, objective='best')


def test_identify_joint_stiffness_equals_kq_identify(tmp):
    tracker = os.path.join(DATA, 'tracker_campaign.csv')
    run_tool('kq-identify', '--robot', KR210, '--tracker', tracker, '--summary', tmp / 'kq.json',
             '--out', tmp / 'kq.yaml', expect_rc=3)  # 3: joint 6 weakly determined
    tool = json.loads((tmp / 'kq.json').read_text())

    model = rm.RobotConfig(KR210).build()
    cases = rm.read_tracker_file(tracker, model.num_joints)
    r = rm.identify_joint_stiffness(model, cases, tracker_noise_m=1e-5)  # the tool's --noise-mm 0.01

    assert r.status == tool['status'] == 'converged' and r.num_cases == tool['num_cases'] == len(cases)
    np.testing.assert_allclose(r.joint_stiffness, tool['joint_stiffness_Nm_per_rad'], rtol=REL)
    np.testing.assert_allclose(r.std_dev, tool['std_dev_Nm_per_rad'], rtol=1e-9)  # covariance: 1e-9
    assert r.determination == tool['determination']
    assert r.advice == tool['advice'] and r.flagged
    # The truth of the synthetic campaign (its header, written by tracker-synth) within 3 sigma.
    truth = [float(re.search(rf'truth_kq{j}_Nm_per_rad: ([0-9.e+]+)', open(tracker).read()).group(1))
             for j in range(1, 7)]
    assert np.all(np.abs(r.joint_stiffness - truth) < 3 * r.std_dev)


def test_load_case_from_python_and_bad_options():
    model = rm.RobotConfig(KR210).build()
    c = rm.LoadCase('C1', np.radians([0, -90, 90, 0, 45, 0]), np.array([0, 0, -500.0]), np.zeros(3))
    assert c.p_load_tip_m is None and c.force_N[2] == -500.0
    with pytest.raises(ValueError, match="loss 'lts'"):
        rm.identify_joint_stiffness(model, [c], loss='lts')
    with pytest.raises(ValueError):
        rm.identify_joint_stiffness(model, [])


@pytest.mark.parametrize('offsets_mm, rc', [([], 3), (['--load-point-mm', '150,0,0', '--target-mm', '0,120,0'], 0)])
def test_plan_load_tests_equals_kq_identify_plan_byte_for_byte(tmp, offsets_mm, rc):
    # kq-identify --plan on the TCP (exit 3: a force at the TCP has no moment
    # about joint 6's axis, so joint 6 is not determined) and off the axis.
    r = run_tool('kq-identify', '--robot', KR210, '--plan', 4, '--seed', 3, '--out', tmp / 'tool.csv',
                 *offsets_mm, expect_rc=rc)
    model = rm.RobotConfig(KR210).build()
    points = {}
    for k, name in (('--load-point-mm', 'p_load_tip_m'), ('--target-mm', 'p_target_tip_m')):
        if k in offsets_mm:
            points[name] = np.array([float(x) for x in offsets_mm[offsets_mm.index(k) + 1].split(',')]) * 1e-3
    plan = rm.plan_load_tests(model, 4, tracker_noise_m=1e-5, seed=3, **points)  # the tool's defaults otherwise
    rm.write_load_test_plan_csv(str(tmp / 'python.csv'), plan, KR210)
    assert (tmp / 'python.csv').read_bytes() == (tmp / 'tool.csv').read_bytes()
    assert plan.flagged == (rc == 3) and len(plan.findings) == (1 if rc == 3 else 0)
    assert (plan.expected_determination[5] == 'not determined') == (rc == 3), r.stderr
    assert len(plan.loads) == 4 * 2 and len(plan.cases) == 4 * 2 * 3
    # Geometry, independently of the planner: every rope goes down from the
    # load point to the floor (z = 0) within 45 degrees of vertical.
    for load in plan.loads:
        d = load.rope_direction
        assert abs(np.linalg.norm(d) - 1) < 1e-12 and -d[2] >= np.cos(np.radians(45)) - 1e-12
        t = -load.p_load_m[2] / d[2]
        np.testing.assert_allclose(load.p_load_m + t * d, load.p_pulley_m, atol=1e-9)
        assert load.p_load_m[2] >= 0.3 - 1e-12


def test_plan_load_tests_bad_options():
    model = rm.RobotConfig(KR210).build()
    with pytest.raises(ValueError, match='num_postures'):
        rm.plan_load_tests(model, 0)
    with pytest.raises(ValueError, match='masses_kg'):
        rm.plan_load_tests(model, 4, masses_kg=[10, -1])


def test_synthesize_hammer_test_equals_frf_synth_byte_for_byte(hammer):
    tmp, _ = hammer  # the fixture's hammer.csv is frf-synth's output for these options
    cfg = rm.RobotConfig(KR210, set={'m6_kg': TRUTH['m6_kg'], 'd6_m': TRUTH['d6_m']})
    postures = rm.read_posture_file(POSTURES, cfg.num_joints)
    frfs = rm.synthesize_hammer_test(cfg, postures, noise_rel=0.01, seed=5, coherence=True)
    rm.write_frf_csv(str(tmp / 'python.csv'), frfs, 'receptance', 5)
    assert (tmp / 'python.csv').read_bytes() == (tmp / 'hammer.csv').read_bytes()


def test_noise_free_synthesis_equals_the_predicted_receptance():
    # A second route to the same numbers: predict_frfs at the grid's lines.
    cfg = rm.RobotConfig(KR210)
    postures = rm.read_posture_file(POSTURES, cfg.num_joints)
    frfs = rm.synthesize_hammer_test(cfg, postures, directions='xx,yx', block_samples=2048, fmax_hz=400.0)
    some = frfs[postures[0].id, 'y', 'x']
    f = np.asarray(some.freq_hz)
    assert f[0] == pytest.approx(2.5) and np.allclose(np.diff(f), 2.5)  # 5120 Hz / 2048
    pred = rm.predict_frfs(cfg.build(), postures, f)
    for p, post in zip(pred['postures'], postures):
        for (r, e), (i, j) in ((('x', 'x'), (0, 0)), (('y', 'x'), (1, 0))):
            h = np.asarray(frfs[post.id, r, e].receptance)
            ref = p['H_m_per_N'][:, i, j]
            # Synthesis rounds to 13 significant digits (UFF58's E20.12).
            assert np.abs(h - ref).max() <= 1e-12 * np.abs(ref).max()
    with pytest.raises(ValueError, match='at least 2'):
        rm.synthesize_hammer_test(cfg, postures, coherence=True, averages=1)


@pytest.mark.parametrize('campaign', ['shipped', 'masses_in_g'])
def test_run_kq_identify_equals_the_tools_summary(tmp_path, campaign):
    """Issue #36 acceptance: kq-identify's JSON summary and the Python call's
    result (workflows::RunKqIdentify), on the shipped campaign and on the
    same file with its masses in g (a unit finding: exit 3, a warning)."""
    path = os.path.join(DATA, 'tracker_campaign.csv')
    if campaign == 'masses_in_g':
        lines = open(path).read().splitlines()
        head = next(i for i, l in enumerate(lines) if not l.startswith('#'))
        m = lines[head].split(',').index('mass_kg')
        out = lines[:head + 1]
        for l in lines[head + 1:]:
            cells = l.split(',')
            cells[m] = repr(float(cells[m]) * 1000.0)
            out.append(','.join(cells))
        path = str(tmp_path / 'grams.csv')
        open(path, 'w').write('\n'.join(out) + '\n')
    r = run_tool('kq-identify', '--robot', KR210, '--tracker', path, '--out', tmp_path / 'kq.yaml',
                 '--summary', tmp_path / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 'tool.json').read_text())
    import warnings
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        run = rm.run_kq_identify(KR210, path)
    assert run['flagged'] == (r.returncode == 3) == tool['flagged']
    assert tool['exit_code'] == r.returncode
    tool_warnings = tool.pop('warnings')
    for key in ('tool', 'exit_code', 'robomach_version'):
        tool.pop(key, None)
    assert run['summary'] == tool
    # The warnings the tool printed before its table are the call's messages,
    # its table is the call's report, and its unit findings are UnitWarnings.
    said = [m['text'] for m in run['messages'] if m['kind'] == 'warning']
    assert tool_warnings[:len(said)] == said
    for line in run['report']:
        assert f'kq-identify: {line}' in r.stderr
    assert [str(w.message) for w in caught if issubclass(w.category, rm.UnitWarning)] == run['unit_findings']
    if campaign == 'masses_in_g':
        assert run['unit_findings'] and 'mass_kg' in run['unit_findings'][0], run['unit_findings']
        assert run['flagged']
    else:
        assert run['unit_findings'] == []


DEMO = os.path.join(os.path.dirname(KR210), 'demo')  # the README's hammer tests (scripts/demo.sh)
DEMO_POSTURES, DEMO_HAMMER = os.path.join(DEMO, 'postures.csv'), os.path.join(DEMO, 'hammer.csv')


def test_run_model_audit_equals_the_tools_summary(tmp_path):
    """Issue #36 acceptance: model-audit's summary.json and the Python call's
    (workflows::RunModelAudit, then the same report) on the shipped demo
    (config/demo/), kept fast: one candidate, no virtual joints, no
    stiffness hypotheses, few iterations - the same options for both."""
    r = run_tool('model-audit', '--robot', KR210, '--postures', DEMO_POSTURES, '--measured', DEMO_HAMMER,
                 '--candidates', 'spindle_interface', '--virtual-joints', 0, '--no-parameter-hypotheses',
                 '--max-iterations', 20, '--report', tmp_path / 'tool_report', '--summary', tmp_path / 'tool.json',
                 expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 'tool.json').read_text())
    run = rm.run_model_audit(KR210, DEMO_POSTURES, measured=[DEMO_HAMMER], candidates=['spindle_interface'],
                             virtual_joints=0, no_parameter_hypotheses=True, max_iterations=20,
                             report=str(tmp_path / 'py_report'))
    assert run['flagged'] == (r.returncode == 3)
    assert run['status'] == ('flagged' if run['flagged'] else 'ok')
    tool.pop('robomach_version', None)  # what only the tool writes
    assert run['summary'] == tool
    # The YAML the tool prints is the call's effects_yaml.
    assert run['effects_yaml'] == r.stdout


def test_run_frf_calibrate_equals_the_tools_summary(tmp_path):
    """Issue #36 acceptance: frf-calibrate's summary.json and the Python
    call's (workflows::RunFrfCalibrate) on the shipped demo hammer tests
    (config/demo/), few iterations (the same for both); the calibrated
    config the tool writes is the call's config_text."""
    r = run_tool('frf-calibrate', '--robot', KR210, '--postures', DEMO_POSTURES, '--measured', DEMO_HAMMER,
                 '--max-iterations', 10, '--out', tmp_path / 'cal.yaml', '--report', tmp_path / 'report',
                 '--summary', tmp_path / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 'tool.json').read_text())
    run = rm.run_frf_calibrate(KR210, DEMO_POSTURES, measured=[DEMO_HAMMER], max_iterations=10,
                               out=str(tmp_path / 'cal.yaml'))
    assert run['flagged'] == (r.returncode == 3) == bool(run['flags'])
    for key in ('calibrated_config', 'uncertainty_out', 'warnings', 'robomach_version'):  # what only the tool writes
        tool.pop(key, None)
    assert run['summary'] == tool
    assert run['config_text'] == (tmp_path / 'cal.yaml').read_text()
    for line in run['result_lines']:
        assert f'frf-calibrate: {line}' in r.stderr


def test_run_tracker_synth_equals_the_tools_summary(tmp_path):
    """Issue #36 acceptance: tracker-synth's JSON summary and tracker file and
    the Python call's (workflows::RunTrackerSynth) on the shipped robot with
    the tool's defaults but 3 random postures (to keep it fast)."""
    r = run_tool('tracker-synth', '--robot', KR210, '--num-postures', 3, '--out', tmp_path / 'tool.csv',
                 '--summary', tmp_path / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp_path / 'tool.json').read_text())
    run = rm.run_tracker_synth(KR210, num_postures=3, out=str(tmp_path / 'py.csv'))
    assert run['flagged'] == (r.returncode == 3)
    for key in ('tool', 'out', 'exit_code', 'warnings', 'robomach_version'):  # what only the tool writes
        tool.pop(key, None)
    assert run['summary'] == tool
    assert (tmp_path / 'py.csv').read_text() == (tmp_path / 'tool.csv').read_text()
    assert f"tracker-synth: {run['counts']}" in r.stderr
    assert len(run['cases']) == len(rm.read_tracker_file(str(tmp_path / 'tool.csv'), rm.RobotConfig(KR210).num_joints))
