"""Built-in scenes (``*.toml``), loaded by name with :func:`rotorred.scenes.schema.load_scene`."""

from importlib import resources


def builtin_scenes() -> list[str]:
    """Names of the built-in scenes (``rotorred/scenes/builtin/*.toml``): read without importing the scene schema
    (the command line lists them in its help)."""
    return sorted(p.name[:-5] for p in resources.files(__name__).iterdir() if p.name.endswith(".toml"))
