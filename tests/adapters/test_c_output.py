"""An engine's C output kept off the caller's streams (adapters/c_output.py)."""

from __future__ import annotations

import subprocess
import sys


def test_c_output_dropped_keeps_a_libraries_own_lines_off_both_streams():
    """What C code writes to file descriptors 1 and 2 inside the block (an engine's banner)
    is gone; Python's writes before and after it reach the caller, in order."""
    script = (
        "import os, sys\n"
        "from dyncheck.adapters.c_output import c_output_dropped\n"
        "print('before', flush=True)\n"
        "with c_output_dropped():\n"
        "    os.write(1, b'banner-out\\n'); os.write(2, b'banner-err\\n')\n"
        "print('after', flush=True); print('err-after', file=sys.stderr, flush=True)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60, check=True)
    assert done.stdout == "before\nafter\n" and done.stderr == "err-after\n"

