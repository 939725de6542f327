"""Fuzzing ``dyncheck check``: mutants of the shipped MJCF and URDF models (bytes cut, doubled
or flipped; attributes set to values a corrupted or hand-edited file holds; elements dropped or
repeated) each get a one-line error (exit 2) or a report (exit 0 or 1) — never a traceback,
never a hang (each mutant under a time limit), never an exit status of another kind.

The mutants are drawn from a fixed seed: the same 1000 files on every run.
"""

from __future__ import annotations

import io
import json
import os
import re
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from dyncheck.__main__ import main
from dyncheck.check import engines

ROOT = Path(__file__).resolve().parents[2]
SOURCES = [
    ROOT / "tests" / "check" / "models" / "branches.urdf",
    ROOT / "tests" / "check" / "models" / "mixed.xml",
    ROOT / "tests" / "check" / "models" / "floating_arm.xml",
    ROOT / "tutorials" / "models" / "arm_defaults.xml",
]
MUTANTS = int(os.environ.get("DYNCHECK_MUTANTS", "1000"))
SEED = 20261123
LIMIT_S = 60
"""Per mutant: the engines' own time limit (they run in their own processes) and an alarm
around the whole command (the parent's parsing and the referee)."""
VALUES = ("-1", "0", "nan", "inf", "-inf", "1e308", "1e-300", "", "abc", "1 2", "0 0 0",
          "1e400", "-0", "1 0 0 0 0", "0x10", "  ", "NaN NaN NaN", "1,2,3")


def _attribute_mutant(text: str, rng: np.random.Generator) -> str | None:
    root = ET.fromstring(text)
    elements = [e for e in root.iter() if e.attrib]
    if not elements:
        return None
    element = elements[rng.integers(len(elements))]
    name = sorted(element.attrib)[rng.integers(len(element.attrib))]
    element.set(name, VALUES[rng.integers(len(VALUES))])
    return ET.tostring(root, encoding="unicode")


def _element_mutant(text: str, rng: np.random.Generator) -> str | None:
    root = ET.fromstring(text)
    parents = [(p, c) for p in root.iter() for c in p]
    if not parents:
        return None
    parent, child = parents[rng.integers(len(parents))]
    if rng.random() < 0.5:
        parent.remove(child)
    else:
        parent.append(ET.fromstring(ET.tostring(child)))
    return ET.tostring(root, encoding="unicode")


def _byte_mutant(data: bytes, rng: np.random.Generator) -> bytes:
    i = int(rng.integers(len(data)))
    j = min(len(data), i + int(rng.integers(1, 40)))
    how = rng.integers(3)
    if how == 0:
        return data[:i] + data[j:]
    if how == 1:
        return data[:j] + data[i:j] + data[j:]
    flipped = bytes([data[i] ^ int(rng.integers(1, 256))])
    return data[:i] + flipped + data[i + 1 :]


def mutants() -> list[tuple[str, bytes]]:
    """``MUTANTS`` (name, content) pairs, a third of each kind, from a fixed seed."""
    rng = np.random.default_rng(SEED)
    out: list[tuple[str, bytes]] = []
    while len(out) < MUTANTS:
        source = SOURCES[len(out) % len(SOURCES)]
        text = source.read_text()
        kind = len(out) % 3
        mutant: str | bytes | None
        if kind == 0:
            mutant = _byte_mutant(text.encode(), rng)
        elif kind == 1:
            mutant = _attribute_mutant(text, rng)
        else:
            mutant = _element_mutant(text, rng)
        if mutant is None:
            continue
        data = mutant.encode() if isinstance(mutant, str) else mutant
        out.append((f"{len(out):04d}{source.suffix}", data))
    return out


class _Hang(Exception):
    pass


def _alarm(_signum: int, _frame: object) -> None:
    raise _Hang


def check_all(folder: str) -> None:
    """Check every mutant in this process, as ``dyncheck check`` would, and write what each
    answered (exit status, or ``None`` for no answer in time; stdout; stderr) to
    ``folder/answers.json``. Run in a fresh interpreter by the test: forking the engines'
    processes from the test session's — JAX, Warp and a full run in memory — costs several
    times more than from the command's own process (measured: 155 s against 44 s)."""
    engines.TIMEOUT_S = engines.LOAD_TIMEOUT_S = float(LIMIT_S)
    signal.signal(signal.SIGALRM, _alarm)
    answers = []
    for name, data in mutants():
        model = Path(folder) / name
        model.write_bytes(data)
        out, err = io.StringIO(), io.StringIO()
        signal.alarm(2 * LIMIT_S)
        code: int | None
        try:
            with redirect_stdout(out), redirect_stderr(err):
                code = main(["check", str(model), "--states", "3", "--impl", "reference",
                             "--impl", "mujoco", "--impl", "pinocchio",
                             "--out", str(Path(folder) / "out")])
        except _Hang:
            code = None
        finally:
            signal.alarm(0)
        answers.append((name, code, out.getvalue(), err.getvalue()))
    (Path(folder) / "answers.json").write_text(json.dumps(answers))


@pytest.mark.slow
def test_mutated_models_never_traceback_or_hang(tmp_path):
    subprocess.run([sys.executable, "-c",
                    f"from tests.check.test_fuzz import check_all; check_all({str(tmp_path)!r})"],
                   cwd=ROOT, check=True, timeout=MUTANTS + 2 * LIMIT_S)  # ~0.04 s a mutant
    answers = json.loads((tmp_path / "answers.json").read_text())
    assert [a[0] for a in answers] == [name for name, _ in mutants()]
    codes: Counter[int] = Counter()
    for name, code, out, err in answers:
        model = tmp_path / name
        context = f"{name}:\n{model.read_bytes().decode(errors='replace')}\n{err}"
        assert code is not None, f"{name}: no answer within {2 * LIMIT_S} s"
        codes[code] += 1
        assert code in (0, 1, 2), context
        assert "Traceback" not in err + out, context
        if code == 2:
            lines = err.strip().splitlines()
            assert len(lines) == 1 and re.match(r"dyncheck: error: ", lines[0]), context
            assert str(model) in lines[0], context  # the error names the file
        else:
            assert re.search(r"\d+ passed, \d+ explained, \d+ failed", out), context
    assert sum(codes.values()) == MUTANTS
    assert codes[2] and codes[0] + codes[1], codes  # both answers met: the mutants vary
