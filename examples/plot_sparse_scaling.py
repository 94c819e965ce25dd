"""
Sparse models: cost against model size
======================================

What an analysis of the full model costs as the mesh grows, from the paper's rig (80 DOFs) to the rig refined 128
times (9224 DOFs): assembly, one speed of a Campbell diagram, one speed of an unbalance response and a Craig–Bampton
reduction, each on the sparse path and, up to 1160 DOFs, on the dense one beside it, with the growth exponent of
each sparse task.

The benchmark takes minutes, too long for the build of this site: ``python validation/bench_sparse.py --checks --csv
docs/data/bench_sparse.csv`` measured it once (one thread, each mesh in its own process) and wrote the CSV this
script reads; its first lines name the machine, the commit and the date.
"""

# %%
# The measured table, read with the benchmark script's own reader (``validation/bench_sparse.py``).
import importlib.util
from pathlib import Path

import matplotlib.pyplot as plt

try:
    ROOT = Path(__file__).resolve().parents[1]
except NameError:  # run by hand from examples/
    ROOT = Path.cwd().parent
spec = importlib.util.spec_from_file_location("bench_sparse", ROOT / "validation" / "bench_sparse.py")
bench = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bench)

rows, header = bench.read_csv(ROOT / "docs" / "data" / "bench_sparse.csv")
print("\n".join(header))
for r in rows:
    print(f"{r['n_dof']:>5} DOFs {'sparse' if r['sparse'] else 'dense ':<6}  Campbell/speed {r['campbell_speed']:.3g} s, "
          f"unbalance/speed {r['unbalance_freq']:.3g} s, reduction {r['reduction']:.3g} s")

# %%
# Growth exponents: the slope of log(cost) against log(DOFs) over the sparse rows from 1000 DOFs on. A banded
# sparse factorisation is O(n): the exponents near 1 say the sparse path grows about linearly, where the dense
# eigen-solution grows as n³.
for task, p in bench.exponents(rows).items():
    print(f"{bench.LABELS[task]:<20} n^{p:.2f}")

# %%
# Cost (left) and traced memory (right) against DOFs, log-log: sparse solid, dense dashed.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 5.6))
bench.draw(rows, ax1, ax2)
fig.tight_layout(rect=(0, 0.15, 1, 1))
plt.show()
