"""Loading a ``validation/`` script from a test, so that the test and the script share one implementation."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_validation(name: str):
    """The module ``validation/<name>.py``, registered as ``validation_<name>`` (dataclasses look their
    module up in ``sys.modules``); loaded once per process."""
    key = f"validation_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, ROOT / "validation" / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        spec.loader.exec_module(module)
    return sys.modules[key]
