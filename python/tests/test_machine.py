"""The five-axis machine tools through Python: acquire reproduces
axis-acquire's acquired path byte for byte (on counts axis-synth made, with
the controller's compensation and temperature log) and its contour error
statistics, and iso230_evaluate equals axis-accuracy's JSON to 1e-12. Then
bad input."""
import json
import os
import re
import warnings

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, SOURCE_DIR, run_tool

M = os.path.join(SOURCE_DIR, 'config', 'machine')
MACHINE, PROGRAM, COMP, TEMP = (os.path.join(M, f) for f in
                                ('dmu80p.yaml', 'cone_frustum.csv', 'dmu80p_comp.mpf', 'dmu80p_temperature.csv'))


def test_acquire_equals_axis_acquire(tmp):
    run_tool('axis-synth', '--machine', MACHINE, '--program', PROGRAM, '--compensation', COMP, '--temperature', TEMP,
             '--feed-mm-min', 20000, '--sample-rate-hz', 2000, '--out', tmp / 'counts.csv',
             '--machine-out', tmp / 'machine.yaml')
    run_tool('axis-acquire', '--machine', tmp / 'machine.yaml', '--counts', tmp / 'counts.csv', '--compensation', COMP,
             '--temperature', TEMP, '--program', PROGRAM, '--out', tmp / 'tool.csv', '--summary', tmp / 'tool.json',
             expect_rc=None)
    a = rm.acquire(str(tmp / 'machine.yaml'), str(tmp / 'counts.csv'), compensation=COMP, temperature=TEMP,
                   program=PROGRAM, out=str(tmp / 'py.csv'))
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    s = json.loads((tmp / 'tool.json').read_text())
    d_um = a['contour_error_m'] * 1e6
    assert d_um.max() == pytest.approx(s['contour_error_um']['max'], rel=1e-12)
    assert np.sqrt(np.mean(d_um ** 2)) == pytest.approx(s['contour_error_um']['rms'], rel=1e-9)
    assert a['axes_si'].shape == (len(a['t_s']), 5) and a['tip_m'].shape == (len(a['t_s']), 3)
    # The tool axis is a unit vector; the synthesised machine follows the path to well under a millimetre.
    np.testing.assert_allclose(np.linalg.norm(a['tool_axis'], axis=1), 1.0, atol=1e-12)
    assert d_um.max() < 1000.0
    assert a['unit_findings'] == []


def test_decode_equals_axis_decode(tmp):
    # A capture axis-synth made with glitches, decoded by axis-decode and by
    # Python: the same counts file; the counts equal axis-synth's own (the
    # glitch filter removes every glitch: no error event).
    run_tool('axis-synth', '--machine', MACHINE, '--program', os.path.join(DATA, 'machine', 'cone_arc.csv'),
             '--feed-mm-min', 2000, '--sample-rate-hz', 8000, '--capture', tmp / 'capture.bin', '--capture-every', 100,
             '--glitch-probability', 0.01, '--seed', 3, '--machine-out', tmp / 'machine.yaml', '--out', tmp / 'synth.csv')
    run_tool('axis-decode', '--machine', tmp / 'machine.yaml', '--capture', tmp / 'capture.bin', '--sample-rate-hz',
             800000, '--every', 100, '--glitch-filter', 2, '--out', tmp / 'tool.csv')
    d = rm.decode_capture(str(tmp / 'machine.yaml'), str(tmp / 'capture.bin'), 800000, every=100, glitch_filter=2,
                          out=str(tmp / 'py.csv'))
    assert (tmp / 'py.csv').read_text() == (tmp / 'tool.csv').read_text()
    assert sum(d['error_events']) == 0 and d['status'] == 'ok' and d['findings'] == []
    # A and B of the first axis flipped together in one sample (formats.md
    # §8.2: bits 0 and 1): an error event into that sample and one out of it
    # (without the glitch filter, which would take the one-sample pulse out;
    # axis-synth's glitches are on one channel at a time: no event).
    words = bytearray((tmp / 'capture.bin').read_bytes())
    words[2 * 1000] ^= 0b11
    (tmp / 'events.bin').write_bytes(bytes(words))
    r = run_tool('axis-decode', '--machine', tmp / 'machine.yaml', '--capture', tmp / 'events.bin',
                 '--sample-rate-hz', 800000, '--every', 100, '--out', tmp / 'events.csv', expect_rc=3)
    bad = rm.decode_capture(str(tmp / 'machine.yaml'), str(tmp / 'events.bin'), 800000, every=100)
    assert bad['error_events'][0] == 2 and sum(bad['error_events']) == 2 and bad['status'] == 'flagged'
    assert len(bad['findings']) == 1 and bad['findings'][0] in r.stderr
    rows = [line.split(',') for line in (tmp / 'synth.csv').read_text().splitlines() if not line.startswith('#')][1:]
    np.testing.assert_array_equal(d['counts'], np.array([[int(x) for x in r[1:]] for r in rows], dtype=np.int64))


