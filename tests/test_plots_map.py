"""Map figures (bifurcation diagram, waterfall, heat map) draw legible figures from NaN-padded arrays;
bad inputs are refused with the one message form."""

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from matplotlib import colormaps
from matplotlib.figure import Figure

from rotorred.plots.axes import save_figure
from rotorred.plots.map import CLASS_COLOURS, plot_bifurcation, plot_heatmap, plot_lines, plot_waterfall
from rotorred.signals.classify import KINDS

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
SPEEDS = np.linspace(60.0, 110.0, 26)  # outer spool speed (Hz)
S = 40  # Poincaré samples per point, NaN-padded
VIRIDIS_TOP, VIRIDIS_BOTTOM = colormaps["viridis"](1.0)[:3], colormaps["viridis"](0.0)[:3]


def _pixels(path, colour, plot_area=False) -> int:
    """Pixels of ``colour`` in the PNG (within 0.1 in RGB); with ``plot_area`` only in the left 70 % of
    the image, which holds the axes but not the colour bar."""
    rgb = matplotlib.image.imread(path)[..., :3]
    if plot_area:
        rgb = rgb[:, : int(0.7 * rgb.shape[1])]
    target = np.array(matplotlib.colors.to_rgb(colour))
    return int(np.sum(np.linalg.norm(rgb - target, axis=-1) < 0.1))


def _png(path, fig):
    """``fig`` written to ``path`` (its folder made): the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


def _assert_png(path, colours=(), plot_area=False):
    """A PNG, bigger than empty labelled axes, in which each of ``colours`` covers >= 300 pixels."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert len(data) > 20_000
    for colour in colours:
        n = _pixels(path, colour, plot_area)
        assert n >= 300, (colour, n)


def _poincare(shift=0.0):
    """Period-1 below 80 Hz, period-2 to 95 Hz, a quasi-periodic smear above (m), NaN-padded to S."""
    out = np.full((SPEEDS.size, S), np.nan)
    for i, f in enumerate(SPEEDS):
        if f < 80.0 + shift:
            out[i, :5] = 20e-6
        elif f < 95.0 + shift:
            out[i, :6] = np.resize([15e-6, 30e-6], 6)
        else:
            out[i] = 25e-6 + 10e-6 * np.sin(2.4 * np.arange(S))
    return out


def test_class_colours_name_every_class_and_failed():
    assert set(CLASS_COLOURS) == set(KINDS) | {"failed"}
    rgb = {matplotlib.colors.to_hex(c) for c in CLASS_COLOURS.values()}
    assert len(rgb) == len(CLASS_COLOURS)


def test_plot_bifurcation_up_and_down(tmp_path):
    down = _poincare(shift=-4.0)
    down[3] = np.nan  # a failed run
    out = _png(tmp_path / "sub" / "bifurcation.png", plot_bifurcation(
        SPEEDS, {"up": _poincare(), "down": down}, xlabel="Outer spool speed (Hz)", title="Bifurcation"))
    assert out == tmp_path / "sub" / "bifurcation.png"
    _assert_png(out, ["tab:blue", "tab:red"], plot_area=True)


def test_plot_bifurcation_xscale_and_all_failed(tmp_path):
    clearances = np.linspace(0.0, 45e-6, 10)
    out = _png(tmp_path / "failed.png", plot_bifurcation(clearances, {"up": np.full((10, 3), np.nan)},
                                                         xlabel="Rub clearance (µm)", xscale=1e6))
    _assert_png(out)
    assert _pixels(out, "tab:blue", plot_area=True) < 50  # nothing drawn but the legend marker


