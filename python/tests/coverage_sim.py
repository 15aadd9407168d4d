"""Coverage of robomach's confidence intervals (issue #37), against a truth
simulated in NumPy that shares no prediction code with the library.

The truth is the KR 210 with joint stiffnesses that differ from the shipped
config (the identification's prior). From the library we take only what the
issue allows: the posture's joint-space mass matrix M, the TCP Jacobian J
and pose X_BT. Everything else is written here from the physics:

- the tracker displacement of a load case, D = J_v K^-1 J_v^T F;
- the lowest natural frequency, from the eigenvalues of (K, M);
- the tool-tip receptance in the cutting plane,
  Phi = R^T J_v (K - w^2 M + i w C)^-1 J_v^T R with C = alpha K + beta M;
- the smallest critical depth of the zero-order (Altintas-Budak) lobes:
  the average directional matrix H0 is integrated here from the cutting
  force model of docs/stability.md (milling.h (2)), and for each eigenvalue
  lam of Phi H0, a_lim = |L|^2 / (2 Re L), L = -1/lam, where Re L > 0; its
  minimum over the chatter frequency is the lowest lobe bottom.

Each campaign draws fresh tracker noise, writes a tracker CSV
(docs/formats.md §2), identifies it with robomach, and predicts the lowest
mode's frequency and the smallest critical depth at three postures with
their intervals.
"""
import math
import os

import numpy as np

import robomach

G = 9.80665
# The truth: the shipped KR 210's stiffnesses scaled joint by joint.
TRUE_SCALE = np.array([1.15, 0.85, 1.10, 0.90, 1.20, 0.95])
# Three prediction postures [deg] (config/postures_demo.csv P1, P3, P4).
PREDICT_DEG = np.array([[0, -90, 90, 0, 45, 0],
                        [30, -60, 60, 90, 30, -45],
                        [-45, -100, 110, -60, 70, 30]], dtype=float)
NOISE_M = 1e-5  # tracker noise, 1 sigma per coordinate
# The cut (written as a cut file for robomach, read here as numbers): the
# shipped demo cut at the low speeds where the robot's modes make lobes.
CUT = dict(diameter_mm=20, teeth=4, radial_immersion=0.5, milling='down', feed_direction=[0, 1, 0],
           feed_per_tooth_mm=0.08, ktc_N_per_mm2=1800, krc_N_per_mm2=650, kac_N_per_mm2=300,
           spindle_speed_min_rpm=150, spindle_speed_max_rpm=1200, spindle_speed_count=300)


def write_cut(path):
    c = CUT
    with open(path, 'w') as fh:
        fh.write(f"""diameter_mm: {c['diameter_mm']}
teeth: {c['teeth']}
radial_immersion: {c['radial_immersion']}
milling: {c['milling']}
feed_direction: {c['feed_direction']}
feed_per_tooth_mm: {c['feed_per_tooth_mm']}
cutting_coefficients:
  ktc_N_per_mm2: {c['ktc_N_per_mm2']}
  krc_N_per_mm2: {c['krc_N_per_mm2']}
  kac_N_per_mm2: {c['kac_N_per_mm2']}
spindle_speed_min_rpm: {c['spindle_speed_min_rpm']}
spindle_speed_max_rpm: {c['spindle_speed_max_rpm']}
spindle_speed_count: {c['spindle_speed_count']}
""")
    return path


def campaign_postures(model, rng, n=12):
    """n random postures inside the KR 210's limits, away from q5 = 0."""
    lo = np.radians([-150, -130, -100, -300, -110, -300])
    hi = np.radians([150, -20, 140, 300, 110, 300])
    out = []
    while len(out) < n:
        q = rng.uniform(lo, hi)
        if abs(q[4]) < 0.3:
            continue
        out.append(q)
    return out


