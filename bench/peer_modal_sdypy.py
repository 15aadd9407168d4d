#!/usr/bin/env python3
"""Peer comparison of frf-modes with sdypy-EMA (issue #34 §8). Not a test.

Runs sdypy-EMA (LSCF/LSFD, PyPI) and robomach's frf-modes on the public
files of ../shared/external/frf_uff58 (read where they lie; the scratch
CSV made from pyuff's numpy text stays in a temporary folder) and prints
natural frequencies, misfit per FRF and time side by side.

Usage (from the repository root, after a build):
    bench/peer_modal_sdypy.sh            # makes a scratch venv with sdypy-EMA
    python3 bench/peer_modal_sdypy.py    # with numpy and sdypy-EMA importable

The misfit is sqrt(sum |H_fit - H|^2 / sum |H|^2) over the band in the
file's quantity (accelerance for pyuff's beam, mobility for dataset58):
the criterion sdypy-EMA's unweighted least squares minimises, and
frf-modes' --weights quantity. frf-modes runs with both weightings (its
default, --weights noise, minimises the misfit in units of the noise).
When robomach's Python module is importable (PYTHONPATH=build/python),
every fit is also judged in units of the noise: rms |H_fit - H| / sigma
over the band, sigma from robomach's noise model of the file
(estimate_noise with global_modal_fit, frf-modes' own; a model built on
robomach's fit, which favours robomach a little).
sdypy-EMA's poles are chosen with select_closest_poles at the frequencies
robomach found (sdypy-EMA has no automatic selection), so both fit the
same modes; its order is 60.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(ROOT, '..', 'shared', 'external', 'frf_uff58')
FRF_MODES = os.environ.get('FRF_MODES', os.path.join(ROOT, 'build', 'apps', 'frf-modes'))


def misfit(h_fit, h):
    return float(np.sqrt(np.sum(np.abs(h_fit - h) ** 2) / np.sum(np.abs(h) ** 2)))


def run_robomach(csv_path, fmin, fmax, out_dir, weights):
    summary = os.path.join(out_dir, 'summary.json')
    t0 = time.time()
    subprocess.run([FRF_MODES, '--measured', csv_path, '--weights', weights, '--fmin-hz', str(fmin), '--fmax-hz', str(fmax),
                    '--out', os.path.join(out_dir, 'modes.csv'), '--summary', summary, '--noise-model', 'scatter'],
                   check=False, capture_output=True)
    t = time.time() - t0
    with open(summary) as f:
        s = json.load(f)
    fit = s['postures'][0]['fits'][0]
    return ([m['freq_hz'] for m in fit['modes']], [x['misfit_relative'] for x in fit['frfs']], t,
            [x['misfit_noise_sigmas'] for x in fit['frfs']])


def noise_sigma(csv_path, freq, band):
    """robomach's noise sigma of each FRF of the file on the band, in the
    file's quantity (accelerance: receptance sigma times omega^2), or None
    without the Python module."""
    try:
        import robomach as rm
    except ImportError:
        return None
    frfs = rm.read_frf_file(csv_path)['frfs']
    noise = rm.estimate_noise(frfs, rm.NoiseOptions(global_modal_fit=True))
    out = []
    for key in sorted(frfs.keys(), key=lambda k: str(k)):
        sig = np.asarray(noise[key].sigma_m_per_N)
        f = np.asarray(frfs[key].freq_hz)
        w2 = (2 * np.pi * f) ** 2
        out.append(np.interp(freq[band], f, sig * w2))
    return out


def run_sdypy(freq, frfs, fmin, fmax, approx):
    from sdypy import EMA
    t0 = time.time()
    model = EMA.Model(frf=np.array(frfs), freq=freq, lower=fmin, upper=fmax, pol_order_high=60, pyfrf=False)
    model.get_poles(show_progress=False)
    model.select_closest_poles(approx)
    h_rec, _ = model.get_constants(whose_poles='own', FRF_ind='all')
    t = time.time() - t0
    # get_constants reconstructs on the model's own band (model.freq).
    rec = np.atleast_2d(h_rec)
    f_model = np.asarray(model.freq)
    band = np.isin(freq, f_model) if rec.shape[1] == len(f_model) else (freq >= fmin) & (freq <= fmax)
    if rec.shape[1] != np.count_nonzero(band):
        rec = rec[:, band]
    return (list(model.nat_freq), [misfit(rec[i], np.array(frfs)[i][band]) for i in range(len(frfs))], t,
            [rec[i] - np.array(frfs)[i][band] for i in range(len(frfs))], band)


def write_csv(path, freq, frfs, quantity):
    dirs = ['x', 'y', 'z']
    with open(path, 'w') as f:
        f.write('# quantity: %s\npose_id,response,excitation,freq_hz,re,im\n' % quantity)
        for i, h in enumerate(frfs):
            d = dirs[i % 3]
            for fr, v in zip(freq, h):
                if fr > 0:
                    f.write('P1,%s,%s,%.10g,%.10g,%.10g\n' % (d, d, fr, v.real, v.imag))


def main():
    if not os.path.isdir(SHARED):
        print('../shared/external/frf_uff58 is absent: nothing to compare')
        return 0
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # pyuff's beam: three accelerances of a roving hammer, 0..1000 Hz.
        frfs = [np.loadtxt(os.path.join(SHARED, 'pyuff', 'meas_point_%d.txt' % p), dtype=complex) for p in (1, 2, 3)]
        freq = np.arange(len(frfs[0]), dtype=float)
        csv = os.path.join(tmp, 'beam.csv')
        # The three reference points become directions x, y, z of one
        # posture (a file holds one point per posture).
        write_csv(csv, freq, frfs, 'accelerance')
        f_r, m_r, t_r, n_r = run_robomach(csv, 5.0, 999.0, tmp, 'noise')
        f_q, m_q, t_q, n_q = run_robomach(csv, 5.0, 999.0, tmp, 'quantity')
        n_s = None
        try:
            f_s, m_s, t_s, resid, band = run_sdypy(freq, frfs, 5.0, 999.0, f_r)
            sig = noise_sigma(csv, freq, band)
            if sig is not None:
                n_s = [float(np.sqrt(np.mean(np.abs(r) ** 2 / s_ ** 2))) for r, s_ in zip(resid, sig)]
        except Exception as e:  # noqa: BLE001 - report whatever the peer raised
            f_s, m_s, t_s = [], [], float('nan')
            print('sdypy-EMA failed on the beam: %s' % e)
        rows.append(('pyuff beam (3 accelerances)', [
            ('robomach (default, --weights noise)', f_r, m_r, t_r, n_r),
            ('robomach --weights quantity', f_q, m_q, t_q, n_q),
            ('sdypy-EMA', f_s, m_s, t_s, n_s)]))
    for name, fits in rows:
        print('== %s' % name)
        for who, f, m, t, n in fits:
            print('  %-36s %5.2f s  misfit %s%s' % (
                who, t, ' / '.join('%.4f' % x for x in m),
                '' if n is None else '  in noise units %s' % ' / '.join('%.1f' % x for x in n)))
            print('  %-36s modes [Hz] %s' % ('', ', '.join('%.1f' % x for x in f)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
