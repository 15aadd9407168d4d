"""Polishing through Python: plan_polishing reproduces polish-plan's path
and removal files byte for byte (the same library calls) on a cycloid timed
for a target and on the zig-zag, its statistics equal the tool's summary,
and bad input raises with the file named."""
import json
import os

import numpy as np
import pytest

import robomach as rm
from conftest import SOURCE_DIR, run_tool

P = os.path.join(SOURCE_DIR, 'config', 'polishing')
DOME, CYLINDER, BELT = (os.path.join(P, f) for f in ('dome.yaml', 'cylinder_r60.yaml', 'belt_2N.yaml'))


@pytest.mark.parametrize('surface, options, tool_args', [
    (DOME, dict(target_removal_um=2.0), ['--target-removal-um', 2]),
    (CYLINDER, dict(pattern='parallel', line_angle_deg=90.0), ['--pattern', 'parallel', '--line-angle-deg', 90]),
])
def test_plan_equals_polish_plan(tmp, surface, options, tool_args):
    r = run_tool('polish-plan', '--surface', surface, '--process', BELT, *tool_args, '--path', tmp / 'tool_path.csv',
                 '--removal', tmp / 'tool_removal.csv', '--summary', tmp / 'tool.json', expect_rc=None)
    plan = rm.plan_polishing(rm.load_surface(surface), rm.read_polishing_process(BELT), **options)
    rm.write_polish_path(str(tmp / 'py_path.csv'), plan)
    rm.write_removal_map(str(tmp / 'py_removal.csv'), plan)
    assert (tmp / 'py_path.csv').read_text() == (tmp / 'tool_path.csv').read_text()
    assert (tmp / 'py_removal.csv').read_text() == (tmp / 'tool_removal.csv').read_text()
    s = json.loads((tmp / 'tool.json').read_text())
    assert plan.stats['cv'] == pytest.approx(s['removal_um']['cv'], rel=1e-12)
    assert plan.stats['mean_um'] == pytest.approx(s['removal_um']['mean'], rel=1e-12)
    assert plan.flagged == (r.returncode == 3)
    assert plan.status == ('flagged' if plan.flagged else 'ok') and bool(plan.findings) == plan.flagged
    for f in plan.findings:  # the tool's warnings are the findings
        assert f in r.stderr
    # With a target: reached, the mean is the target; out of reach within the
    # speed limit, the path runs at the limit and removes more (flagged).
    if 'target_removal_um' in options:
        target = options['target_removal_um']
        assert plan.target_reached == s['target']['reached']
        if plan.target_reached:
            assert plan.stats['mean_um'] == pytest.approx(target, rel=1e-6)
        else:
            assert plan.flagged and plan.target_message and plan.stats['mean_um'] > target
    else:
        assert plan.target_reached is None
    assert np.all(np.diff(plan.t_s) >= 0)
    assert plan.p_m.shape == (len(plan.t_s), 3)


def test_simulate_equals_polish_sim(tmp):
    # A path polish-plan wrote, simulated by polish-sim and by Python: the
    # same removal map; and the simulation of the plan's own path gives the
    # plan's statistics (two routes to one removal): the file rounds the
    # positions to 1e-4 mm, about 2e-5 of the 4.9 mm contact width, so the
    # statistics agree to 1e-4 (measured: 6e-7 for the cv).
    surface, process = rm.load_surface(DOME), rm.read_polishing_process(BELT)
    plan = rm.plan_polishing(surface, process)
    rm.write_polish_path(str(tmp / 'path.csv'), plan)
    run_tool('polish-sim', '--surface', DOME, '--process', BELT, '--path', tmp / 'path.csv', '--removal',
             tmp / 'tool_removal.csv', '--summary', tmp / 'tool.json', expect_rc=None)
    sim = rm.simulate_polish_path(surface, process, str(tmp / 'path.csv'))
    rm.write_simulated_removal_map(str(tmp / 'py_removal.csv'), sim)
    assert (tmp / 'py_removal.csv').read_text() == (tmp / 'tool_removal.csv').read_text()
    assert sim.stats['cv'] == pytest.approx(plan.stats['cv'], rel=1e-4)
    assert sim.stats['mean_um'] == pytest.approx(plan.stats['mean_um'], rel=1e-4)
    assert not sim.speed_limit_exceeded


