"""The version of rotorred: written here only (``pyproject.toml``, ``rotorred.__version__`` and ``rotorred --version``
read it)."""

__version__ = "0.1.0"
