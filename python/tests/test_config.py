"""Robot configs: load, --add and --set equivalents, errors. Reference: the
frf-predict tool's --summary JSON for the same config, adds and sets (the
parameters it used), and its stderr for a bad config (the same message)."""
import json
import os
import warnings

import pytest

import robomach as rm
from conftest import KR210, run_tool


def write_posture(path):
    path.write_text('pose_id,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg\nP1,0,-90,90,0,45,0\n')
    return path


def test_parameters_equal_the_tools_after_add_and_set(tmp):
    cfg = rm.RobotConfig(KR210, add=['tip_mass'], set={'m6_kg': 31.5, 'tip_mass.mass_kg': 0.25})
    postures = write_posture(tmp / 'p.csv')
    run_tool('frf-predict', '--robot', KR210, '--postures', postures, '--out', tmp / 'h.csv',
             '--summary', tmp / 's.json', '--add', 'tip_mass', '--set', 'm6_kg=31.5',
             '--set', 'tip_mass.mass_kg=0.25', '--fmax-hz', '2')
    tool = json.loads((tmp / 's.json').read_text())['parameters']
    assert cfg.parameters == tool  # exact: both are the library's doubles, JSON keeps 17 digits
    assert cfg.build().parameters == tool
    assert 'tip_mass' in cfg.effects and 'tip_mass' in cfg.build().effects


def test_add_effect_then_set_is_the_same_as_the_constructor():
    a = rm.RobotConfig(KR210)
    a.add_effect('tip_mass')
    a.set('tip_mass.mass_kg', 0.25)
    a.set('m6_kg', 31.5)
    b = rm.load_robot_config(KR210, add=['tip_mass'], set={'m6_kg': 31.5, 'tip_mass.mass_kg': 0.25})
    assert a.parameters == b.parameters
    assert a.get('m6_kg') == 31.5


def test_add_keeps_values_already_set():
    cfg = rm.RobotConfig(KR210)
    cfg.set('m6_kg', 30.0)
    cfg.add_effect('tip_mass')
    assert cfg.get('m6_kg') == 30.0
    spec = {s.name: s for s in cfg.parameter_specs}['tip_mass.mass_kg']
    assert cfg.get('tip_mass.mass_kg') == spec.default_value
    assert spec.unit == 'kg'


def test_unknown_effect_and_parameter_raise_value_error_with_the_librarys_message():
    cfg = rm.RobotConfig(KR210)
    before = cfg.parameters
    with pytest.raises(ValueError, match="unknown effect 'no_such_effect'"):
        cfg.add_effect('no_such_effect')
    assert cfg.parameters == before and cfg.effects == rm.RobotConfig(KR210).effects  # unchanged
    with pytest.raises(ValueError, match="unknown parameter 'm7_kg'"):
        cfg.set('m7_kg', 1.0)
    with pytest.raises(ValueError, match='m6_kg'):
        cfg.set('m6_kg', -1.0)  # below the lower bound
    assert set(rm.available_effects()) >= {'tip_mass'}


def test_missing_file_is_file_not_found():
    with pytest.raises(FileNotFoundError, match='no such file'):
        rm.RobotConfig('/nonexistent/robot.yaml')


def test_bad_config_raises_input_error_with_the_tools_message(tmp):
    text = open(KR210).read().replace('  alpha_s: 1.0e-4', '  alpha_s: fast', 1)
    assert 'alpha_s: fast' in text
    bad = tmp / 'bad.yaml'
    bad.write_text(text)
    # Relative paths (the URDF) resolve from the config's folder: copy what it names.
    src_dir = os.path.dirname(KR210)
    for name in os.listdir(src_dir):
        if name.endswith('.urdf'):
            (tmp / name).write_text(open(os.path.join(src_dir, name)).read())
    with pytest.raises(rm.InputError) as e:
        rm.RobotConfig(str(bad))
    err = e.value
    assert isinstance(err, ValueError)
    assert err.path == str(bad) and err.line > 0
    assert str(err).startswith(f'{bad}:{err.line}')
    r = run_tool('frf-predict', '--robot', bad, '--postures', write_posture(tmp / 'p.csv'), expect_rc=65)
    assert str(err) in r.stderr


# Issue #35: Ceres's glog lines ("Covariance matrix is near rank deficient")
# reached Python's stderr. Importing the module sets glog's minloglevel to
# FATAL (3), as the tools do; the conditions are in the results
# (covariance_ok, std_dev NaN, solver messages). GLOG_minloglevel in the
# environment is respected. Read from the libglog the module loaded.
GLOG_PROBE = '''
import ctypes, robomach
path = next(l.split()[-1] for l in open('/proc/self/maps') if 'libglog' in l)
print(ctypes.c_int.in_dll(ctypes.CDLL(path), '_ZN3fLI17FLAGS_minloglevelE').value)
'''


def glog_minloglevel(env_value):
    import subprocess
    import sys
    env = {k: v for k, v in os.environ.items() if k != 'GLOG_minloglevel'}
    if env_value is not None:
        env['GLOG_minloglevel'] = env_value
    r = subprocess.run([sys.executable, '-c', GLOG_PROBE], capture_output=True, text=True, env=env, timeout=60)
    assert r.returncode == 0, r.stderr
    return int(r.stdout)


def test_import_silences_ceres_log_lines_unless_asked():
    assert glog_minloglevel(None) == 3
    assert glog_minloglevel('0') == 0


def test_stiffness_in_n_mm_per_rad_gives_the_tools_unit_warning(tmp):
    # The same finding as frf-predict's exit 3 (docs/plausibility.md):
    # joint stiffnesses typed in N mm/rad, 1000 x too stiff.
    text = open(KR210).read()
    text = text.replace('urdf: kr210_r2700_2.urdf', 'urdf: ' + os.path.join(os.path.dirname(KR210), 'kr210_r2700_2.urdf'))
    text = text.replace('[3.3479e+6, 3.1318e+6, 4.2895e+6, 2.4787e+5, 6.4292e+5, 1.8847e+5]',
                        '[3.3479e+9, 3.1318e+9, 4.2895e+9, 2.4787e+8, 6.4292e+8, 1.8847e+8]')
    path = tmp / 'kq_Nmm.yaml'
    path.write_text(text)
    with pytest.warns(rm.UnitWarning, match=r'implausible \(unit mistake\?\).*N.mm/rad'):
        rm.RobotConfig(str(path))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        rm.RobotConfig(KR210)
    assert not [w for w in caught if issubclass(w.category, rm.UnitWarning)]