def test_optimisation_status():
    # The optimiser ends with the library's one solver status; its own word
    # for stopping ("converged", "max_time") is the stop reason beside it.
    plan = rm.plan_polishing(rm.load_surface(DOME), rm.read_polishing_process(BELT), pattern='parallel',
                             optimise='nlopt', opt_sample_mm=2.0, max_time_s=1.0)
    o = plan.optimisation
    assert o['status'] in ('converged', 'not_converged')
    assert o['stop_reason'] in ('converged', 'max_time')
    assert (o['status'] == 'converged') == (o['stop_reason'] == 'converged')


def test_bad_input(tmp):
    surface = rm.load_surface(DOME)
    process = rm.read_polishing_process(BELT)
    with pytest.raises(ValueError, match='unknown path pattern'):
        rm.plan_polishing(surface, process, pattern='spiral')
    with pytest.raises(ValueError, match='d <= 2r'):
        rm.plan_polishing(surface, process, offset_mm=20.0)
    # polish-plan's ranges hold here too: a typo in the sampling is refused, not hours of work.
    with pytest.raises(ValueError, match=r'sample_mm: expected a value in \[0.05, 0.5\]'):
        rm.plan_polishing(surface, process, sample_mm=1e-6)
    with pytest.raises(ValueError, match='pso applies to the cycloid'):
        rm.plan_polishing(surface, process, pattern='parallel', optimise='pso')
    with pytest.raises(TypeError):
        rm.plan_polishing(None, process)
    # A part whose size says its unit is wrong: a warning, as polish-plan gives.
    with pytest.warns(UserWarning, match='probably in metres'):
        rm.load_surface(os.path.join(P, 'blade.step'), cad_unit_scale=1e-4)
    # A face 100 times too large (a unit mistake): refused before the work, with the estimate.
    with pytest.warns(UserWarning), pytest.raises(ValueError, match='too large to plan within the limits'):
        rm.plan_polishing(rm.load_surface(os.path.join(P, 'blade.step'), cad_unit_scale=100.0), process)
    with pytest.raises(ValueError, match='STEP/IGES'):
        rm.load_surface(DOME, face=2)
    bad = tmp / 'belt.yaml'
    bad.write_text(open(BELT).read().replace('margin_mm', 'margin_cm'))
    with pytest.raises(rm.InputError) as e:
        rm.read_polishing_process(str(bad))
    assert e.value.path == str(bad)
    assert set(rm.path_patterns()) == {'cycloid', 'parallel'}


def test_run_polish_plan_equals_the_tools_summary(tmp):
    """Issue #36 acceptance: polish-plan's JSON summary and the Python call's
    (workflows::RunPolishPlan) on the shipped blade and belt with the
    README's 5 um target (not optimised, to keep it fast)."""
    blade = os.path.join(P, 'blade.yaml')
    r = run_tool('polish-plan', '--surface', blade, '--process', BELT, '--target-removal-um', 5, '--path',
                 tmp / 'tool_path.csv', '--summary', tmp / 'tool.json', expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool = json.loads((tmp / 'tool.json').read_text())
    run = rm.run_polish_plan(blade, BELT, target_removal_um=5.0)
    assert run['flagged'] == (r.returncode == 3)
    assert run['status'] == ('flagged' if run['flagged'] else 'ok')
    for key in ('warnings', 'robomach_version'):  # what only the tool writes
        tool.pop(key, None)
    assert run['summary'] == tool
    rm.write_polish_path(str(tmp / 'py_path.csv'), run['plan'])
    assert (tmp / 'py_path.csv').read_text() == (tmp / 'tool_path.csv').read_text()
    for f in run['findings']:  # the tool's warnings are the findings
        assert f in r.stderr
