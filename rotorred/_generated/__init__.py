"""Generated code: written by `python -m derivations`, do not edit."""