def write_campaign(path, model, postures, kq, rng):
    """A tracker CSV of 2 rope directions x 3 masses per posture."""
    kinv = np.diag(1.0 / kq)
    rows = ['case_id,pose_id,' + ','.join(f'q{j}_deg' for j in range(1, 7)) +
            ',x0_mm,y0_mm,z0_mm,x1_mm,y1_mm,z1_mm,fx_N,fy_N,fz_N']
    directions = [np.array([1.0, 0.0, -1.0]) / math.sqrt(2), np.array([0.0, 1.0, -1.0]) / math.sqrt(2)]
    case = 0
    for i, q in enumerate(postures):
        d = model.evaluate(q, cartesian=False, modes=False)
        jv = d.J[:3, :]
        p0 = d.X_BT[:3, 3]
        for u in directions:
            for mass in (10.0, 20.0, 30.0):
                f = mass * G * u
                disp = jv @ kinv @ jv.T @ f
                x0 = p0 + rng.normal(0.0, NOISE_M, 3)
                x1 = p0 + disp + rng.normal(0.0, NOISE_M, 3)
                case += 1
                cells = [f'C{case}', f'P{i + 1}'] + [repr(math.degrees(v)) for v in q]
                cells += [repr(1e3 * v) for v in np.concatenate([x0, x1])] + [repr(v) for v in f]
                rows.append(','.join(cells))
    with open(path, 'w') as fh:
        fh.write('\n'.join(rows) + '\n')


def lowest_frequency_hz(m_q, kq):
    """sqrt of the smallest eigenvalue of K phi = w^2 M phi, in Hz."""
    l = np.linalg.cholesky(m_q)
    li = np.linalg.inv(l)
    w2 = np.linalg.eigvalsh(li @ np.diag(kq) @ li.T)
    return math.sqrt(w2[0]) / (2 * math.pi)


def average_directional_matrix(cut):
    """H0 = (N / 2 pi) * integral over the cut of the force matrix [N/m^2]."""
    kt, kr = cut['ktc_N_per_mm2'] * 1e6, cut['krc_N_per_mm2'] * 1e6
    ae = cut['radial_immersion']
    if cut['milling'] == 'down':
        phi_st, phi_ex = math.acos(2 * ae - 1), math.pi
    else:
        phi_st, phi_ex = 0.0, math.acos(1 - 2 * ae)
    phi = np.linspace(phi_st, phi_ex, 20001)
    s, c = np.sin(phi), np.cos(phi)
    h = np.array([[s * (kt * c + kr * s), c * (kt * c + kr * s)],
                  [s * (-kt * s + kr * c), c * (-kt * s + kr * c)]])
    return cut['teeth'] / (2 * math.pi) * np.trapz(h, phi, axis=2)


