"""What a figure worker imports (:mod:`rotorred.plots.pool`): once in the fork server, so that each worker forked
from it starts with matplotlib (Agg) and the plot module imported, while the caller computes."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.figure  # noqa: E402,F401
import matplotlib.patches  # noqa: E402,F401
import matplotlib.transforms  # noqa: E402,F401

import rotorred.plots.scene  # noqa: E402,F401 - light: no signals module, no pyFFTW (the jobs carry plain arrays)