def test_run_axis_synth_equals_the_tools_summary(tmp):
    """Issue #36 acceptance for axis-synth, which has no --summary: what it
    writes (the counts, the machine file with the measured start as origins,
    the raw capture) and the Python call's (workflows::RunAxisSynth), on the
    shipped machine, path, tables and temperature log (feed and rate as
    test_acquire_equals_axis_acquire's, to keep it fast). The tool, then the
    call, write to the same paths (the counts file names the machine file)."""
    out, machine_out = tmp / 'counts.csv', tmp / 'machine.yaml'
    r = run_tool('axis-synth', '--machine', MACHINE, '--program', PROGRAM, '--compensation', COMP, '--temperature', TEMP,
                 '--feed-mm-min', 20000, '--sample-rate-hz', 2000, '--out', out, '--machine-out', machine_out,
                 expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool_counts, tool_machine = out.read_text(), machine_out.read_text()
    out.unlink()
    machine_out.unlink()
    run = rm.run_axis_synth(MACHINE, PROGRAM, out=str(out), machine_out=str(machine_out), compensation=COMP,
                            temperature=TEMP, feed_mm_min=20000, sample_rate_hz=2000)
    assert run['flagged'] == (r.returncode == 3)
    assert run['status'] == ('flagged' if r.returncode == 3 else 'ok')
    assert out.read_text() == tool_counts
    assert machine_out.read_text() == tool_machine
    # The values of the tool's counts file are the call's.
    lines = [line for line in tool_counts.splitlines() if not line.startswith('#')]
    assert lines[0].split(',') == ['t_s'] + [f'{a}_count' for a in run['axis_names']]
    rows = [line.split(',') for line in lines[1:]]
    assert run['rows'] == len(rows) and f"axis-synth: {run['rows']} rows, " in r.stderr
    assert run['t_s'] == [float(row[0]) for row in rows]  # written shortest round-trip: exact
    np.testing.assert_array_equal(run['counts'], np.array([[int(x) for x in row[1:]] for row in rows], dtype=np.int64))
    assert not run['counts'][0].any()  # the first row is the reference
    assert len(run['origins_si']) == len(run['axis_names'])

    # The raw capture (with glitches) on the path and options of
    # test_decode_equals_axis_decode, which the tool is known to capture.
    arc = os.path.join(DATA, 'machine', 'cone_arc.csv')
    opts = ['--feed-mm-min', 2000, '--sample-rate-hz', 8000, '--capture-every', 100, '--glitch-probability', 0.01,
            '--seed', 3]
    r = run_tool('axis-synth', '--machine', MACHINE, '--program', arc, *opts, '--capture', tmp / 'capture.bin',
                 '--machine-out', machine_out, '--out', out, expect_rc=None)
    assert r.returncode in (0, 3), r.stderr
    tool_capture, tool_counts = (tmp / 'capture.bin').read_bytes(), out.read_text()
    for p in (tmp / 'capture.bin', out, machine_out):
        p.unlink()
    run = rm.run_axis_synth(MACHINE, arc, feed_mm_min=2000, sample_rate_hz=8000, capture_every=100,
                            glitch_probability=0.01, seed=3, capture=str(tmp / 'capture.bin'),
                            machine_out=str(machine_out), out=str(out))
    assert run['flagged'] == (r.returncode == 3)
    assert (tmp / 'capture.bin').read_bytes() == tool_capture
    assert out.read_text() == tool_counts
    assert run['capture_samples'] == (run['rows'] - 1) * 100 + 1 == len(tool_capture) // 2
    assert f"capture of {run['capture_samples']} samples" in r.stderr
    assert f", {run['capture_glitches']} glitches" in r.stderr


def test_iso230_equals_axis_accuracy(tmp):
    runs = os.path.join(DATA, 'machine', 'x_runs_hand.csv')
    rc = run_tool('axis-accuracy', '--runs', runs, '--out', tmp / 'tool.json', expect_rc=None).returncode
    tool = json.loads((tmp / 'tool.json').read_text())
    r = rm.iso230_evaluate(runs)
    assert r['unit'] == tool['unit']
    assert r['status'] == ('flagged' if rc == 3 else 'ok')
    assert len(r['findings']) == len(r['unit_findings'])
    for axis, t in tool['axes'].items():
        for k in ('A', 'A_up', 'A_down', 'E', 'M', 'R', 'R_up', 'R_down', 'B', 'B_mean'):
            assert r['axes'][axis][k] == pytest.approx(t[k], rel=1e-12, abs=1e-15)
        # ISO 230-2: A is at least the systematic error E and the repeatability R of each direction.
        a = r['axes'][axis]
        assert a['A'] >= a['E'] - 1e-12 and a['A'] >= max(a['R_up'], a['R_down']) - 1e-12


def test_bad_input(tmp):
    with pytest.raises(FileNotFoundError):
        rm.acquire(MACHINE, str(tmp / 'none.csv'))
    with pytest.raises(rm.InputError) as e:
        rm.acquire(MACHINE, os.path.join(DATA, 'machine', 'counts_first_row_nonzero.csv'))
    assert e.value.path.endswith('counts_first_row_nonzero.csv') and e.value.line == 3
    odd = tmp / 'odd.bin'
    odd.write_bytes(b'\x00\x01\x02')
    with pytest.raises(rm.InputError, match='16-bit words'):
        rm.decode_capture(MACHINE, str(odd), 1000.0)
    with pytest.raises(rm.InputError, match='axis'):
        rm.iso230_evaluate(os.path.join(DATA, 'machine', 'x_runs_no_down.csv'))


def test_machine_file_findings_are_unit_warnings(tmp):
    # The machine file's X resolution in um (0.5 under resolution_mm) and a
    # temperature log's K0 in um (x1000): axis-acquire prints one finding per
    # mistake and exits 3; acquire gives the same text as one UnitWarning
    # each, and decode_capture the machine file's. The shipped files give
    # none (the tools' reference: exit 0 and no finding).
    text = open(MACHINE).read()
    assert 'X: {resolution_mm: 0.0005,' in text
    (tmp / 'um.yaml').write_text(text.replace('X: {resolution_mm: 0.0005,', 'X: {resolution_mm: 0.5,'))
    log = open(TEMP).read()
    assert '4,X,0.0018,' in log
    (tmp / 'temp_um.csv').write_text(log.replace('4,X,0.0018,', '4,X,1.8,'))
    counts = os.path.join(DATA, 'machine', 'counts_tiny.csv')
    r = run_tool('axis-acquire', '--machine', tmp / 'um.yaml', '--counts', counts, '--temperature', tmp / 'temp_um.csv',
                 '--out', tmp / 'tool.csv', expect_rc=3)
    tool = [line.split('warning: ', 1)[1] for line in r.stderr.splitlines() if 'implausible (unit mistake?)' in line]
    assert len(tool) == 2
    with pytest.warns(rm.UnitWarning) as caught:
        rm.acquire(str(tmp / 'um.yaml'), counts, temperature=str(tmp / 'temp_um.csv'))
    got = [str(w.message) for w in caught if issubclass(w.category, rm.UnitWarning)]
    assert got == tool
    assert re.search(r'um\.yaml:10:\d+: axes\.X\.resolution_mm 0\.5 mm .*a resolution in um typed in the mm field', got[0])
    assert re.search(r'temp_um\.csv:5: column K0_mm: 1\.8 mm .*an offset in um typed in the mm column', got[1])
    (tmp / 'zeros.bin').write_bytes(bytes(8))
    with pytest.warns(rm.UnitWarning, match=r'axes\.X\.resolution_mm 0\.5 mm'):
        rm.decode_capture(str(tmp / 'um.yaml'), str(tmp / 'zeros.bin'), 10000.0)
    with warnings.catch_warnings():
        warnings.simplefilter('error', rm.UnitWarning)
        rm.acquire(MACHINE, counts, temperature=TEMP)
        rm.decode_capture(MACHINE, str(tmp / 'zeros.bin'), 10000.0)
