"""dyncheck as a pytest plugin (registered by entry point: installing dyncheck is enough) —
a user's own test suite checks their models without copied code:

    pytest --dyncheck-model robots/arm.xml --dyncheck-model robots/dog.urdf --dyncheck-floating

adds one test per model, ``robots/arm.xml::dyncheck``, that fails with the check's failed rows
(every row passed or explained: it passes). The tests are collected as pytest collects its own
(a collector per model file, reported before ``-k``, ``-m`` and ``--collect-only`` see them),
so ``-k arm`` selects and counts them as any test. In a test, the fixture ``dyncheck_model``
checks a model and asserts the same::

    def test_my_arm(dyncheck_model):
        result = dyncheck_model("robots/arm.xml", states=100)   # a CheckResult

and ``dyncheck_baseline`` holds a model's rows to a baseline stored beside the test, as
pytest-regressions' ``data_regression`` holds data (``--dyncheck-update-baseline`` accepts the
new values)::

    def test_my_arm_has_not_moved(dyncheck_baseline):
        dyncheck_baseline("robots/arm.xml")   # tests/test_arm/test_my_arm_has_not_moved.csv
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

DEFAULT_STATES = 100


class CheckFailed(AssertionError):
    """A model the check finds wrong: its message the failed rows."""


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("dyncheck", "dyncheck: do the engines read your model alike?")
    group.addoption("--dyncheck-model", action="append", default=[], metavar="PATH",
                    help="check this MJCF or URDF file as one test (repeatable)")
    group.addoption("--dyncheck-floating", action="store_true",
                    help="a URDF's root link is a free body")
    group.addoption("--dyncheck-states", type=int, default=DEFAULT_STATES, metavar="N",
                    help=f"sampled states per model (default {DEFAULT_STATES})")
    group.addoption("--dyncheck-update-baseline", action="store_true",
                    help="dyncheck_baseline writes each test's baseline from this run "
                    "(accepting what moved) instead of comparing with it")


def _check(path: str, **options: Any) -> Any:
    from dyncheck.check.model_check import check_model

    result = check_model(path, **options)
    if not result.ok:
        raise CheckFailed(f"dyncheck check {path}: differences found\n{result.failures()}")
    return result


class ModelItem(pytest.Item):
    """One model file, checked."""

    def __init__(self, *, model: str, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.model = model

    def runtest(self) -> None:
        config = self.config
        _check(self.model, floating=config.getoption("dyncheck_floating"),
               states=config.getoption("dyncheck_states"))

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> Any:
        """The failed rows (or a bad file's one line), not a traceback into dyncheck."""
        from dyncheck.errors import DyncheckError

        if isinstance(excinfo.value, CheckFailed | DyncheckError):
            return str(excinfo.value)
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple[Any, int | None, str]:
        return self.path, None, f"dyncheck[{self.model}]"


class ModelFile(pytest.File):
    """A model file named by ``--dyncheck-model``: collects its one :class:`ModelItem`
    (node id ``PATH::dyncheck``)."""

    def __init__(self, *, model: str, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.model = model

    def collect(self) -> list[pytest.Item]:
        return [ModelItem.from_parent(self, name="dyncheck", model=self.model)]


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config,
                                  items: list[pytest.Item]) -> None:
    """The models' tests, collected and reported as pytest's own are — before any other
    plugin's hook, so that ``-k`` and ``-m`` deselect among them and the terminal counts
    them (they were appended after the count: ``-k`` said "-1 selected")."""
    from pathlib import Path

    for model in config.getoption("dyncheck_model"):
        collector = ModelFile.from_parent(session, path=Path(model).absolute(), model=model)
        report = session.ihook.pytest_make_collect_report(collector=collector)
        session.ihook.pytest_collectreport(report=report)
        items.extend(i for i in report.result if isinstance(i, pytest.Item))


@pytest.fixture
def dyncheck_model() -> Callable[..., Any]:
    """``check(path, **options)``: :func:`~dyncheck.check.model_check.check_model` that fails
    the test with the failed rows, and returns the result otherwise."""
    return _check


class BaselineMoved(AssertionError):
    """A model whose rows moved against its stored baseline: the message names each row."""


def baseline_file(node_path: Any, test_name: str) -> Any:
    """Where a test's baseline lives: ``<test module's folder>/<module name>/<test>.csv``
    (the test's name made one file name)."""
    from dyncheck.escaping import file_name

    return node_path.parent / node_path.stem / f"{file_name(test_name)}.csv"


def _held(path: str, stored: Any, update: bool, **options: Any) -> Any:
    """Check ``path`` and hold its rows to the baseline ``stored``: write it where it is
    absent (and fail: a first baseline is to be looked at and committed) or ``update``; else
    fail naming every row that moved."""
    from dyncheck import baseline
    from dyncheck.check import baseline as check_baseline
    from dyncheck.check.model_check import check_model
    from dyncheck.check.page import engine_versions_of
    from dyncheck.provenance import dyncheck_version

    __tracebackhide__ = True  # pytest shows the test's line and the message, not dyncheck
    result = check_model(path, **options)
    tables = {result.model: result.rows}
    versions = {"dyncheck": dyncheck_version(), **engine_versions_of(result.impls)}
    if update or not stored.exists():
        stored.parent.mkdir(parents=True, exist_ok=True)
        check_baseline.write(tables, stored, versions)
        if not update:
            raise BaselineMoved(f"no baseline for {path}: written to {stored} (look at it, "
                                "commit it, and run again)")
        return result
    moved = check_baseline.compare(check_baseline.table(tables), check_baseline.load(stored))
    if len(moved):
        changed = baseline.version_changes(stored, versions)
        lines = [f"{r.row}: {r.move}: {r.note}" for r in moved.itertuples(index=False)]
        raise BaselineMoved(
            f"dyncheck check {path}: {len(moved)} rows moved against {stored}"
            + (f" (versions changed: {', '.join(changed)})" if changed else "")
            + "\n" + "\n".join(lines) + "\n(--dyncheck-update-baseline accepts them)")
    return result


@pytest.fixture
def dyncheck_baseline(request: pytest.FixtureRequest) -> Callable[..., Any]:
    """``check(path, **options)``: :func:`~dyncheck.check.model_check.check_model`, its rows
    held to the test's stored baseline (:func:`baseline_file`); returns the result."""
    from functools import partial

    stored = baseline_file(request.node.path, request.node.name)
    update = bool(request.config.getoption("dyncheck_update_baseline"))
    return partial(_held, stored=stored, update=update)
