"""Nonlinear periodic responses: harmonic balance with the AFT, continuation with folds, Hill stability."""
