"""FRF files and the noise model. References: files other people's code
wrote (tests/data/kr210_P1_receptance.csv and .uff, the same FRFs in two
formats) parsed with Python's csv module; files written from Python parsed
back with the csv module (an independent reader) and with the C++ readers;
the coherence noise formula of Bendat & Piersol (calibration/frf_noise.h)."""
import csv
import math
import os

import numpy as np
import pytest

import robomach as rm
from conftest import DATA, SOURCE_DIR


def parse_csv(path):
    """{(pose, resp, exc): (freq, values)} and the '# key: value' metadata, by the csv module."""
    meta, out = {}, {}
    with open(path) as f:
        lines = [l for l in f]
    for l in lines:
        if l.startswith('#') and ':' in l:
            k, v = l[1:].split(':', 1)
            meta[k.strip()] = v.strip()
    rows = list(csv.DictReader(l for l in lines if not l.startswith('#')))
    for r in rows:
        f, v = out.setdefault((r['pose_id'], r['response'], r['excitation']), ([], []))
        f.append(float(r['freq_hz']))
        v.append(complex(float(r['re']), float(r['im'])))
    return {k: (np.array(f), np.array(v)) for k, (f, v) in out.items()}, meta


def test_read_csv_of_others_equals_the_csv_module():
    path = os.path.join(DATA, 'kr210_P1_receptance.csv')
    r = rm.read_frf_csv(path)
    ref, _ = parse_csv(path)
    assert r['quantity'] == 'receptance' and r['warnings'] == []
    frfs = r['frfs']
    assert sorted(frfs.keys()) == sorted(ref.keys()) and len(frfs) == len(ref)
    for key, (f, h) in ref.items():
        np.testing.assert_array_equal(frfs[key].freq_hz, f)  # same decimal text, same double
        np.testing.assert_array_equal(frfs[key].receptance, h)


def test_uff_copy_equals_the_csv():
    a = rm.read_frf_csv(os.path.join(DATA, 'kr210_P1_receptance.csv'))['frfs']
    b = rm.read_frf_file(os.path.join(DATA, 'kr210_P1_receptance.uff'))['frfs']
    assert a.keys() == b.keys()
    for key in a:
        # The CSV keeps 11 significant digits (5e-11 relative rounding), the
        # UFF's E20.12 13 and its abscissa E13.5 6 (formats.md §3).
        np.testing.assert_allclose(b[key].freq_hz, a[key].freq_hz, rtol=5e-6)
        h = a[key].receptance
        assert np.abs(b[key].receptance - h).max() <= 1e-10 * np.abs(h).max()


def synthetic_set(seed=3, lines=400):
    """A two-mode FRF with additive complex noise and a coherence, 1..200 Hz."""
    rng = np.random.default_rng(seed)
    f = np.linspace(0.5, 200, lines)
    w = 2 * np.pi * f
    h = sum(1 / (m * ((2 * np.pi * fn) ** 2 - w ** 2 + 2j * z * (2 * np.pi * fn) * w))
            for m, fn, z in ((40, 18, 0.04), (70, 61, 0.03)))
    noise = 2e-9 * (rng.standard_normal(lines) + 1j * rng.standard_normal(lines)) / math.sqrt(2)
    coh = np.clip(1 - 0.3 * rng.random(lines), 0, 1)
    s = rm.FrfSet()
    s['P1', 'x', 'x'] = rm.Frf(f, h + noise, coh)
    s['P1', 'y', 'x'] = rm.Frf(f, 0.3 * h, coh)
    return s


