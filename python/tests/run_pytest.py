"""Runs one pytest file for ctest (python/CMakeLists.txt). Exits 77, which
ctest reports as skipped, with a message when numpy or pytest is missing
from this interpreter; the module itself must import (a build error is a
failure, not a skip)."""
import sys

missing = []
for name in ('numpy', 'pytest'):
    try:
        __import__(name)
    except ImportError:
        missing.append(name)
if missing:
    print(f'python tests skipped: {", ".join(missing)} not installed for {sys.executable} '
          f'(Debian: apt-get install python3-numpy python3-pytest; scripts/setup-deps.sh)')
    sys.exit(77)

import pytest  # noqa: E402

sys.exit(pytest.main(['-q', '-p', 'no:cacheprovider', *sys.argv[1:]]))
