"""What made an output folder: the rotorred version, the command line, the date and the resolved input.

Every command that writes a folder records a :class:`Provenance`: the folder holds the resolved input
(``scene.toml`` for ``run``, ``map`` and ``continue``; ``rotor.toml`` for ``campbell`` and ``harmonic``
given a rotor), its text summary starts with :meth:`Provenance.header_lines`, and every data file
that holds attributes carries :meth:`Provenance.attributes` (NPZ entries, ``.mat`` variables, NetCDF
global attributes, with :meth:`Provenance.netcdf_attributes`). The command line builds it from its
arguments (:meth:`Provenance.of_command`); a script calling the API may pass its own, or none.

This module sits at the bottom layer with :mod:`rotorred.checks` and :mod:`rotorred.writers`: it
imports neither; the writers take its attributes as a plain mapping.
"""

from __future__ import annotations

import shlex
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timezone

__all__ = ["Provenance", "KINDS", "ATTRIBUTES", "utc_now", "package_version"]

#: the kinds of resolved input, each written to ``<kind>.toml``
KINDS = ("scene", "rotor")
#: the attribute names of every kind (NPZ keys, .mat variables, NetCDF global attributes)
ATTRIBUTES = ("rotorred_version", "rotorred_command", "rotorred_date") + tuple(f"rotorred_{k}" for k in KINDS)


def utc_now() -> str:
    """The current time, ISO 8601 in UTC to the second (``"2025-06-01T12:34:56Z"``)."""
    return datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def package_version() -> str:
    """``rotorred.__version__``, from its one place (:mod:`rotorred._version`)."""
    from rotorred._version import __version__

    return __version__


@dataclass(frozen=True)
class Provenance:
    """The rotorred version, command line, date and resolved input of one result.

    Attributes
    ----------
    version : str
        ``rotorred.__version__`` of the run.
    command : str
        The command line as typed, shell-quoted (``"rotorred run paper-rub --out out"``); for a script, what it says
        it ran.
    date : str
        When the command started, ISO 8601 in UTC (:func:`utc_now`).
    kind : {"scene", "rotor"}
        What :attr:`toml` holds: a scene (:mod:`rotorred.scenes.schema`) or a rotor file.
    toml : str
        The resolved scene or rotor as TOML text: every key resolved, floats written with ``repr``, so that the
        file written from it reproduces the run when passed back.
    """

    version: str
    command: str
    date: str
    kind: str
    toml: str

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"Provenance.kind = {self.kind!r}: must be one of {', '.join(KINDS)}")
        for name in ("version", "command", "date", "toml"):
            if not isinstance(getattr(self, name), str):
                raise TypeError(f"Provenance.{name} = {getattr(self, name)!r}: must be a str")

    @classmethod
    def of_command(cls, argv: Sequence[str], kind: str, toml: str, date: str | None = None) -> Provenance:
        """The provenance of ``rotorred <argv...>`` run now (or at ``date``) with the resolved input ``toml``."""
        return cls(package_version(), shlex.join(["rotorred", *argv]), date or utc_now(), kind, toml)

    @property
    def file_name(self) -> str:
        """The file of the resolved input in the output folder: ``"scene.toml"`` or ``"rotor.toml"``."""
        return f"{self.kind}.toml"

    def attributes(self) -> dict[str, str]:
        """``rotorred_version``, ``rotorred_command``, ``rotorred_date`` and ``rotorred_scene`` (or
        ``rotorred_rotor``): the attributes of a data file (NPZ entries, .mat variables)."""
        return {"rotorred_version": self.version, "rotorred_command": self.command, "rotorred_date": self.date,
                f"rotorred_{self.kind}": self.toml}

    def netcdf_attributes(self) -> dict[str, str]:
        """:meth:`attributes` with CF's global attributes ``source`` (the program) and ``history`` (when, what)."""
        return {"source": f"rotorred {self.version}", "history": f"{self.date}: {self.command}",
                **self.attributes()}

    def header_lines(self) -> list[str]:
        """The lines a text summary starts with: version and date, the command, the resolved input's file."""
        return [f"rotorred {self.version}, {self.date}",
                f"command: {self.command}",
                f"resolved {self.kind}: {self.file_name}"]

    def on_top(self, text: str) -> str:
        """A text summary under :meth:`header_lines` and a blank line; its first line stays first when it says the
        result is incomplete (``"INCOMPLETE: ..."``), as the first line of every summary does."""
        first, rest = ("", text) if not text.startswith("INCOMPLETE: ") else text.partition("\n")[::2]
        block = "\n".join(self.header_lines()) + "\n\n" + rest.lstrip("\n")
        return first + "\n\n" + block if first else block

    def file_text(self) -> str:
        """The text of :attr:`file_name`: the header lines as TOML comments, then :attr:`toml`."""
        return "".join(f"# {line}\n" for line in self.header_lines()[:2]) + "\n" + self.toml