def test_written_accelerance_csv_reads_back_in_python_and_cpp(tmp):
    s = synthetic_set()
    path = str(tmp / 'acc.csv')
    rm.write_frf_csv(path, s, quantity='accelerance', averages=5)
    ref, meta = parse_csv(path)
    assert meta['quantity'] == 'accelerance' and meta['averages'] == '5'
    for key in s:
        f, a = ref[key]
        h = s[key].receptance
        np.testing.assert_array_equal(f, s[key].freq_hz)
        # A = -w^2 H, one multiplication: 2 ulp.
        np.testing.assert_allclose(a, -(2 * np.pi * f) ** 2 * h, rtol=4.5e-16)
    back = rm.read_frf_csv(path)
    assert back['quantity'] == 'accelerance' and back['averages'] == 5
    for key in s:
        # Two conversions (to accelerance and back): a few ulp.
        np.testing.assert_allclose(back['frfs'][key].receptance, s[key].receptance, rtol=1e-15)
        np.testing.assert_array_equal(back['frfs'][key].coherence, s[key].coherence)
    # Receptance reads back exactly (the writer keeps 17 digits).
    rm.write_frf_csv(str(tmp / 'h.csv'), s)
    again = rm.read_frf_csv(str(tmp / 'h.csv'))['frfs']
    for key in s:
        np.testing.assert_array_equal(again[key].receptance, s[key].receptance)


def test_uff58_round_trip(tmp):
    s = synthetic_set()
    path = str(tmp / 'h.uff')
    rm.write_uff58(path, s, quantity='mobility')
    r = rm.read_uff58(path)
    assert r['quantity'] == 'mobility'
    for key in s:
        h = s[key].receptance
        # E20.12: 13 significant digits, each of re and im (5e-13 of |H|),
        # through the mobility conversion and back.
        assert np.all(np.abs(r['frfs'][key].receptance - h) <= 1e-12 * np.abs(h))
        assert rm.round_to_uff_precision(h[0].real) == float('%.12e' % h[0].real)


def test_frf_validation_and_set_errors():
    with pytest.raises(ValueError, match='increasing'):
        rm.Frf(np.array([1.0, 1.0, 2.0]), np.ones(3, complex))
    s = synthetic_set()
    with pytest.raises(KeyError, match='pose P9'):
        s['P9', 'x', 'x']
    with pytest.raises(ValueError):
        s['P1', 'x', 'x'] = s['P1', 'x', 'x']  # duplicate key
    with pytest.raises(ValueError, match="direction 'w'"):
        s['P1', 'w', 'x']
    with pytest.raises(FileNotFoundError):
        rm.read_frf_csv('/nonexistent.csv')


def test_bad_csv_is_an_input_error_with_line_and_column(tmp):
    p = tmp / 'bad.csv'
    p.write_text('pose_id,response,excitation,freq_hz,re,im\nP1,x,x,1.0,1e-7,0\nP1,x,x,2.0,abc,0\n')
    with pytest.raises(rm.InputError) as e:
        rm.read_frf_csv(str(p))
    assert e.value.path == str(p) and e.value.line == 3
    assert str(e.value) == f'{p}:3: column re: expected a number, got "abc"'
    assert e.value.message == 'column re: expected a number, got "abc"'


def test_coherence_noise_is_bendat_piersol():
    frf = synthetic_set()['P1', 'x', 'x']
    n = rm.estimate_frf_noise(frf, rm.NoiseOptions(averages=5))
    assert n.source == 'coherence' and n.averages == 5
    g2 = frf.coherence
    # sigma^2 = |H|^2 (1 - g^2) / ((n - 1) g^2) [Bendat & Piersol 2010, eq. 9.73
    # with the n - 1 of the header]; evaluated in a different order: 1e-14.
    ref = np.abs(frf.receptance) * np.sqrt((1 - g2) / (4 * g2))
    np.testing.assert_allclose(n.sigma_m_per_N, ref, rtol=1e-14)
    assert rm.estimate_frf_noise(frf).source == 'scatter'  # averages unknown
    with pytest.raises(ValueError, match='min_snr'):
        rm.NoiseOptions(min_snr=-1)


