"""A notebook, executed by nbclient, displays a Campbell result, a transient result and a branch inline.

Small settings: the Campbell diagram of seed-rig at 13 speeds, paper-rub over 0.6 s (0.2 s recorded, no normal
comparison), its harmonic-balance branch from 45 to 35 µm at 10 harmonics without stability (about 30 s with the
kernel's start on a loaded 2-core machine).
"""

from __future__ import annotations

import pytest

CELLS = [
    "import numpy as np\nimport rotorred as rr",
    "cd = rr.campbell(rr.load_rotor('seed-rig'), rr.Operating.line(np.linspace(0, 12000, 13), unit='rpm'))\ncd",
    "cd.view()",
    "scene = rr.load_scene('paper-rub', {'solver.duration': 0.6, 'solver.record_start': 0.4,\n"
    "                                    'output.plot_window': [0.4, 0.5]})\n"
    "transient = rr.run_scene(scene, compare_normal=False)\ntransient.view()",
    "model = rr.build_model(scene).model\n"
    "branch = rr.continue_scene(scene, model, 'rub.clearance', 45e-6, 35e-6, rr.BranchOptions(10, 128, 1e-9, False))\n"
    "branch.view()",
    "branch",
]
PLOTLY = "application/vnd.plotly.v1+json"


def _displayed(cell) -> dict:
    """The MIME bundle of a cell's displayed result (execute_result or display_data)."""
    bundles = [o["data"] for o in cell["outputs"] if o["output_type"] in ("execute_result", "display_data")]
    assert bundles, cell["outputs"]
    return {k: v for b in bundles for k, v in b.items()}


def test_a_notebook_displays_a_campbell_result_a_transient_and_a_branch_inline(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in CELLS])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    nbformat.write(nb, str(tmp_path / "views.ipynb"))
    summary = _displayed(nb.cells[1])
    assert "<strong>CampbellResult</strong>" in summary["text/html"] and "13 speeds" in summary["text/html"]
    for k, what in ((2, "Campbell diagram"), (3, "time waveforms"), (4, "branch of paper-rub")):
        shown = _displayed(nb.cells[k])
        assert PLOTLY in shown, (what, list(shown))  # plotly's renderer in a kernel: its MIME type, JupyterLab's
        assert what in shown[PLOTLY]["layout"]["title"]["text"] and shown[PLOTLY]["data"], what
    assert "<strong>SceneBranch</strong>" in _displayed(nb.cells[5])["text/html"]
