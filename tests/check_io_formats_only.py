#!/usr/bin/env python3
"""io is formats only (issue #36): the rule test on what io calls.

io reads and writes files. It may use the domain modules' types (build a
model from a config, a surface from its control points, an FRF from its
samples), their names and parsers, their validity checks and accessors; it
may not run their algorithms: those belong to the domain modules, and the
runs that chain reading and algorithms to the workflows layer.

The check reads the undefined symbols of librobomach_io.a (nm), keeps the
functions of the domain namespaces, and fails on any that is neither a
type's own business (ALLOWED) nor one of the calls still waiting to move
(PENDING, each with where and why). A PENDING entry io no longer calls is an
error too, so that the list shrinks as the work moves.

Usage: check_io_formats_only.py path/to/librobomach_io.a
"""
import re
import subprocess
import sys

DOMAINS = ('dynamics', 'stability', 'calibration', 'identification', 'drilling', 'polishing', 'machine',
           'kinematics', 'audit')

# A type's own business: construction from a file's values, names and
# parsers, validity checks, containers and accessors.
ALLOWED = [
    r'.*::(\w+)::\1$',                       # constructors
    r'.*::ToString$', r'.*::Parse\w*$', r'.*::Find\w*Kind$', r'machine::FindAxis$',
    r'.*::CheckValid$', r'.*::\w*Name$',
    r'dynamics::Frf::FromSamples$', r'dynamics::Frf::\w+$', r'dynamics::FrfSet::\w+$',
    r'dynamics::ParameterSet::\w+$', r'dynamics::DefaultParameters$',
    r'dynamics::EffectRegistry::\w+$', r'dynamics::RobotModel::Build$', r'dynamics::Reference[MD]6$',
    r'kinematics::BuildModifiedDhChain$', r'kinematics::ToKdl$', r'kinematics::TransformInertial$',
    r'stability::CuttingCoefficients::FromKsBeta$',
    r'polishing::NurbsSurface::Create$', r'polishing::PathPatternOf$', r'polishing::SampleGrid::\w+$',
    r'calibration::GlobalModalFitResult::ModeShapes$',
    r'dynamics::FrequencyAxisFinding$',      # the sentence of a unit finding
    r'dynamics::CombineIndependent$',        # several uncertainty files read as one
    r'machine::WrapDeviationDeg$',           # a rotary deviation as the file means it
    r'machine::MapKinematicAxes$',           # the machine file's axes to its kinematics
    r'machine::KinematicsKinds$',            # the registry of kinematics type names
]

# Algorithms io still runs, to move (issue #36), each as 'name': 'file: why'.
# Empty since 2026-12-02: the config's joint plausibility is
# dynamics::JointPlausibilityFindings (workflows::LoadRobotConfigChecked),
# axis-acquire's loop and contour figures workflows::WriteAcquiredPath and
# ContourFiguresOf, the mode shapes calibration::ShapesOfRovingTests, the
# polishing path figures workflows::PathFiguresOf, PlanFiguresOf and
# PlannedPathMetadata; io's writers take what they computed.
PENDING = {}


def called_domain_functions(lib):
    out = subprocess.run(['nm', '-C', '--undefined-only', lib], check=True, capture_output=True, text=True).stdout
    names = set()
    pattern = re.compile(r'robomach::((?:%s)::[A-Za-z_][\w:]*)\(' % '|'.join(DOMAINS))
    for line in out.splitlines():
        m = pattern.search(line)
        if m:
            names.add(m.group(1))
    return names


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    names = called_domain_functions(sys.argv[1])
    if not names:
        print('io.formats_only: no domain function found in %s (nm failed to read it?)' % sys.argv[1])
        return 1
    bad = sorted(n for n in names if n not in PENDING and not any(re.match(a, n) for a in ALLOWED))
    stale = sorted(n for n in PENDING if n not in names)
    for n in bad:
        print('io calls %s: an algorithm belongs in its module, a run in workflows (or add it to ALLOWED if it is '
              "the type's own business)" % n)
    for n in stale:
        print('io no longer calls %s: remove it from PENDING' % n)
    print('io.formats_only: %d domain functions called, %d pending to move, %d problem(s)' %
          (len(names), len(PENDING), len(bad) + len(stale)))
    return 1 if bad or stale else 0


if __name__ == '__main__':
    sys.exit(main())
