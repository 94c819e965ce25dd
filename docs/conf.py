"""Sphinx configuration of rotorred's documentation site.

Build (offline, warnings as errors; the README names this command and ``.ci/run`` runs it)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

What the build makes, so that nothing on the site can go stale:

* the API reference: one page per name of ``rotorred.__all__``, generated from the docstrings (autosummary, numpydoc)
  into ``docs/api/generated/``, grouped by layer (:data:`API_GROUPS`); a name in no group stops the build;
* the gallery (``examples/`` -> ``docs/gallery/``) and the tutorials (``tutorials/`` -> ``docs/tutorials/``): every
  script is executed by sphinx-gallery and every figure of the site is one of theirs;
* the Markdown pages (myst-parser).

Offline: no intersphinx, no asset from the network (the theme's icon links, analytics and version switcher are off;
the few formulas of the docstrings are written as MathML by :func:`mathml_renderer`, not fetched MathJax).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "sphinxext"))  # rotorred_figures: the gallery's scraper of rotorred's figures

os.environ.setdefault("MPLBACKEND", "agg")
# one thread for BLAS and numba in the executed scripts, as the commands run (2 cores: the build runs alone)
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import rotorred  # noqa: E402

project = "rotorred"
author = "rotorred contributors"
copyright = "rotorred contributors"
release = rotorred.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "**/README.txt", "gallery/*.md5", "tutorials/*.md5", "**/*.ipynb", "**/*.py",
                    "**/*.zip", "**/*.pickle", "**/*.json"]

# --- docstrings ---------------------------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc Parameters give every type, with its shape and unit
autodoc_inherit_docstrings = True
numpydoc_show_class_members = False  # the class page lists its members itself (autodoc :members:)
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# --- Markdown pages -----------------------------------------------------------------------------------------------
myst_enable_extensions = ["colon_fence"]
myst_heading_anchors = 3  # "#coming-from-ross"-style anchors of the Markdown headings, as on GitHub

# --- theme: pydata-sphinx-theme, nothing fetched -----------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"rotorred {release}"
html_static_path = ["_static"]
html_css_files = ["rotorred.css"]
html_show_sourcelink = False
html_copy_source = True  # the search page's result previews read _sources/
html_theme_options = {
    "icon_links": [],
    "analytics": {},
    "show_version_warning_banner": False,
    "navbar_end": ["theme-switcher", "navbar-icon-links"],
    "navigation_with_keys": False,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
    "header_links_before_dropdown": 8,
}
html_context = {"default_mode": "light"}

# --- the gallery and the tutorials (sphinx-gallery) ---------------------------------------------------------------
#: (scripts folder at the repository's root, generated folder under docs/)
GALLERIES = (("examples", "gallery"), ("tutorials", "tutorials"))

sphinx_gallery_conf = {
    "examples_dirs": [f"../{src}" for src, _ in GALLERIES],
    "gallery_dirs": [out for _, out in GALLERIES],
    "filename_pattern": r"\.py$",  # every script is executed, not only plot_*
    "ignore_pattern": r"(__init__|_helpers?)\.py",
    "download_all_examples": False,
    "show_signature": False,
    "remove_config_comments": True,
    "write_computation_times": False,  # no "Computation times" pages (each example page gives its own time)
    "min_reported_time": 0,  # every page says how long its script ran (tests/e2e/test_site.py reads it)
    "capture_repr": ("_repr_html_", "__repr__"),
    "matplotlib_animations": False,
    "image_scrapers": ("rotorred_figures.scrape", "matplotlib"),  # result.plot() figures, then pyplot's
    "reset_modules": ("matplotlib",),
    "within_subsection_order": "FileNameSortKey",
}

# --- the API reference --------------------------------------------------------------------------------------------
#: the API's groups, one page each, in the order of the layers (tests/test_architecture.py): (page, title, what it
#: holds, the modules whose names it holds). Every name of rotorred.__all__ must fall in exactly one group.
API_GROUPS = (
    ("model", "Model", "rotors, elements, assembly, loads, speed profiles, operating points", ("rotorred.model",)),
    ("linear", "Linear analyses", "Campbell diagrams, critical speeds, mode shapes, separation margins, unbalance and "
     "frequency responses, Craig–Bampton reduction", ("rotorred.linear",)),
    ("transient", "Transient", "the compiled Newmark/HHT-α step, rub plates, options, results, energy balance",
     ("rotorred.transient",)),
    ("nonlinear", "Nonlinear", "harmonic balance (periodic and on a torus), continuation through folds, Floquet "
     "stability", ("rotorred.nonlinear",)),
    ("signals", "Signals", "spectra, line fit, settling, response classes, Poincaré samples, order tracks",
     ("rotorred.signals",)),
    ("scenes", "Scenes", "scene files, runs, run-ups, harmonic balance of a rub scene, branches, reduced against full",
     ("rotorred.scenes",)),
    ("maps", "Maps", "maps of the operating envelope", ("rotorred.maps",)),
    ("plots", "Plots", "figures and the figure pool", ("rotorred.plots",)),
    ("services", "Services", "input checks, file writers, progress, provenance (the bottom layer)", (
        "rotorred.checks", "rotorred.writers", "rotorred.progress", "rotorred.provenance", "rotorred.results")),
)


def defining_module(name: str) -> str:
    """The module that defines a public name of ``rotorred`` (the module itself for a public module)."""
    if name in rotorred._MODULES:
        return f"rotorred.{name}"
    return rotorred._EXPORTS[name]


def api_groups() -> dict[str, list[str]]:
    """Group page -> the public names it documents, in the order of ``rotorred/__init__.py``.

    Raises RuntimeError (which stops the build) for a name of ``rotorred.__all__`` that no group holds."""
    order = {name: k for k, name in enumerate([*rotorred._MODULES, *rotorred._EXPORTS])}
    groups: dict[str, list[str]] = {page: [] for page, _, _, _ in API_GROUPS}
    orphans = []
    for name in sorted(rotorred.__all__, key=order.__getitem__):
        module = defining_module(name)
        pages = [page for page, _, _, prefixes in API_GROUPS
                 if any(module == p or module.startswith(p + ".") for p in prefixes)]
        if len(pages) != 1:
            orphans.append(f"{name} ({module})")
        else:
            groups[pages[0]].append(name)
    if orphans:
        raise RuntimeError("docs/conf.py: names of rotorred.__all__ in no group of API_GROUPS (add their layer): "
                           + ", ".join(orphans))
    return groups


def write_api_pages(out: Path = DOCS / "api" / "generated") -> None:
    """Write one page per group (an autosummary table whose stubs, one per name, autosummary generates)."""
    out.mkdir(parents=True, exist_ok=True)
    groups = api_groups()
    for page, title, what, prefixes in API_GROUPS:
        names = groups[page]
        text = [f".. _api-{page}:", "", title, "=" * len(title), "",
                what[0].upper() + what[1:] + ": the names defined in " + ", ".join(f"``{p}``" for p in prefixes)
                + ", all importable from ``rotorred`` (``import rotorred as rr``).", "", ".. currentmodule:: rotorred", "",
                ".. autosummary::", "   :toctree: .", "", *[f"   {name}" for name in names], ""]
        path = out / f"{page}.rst"
        new = "\n".join(text)
        if not path.is_file() or path.read_text() != new:  # unchanged pages keep their time: no needless rebuild
            path.write_text(new)


write_api_pages()


# --- formulas as MathML (no MathJax from the network) --------------------------------------------------------------
def mathml_renderer(app):
    """Render :math: and .. math:: as MathML (docutils' LaTeX -> MathML), which Chromium draws natively."""
    from docutils.utils.math import latex2mathml

    def html_visit_math(self, node):
        self.body.append(latex2mathml.tex2mathml(node.astext()))
        from docutils import nodes
        raise nodes.SkipNode

    def html_visit_displaymath(self, node):
        self.body.append('<div class="math">' + latex2mathml.tex2mathml(node.astext(), as_block=True) + "</div>")
        from docutils import nodes
        raise nodes.SkipNode

    app.add_html_math_renderer("mathml", (html_visit_math, None), (html_visit_displaymath, None))


html_math_renderer = "mathml"


# --- a public constant's doc comment ------------------------------------------------------------------------------
def constant_docstring(app, what, name, obj, options, lines):
    """A constant exported by ``rotorred`` (an int has int's docstring) gets the ``#:`` comment written above it in
    the module that defines it."""
    short = name.rsplit(".", 1)[-1]
    if what not in ("data", "attribute") or name != f"rotorred.{short}" or short not in rotorred._EXPORTS:
        return
    from sphinx.pycode import ModuleAnalyzer

    comment = ModuleAnalyzer.for_module(rotorred._EXPORTS[short]).find_attr_docs().get(("", short))
    if comment:
        lines[:] = [line for line in comment if line.strip()] + [""]


def setup(app):
    mathml_renderer(app)
    app.connect("autodoc-process-docstring", constant_docstring)
    return {"parallel_read_safe": True}

