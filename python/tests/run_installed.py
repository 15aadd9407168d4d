"""The acceptance check of the install: `cmake --install` the Python
component into a scratch prefix, then run test_frf_predict.py (the ten-line
script against frf-predict to 1e-12) with `robomach` imported from that
prefix only (PYTHONPATH is the prefix's packages folder, never the build
tree; test_frf_predict checks where the module came from).

  run_installed.py <cmake> <build dir> <scratch prefix> <packages folder relative to the prefix>
"""
import os
import shutil
import subprocess
import sys

cmake, build, prefix, packages = sys.argv[1:5]
here = os.path.dirname(os.path.abspath(__file__))
shutil.rmtree(prefix, ignore_errors=True)
subprocess.run([cmake, '--install', build, '--component', 'python', '--prefix', prefix], check=True,
               stdout=subprocess.DEVNULL)
site = os.path.join(prefix, packages)
if not any(f.startswith('robomach.') and f.endswith('.so') for f in os.listdir(site)):
    sys.exit(f'run_installed.py: cmake --install put no robomach module into {site}')
env = dict(os.environ, PYTHONPATH=site, ROBOMACH_EXPECT_MODULE_DIR=site)
sys.exit(subprocess.run([sys.executable, os.path.join(here, 'run_pytest.py'),
                         os.path.join(here, 'test_frf_predict.py')], env=env).returncode)
