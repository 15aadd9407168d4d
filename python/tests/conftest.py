"""Shared fixtures of the Python module's tests: paths from ctest's
environment (python/CMakeLists.txt), and a runner for the built tools."""
import os
import subprocess

import pytest

SOURCE_DIR = os.environ.get('ROBOMACH_SOURCE_DIR',
                            os.path.abspath(os.path.join(os.path.dirname(__file__), '..', '..')))
BINARY_DIR = os.environ.get('ROBOMACH_BINARY_DIR', os.path.join(SOURCE_DIR, 'build'))
KR210 = os.path.join(SOURCE_DIR, 'config', 'kr210.yaml')
DATA = os.path.join(SOURCE_DIR, 'tests', 'data')


def tool_path(name):
    """The built tool `name` (apps/), or None if apps were not built."""
    p = os.path.join(BINARY_DIR, 'apps', name)
    return p if os.access(p, os.X_OK) else None


def run_tool(name, *args, expect_rc=0):
    exe = tool_path(name)
    if exe is None:
        pytest.skip(f'{name} is not built (ROBOMACH_BUILD_APPS=OFF?): no C++ reference to compare with')
    r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=120)
    assert expect_rc is None or r.returncode == expect_rc, f'{name} exited {r.returncode}:\n{r.stderr}'
    return r


@pytest.fixture
def tmp(tmp_path):
    return tmp_path
