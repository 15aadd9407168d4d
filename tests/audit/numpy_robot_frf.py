#!/usr/bin/env python3
"""A second model of the KR210 milling system that shares no code with robomach
(issue #33: test data the library's own code did not make).

From the URDF (xml.etree) and the end effector of config/kr210.yaml (values
below, with the config as their source): forward kinematics by homogeneous
transforms (URDF origin rpy = fixed-axis x, y, z), the geometric Jacobian of
every body's centre of mass from the joint axes, M(q) = sum_b m_b Jv_b' Jv_b +
Jw_b' I_b Jw_b, K = diag(kq), C = alpha K + beta M, and the tool-tip receptance
H(w) = Jv_T (K - w^2 M + i w C)^-1 Jv_T'. Writes the xx and yy FRFs of the
postures of a posture CSV with 2 % complex Gaussian noise (seeded) as the FRF
CSV of docs/formats.md section 3.

usage: numpy_robot_frf.py URDF POSTURES_CSV OUT_CSV kq1 ... kq6 [--seed N]
"""
import csv
import math
import sys
import xml.etree.ElementTree as ET

import numpy as np

# config/kr210.yaml: end effector in the tool0 frame, damping.
EE_BODIES = [  # mass [kg], COM [m], inertia about the COM (Ixx Iyy Izz) [kg m^2]
    (22.0, (0.0, 0.0, 0.110), (0.256, 0.256, 0.062)),
    (0.45, (0.0, 0.0, 0.290), (4.0e-4, 4.0e-4, 5.0e-5)),
]
TCP = np.array([0.0, 0.0, 0.335])
ALPHA_S, BETA_PER_S = 1.0e-4, 5.0


def rot_rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def rot_axis(a, t):
    a = np.asarray(a, float) / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def transform(rpy, xyz):
    t = np.eye(4)
    t[:3, :3] = rot_rpy(*rpy)
    t[:3, 3] = xyz
    return t


def floats(s, n=3):
    return [float(v) for v in s.split()] if s else [0.0] * n


def load(urdf):
    root = ET.parse(urdf).getroot()
    links = {}
    for l in root.findall("link"):
        i = l.find("inertial")
        if i is None:
            continue
        o = i.find("origin")
        t = transform(floats(o.get("rpy")), floats(o.get("xyz")))
        I = i.find("inertia")
        Ic = np.array([[float(I.get("ixx")), float(I.get("ixy")), float(I.get("ixz"))],
                       [float(I.get("ixy")), float(I.get("iyy")), float(I.get("iyz"))],
                       [float(I.get("ixz")), float(I.get("iyz")), float(I.get("izz"))]])
        links[l.get("name")] = (float(i.find("mass").get("value")), t, Ic)
    joints = {}
    for j in root.findall("joint"):
        o = j.find("origin")
        a = j.find("axis")
        joints[j.find("child").get("link")] = (j.get("type"), j.find("parent").get("link"),
                                                transform(floats(o.get("rpy")), floats(o.get("xyz"))),
                                                floats(a.get("xyz")) if a is not None else None)
    # The chain from base_link to tool0.
    chain, link = [], "tool0"
    while link in joints:
        chain.append((link,) + joints[link])
        link = joints[link][1]
    chain.reverse()
    return links, chain


def bodies_and_axes(links, chain, q):
    """World poses: the list of (mass, com, inertia in world) of every body, the
    joint axes (origin, unit axis) and the tool-tip position."""
    t = np.eye(4)
    axes, bodies, k = [], [], 0
    if "base_link" in links:
        pass  # the base does not move: no kinetic energy
    for child, typ, parent, origin, axis in chain:
        t = t @ origin
        if typ == "revolute":
            a = t[:3, :3] @ np.array(axis) / np.linalg.norm(axis)
            axes.append((t[:3, 3].copy(), a))
            r = np.eye(4)
            r[:3, :3] = rot_axis(axis, q[k])
            t = t @ r
            k += 1
        if child in links:
            m, ti, Ic = links[child]
            tb = t @ ti
            R = tb[:3, :3]
            bodies.append((m, tb[:3, 3].copy(), R @ Ic @ R.T, len(axes)))
        if child == "tool0":
            for m, c, d in EE_BODIES:
                R = t[:3, :3]
                bodies.append((m, (t @ np.array([*c, 1.0]))[:3], R @ np.diag(d) @ R.T, len(axes)))
            tip = (t @ np.array([*TCP, 1.0]))[:3]
    return bodies, axes, tip


def dynamics(links, chain, q, kq):
    bodies, axes, tip = bodies_and_axes(links, chain, q)
    n = len(axes)
    M = np.zeros((n, n))
    for m, c, I, moved_by in bodies:
        jv, jw = np.zeros((3, n)), np.zeros((3, n))
        for k in range(moved_by):
            o, a = axes[k]
            jv[:, k] = np.cross(a, c - o)
            jw[:, k] = a
        M += m * jv.T @ jv + jw.T @ I @ jw
    jt = np.zeros((3, n))
    for k, (o, a) in enumerate(axes):
        jt[:, k] = np.cross(a, tip - o)
    K = np.diag(kq)
    return M, K, jt


def main(argv):
    seed = 2033
    if "--seed" in argv:
        i = argv.index("--seed")
        seed = int(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    urdf, postures_csv, out = argv[1], argv[2], argv[3]
    kq = np.array([float(v) for v in argv[4:10]])
    links, chain = load(urdf)
    rng = np.random.default_rng(seed)
    freq = np.arange(1, 2001) * 0.25  # 0.25 .. 500 Hz
    rows = []
    with open(postures_csv) as f:
        for r in csv.DictReader(line for line in f if not line.startswith("#")):
            q = np.radians([float(r["q%d_deg" % (j + 1)]) for j in range(6)])
            M, K, jt = dynamics(links, chain, q, kq)
            C = ALPHA_S * K + BETA_PER_S * M
            for d, name in ((0, "x"), (1, "y")):
                for fz in freq:
                    w = 2 * math.pi * fz
                    h = jt[d] @ np.linalg.solve(K - w * w * M + 1j * w * C, jt[d])
                    h *= 1.0 + 0.02 * (rng.normal() + 1j * rng.normal()) / math.sqrt(2.0)
                    rows.append((r["pose_id"], name, name, fz, h.real, h.imag))
    with open(out, "w") as f:
        f.write("# quantity: receptance\n# written by tests/audit/numpy_robot_frf.py (a second model, NumPy)\n")
        f.write("pose_id,response,excitation,freq_hz,re,im\n")
        for p, a, b, fz, re, im in rows:
            f.write("%s,%s,%s,%.6g,%.12g,%.12g\n" % (p, a, b, fz, re, im))


if __name__ == "__main__":
    main(sys.argv)
