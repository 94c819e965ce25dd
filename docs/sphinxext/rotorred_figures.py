"""A sphinx-gallery image scraper for rotorred's figures.

rotorred draws into :class:`matplotlib.figure.Figure` objects that pyplot does not manage (``result.plot()``
returns one; ``rotorred.plots``), which sphinx-gallery's matplotlib scraper, reading pyplot's figures, does not see.
This scraper saves, after each code block of an example, every such Figure the example holds in a variable (or in a
list, tuple or dict held in one) that it has not saved yet, in the order they were made.
"""

from __future__ import annotations

from matplotlib.figure import Figure
from sphinx_gallery.scrapers import figure_rst

#: block_vars key of the ids of the figures this example has already had saved
_SEEN = "rotorred_figures_seen"


def _figures(value, depth: int = 0):
    if isinstance(value, Figure):
        yield value
    elif depth < 2 and isinstance(value, (list, tuple)):
        for item in value:
            yield from _figures(item, depth + 1)
    elif depth < 2 and isinstance(value, dict):
        for item in value.values():
            yield from _figures(item, depth + 1)


def scrape(block, block_vars, gallery_conf, **kwargs):
    """Save the example's new unmanaged Figures; return their reST (sphinx-gallery's image scraper protocol)."""
    seen = block_vars.setdefault(_SEEN, set())
    new = {}
    for name, value in list(block_vars["example_globals"].items()):
        if name.startswith("__"):
            continue
        for fig in _figures(value):
            if id(fig) not in seen and id(fig) not in new and getattr(fig.canvas, "manager", None) is None:
                new[id(fig)] = fig
    paths = []
    for fig in new.values():  # in the order of the example's variables
        path = next(block_vars["image_path_iterator"])
        fig.savefig(path, dpi=fig.dpi)
        paths.append(path)
        seen.add(id(fig))
    return figure_rst(paths, gallery_conf["src_dir"])