def cutting_frame(x_bt, feed):
    z = -x_bt[:3, 2]  # the tool axis, tip to spindle: -z of the TCP frame
    x = feed - feed.dot(z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def min_critical_depth_m(m_q, jv, x_bt, kq, alpha, beta, cut, fmax_hz=400.0):
    """The smallest ZOA critical depth over all chatter frequencies [m]."""
    k = np.diag(kq)
    c = alpha * k + beta * m_q
    r = cutting_frame(x_bt, np.asarray(cut['feed_direction'], dtype=float))
    h0 = average_directional_matrix(cut)

    def a_lim(f_hz):
        w = 2 * math.pi * f_hz
        z = k[None] - (w ** 2)[:, None, None] * m_q[None] + 1j * w[:, None, None] * c[None]
        phi_b = jv[None] @ np.linalg.solve(z, np.broadcast_to(jv.T, (len(f_hz),) + jv.T.shape))
        phi_c = (r.T[None] @ phi_b @ r[None])[:, :2, :2]
        lam = np.linalg.eigvals(phi_c @ h0[None])
        big_l = -1.0 / lam
        a = np.where(big_l.real > 0, np.abs(big_l) ** 2 / (2 * big_l.real), np.inf)
        return a.min(axis=1)

    f = np.arange(0.5, fmax_hz, 0.02)
    a = a_lim(f)
    best = f[np.argmin(a)]
    fine = np.linspace(best - 0.05, best + 0.05, 2001)
    return float(min(a.min(), a_lim(fine).min()))


class Truth:
    """The truth at the prediction postures."""

    def __init__(self, config, cut=CUT):
        self.kq = TRUE_SCALE * np.array([config.get(f'kq{j}_Nm_per_rad') for j in range(1, 7)])
        model = config.build()
        self.f1, self.depth = [], []
        for q_deg in PREDICT_DEG:
            d = model.evaluate(np.radians(q_deg), cartesian=False, modes=False)
            self.f1.append(lowest_frequency_hz(d.M_q, self.kq))
            self.depth.append(min_critical_depth_m(d.M_q, d.J[:3, :], d.X_BT, self.kq, config.get('alpha_s'),
                                                   config.get('beta_per_s'), cut))


def run_campaigns(n, seed, tmpdir, source_dir, samples=2000, confidence=0.95, speeds=0):
    """n campaigns; per campaign and prediction posture: (f1 interval, depth
    interval) with the truth. Returns a dict of arrays."""
    config = robomach.load_robot_config(os.path.join(source_dir, 'config', 'kr210.yaml'))
    cut = robomach.read_cut_file(write_cut(os.path.join(tmpdir, 'cut.yaml')))
    truth = Truth(config)
    prior = config.build()
    rng = np.random.default_rng(seed)
    out = {k: [] for k in ('f1', 'f1_lo', 'f1_hi', 'f1_sd', 'f1_method', 'd', 'd_lo', 'd_hi', 'd_method')}
    for i in range(n):
        truth_model = config.copy()
        for j in range(6):
            truth_model.set(f'kq{j + 1}_Nm_per_rad', truth.kq[j])
        postures = campaign_postures(prior, rng)
        path = os.path.join(tmpdir, f'campaign_{i}.csv')
        write_campaign(path, truth_model.build(), postures, truth.kq, rng)
        cases = robomach.read_tracker_file(path, 6)
        fit = robomach.identify_joint_stiffness(prior, cases, tracker_noise_m=NOISE_M)
        u = robomach.stiffness_uncertainty(fit, f'campaign {i}')
        for p, q_deg in enumerate(PREDICT_DEG):
            q = np.radians(q_deg)
            m = robomach.modal_intervals(config, u, q, confidence=confidence, samples=samples, seed=i + 1)
            f = m['modes'][0]['freq_hz']
            out['f1'].append(f['value'])
            out['f1_lo'].append(f['lower'])
            out['f1_hi'].append(f['upper'])
            out['f1_sd'].append(f['std_dev'])
            out['f1_method'].append(m['method'])
            b = robomach.zoa_lobe_band(config, cut, u, q, speeds=speeds, confidence=confidence, samples=samples,
                                       seed=i + 1, id=f'Q{p + 1}')
            out['d'].append(b['min_critical_depth_mm'] * 1e-3)
            out['d_lo'].append(b['min_critical_depth_mm_lower'] * 1e-3)
            out['d_hi'].append(b['min_critical_depth_mm_upper'] * 1e-3)
            out['d_method'].append(b['method'])
        os.remove(path)
    res = {k: np.array(v) for k, v in out.items()}
    res['f1_true'] = np.tile(truth.f1, n)
    res['d_true'] = np.tile(truth.depth, n)
    return res


def summary(res):
    """Coverage of both quantities, pooled and per posture."""
    n_post = len(PREDICT_DEG)
    cov_f = (res['f1_lo'] <= res['f1_true']) & (res['f1_true'] <= res['f1_hi'])
    cov_d = (res['d_lo'] <= res['d_true']) & (res['d_true'] <= res['d_hi'])
    lines = [f'campaigns: {len(cov_f) // n_post}, postures: {n_post}',
             f'lowest frequency: coverage {cov_f.mean():.3f} (per posture ' +
             ', '.join(f'{cov_f[p::n_post].mean():.3f}' for p in range(n_post)) + ')',
             f'smallest critical depth (ZOA): coverage {cov_d.mean():.3f} (per posture ' +
             ', '.join(f'{cov_d[p::n_post].mean():.3f}' for p in range(n_post)) + ')']
    return cov_f, cov_d, lines
