"""Built-in scenes (``*.toml``), loaded by name with :func:`rotorred.scenes.schema.load_scene`."""
