"""The one check of a refused rotor file, shared by the rotor-file tests."""

from __future__ import annotations

import re

import pytest

from rotorred.model.rotor_file import RotorFileError, rotor_from_toml


def assert_refused(text: str, old: str, new: str, message: str) -> None:
    """``text`` with ``old`` (which must be in it) replaced by ``new`` is refused with exactly ``message``, the file
    named ``bad.toml``."""
    assert old in text, old
    with pytest.raises(RotorFileError, match=f"^{re.escape(message)}$"):
        rotor_from_toml(text.replace(old, new, 1), source="bad.toml")
