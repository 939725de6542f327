"""dyncheck: a textbook's dynamics checked against MuJoCo and Pinocchio.

Subpackages: ``dyncheck.cases`` (systems, defined once), ``dyncheck.reference`` (the book,
clean-room), ``dyncheck.adapters`` (engines, one interface). The comparison layer
(``dyncheck.comparison``, ``dyncheck.trajectories``) is the only code that sees both the
reference and the engines.
"""

__version__ = "0.1.0"


def check_model(*args, **kwargs):
    """:func:`dyncheck.check.model_check.check_model` (imported on first use: the engines load
    only when a model is checked)."""
    from dyncheck.check.model_check import check_model as _check_model

    return _check_model(*args, **kwargs)
