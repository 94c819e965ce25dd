"""The status codes of every compiled step loop, one meaning and one message each.

The loops (:func:`rotorred.transient.kernel.run_steps`, :func:`rotorred.transient.eigen_kernel.run_eigen_steps`,
:func:`rotorred.transient.ramp_kernel.run_ramp_steps`) return one of these integers, and a failing loop writes it to
``Diagnostics.err[E_STATUS]``. They are plain module-level ints because numba reads those as compile-time constants;
an ``IntEnum`` member is not usable in nopython mode (numba cannot cast it to the float of ``Diagnostics.err``).
:class:`Status` mirrors them for the Python side, with :attr:`Status.message` the text of an error.
"""

from __future__ import annotations

from enum import IntEnum

__all__ = ["RUNNING", "NONFINITE", "NEWTON_FAILED", "LIMIT", "PASSES_FAILED", "NEED_LEVELS", "NEED_DENSE", "Status"]

#: every step asked for was taken (a chunk completed)
RUNNING = 0
#: a value of the step was not finite, after every halving of the step (the DOF in ``Diagnostics.err``)
NONFINITE = 1
#: the contact Newton iteration did not converge, after every halving of the step (the plate in ``Diagnostics.err``)
NEWTON_FAILED = 2
#: a contact-node displacement went beyond ``displacement_limit`` (the contact DOF in ``Diagnostics.err``)
LIMIT = 3
#: the fixed-point passes of a step at varying speed did not converge, after every halving of the step
PASSES_FAILED = 4
#: the loop stopped at the start of main step ``diag.counters[C_STEPS]`` (its state in ``state``) because the step
#: needs halving and ``levels`` holds level 0 only: the caller builds every level and calls again from there (the
#: halving levels, dense n x 2n matrices each, are built on first need)
NEED_LEVELS = 5
#: the eigenbasis loop stopped at the start of main step ``diag.counters[C_STEPS]`` (its state in ``state``) whose
#: contact solve failed there: the caller redoes that step with the dense loop and goes on
NEED_DENSE = 6


class Status(IntEnum):
    """The codes above, for messages (``Status(code).message``); equal to the ints the loops return."""

    RUNNING = RUNNING
    NONFINITE = NONFINITE
    NEWTON_FAILED = NEWTON_FAILED
    LIMIT = LIMIT
    PASSES_FAILED = PASSES_FAILED
    NEED_LEVELS = NEED_LEVELS
    NEED_DENSE = NEED_DENSE

    @property
    def message(self) -> str:
        """What the code means, as the cause of an error ("the contact Newton iteration failed")."""
        return _MESSAGES[self]


_MESSAGES = {
    Status.RUNNING: "every step was taken",
    Status.NONFINITE: "a non-finite value",
    Status.NEWTON_FAILED: "the contact Newton iteration failed",
    Status.LIMIT: "a contact-node displacement beyond `displacement_limit`",
    Status.PASSES_FAILED: "the step at varying speed did not converge",
    Status.NEED_LEVELS: "the step needs halving and only level 0 is built",
    Status.NEED_DENSE: "the eigenbasis step's contact solve failed: the dense step redoes it",
}
