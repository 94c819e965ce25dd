"""The drawings draw legible PNG files from plain arrays, into a new figure or given axes; bad inputs are refused."""

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from matplotlib.figure import Figure

from functools import partial

from rotorred.plots.axes import save_figure
from rotorred.plots.scene import draw_orbits, draw_poincare, draw_spectra, draw_waveforms, plot_label, write_figure
from rotorred.signals.linefit import fit_peaks
from rotorred.signals.spectra import settled_spectrum

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
DT = 1e-5
T = np.arange(30_000) * DT  # 0.3 s: three common periods of 70/90 Hz
COMBOS = [(0, 1, 0.3), (1, 0, 1.0), (1, -1, 0.05), (2, -1, 0.1), (0, 2, 0.2), (2, 1, 0.08)]


def _signal(phase=0.0):
    return 60e-6 * sum(
        a * np.cos(2 * np.pi * (m * 90.0 + n * 70.0) * T + phase + m) for m, n, a in COMBOS
    )


def _assert_png(path, n_series=2):
    """A PNG, bigger than empty labelled axes (~16 kB at this size), in which the curves of
    the first ``n_series`` default colours are drawn (>= 300 pixels of each)."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert len(data) > 20_000
    rgb = matplotlib.image.imread(path)[..., :3]
    for colour in ["C0", "C1"][:n_series]:
        target = np.array(matplotlib.colors.to_rgb(colour))
        n_pixels = np.sum(np.linalg.norm(rgb - target, axis=-1) < 0.1)
        assert n_pixels >= 300, (colour, n_pixels)


def test_draw_waveforms(tmp_path):
    rub = _signal()
    normal = 60e-6 * np.cos(2 * np.pi * 90.0 * T)
    signals = {"node 13 (inner)": {"normal": 0.05 * normal}, "node 14 (outer)": {"normal": normal, "rub": rub}}
    out = write_figure(tmp_path / "sub" / "waveforms.png",
                       partial(draw_waveforms, T, signals, title="Y displacement", t_window=(0.1, 0.2)))
    assert out == tmp_path / "sub" / "waveforms.png"
    _assert_png(out)
    # into given axes: every panel's series, a label of two panels prefixed with its panel
    ax = Figure().subplots()
    assert draw_waveforms(T, signals, ax, t_window=(0.1, 0.2)) is ax.figure
    assert [line.get_label() for line in ax.lines] == ["node 13 (inner): normal", "node 14 (outer): normal", "rub"]
    np.testing.assert_array_equal(ax.lines[2].get_ydata(), 1e6 * rub[(T >= 0.1) & (T <= 0.2)])
    with pytest.raises(ValueError, match="must have 30000 samples"):
        draw_waveforms(T, {"a": rub[:-1]})
    with pytest.raises(ValueError, match=r"^t_window = \(0.2, 0.1\): must be \(start, end\) with start < end \(s\)"):
        draw_waveforms(T, {"a": rub}, t_window=(0.2, 0.1))
    with pytest.raises(ValueError, match="^signals = {}: must be a non-empty mapping"):
        draw_waveforms(T, {})
    with pytest.raises(ValueError, match="mixes panels"):
        draw_waveforms(T, {"a": rub, "b": {"c": rub}})


def test_plot_spectra_with_labels_linear_and_log(tmp_path):
    s_rub = settled_spectrum(_signal(), DT, 70.0, 90.0)
    s_normal = settled_spectrum(60e-6 * np.cos(2 * np.pi * 90.0 * T), DT, 70.0, 90.0)
    lines = fit_peaks(T, _signal(), 70.0, 90.0, spectrum=s_rub).lines
    assert len(lines) == len(COMBOS)
    out = save_figure(draw_spectra({"normal": s_normal, "rub": s_rub}, lines={"rub": lines},
                                   title="Outer rotor, Y"), tmp_path / "spectra.png")
    _assert_png(out)
    out_log = save_figure(draw_spectra(
        {"outer": {"rub": s_rub}, "inner": {"plain arrays": (s_normal.frequencies, s_normal.amplitudes)}},
        lines={"rub": lines}, log_y=True, f_max=400.0,
    ), tmp_path / "spectra_log.png")
    _assert_png(out_log, n_series=1)  # one series per panel: both drawn in C0
    ax = Figure().subplots()  # into given axes: both panels' series, the lines marked and labelled
    assert draw_spectra({"outer": {"rub": s_rub}, "inner": {"normal": s_normal}}, ax, lines={"rub": lines}) is ax.figure
    assert [line.get_label() for line in ax.lines][::2] == ["rub", "normal"] and len(ax.texts) == len(COMBOS)
    with pytest.raises(ValueError, match=r"^lines\['other'\] = 'other': lines key must be a series of spectra"):
        draw_spectra({"rub": s_rub}, lines={"other": lines})
    with pytest.raises(ValueError, match="must be a Spectrum"):
        draw_spectra({"rub": np.ones(4)})
    with pytest.raises(ValueError, match=r"^f_max = -1.0: must be > 0 \(Hz\)"):
        draw_spectra({"rub": s_rub}, f_max=-1.0)


def test_draw_poincare(tmp_path):
    theta = np.linspace(0.0, 2 * np.pi, 150, endpoint=False)
    _assert_png(save_figure(draw_poincare(50e-6 * np.cos(theta), 0.03 * np.sin(theta), label="quasi-periodic",
                                          title="Poincare"), tmp_path / "poincare.png"), n_series=1)
    ax = Figure().subplots()
    assert draw_poincare(50e-6 * np.cos(theta), 0.03 * np.sin(theta), ax) is ax.figure and len(ax.lines) == 1
    with pytest.raises(ValueError, match=r"^velocity = array of shape \(149,\): must be a 1-D array of 150 values$"):
        draw_poincare(np.zeros(150), np.zeros(149))


def test_draw_orbits(tmp_path):
    rub_x, rub_y = _signal(np.pi / 2), _signal()
    nx, ny = 60e-6 * np.sin(2 * np.pi * 90 * T), 60e-6 * np.cos(2 * np.pi * 90 * T)
    orbits = {"node 14 (outer)": {"normal": (nx, ny), "rub": (rub_x, rub_y)},
              "node 13 (inner)": {"normal": (0.05 * nx, 0.05 * ny)}}
    out = save_figure(draw_orbits(orbits, clearance={"node 14 (outer)": 120e-6}, title="Orbits"),
                      tmp_path / "orbits.png")
    _assert_png(out)
    ax = Figure().subplots()  # into given axes: every orbit, the clearance circle
    assert draw_orbits(orbits, ax, clearance={"node 14 (outer)": 120e-6}) is ax.figure
    assert len(ax.lines) == 3 + 2 and len(ax.patches) == 1  # three orbits and the axes' two zero lines
    with pytest.raises(ValueError, match=r"^clearance = -1.0: must be > 0 \(m\)"):
        draw_orbits({"a": (nx, ny)}, clearance=-1.0)
    with pytest.raises(ValueError, match="not panels"):
        draw_orbits({"a": (nx, ny)}, clearance={"b": 1e-4})
    with pytest.raises(ValueError, match="pair"):
        draw_orbits({"a": nx})
    with pytest.raises(ValueError, match="^path = .*no_extension': must have a file extension"):
        write_figure(tmp_path / "no_extension", partial(draw_orbits, {"a": (nx, ny)}))


def test_line_labels_are_plain_text_with_subscripts():
    """Spectrum annotations are ordinary text (no mathtext): f_H and f_L with Unicode subscripts h and l."""
    assert plot_label("2f_H-f_L") == "2f\u2095\u2212f\u2097"
    assert plot_label("f_H+3f_L/2") == "f\u2095+3f\u2097/2" and "$" not in plot_label("f_H")