def test_usable_data_attaches_sigma():
    s = synthetic_set()
    noise = rm.estimate_noise(s, rm.NoiseOptions(averages=5))
    assert set(noise) == set(s.keys())
    u = rm.usable_data(s, noise)
    for key in u:
        n = noise[key]
        lines = np.flatnonzero(n.usable)
        assert len(u[key]) == n.usable_lines == len(lines)
        np.testing.assert_array_equal(u[key].freq_hz, s[key].freq_hz[lines])
        np.testing.assert_array_equal(u[key].noise_sigma, n.sigma_m_per_N[lines])


def test_unwritable_output_is_an_output_error(tmp):
    with pytest.raises(rm.OutputError) as e:
        rm.write_frf_csv(str(tmp / 'no_such_folder' / 'h.csv'), synthetic_set())
    assert isinstance(e.value, OSError) and 'no_such_folder' in str(e.value)
    assert not (tmp / 'no_such_folder').exists()


def test_non_utf8_header_of_another_programs_uff_is_read():
    """pyuff's non_ascii_header.uff (../shared/external, not in the project):
    a Latin-1 unit string, (1/N)*(m/s²), that the reader quotes in a note.
    The FRF is read as accelerance, and the note keeps the text with the
    undecodable byte replaced (a UnicodeDecodeError lost the result before)."""
    path = os.path.join(SOURCE_DIR, '..', 'shared', 'external', 'frf_uff58', 'pyuff', 'non_ascii_header.uff')
    if not os.path.exists(path):
        pytest.skip('../shared/external is absent')
    r = rm.read_frf_file(path, "P1")
    assert r['quantity'] == 'accelerance'
    assert len(r['frfs']) == 1
    assert any('\ufffd' in n and 'accelerance' in n for n in r['notes'])


def test_read_measured_frfs_is_the_tools_route(tmp):
    """read_measured_frfs (workflows/measured_frfs.h) against the same work
    done call by call: the file read by read_frf_file, the noise model of
    each FRF by estimate_noise with the file's averages, the usable lines by
    usable_data."""
    path = os.path.join(DATA, 'kr210_P1_receptance.csv')
    m = rm.read_measured_frfs([path])
    r = rm.read_frf_file(path)
    assert sorted(m.frfs.keys()) == sorted(r['frfs'].keys())
    assert all(f == path for f in m.file.values())
    assert all(p == 0 for p in m.file_power.values()) and m.unit_findings == []
    noise = rm.estimate_noise(r['frfs'], rm.NoiseOptions(averages=r['averages']))
    assert set(m.noise) == set(noise)
    for key, n in noise.items():
        np.testing.assert_array_equal(m.noise[key].sigma_m_per_N, n.sigma_m_per_N)
    u = rm.usable_data(r['frfs'], noise)
    fit = m.fit_data
    for key in u:
        np.testing.assert_array_equal(fit[key].freq_hz, u[key].freq_hz)
    # No noise model: every line.
    none = rm.read_measured_frfs([path], noise_model='none')
    assert none.noise == {} and all(len(none.fit_data[k]) == len(r['frfs'][k]) for k in r['frfs'].keys())
    with pytest.raises(ValueError, match='min_snr'):
        rm.read_measured_frfs([path], min_snr=0)
    with pytest.raises(ValueError, match='noise model'):
        rm.read_measured_frfs([path], noise_model='coherent')
    with pytest.raises(FileNotFoundError):
        rm.read_measured_frfs([str(tmp / 'absent.csv')])
    # A response in mm under the m/N receptance: a UnitWarning, as the tools' exit 3.
    mm_set = rm.FrfSet()
    for k, f in r['frfs'].items():
        mm_set[k] = rm.Frf(f.freq_hz, 1e3 * f.receptance)
    rm.write_frf_csv(str(tmp / 'mm.csv'), mm_set)
    with pytest.warns(rm.UnitWarning, match='implausible'):
        mm = rm.read_measured_frfs([str(tmp / 'mm.csv')])
    assert mm.unit_findings