def test_plot_bifurcation_refuses_bad_input():
    with pytest.raises(ValueError, match=r"^samples\['up'\] = array of shape \(25, 40\): must have shape \(26, S\) "
                                         r"\(m\)$"):
        plot_bifurcation(SPEEDS, {"up": _poincare()[1:]}, xlabel="x")
    with pytest.raises(ValueError, match=r"^samples\['down'\] = array of shape \(26,\): must have shape \(26, S\) "
                                         r"\(m\)$"):
        plot_bifurcation(SPEEDS, {"up": _poincare(), "down": np.zeros(26)}, xlabel="x")
    with pytest.raises(ValueError, match=r"^samples = \{\}: must be a non-empty mapping sweep label -> array "
                                         r"\(n, S\)$"):
        plot_bifurcation(SPEEDS, {}, xlabel="x")
    with pytest.raises(ValueError, match=r"^samples\['up'\] = array of shape \(26, 40\): must hold finite numbers or "
                                         r"NaN \(padding\) only \(m\)$"):
        plot_bifurcation(SPEEDS, {"up": np.where(np.isnan(_poincare()), np.inf, _poincare())}, xlabel="x")
    with pytest.raises(ValueError, match=r"^values = \[\]: must be a 1-D array of at least 1 value$"):
        plot_bifurcation([], {"up": np.zeros((0, 1))}, xlabel="x")
    with pytest.raises(ValueError, match=r"^scale = 0: must be > 0$"):
        plot_bifurcation(SPEEDS, {"up": _poincare()}, xlabel="x", scale=0)


def _lines():
    """Per speed f: 1x at f (strong), 2x (weaker), a combination at 1.5x (weak), NaN-padded to 6 lines;
    the point at index 5 failed (all NaN)."""
    f = np.full((SPEEDS.size, 6), np.nan)
    a = np.full_like(f, np.nan)
    f[:, :3] = SPEEDS[:, None] * [1.0, 2.0, 1.5]
    a[:, :3] = [50e-6, 5e-6, 1e-12]  # the weakest below the colour range: lowest colour
    f[5], a[5] = np.nan, np.nan
    return f, a


def test_plot_waterfall(tmp_path):
    f, a = _lines()
    out = _png(tmp_path / "waterfall.png", plot_waterfall(
        SPEEDS, f, a, xlabel="Outer spool speed (Hz)", f_max=400.0,
        orders={"1× outer": 1.0, "2× outer": 2.0, "3× outer": 3.0}, title="Waterfall"))
    _assert_png(out, [VIRIDIS_TOP, VIRIDIS_BOTTOM], plot_area=True)  # strongest and weakest lines
    plain = _png(tmp_path / "plain.png", plot_waterfall(SPEEDS, f, a, xlabel="Outer spool speed (Hz)", f_max=400.0))
    assert _pixels(out, "0.35", plot_area=True) > _pixels(plain, "0.35", plot_area=True) + 200  # the order lines
    empty = _png(tmp_path / "empty.png", plot_waterfall(SPEEDS[:2], np.full((2, 3), np.nan), np.full((2, 3), np.nan),
                                                        xlabel="Outer spool speed (Hz)", orders={"1×": 1.0}))
    assert empty.read_bytes()[:8] == PNG_SIGNATURE


def test_plot_waterfall_refuses_bad_input():
    f, a = _lines()
    with pytest.raises(ValueError, match=r"^amplitudes = array of shape \(26, 5\): must have shape \(26, 6\) \(m\)$"):
        plot_waterfall(SPEEDS, f, a[:, :5], xlabel="x")
    with pytest.raises(ValueError, match=r"^frequencies = array of shape \(25, 6\): must have shape \(26, L\) \(Hz\)$"):
        plot_waterfall(SPEEDS, f[1:], a, xlabel="x")
    with pytest.raises(ValueError, match=r"^amplitudes = array of shape \(26, 6\): must hold values >= 0 or NaN "
                                         r"\(padding\) only \(m\)$"):
        plot_waterfall(SPEEDS, f, -a, xlabel="x")
    with pytest.raises(ValueError, match=r"^f_max = 0: must be > 0 \(Hz\)$"):
        plot_waterfall(SPEEDS, f, a, xlabel="x", f_max=0)
    with pytest.raises(ValueError, match=r"^orders\['1×'\] = -1.0: must be > 0 \(Hz per unit of values\)$"):
        plot_waterfall(SPEEDS, f, a, xlabel="x", orders={"1×": -1.0})
    with pytest.raises(ValueError, match=r"^dynamic_range = 1: must be > 1$"):
        plot_waterfall(SPEEDS, f, a, xlabel="x", dynamic_range=1)


