"""The drilling robot through Python: drill_sim reproduces drill-sim's
time series byte for byte (the same library calls), its runs' summary
values equal the tool's summary JSON, and bad input raises with the file
named."""
import json
import os

import numpy as np
import pytest

import robomach as rm
from conftest import SOURCE_DIR, run_tool

D = os.path.join(SOURCE_DIR, 'config', 'drilling')
ROBOT, DRILL, MATERIAL = (os.path.join(D, f) for f in ('planar3r.yaml', 'drill_5mm.yaml', 'q235.yaml'))


def test_drill_sim_equals_the_tool(tmp):
    run_tool('drill-sim', '--robot', ROBOT, '--drill', DRILL, '--material', MATERIAL, '--controller', 'pid,pd-tdc',
             '--gains', 'pid=50,0.9,5', '--out', tmp / 'tool.csv', '--summary', tmp / 'tool.json')
    runs, findings = rm.drill_sim(ROBOT, DRILL, MATERIAL, controllers=['pid', 'pd-tdc'], gains={'pid': (50, 0.9, 5)})
    assert findings == []
    assert [r.controller for r in runs] == ['pid', 'pd-tdc']
    for r in runs:
        rm.write_drill_series_csv(str(tmp / f'py_{r.controller}.csv'), r)
        assert (tmp / f'py_{r.controller}.csv').read_text() == (tmp / f'tool_{r.controller}.csv').read_text()
        s = json.loads((tmp / f'tool_{r.controller}.json').read_text())
        assert r.cost_rad_s2 == pytest.approx(s['cost_rad_s2'], rel=1e-12)
        np.testing.assert_allclose(np.degrees(r.max_abs_error_rad), s['max_abs_error_deg'], rtol=1e-12)
        assert r.diverged == s['diverged']
    assert runs[0].parameters['omega_rad_s'] == 50 and np.isnan(runs[0].tde_measure)
    assert 0 < runs[1].tde_measure < 1
    # The series: q_d - q is e, and the offset is an angle, >= 0.
    r = runs[1]
    assert r.q_rad.shape == r.e_rad.shape == (3, len(r.t_s))
    assert min(r.offset_rad) >= 0


def test_force_fit_equals_the_tool(tmp):
    table = os.path.join(D, 'q235_hss.csv')
    run_tool('drill-force-fit', '--table', table, '--drill', DRILL, '--out', tmp / 'tool.yaml')
    f = rm.fit_drill_forces(table, DRILL)
    assert f['material_yaml'] == (tmp / 'tool.yaml').read_text()
    assert f['status'] == 'converged' and f['unit_findings'] == []
    assert f['flagged'] is False and f['findings'] == []  # drill-force-fit exited 0
    # The table's own rows back: the model is within the largest relative error it reports.
    import csv
    with open(table) as fh:
        rows = [r for r in csv.DictReader(line for line in fh if not line.startswith('#'))]
    thrust = np.array([float(r['thrust_N']) for r in rows])
    assert np.max(np.abs(np.array(f['thrust_model_N']) - thrust) / thrust) == pytest.approx(f['max_rel_error_thrust'],
                                                                                           rel=1e-9)


def test_bad_input(tmp):
    with pytest.raises(FileNotFoundError):
        rm.drill_sim(ROBOT, str(tmp / 'none.yaml'), MATERIAL)
    with pytest.raises(ValueError, match='lqr'):
        rm.drill_sim(ROBOT, DRILL, MATERIAL, controllers=['lqr'])
    with pytest.raises(ValueError, match='gains'):
        rm.drill_sim(ROBOT, DRILL, MATERIAL, gains={'pid': (50,)})
    # A torque limit the motors cannot hold the robot with: the drill file's posture is named.
    with pytest.raises(rm.InputError) as e:
        rm.drill_sim(ROBOT, DRILL, MATERIAL, motor_torque_limit_Nm=1e-6)
    assert e.value.path == DRILL and 'cannot hold' in e.value.message
    assert 'pd-tdc' in rm.controller_kinds()
    with pytest.raises(ValueError, match='given twice'):
        rm.drill_sim(ROBOT, DRILL, MATERIAL, controllers=['pd', 'pd'])
    with pytest.raises(ValueError, match='gains'):
        rm.drill_sim(ROBOT, DRILL, MATERIAL, gains={'pd': (float('nan'), 1.0)})
    with pytest.raises(ValueError, match='chisel'):
        rm.fit_drill_forces(os.path.join(D, 'q235_hss.csv'), DRILL, chisel='round')


def test_run_drill_sim_equals_the_tools_summary(tmp):
    """Issue #36 acceptance: drill-sim's JSON summary and the Python call's
    (workflows::RunDrillSim) on the shipped defaults (config/drilling/, the
    default controller)."""
    r = run_tool('drill-sim', '--robot', ROBOT, '--drill', DRILL, '--material', MATERIAL, '--summary',
                 tmp / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp / 'tool.json').read_text())
    run = rm.run_drill_sim(ROBOT, DRILL, MATERIAL)
    assert run['flagged'] == (r.returncode == 3)
    assert run['status'] == ('flagged' if run['flagged'] else 'ok')
    assert [x.controller for x in run['runs']] == list(run['summaries']) == ['pd-tdc']
    for key in ('warnings', 'robomach_version'):  # what only the tool writes
        tool.pop(key, None)
    assert run['summaries']['pd-tdc'] == tool
