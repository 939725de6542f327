"""dyncheck's own exceptions: one base class, a few subclasses.

Adapters translate engine errors into these, in dyncheck's words. Every message is one line
that names the field (or argument) and the offending value.
"""

from __future__ import annotations

from collections.abc import Iterable


def _rebuilt(cls: type[DyncheckError], message: str, state: dict) -> DyncheckError:
    error = cls.__new__(cls)
    Exception.__init__(error, message)
    error.__dict__.update(state)
    return error


class DyncheckError(Exception):
    """Base class of every error dyncheck raises on purpose. Pickled as its class, message
    and fields, whatever its constructor takes: it survives a process pool or a cluster."""

    def __reduce__(self) -> tuple:
        return (_rebuilt, (type(self), self.args[0] if self.args else "", self.__dict__))


class InvalidInput(DyncheckError, ValueError):
    """A case parameter, state, option or file is not acceptable."""

    def __init__(self, field: str, value: object, expected: str) -> None:
        self.field, self.value, self.expected = field, value, expected
        super().__init__(f"{field} must be {expected}, got {value!r}")


SHOWN_NAMES = 25
"""Valid names an UnknownName lists (the rest counted): the error stays one readable line."""


class UnknownName(DyncheckError, KeyError):
    """A case, implementation, integrator or quantity name that does not exist."""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        self.kind, self.name, self.valid = kind, name, sorted(valid)
        shown = self.valid[:SHOWN_NAMES]
        more = len(self.valid) - len(shown)
        listed = ", ".join(shown) + (f", … and {more} more" if more else "")
        super().__init__(f"unknown {kind} {name!r}; valid: {listed}")

    def __str__(self) -> str:  # KeyError would quote the message
        return self.args[0]


class EngineNotInstalled(DyncheckError, ImportError):
    """An implementation whose engine package cannot be imported."""

    def __init__(
        self, implementation: str, package: str, reason: str, extra: str | None = None
    ) -> None:
        self.implementation, self.package, self.extra = implementation, package, extra
        from dyncheck.installation import install_hint

        self.hint = (
            f"{install_hint(extra)} (the extra {extra!r})"
            if extra
            else f"pip install {package}"
        )
        super().__init__(
            f"implementation {implementation!r} needs {package!r}, which is not installed "
            f"({reason}); {self.hint}"
        )


class Unsupported(DyncheckError):
    """An engine cannot represent a case's model (reported as skipped, with the reason)."""


class EngineError(DyncheckError, RuntimeError):
    """An engine call failed or returned a non-finite value."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the work is (:func:`dyncheck.workers.on_sigterm`), so that it
    unwinds as Ctrl-C does: workers stopped, temporary files removed, nothing half-written;
    the command exits 143."""
