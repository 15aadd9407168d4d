"""Chatter stability through Python: stability-lobes' three tool-tip sources
and its lobes reproduce the tool's --out file byte for byte (the same
library call, ComputeLobes), and stability-map's points from a region file
reproduce the tool's map CSV to 1e-12. Then bad input."""
import csv
import json
import math
import os

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, KR210, SOURCE_DIR, run_tool

CUT = os.path.join(SOURCE_DIR, 'config', 'cut_demo.yaml')
MODAL = os.path.join(DATA, 'stability', 'modal_benchmark.csv')
FRF = os.path.join(DATA, 'kr210_P1_receptance.csv')
REGION = os.path.join(SOURCE_DIR, 'config', 'region_demo.yaml')


def read_lobes(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_modal_table_lobes_equal_stability_lobes(tmp):
    run_tool('stability-lobes', '--modal-table', MODAL, '--cut', CUT, '--method', 'both', '--sd-speeds', 3,
             '--out', tmp / 'tool.csv')
    cut = rm.read_cut_file(CUT)
    tips = rm.tips_from_modal_table(MODAL, cut)
    lobes, messages = rm.stability_lobes(tips, cut, method='both', sd_speeds=3)
    rm.write_lobes_csv(str(tmp / 'py.csv'), lobes)
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    rows = read_lobes(tmp / 'tool.csv')
    assert len(lobes) == len(rows)
    depth = np.array([float(r['critical_depth_mm']) if r['critical_depth_mm'] else math.nan for r in rows])
    ok = np.isfinite(depth)
    assert np.all(np.abs(lobes.critical_depth_mm[ok] - depth[ok]) <= 1e-12 * depth[ok])
    assert lobes.method == [r['method'] for r in rows]
    assert any(m['kind'] == 'info' and 'SD of' in m['text'] for m in messages)


def test_measured_frf_lobes_equal_stability_lobes(tmp):
    r = run_tool('stability-lobes', '--frf', FRF, '--cut', CUT, '--out', tmp / 'tool.csv')
    cut = rm.read_cut_file(CUT)
    tips, messages = rm.tips_from_frf_file(FRF, cut)
    assert len(tips) == 1 and tips[0].modes_fitted
    assert tips[0].phi_c.shape == (tips[0].freq_hz.size, 2, 2)
    lobes, more = rm.stability_lobes(tips, cut)
    rm.write_lobes_csv(str(tmp / 'py.csv'), lobes)
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    # The tool prints what the library said: every fit report is on its stderr.
    for m in messages + more:
        if m['kind'] == 'info':
            assert m['text'].splitlines()[0] in r.stderr


def test_mobility_read_as_receptance_is_flagged(tmp):
    # The shipped receptance times i omega (a mobility) under a receptance
    # header: the tip carries the unit finding, the lobes are flagged and warn.
    lines = open(FRF).read().splitlines()
    out = []
    for line in lines:
        if line.startswith('#') or line.startswith('pose_id'):
            out.append(line)
            continue
        pose, r, e, f, re, im = line.split(',')
        h = complex(float(re), float(im)) * 2j * math.pi * float(f)
        out.append(f'{pose},{r},{e},{f},{h.real!r},{h.imag!r}')
    (tmp / 'mobility.csv').write_text('\n'.join(out) + '\n')
    cut = rm.read_cut_file(CUT)
    good, _ = rm.tips_from_frf_file(FRF, cut)
    assert good[0].unit_finding == ''
    tips, said = rm.tips_from_frf_file(str(tmp / 'mobility.csv'), cut)
    assert 'outside the plausible' in tips[0].unit_finding
    lobes, messages = rm.stability_lobes(tips, cut)
    assert lobes.flagged and lobes.run_status == 'flagged'
    assert any(f.startswith('implausible (unit mistake?)') for f in lobes.findings)
    # Each finding was told as it was found, once: the unit finding when the
    # tips were built (before the fits' reports), the others by the lobes.
    told = said + messages
    assert all(sum(m['text'] == f for m in told) == 1 for f in lobes.findings)
    assert any(m['kind'] == 'warning' and m['text'].startswith('implausible (unit mistake?)') for m in said)


def test_robot_posture_lobes_equal_stability_lobes(tmp):
    run_tool('stability-lobes', '--robot', KR210, '--postures', os.path.join(SOURCE_DIR, 'config', 'postures_demo.csv'),
             '--posture', 'P1', '--cut', CUT, '--out', tmp / 'tool.csv', expect_rc=None)
    model = rm.RobotConfig(KR210).build()
    pose = [p for p in rm.read_posture_file(os.path.join(SOURCE_DIR, 'config', 'postures_demo.csv'),
                                            model.num_joints) if p.id == 'P1'][0]
    cut = rm.read_cut_file(CUT)
    tip = rm.tip_from_posture(model, pose.q, cut, id='P1')
    # The cutting frame is orthonormal, with x along the feed's part normal to the tool axis.
    R = tip.R_BC
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
    lobes, _ = rm.stability_lobes([tip], cut)
    rm.write_lobes_csv(str(tmp / 'py.csv'), lobes)
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()


def test_region_map_equals_stability_map(tmp):
    run_tool('stability-map', '--robot', KR210, '--cut', CUT, '--region', REGION, '--out', tmp / 'map.csv')
    model = rm.RobotConfig(KR210).build()
    cut = rm.read_cut_file(CUT)
    region = rm.region_targets(REGION, model.num_joints, cut)
    points = rm.stability_map(model, region['targets'], region['rows'], region['cols'], cut, region['seed_q'],
                              rotation_rad=region['rotation_rad'], optimise_rotation=region['rotation_free'],
                              rotation_min_rad=region['rotation_min_rad'], rotation_max_rad=region['rotation_max_rad'])
    rows = read_lobes(tmp / 'map.csv')
    assert len(points) == len(rows) == region['rows'] * region['cols']
    for p, r in zip(points, rows):
        assert p['status'] == r['status']
        if r['critical_depth_mm']:
            d = float(r['critical_depth_mm'])
            assert abs(p['critical_depth_mm'] - d) <= 1e-12 * d
            assert p['limiting_mechanism'] == r['limiting_mechanism']
        q_deg = np.array([float(r[f'q{j}_deg']) for j in range(1, 7)])
        assert np.all(np.abs(np.degrees(p['q']) - q_deg) <= 1e-12 * np.maximum(1.0, np.abs(q_deg)))


def test_stability_map_names_the_keywords():
    """The ValueError names stability_map's keywords (rotation_min_rad), not
    the library's fields (rotation_min)."""
    model = rm.RobotConfig(KR210).build()
    cut = rm.read_cut_file(CUT)
    region = rm.region_targets(REGION, model.num_joints, cut)
    args = (model, region['targets'], region['rows'], region['cols'], cut, region['seed_q'])
    with pytest.raises(ValueError, match=r'^rotation_max_rad: expected a value > rotation_min_rad 1 \[rad\], got 0.5$'):
        rm.stability_map(*args, optimise_rotation=True, rotation_min_rad=1.0, rotation_max_rad=0.5)
    with pytest.raises(ValueError, match=r'^rotation_rad: expected a finite value, got nan$'):
        rm.stability_map(*args, rotation_rad=math.nan)


def test_bad_input():
    cut = rm.read_cut_file(CUT)
    with pytest.raises(FileNotFoundError):
        rm.read_cut_file('/nonexistent/cut.yaml')
    tips = rm.tips_from_modal_table(MODAL, cut)
    with pytest.raises(ValueError, match='method'):
        rm.stability_lobes(tips, cut, method='fast')
    with pytest.raises(ValueError, match=r'sd_speeds 0 is outside \[1, 10000\]'):
        rm.stability_lobes(tips, cut, sd_speeds=0)
    with pytest.raises(rm.InputError, match='none of the requested postures'):
        rm.tips_from_modal_table(MODAL, cut, poses=['nope'])
    # The feed along the tool axis has no cutting plane: the error names the cut file.
    with pytest.raises(rm.InputError) as e:
        rm.tips_from_modal_table(MODAL, cut, tool_axis=np.array(cut.feed_direction))
    assert e.value.path == CUT and 'feed_direction' in e.value.message


@pytest.mark.parametrize('source', ['robot', 'frf'])
def test_run_stability_lobes_equals_the_tools_summary(tmp, source):
    """Issue #36 acceptance: the tool's JSON summary and the Python call's
    result on the shipped defaults (the README's robot, postures and cut; a
    measured FRF file), the same library call (workflows::RunStabilityLobes)."""
    args = {'robot': ['--robot', KR210, '--postures', os.path.join(SOURCE_DIR, 'config', 'postures_demo.csv')],
            'frf': ['--frf', FRF]}[source]
    r = run_tool('stability-lobes', *args, '--cut', CUT, '--method', 'both', '--sd-speeds', 4, '--out',
                 tmp / 'tool.csv', '--summary', tmp / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp / 'tool.json').read_text())
    kw = {'robot': dict(robot=KR210, postures=os.path.join(SOURCE_DIR, 'config', 'postures_demo.csv')),
          'frf': dict(frf=FRF)}[source]
    run = rm.run_stability_lobes(CUT, method='both', sd_speeds=4, **kw)
    assert run['flagged'] == (r.returncode == 3)
    assert tool['exit_code'] == r.returncode
    tool_warnings = tool.pop('warnings')  # every warning printed (formats.md §4.1)
    for key in ('tool', 'lobes_csv', 'exit_code', 'robomach_version'):  # what only the tool writes
        del tool[key]
    assert run['summary'] == tool
    rm.write_lobes_csv(str(tmp / 'py.csv'), run['lobes'])
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    # What the tool printed as warnings, the call returns as messages.
    printed = [line.split('warning: ', 1)[1] for line in r.stderr.splitlines() if ': warning: ' in line]
    said = [m['text'] for m in run['messages'] if m['kind'] == 'warning']
    assert [w.splitlines()[0] for w in said] == printed
    assert [w.splitlines()[0] for w in tool_warnings] == printed


