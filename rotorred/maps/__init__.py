"""Maps of the operating envelope: a scene over a grid of keys, with continuation, on Dask."""
