"""Plot helpers write legible PNG files from plain arrays; bad inputs are refused."""

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest

from rotorred.plots.scene import plot_label, plot_orbits, plot_spectra, plot_waveforms
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


def test_plot_waveforms(tmp_path):
    rub = _signal()
    normal = 60e-6 * np.cos(2 * np.pi * 90.0 * T)
    out = plot_waveforms(
        T,
        {"node 13 (inner)": {"normal": 0.05 * normal}, "node 14 (outer)": {"normal": normal, "rub": rub}},
        tmp_path / "sub" / "waveforms.png",
        title="Y displacement",
        t_window=(0.1, 0.2),
    )
    assert out == tmp_path / "sub" / "waveforms.png"
    _assert_png(out)
    with pytest.raises(ValueError, match="must have 30000 samples"):
        plot_waveforms(T, {"a": rub[:-1]}, tmp_path / "bad.png")
    with pytest.raises(ValueError, match=r"^t_window = \(0.2, 0.1\): must be \(start, end\) with start < end \(s\)"):
        plot_waveforms(T, {"a": rub}, tmp_path / "bad.png", t_window=(0.2, 0.1))
    with pytest.raises(ValueError, match="^signals = {}: must be a non-empty mapping"):
        plot_waveforms(T, {}, tmp_path / "bad.png")
    with pytest.raises(ValueError, match="mixes panels"):
        plot_waveforms(T, {"a": rub, "b": {"c": rub}}, tmp_path / "bad.png")
    assert not (tmp_path / "bad.png").exists()


def test_plot_spectra_with_labels_linear_and_log(tmp_path):
    s_rub = settled_spectrum(_signal(), DT, 70.0, 90.0)
    s_normal = settled_spectrum(60e-6 * np.cos(2 * np.pi * 90.0 * T), DT, 70.0, 90.0)
    lines = fit_peaks(T, _signal(), 70.0, 90.0, spectrum=s_rub).lines
    assert len(lines) == len(COMBOS)
    out = plot_spectra(
        {"normal": s_normal, "rub": s_rub}, tmp_path / "spectra.png",
        lines={"rub": lines}, title="Outer rotor, Y",
    )
    _assert_png(out)
    out_log = plot_spectra(
        {"outer": {"rub": s_rub}, "inner": {"plain arrays": (s_normal.frequencies, s_normal.amplitudes)}},
        tmp_path / "spectra_log.png", lines={"rub": lines}, log_y=True, f_max=400.0,
    )
    _assert_png(out_log, n_series=1)  # one series per panel: both drawn in C0
    with pytest.raises(ValueError, match=r"^lines\['other'\] = 'other': lines key must be a series of spectra"):
        plot_spectra({"rub": s_rub}, tmp_path / "bad.png", lines={"other": lines})
    with pytest.raises(ValueError, match="must be a Spectrum"):
        plot_spectra({"rub": np.ones(4)}, tmp_path / "bad.png")
    with pytest.raises(ValueError, match=r"^f_max = -1.0: must be > 0 \(Hz\)"):
        plot_spectra({"rub": s_rub}, tmp_path / "bad.png", f_max=-1.0)


def test_plot_poincare(tmp_path):
    from rotorred.plots.scene import plot_poincare
    theta = np.linspace(0.0, 2 * np.pi, 150, endpoint=False)
    _assert_png(plot_poincare(50e-6 * np.cos(theta), 0.03 * np.sin(theta), tmp_path / "poincare.png",
                              label="quasi-periodic", title="Poincare"), n_series=1)
    with pytest.raises(ValueError, match=r"^velocity = array of shape \(149,\): must be a 1-D array of 150 values$"):
        plot_poincare(np.zeros(150), np.zeros(149), tmp_path / "bad.png")


def test_plot_orbits(tmp_path):
    rub_x, rub_y = _signal(np.pi / 2), _signal()
    nx, ny = 60e-6 * np.sin(2 * np.pi * 90 * T), 60e-6 * np.cos(2 * np.pi * 90 * T)
    out = plot_orbits(
        {"node 14 (outer)": {"normal": (nx, ny), "rub": (rub_x, rub_y)},
         "node 13 (inner)": {"normal": (0.05 * nx, 0.05 * ny)}},
        tmp_path / "orbits.png", clearance={"node 14 (outer)": 120e-6}, title="Orbits",
    )
    _assert_png(out)
    with pytest.raises(ValueError, match=r"^clearance = -1.0: must be > 0 \(m\)"):
        plot_orbits({"a": (nx, ny)}, tmp_path / "bad.png", clearance=-1.0)
    with pytest.raises(ValueError, match="not panels"):
        plot_orbits({"a": (nx, ny)}, tmp_path / "bad.png", clearance={"b": 1e-4})
    with pytest.raises(ValueError, match="pair"):
        plot_orbits({"a": nx}, tmp_path / "bad.png")
    with pytest.raises(ValueError, match="^path = .*no_extension': must have a file extension"):
        plot_orbits({"a": (nx, ny)}, tmp_path / "no_extension")


def test_line_labels_are_plain_text_with_subscripts():
    """Spectrum annotations are ordinary text (no mathtext): f_H and f_L with Unicode subscripts h and l."""
    assert plot_label("2f_H-f_L") == "2f\u2095\u2212f\u2097"
    assert plot_label("f_H+3f_L/2") == "f\u2095+3f\u2097/2" and "$" not in plot_label("f_H")