@pytest.mark.parametrize('uncertain', [False, True])
def test_run_stability_map_equals_the_tools_summary(tmp, uncertain):
    """Issue #36 acceptance: stability-map's JSON summary and the Python
    call's on the shipped defaults (the README's robot, cut and region), the
    same library call (workflows::RunStabilityMap); with a parameter
    uncertainty, first order, the intervals too."""
    unc = os.path.join(DATA, 'uncertainty', 'kq_demo.yaml')
    extra = ['--uncertainty', unc, '--uncertainty-method', 'first-order'] if uncertain else []
    r = run_tool('stability-map', '--robot', KR210, '--cut', CUT, '--region', REGION, *extra, '--out',
                 tmp / 'tool.csv', '--summary', tmp / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp / 'tool.json').read_text())
    kw = dict(uncertainty=[unc], uncertainty_method='first-order') if uncertain else {}
    run = rm.run_stability_map(KR210, CUT, REGION, **kw)
    assert run['flagged'] == (r.returncode == 3)
    assert tool['exit_code'] == r.returncode
    tool.pop('warnings')
    for key in ('tool', 'points_csv', 'exit_code', 'robomach_version'):  # what only the tool writes
        del tool[key]
    assert run['summary'] == tool
    rows = read_lobes(tmp / 'tool.csv')
    assert len(rows) == len(run['points']) == run['rows'] * run['cols']
    for row, p in zip(rows, run['points']):
        assert row['status'] == p['status']
        if row['critical_depth_mm']:
            assert abs(float(row['critical_depth_mm']) - p['critical_depth_mm']) <= 1e-9 * p['critical_depth_mm']
    if uncertain:
        lower = [float(row['critical_depth_mm_lower']) for row in rows if row['critical_depth_mm_lower']]
        py_lower = [v for v in run['critical_depth_mm_lower'] if math.isfinite(v)]
        assert lower == pytest.approx(py_lower, rel=1e-9)
        assert any(m['text'].startswith('intervals at 95 %') for m in run['messages'])
    else:
        assert 'critical_depth_mm_lower' not in run


def test_run_stability_map_names_the_option():
    with pytest.raises(ValueError, match=r'max_depth_mm 0: expected a depth > 0 and at most 10000 mm'):
        rm.run_stability_map(KR210, CUT, REGION, max_depth_mm=0)
    with pytest.raises(ValueError, match=r'rotation_evaluations 3: expected >= 8'):
        rm.run_stability_map(KR210, CUT, REGION, rotation_evaluations=3)


def test_run_stability_lobes_names_the_option():
    with pytest.raises(ValueError, match=r'sd_speeds 0 is outside \[1, 10000\]'):
        rm.run_stability_lobes(CUT, modal_table=MODAL, sd_speeds=0)
    with pytest.raises(ValueError, match='exactly one tool-tip source'):
        rm.run_stability_lobes(CUT, modal_table=MODAL, frf=FRF)
    with pytest.raises(ValueError, match="method 'zo': expected zoa, sd or both"):
        rm.run_stability_lobes(CUT, modal_table=MODAL, method='zo')