def test_plot_lines_of_a_clearance_sweep(tmp_path):
    """Lines, contact and the free reach marker; a failed point (NaN) is a gap, not an error."""
    c = np.array([5e-6, 20e-6, 40e-6, 50e-6, 60e-6])
    amps = {"f_L": np.array([9e-6, 9e-6, 9e-6, 9e-6, np.nan]), "f_H": np.full(5, 12e-6),
            "2f_H-f_L": np.array([3e-6, 2e-6, 1e-6, 0.0, np.nan]), "f_H-f_L": np.array([1e-6, 1e-6, 0.5e-6, 0.0, 0.0])}
    out = _png(tmp_path / "lines.png", plot_lines(c, amps, [0.1, 0.08, 0.03, 0.0, np.nan], [9, 7, 2, 0, np.nan],
                                                  xlabel="Rub clearance (µm)", xscale=1e6, reach=43e-6, title="sweep"))
    _assert_png(out, ["C0", "C1", "C3"])  # f_L, f_H and the contact fraction drawn
    without = _png(tmp_path / "plain.png", plot_lines(c, amps, [0.1, 0.08, 0.03, 0.0, np.nan], [9, 7, 2, 0, np.nan],
                                                      xlabel="Rub clearance (µm)", xscale=1e6, title="sweep"))
    # the same but the reach
    rgb, rgb_without = (matplotlib.image.imread(p)[..., :3] for p in (out, without))
    differs = np.any(np.abs(rgb - rgb_without) > 0.05, axis=-1)
    line = np.nonzero(differs.sum(axis=0) > 0.5 * differs.shape[0])[0]  # columns that differ over half the height
    assert 1 <= line.size <= 3 and np.ptp(line) <= 2  # the reach: one vertical line (628 of 900 rows measured)
    grey = np.ptp(rgb[differs[:, line[0]], line[0]], axis=-1) < 0.02
    assert grey.mean() > 0.9  # grey, but where it crosses a coloured line (98 % of its pixels measured)
    with pytest.raises(ValueError, match=r"^amplitudes\['f_L'\] = array of shape \(4,\): must have shape \(5\) \(m\)$"):
        plot_lines(c, {"f_L": np.ones(4)}, np.zeros(5), np.zeros(5), xlabel="x")
    with pytest.raises(ValueError, match=r"^amplitudes\['f_L'\] = .*must hold values >= 0 or NaN"):
        plot_lines(c, {"f_L": -np.ones(5)}, np.zeros(5), np.zeros(5), xlabel="x")
    with pytest.raises(ValueError, match=r"^amplitudes = \[1, 2\]: must be a mapping line label -> array \(n,\)$"):
        plot_lines(c, [1, 2], np.zeros(5), np.zeros(5), xlabel="x")
    with pytest.raises(ValueError, match=r"^ax = .*: must be a pair of axes \(top, bottom\): the lines figure has two "
                                         r"panels$"):
        plot_lines(c, amps, np.zeros(5), np.zeros(5), Figure().subplots(), xlabel="x")


def test_plot_lines_draws_into_a_pair_of_axes():
    """Given two axes, the two panels are drawn into them (the figure theirs), the amplitudes above, the contact
    fraction below (and the impacts on its twin)."""
    fig = Figure()
    top, bottom = fig.subplots(2, 1)
    c = np.array([5e-6, 20e-6, 40e-6])
    drawn = plot_lines(c, {"f_L": np.full(3, 9e-6), "f_H": np.full(3, 1e-6)}, [0.1, 0.0, 0.0], [3, 0, 0],
                       (top, bottom), xlabel="clearance", title="into axes")
    assert drawn is fig and len(top.lines) == 2 and len(bottom.lines) == 1 and len(fig.axes) == 3
    assert top.get_title() == "into axes" and not fig.get_suptitle()


CLEARANCES = np.array([0.0, 5e-6, 10e-6, 20e-6, 45e-6])  # non-uniform (m)
SPEEDS_2D = np.array([60.0, 70.0, 80.0, 90.0, 100.0, 110.0])


