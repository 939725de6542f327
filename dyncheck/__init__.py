"""dyncheck: a textbook's dynamics checked against MuJoCo, its ports, Pinocchio, Drake,
Newton, PyBullet and sympy.physics.mechanics.

Subpackages: ``dyncheck.cases`` (systems, defined once; the top-level ``cases/``),
``dyncheck.reference`` (§2.2 of Heinbockel's *Introduction to Tensor Calculus and Continuum
Mechanics*, clean-room; ``reference/``), ``dyncheck.adapters`` (engines, one interface;
``adapters/``). The comparison layer (``dyncheck.comparison``,
``dyncheck.studies``, ``dyncheck.check``) is the only code that sees both the reference and
the engines.
"""

__version__ = "0.1.0"


def check_model(*args, **kwargs):
    """:func:`dyncheck.check.model_check.check_model` (imported on first use: the engines load
    only when a model is checked)."""
    from dyncheck.check.model_check import check_model as _check_model

    return _check_model(*args, **kwargs)
