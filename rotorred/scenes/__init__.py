"""Built-in scenes (``*.toml``), loaded by name with :func:`rotorred.scene.load_scene`."""
