"""Symbolic derivations of rotorred's element matrices and contact tangents.

``python -m derivations`` writes every module listed in :data:`TARGETS`.
"""

from __future__ import annotations


def _timoshenko() -> str:
    from derivations.timoshenko import module_text

    return module_text()


def _tapered() -> str:
    from derivations.tapered import module_text

    return module_text()


def _contact() -> str:
    from derivations.contact import module_text

    return module_text()


def _internal_damping() -> str:
    from derivations.internal_damping import module_text

    return module_text()


#: (path relative to the project root, function returning the module text)
TARGETS: list[tuple[str, object]] = [
    ("rotorred/_generated/timoshenko.py", _timoshenko),
    ("rotorred/_generated/contact.py", _contact),
    ("rotorred/_generated/tapered.py", _tapered),
    ("rotorred/_generated/internal_damping.py", _internal_damping),
]