def test_plot_heatmap_classes(tmp_path):
    names = list(CLASS_COLOURS)
    z = np.arange(CLEARANCES.size * SPEEDS_2D.size).reshape(CLEARANCES.size, SPEEDS_2D.size) % len(names)
    full = _png(tmp_path / "classes.png", plot_heatmap(SPEEDS_2D, CLEARANCES, z, xlabel="Outer spool speed (Hz)",
                                                       ylabel="Rub clearance (µm)", zlabel="Response class",
                                                       yscale=1e6, categories=names))
    _assert_png(full, CLASS_COLOURS.values(), plot_area=True)
    z[0, :] = -1  # missing points are blank
    gaps = _png(tmp_path / "gaps.png", plot_heatmap(SPEEDS_2D, CLEARANCES, z, xlabel="Outer spool speed (Hz)",
                                                    ylabel="Rub clearance (µm)", zlabel="Response class", yscale=1e6,
                                                    categories=names))
    assert _pixels(gaps, "white", plot_area=True) > _pixels(full, "white", plot_area=True) + 5_000


def test_plot_heatmap_continuous_single_row_and_nan(tmp_path):
    z = np.linspace(0.0, 1.0, CLEARANCES.size * SPEEDS_2D.size).reshape(CLEARANCES.size, SPEEDS_2D.size)
    full = _png(tmp_path / "contact.png", plot_heatmap(SPEEDS_2D, CLEARANCES, z, xlabel="Outer spool speed (Hz)",
                                                       ylabel="Rub clearance (µm)", zlabel="Contact fraction (-)",
                                                       yscale=1e6))
    _assert_png(full, [VIRIDIS_TOP, VIRIDIS_BOTTOM], plot_area=True)
    z[2, 3] = z[4, :] = np.nan
    holes = _png(tmp_path / "holes.png", plot_heatmap(SPEEDS_2D, CLEARANCES, z, xlabel="Outer spool speed (Hz)",
                                                      ylabel="Rub clearance (µm)", zlabel="Contact fraction (-)",
                                                      yscale=1e6))
    assert _pixels(holes, "white", plot_area=True) > _pixels(full, "white", plot_area=True) + 5_000
    row = _png(tmp_path / "row.png", plot_heatmap(SPEEDS_2D[::-1], [20e-6], z[1:2], xlabel="Outer spool speed (Hz)",
                                                  ylabel="Rub clearance (µm)", zlabel="Contact fraction (-)",
                                                  yscale=1e6))
    _assert_png(row)
    blank = _png(tmp_path / "blank.png", plot_heatmap([60.0], [20e-6], [[np.nan]], xlabel="x", ylabel="y", zlabel="z"))
    assert blank.read_bytes()[:8] == PNG_SIGNATURE


def test_plot_heatmap_refuses_bad_input():
    z = np.zeros((CLEARANCES.size, SPEEDS_2D.size))
    kw = dict(xlabel="x", ylabel="y", zlabel="z")
    with pytest.raises(ValueError, match=r"^z = array of shape \(6, 5\): must have shape \(5, 6\)$"):
        plot_heatmap(SPEEDS_2D, CLEARANCES, z.T, **kw)
    with pytest.raises(ValueError, match=r"^x = \[60.0, 80.0, 70.0\]: must be strictly increasing or strictly "
                                         r"decreasing$"):
        plot_heatmap([60.0, 80.0, 70.0], CLEARANCES, z[:, :3], **kw)
    with pytest.raises(ValueError, match=r"^z = array of shape \(5, 6\): must hold category indices 0 to 1, "
                                         r"or -1 for missing$"):
        plot_heatmap(SPEEDS_2D, CLEARANCES, z + 2, categories=["periodic", "chaotic"], **kw)
    with pytest.raises(ValueError, match=r"^categories = \['periodic', 'periodic'\]: must not list an entry twice$"):
        plot_heatmap(SPEEDS_2D, CLEARANCES, z, categories=["periodic", "periodic"], **kw)
    with pytest.raises(ValueError, match=r"^categories = 'periodic': must be a list of category names$"):
        plot_heatmap(SPEEDS_2D, CLEARANCES, z, categories="periodic", **kw)
    with pytest.raises(ValueError, match=r"^yscale = -1.0: must be > 0$"):
        plot_heatmap(SPEEDS_2D, CLEARANCES, z, yscale=-1.0, **kw)
