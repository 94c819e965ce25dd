"""Test configuration.

BLAS is pinned to one thread before numpy loads: rotorred's dense problems are small
(a few hundred DOFs), where one thread is as fast as several, and a busy 2-core CI machine
makes multi-threaded OpenBLAS 10-40x slower on them.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
