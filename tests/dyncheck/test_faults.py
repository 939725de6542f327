"""Every kind of bad input and fault a user has met or could meet, with the answer dyncheck
gives — each one asserted (exit status, one line, no traceback, the words that name the field
or path and the value, nothing written) and the table of observed answers kept in
``reports/reliability.md`` (this module renders it; ``DYNCHECK_WRITE_PAGES=1`` rewrites it).

Faults that need a real run, a killed process or a crashing engine have their own tests
(:data:`DEDICATED`); they are listed on the same page.
"""

from __future__ import annotations

import csv
import dataclasses
import errno
import io
import os
import re
from collections.abc import Callable
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass
from pathlib import Path

import pytest

from dyncheck.__main__ import main
from dyncheck.adapters import MODELS as LOADERS
from dyncheck.adapters import REGISTRY
from dyncheck.cases import CASES, get_case
from dyncheck.cases.multibody import Body, Joint
from dyncheck.errors import DyncheckError

ROOT = Path(__file__).resolve().parents[2]
REPORTS = ROOT / "reports"
PAGE = REPORTS / "reliability.md"
MODELS = ROOT / "tests" / "check" / "models"
URDF = (MODELS / "branches.urdf").read_text()
Y = (0.0, 1.0, 0.0)

CHECKED = ", ".join(sorted(["reference", *LOADERS]))
"""``check --impl``'s valid names, from the registry: the referee and every file loader."""
VERSIONED = ", ".join(sorted(n for n, r in REGISTRY.items() if r.releases))
"""``versions --engine``'s valid names: the registrations that list releases."""
CASE_NAMES = ", ".join(sorted(CASES))
"""A case's valid names: the registry's."""
RUN_NAMES = ", ".join(sorted(["reference", "book", *REGISTRY]))
"""``run --impl``'s valid names: the book's side and every registration."""


@dataclass(frozen=True, kw_only=True)
class Fault:
    """One kind of bad input or fault: a ``dyncheck`` command (``{tmp}`` and ``{models}``
    filled in) or a Python call that must raise; what is set up first; the answer expected."""

    kind: str
    area: str
    answer: str
    """A regular expression the one line of the answer must match."""
    argv: tuple[str, ...] = ()
    call: Callable[[Path], object] | None = None
    prepare: Callable[[Path], object] | None = None
    patch: Callable[[pytest.MonkeyPatch, Path], None] | None = None
    exit: int = 2


def _file(name: str, content: str | bytes) -> Callable[[Path], Path]:
    def make(tmp: Path) -> Path:
        path = tmp / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        return path

    return make


def _folder(name: str) -> Callable[[Path], Path]:
    def make(tmp: Path) -> Path:
        (tmp / name).mkdir()
        return tmp / name

    return make


def _baseline(edit: Callable[[str], str]) -> Callable[[Path], Path]:
    return lambda tmp: _file("base.csv", edit((REPORTS / "baseline.csv").read_text()))(tmp)


def _data_lines(text: str) -> list[str]:
    return [ln for ln in text.splitlines() if not ln.startswith("#")]


def _rows(text: str) -> list[list[str]]:
    """The CSV's rows, parsed (a merged skipped row's quantities are one quoted field)."""
    return list(csv.reader(_data_lines(text)))


def _written(rows: list[list[str]]) -> str:
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(rows)
    return out.getvalue()


def _column(text: str, name: str, value: str) -> str:
    rows = _rows(text)
    k = rows[0].index(name)
    return _written([rows[0], *([value if i == k else f for i, f in enumerate(r)]
                                for r in rows[1:])])


def _headed_half(text: str) -> str:
    from dyncheck import baseline

    body = _data_lines(text)
    return "\n".join([f"{baseline.HEADER} rows={len(body) - 1}", *body[: len(body) // 2]]) + "\n"


def _drop_column(text: str, name: str) -> str:
    rows = _rows(text)
    k = rows[0].index(name)
    return _written([[f for i, f in enumerate(r) if i != k] for r in rows])


def _raise(exc: BaseException) -> Callable[..., object]:
    def raiser(*_args: object, **_kwargs: object) -> object:
        raise exc

    return raiser


def _patch_run_then_write(error: OSError) -> Callable[[pytest.MonkeyPatch, Path], None]:
    """The run itself replaced (its cost is not the point); the report's write fails."""

    def patch(mp: pytest.MonkeyPatch, tmp: Path) -> None:
        from dyncheck import run
        from dyncheck.report import folder as report

        mp.setattr(run, "run", lambda *a, **k: None)
        mp.setattr(report, "write", _raise(error))

    return patch


def _interrupt(module: str, name: str) -> Callable[[pytest.MonkeyPatch, Path], None]:
    def patch(mp: pytest.MonkeyPatch, tmp: Path) -> None:
        import importlib

        mp.setattr(importlib.import_module(module), name, _raise(KeyboardInterrupt()))

    return patch


def _body(**kw: object) -> Body:
    args: dict[str, object] = dict(name="b", parent=None, joint_pos=(0, 0, 0),
                                   joints=(Joint("j", "hinge", Y),), mass=1.0, com=(0, 0, -1))
    return Body(**(args | kw))  # type: ignore[arg-type]


def _case(name: str, **change: object) -> Callable[[Path], object]:
    return lambda tmp: dataclasses.replace(get_case(name), **change)


def _trajectory(name: str, **change: object) -> Callable[[Path], object]:
    def call(tmp: Path) -> object:
        case = get_case(name)
        return dataclasses.replace(case, trajectory=dataclasses.replace(case.trajectory, **change))

    return call


OUT = "{tmp}/out"
BRANCHES = "{models}/branches.urdf"
SMALL_MJCF = "<mujoco><worldbody><body><joint type='hinge'/><geom size='0.1'/></body>" \
    "</worldbody></mujoco>"

FAULTS: tuple[Fault, ...] = (
    # --- the command line itself
    Fault(kind="no command", area="dyncheck", argv=(),
          answer=r"^dyncheck: error: the following arguments are required: command$"),
    Fault(kind="unknown command", area="dyncheck", argv=("frobnicate",),
          answer=r"invalid choice: 'frobnicate'"),
    Fault(kind="unknown option", area="dyncheck", argv=("run", "--frob"),
          answer=r"unrecognized arguments: --frob"),
    # --- run
    Fault(kind="unknown case", area="run", argv=("run", "no_such_case", "--out", OUT),
          answer=r"unknown case 'no_such_case'; valid: " + re.escape(CASE_NAMES) + "$"),
    Fault(kind="unknown implementation", area="run",
          argv=("run", "simple_pendulum", "--impl", "bullet", "--out", OUT),
          answer=r"unknown implementation 'bullet'; valid: "),
    Fault(kind="--jobs 0", area="run", argv=("run", "--jobs", "0", "--out", OUT),
          answer=r"--jobs must be a positive integer at most 256, got 0$"),
    Fault(kind="--jobs negative", area="run", argv=("run", "--jobs", "-2", "--out", OUT),
          answer=r"--jobs must be a positive integer at most 256, got -2$"),
    Fault(kind="--jobs not a number", area="run", argv=("run", "--jobs", "two", "--out", OUT),
          answer=r"argument --jobs: invalid int value: 'two'$"),
    Fault(kind="--states 0", area="run", argv=("run", "--states", "0", "--out", OUT),
          answer=r"--states must be a positive integer, got 0$"),
    Fault(kind="--states negative", area="run", argv=("run", "--states", "-5", "--out", OUT),
          answer=r"--states must be a positive integer, got -5$"),
    Fault(kind="--states 1e11 (days of work)", area="run",
          argv=("run", "--states", str(10**11), "--out", OUT),
          answer=r"--states must be at most 1000000000 \(.*\), got 100000000000$"),
    Fault(kind="--states in float notation", area="run", argv=("run", "--states", "1e3"),
          answer=r"argument --states: invalid int value: '1e3'$"),
    Fault(kind="--out empty", area="run", argv=("run", "simple_pendulum", "--out", ""),
          answer=r"argument --out: an empty path is not a folder or file name$"),
    Fault(kind="--out below a file", area="run", prepare=_file("file", "keep"),
          argv=("run", "simple_pendulum", "--out", "{tmp}/file/sub"),
          answer=r"--out must be a folder path \(<tmp>/file is a file\), got '<tmp>/file/sub'"),
    Fault(kind="--out an existing file", area="run", prepare=_file("file", "keep"),
          argv=("run", "simple_pendulum", "--out", "{tmp}/file"),
          answer=r"--out must be a directory, got '<tmp>/file'$"),
    Fault(kind="--out in a read-only system folder", area="run",
          argv=("run", "simple_pendulum", "--out", "/proc/dyncheck-nope"),
          answer=r"--out must be a writable directory \(.+\), got '/proc/dyncheck-nope'$"),
    Fault(kind="--baseline missing", area="run",
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/none.csv", "--out", OUT),
          answer=r"--baseline .*'<tmp>/none.csv'"),
    Fault(kind="--baseline a folder", area="run", prepare=_folder("base"),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base", "--out", OUT),
          answer=r"--baseline must be a baseline CSV file, not a folder, got '<tmp>/base'$"),
    Fault(kind="--baseline binary, not UTF-8", area="run",
          prepare=_file("base.csv", b"\x89PNG\r\n\x1a\n\xff\xfe\x00\x00"),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*'<tmp>/base.csv'"),
    Fault(kind="--baseline empty file", area="run", prepare=_file("base.csv", ""),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*'<tmp>/base.csv'"),
    Fault(kind="--baseline all errors NaN", area="run",
          prepare=_baseline(lambda t: _column(t, "max_rel_err", "nan")),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*finite"),
    Fault(kind="--baseline a tolerance negative", area="run",
          prepare=_baseline(lambda t: _column(t, "tolerance", "-1")),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*tolerance"),
    Fault(kind="--baseline a duplicated row", area="run",
          prepare=_baseline(lambda t: t + t.splitlines()[-1] + "\n"),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*repeats a key"),
    Fault(kind="--baseline truncated mid-line", area="run",
          prepare=_baseline(lambda t: t[: len(t) // 2 - 7]),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*truncated or edited"),
    Fault(kind="--baseline truncated at a line end", area="run", prepare=_baseline(_headed_half),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*truncated\?"),
    Fault(kind="--baseline a column missing", area="run",
          prepare=_baseline(lambda t: _drop_column(t, "verdict")),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*verdict"),
    Fault(kind="--baseline an unknown verdict", area="run",
          prepare=_baseline(lambda t: _column(t, "verdict", "fine")),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/base.csv", "--out", OUT),
          answer=r"--baseline .*'fine'"),
    Fault(kind="disk full while the report is written", area="run",
          patch=_patch_run_then_write(OSError(errno.ENOSPC, "No space left on device",
                                              "out/x.csv")),
          argv=("run", "simple_pendulum", "--impl", "reference", "--out", OUT),
          answer=r"^dyncheck: error: cannot write out/x.csv: No space left on device$"),
    Fault(kind="disk full at the write itself (/dev/full): the file named", area="check",
          patch=lambda mp, tmp: mp.setattr(
              "dyncheck.results.tempfile.mkstemp",
              lambda dir, prefix, suffix: (os.open("/dev/full", os.O_WRONLY),
                                           str(Path(dir) / f"{prefix}{suffix}"))),
          argv=("check", BRANCHES, "--states", "2", "--out", OUT),
          answer=r"^dyncheck: error: cannot write <tmp>/out/branches.csv: No space left on "
                 r"device$"),
    Fault(kind="file-size limit while the report is written", area="run",
          patch=_patch_run_then_write(OSError(errno.EFBIG, "File too large", "out/x.csv")),
          argv=("run", "simple_pendulum", "--impl", "reference", "--out", OUT),
          answer=r"^dyncheck: error: cannot write out/x.csv: File too large$"),
    Fault(kind="Ctrl-C during the run", area="run", patch=_interrupt("dyncheck.run", "run"),
          argv=("run", "simple_pendulum", "--out", OUT), exit=130,
          answer=r"^dyncheck: interrupted \(nothing half-written\)$"),
    # --- check
    Fault(kind="no model given", area="check", argv=("check", "--out", OUT),
          answer=r"PATH must be at least one model file, folder, --robot or --case"),
    Fault(kind="model file missing", area="check", argv=("check", "{tmp}/nope.xml"),
          answer=r"<tmp>/nope.xml: no such file$"),
    Fault(kind="model path a folder without models", area="check", prepare=_folder("m"),
          argv=("check", "{tmp}/m", "--out", OUT),
          answer=r"PATH must be a folder holding MJCF or URDF files, got '<tmp>/m'"),
    Fault(kind="model not XML", area="check", prepare=_file("bad.xml", "<mujoco><worldbody>"),
          argv=("check", "{tmp}/bad.xml", "--out", OUT),
          answer=r"<tmp>/bad.xml: not XML \(line 1"),
    Fault(kind="model binary, not UTF-8", area="check",
          prepare=_file("bin.xml", b"\xff\xfe<\x00m\x00\x00\x01\x02"),
          argv=("check", "{tmp}/bin.xml", "--out", OUT), answer=r"<tmp>/bin.xml: not XML"),
    Fault(kind="model file empty", area="check", prepare=_file("empty.urdf", ""),
          argv=("check", "{tmp}/empty.urdf", "--out", OUT),
          answer=r"<tmp>/empty.urdf: not XML"),
    Fault(kind="XML that is neither MJCF nor URDF", area="check", prepare=_file("x.xml", "<svg/>"),
          argv=("check", "{tmp}/x.xml", "--out", OUT),
          answer=r"root element <svg> is neither <mujoco> nor <robot>$"),
    Fault(kind="MJCF MuJoCo refuses (negative geom size)", area="check",
          prepare=_file("r.xml", "<mujoco><worldbody><body><joint type='hinge'/>"
                        "<geom size='-1'/></body></worldbody></mujoco>"),
          argv=("check", "{tmp}/r.xml", "--out", OUT), answer=r"<tmp>/r.xml: mujoco refused"),
    Fault(kind="MJCF include of a missing file", area="check",
          prepare=_file("inc.xml", "<mujoco><include file='gone.xml'/></mujoco>"),
          argv=("check", "{tmp}/inc.xml", "--out", OUT),
          answer=r"<tmp>/inc.xml: <include file='gone.xml'>: cannot be read \(No such file"),
    Fault(kind="MJCF that includes itself (Drake's parser recursed without bound)",
          area="check", prepare=_file("self.xml", "<mujoco><include file='self.xml'/></mujoco>"),
          argv=("check", "{tmp}/self.xml", "--out", OUT),
          answer=r"<tmp>/self.xml: <include file='self.xml'> includes itself \(an include cycle"),
    Fault(kind="MJCF include cycle through a second file", area="check",
          prepare=lambda tmp: (_file("b.xml", "<mujoco><include file='c.xml'/></mujoco>")(tmp),
                               _file("c.xml", "<mujoco><include file='b.xml'/></mujoco>")(tmp)),
          argv=("check", "{tmp}/b.xml", "--out", OUT), answer=r"includes itself"),
    Fault(kind="MJCF include of a named pipe (blocked every reader)", area="check",
          prepare=lambda tmp: (os.mkfifo(tmp / "pipe.xml"), _file(
              "p.xml", "<mujoco><include file='pipe.xml'/></mujoco>")(tmp)),
          argv=("check", "{tmp}/p.xml", "--out", OUT),
          answer=r"<tmp>/p.xml: <include file='pipe.xml'>: not a regular file"),
    Fault(kind="MJCF with an unknown element", area="check",
          prepare=_file("u.xml", "<mujoco><worldbody><gizmo/></worldbody></mujoco>"),
          argv=("check", "{tmp}/u.xml", "--out", OUT), answer=r"<tmp>/u.xml: mujoco refused"),
    Fault(kind="URDF mesh missing (no mesh is read: a note on the page, the model checked)",
          area="check",
          prepare=_file("m.urdf", URDF.replace(
              '<link name="base">', '<link name="base"><visual><geometry><mesh filename='
              '"meshes/base.stl"/></geometry></visual>')),
          argv=("check", "{tmp}/m.urdf", "--states", "2", "--out", OUT),
          answer=r"^m: \d+ passed", exit=0),
    Fault(kind="model with no degree of freedom", area="check",
          prepare=_file("z.xml", "<mujoco><worldbody><body><geom size='0.1'/></body>"
                        "</worldbody></mujoco>"),
          argv=("check", "{tmp}/z.xml", "--out", OUT),
          answer=r"<tmp>/z.xml: has no degrees of freedom"),
    Fault(kind="URDF joint type no engine maps (planar)", area="check",
          prepare=_file("p.urdf", URDF.replace('type="continuous"', 'type="planar"')),
          argv=("check", "{tmp}/p.urdf", "--out", OUT),
          answer=r"joint 'leg_joint' has type 'planar'"),
    Fault(kind="URDF with a negative mass", area="check", exit=1,
          prepare=_file("neg.urdf", URDF.replace('<mass value="1.5"/>', '<mass value="-1.5"/>')),
          argv=("check", "{tmp}/neg.urdf", "--states", "5", "--out", OUT),
          answer=r"^neg: \d+ passed, \d+ explained, [1-9]\d* failed"),
    Fault(kind="URDF inertia breaking the triangle inequality", area="check", exit=1,
          prepare=_file("tri.urdf", URDF.replace('ixx="0.02"', 'ixx="2.0"', 1)),
          argv=("check", "{tmp}/tri.urdf", "--states", "5", "--out", OUT),
          answer=r"^tri: \d+ passed, \d+ explained, [1-9]\d* failed"),
    Fault(kind="--states 0", area="check", argv=("check", BRANCHES, "--states", "0",
                                                 "--out", OUT),
          answer=r"--states must be an integer in \[1, 100000\], got 0$"),
    Fault(kind="--states too many", area="check",
          argv=("check", BRANCHES, "--states", str(10**11), "--out", OUT),
          answer=r"--states must be an integer in \[1, 100000\], got 100000000000$"),
    Fault(kind="--seed negative", area="check",
          argv=("check", BRANCHES, "--seed", "-1", "--out", OUT),
          answer=r"--seed must be a non-negative integer, got -1$"),
    Fault(kind="--seed not a number", area="check",
          argv=("check", BRANCHES, "--seed", "x", "--out", OUT),
          answer=r"argument --seed: invalid int value: 'x'$"),
    Fault(kind="unknown robot", area="check", argv=("check", "--robot", "no_such_robot",
                                                    "--out", OUT),
          answer=r"no_such_robot"),
    Fault(kind="MJCF encoded as UTF-16 (it says so; read as UTF-8 before: a traceback)",
          area="check",
          prepare=_file("u16.xml", ('<?xml version="1.0" encoding="UTF-16"?>' + SMALL_MJCF
                                    .replace("<body>", "<body name='b'>")).encode("utf-16")),
          argv=("check", "{tmp}/u16.xml", "--states", "2", "--out", OUT),
          answer=r"^u16: \d+ passed, \d+ explained, 0 failed, 0 skipped", exit=0),
    Fault(kind="MJCF encoded as Latin-1 with a non-ASCII name (every engine failed)",
          area="check",
          prepare=_file("l1.xml", ('<?xml version="1.0" encoding="ISO-8859-1"?><mujoco '
                                   "model='ïn'><worldbody><body name='bödy'><joint name='j' "
                                   "type='hinge'/><geom size='0.1'/></body></worldbody>"
                                   "</mujoco>").encode("latin-1")),
          argv=("check", "{tmp}/l1.xml", "--states", "2", "--out", OUT),
          answer=r"^l1: \d+ passed, \d+ explained, 0 failed, 0 skipped", exit=0),
    Fault(kind="URDF encoded as Latin-1 with a non-ASCII link name (decoded as declared)",
          area="check",
          prepare=_file("l1.urdf", ('<?xml version="1.0" encoding="ISO-8859-1"?>' + URDF
                                    .split("?>", 1)[-1].replace('name="base"', 'name="bäse"')
                                    .replace('link="base"', 'link="bäse"')).encode("latin-1")),
          argv=("check", "{tmp}/l1.urdf", "--states", "2", "--out", OUT),
          answer=r"^l1: \d+ passed", exit=0),
    Fault(kind="inertia of 1e308 (eigenvalues overflowed: a traceback before)", area="check",
          prepare=_file("big.xml", "<mujoco><worldbody><body><joint type='hinge'/><inertial "
                        "pos='0 0 -0.2' mass='1e308' diaginertia='1e308 1e308 1e308'/></body>"
                        "</worldbody></mujoco>"),
          argv=("check", "{tmp}/big.xml", "--states", "2", "--out", OUT),
          answer=r"returned a non-finite", exit=1),
    Fault(kind="--junit a folder", area="check", prepare=_folder("j"),
          argv=("check", BRANCHES, "--junit", "{tmp}/j", "--out", OUT),
          answer=r"--junit must be a file path, not a folder"),
    Fault(kind="--json under a path that is a file", area="run",
          prepare=_file("f.txt", "not a folder"),
          argv=("run", "simple_pendulum", "--json", "{tmp}/f.txt/r.json", "--out", OUT),
          answer=r"--json must be a directory, got '<tmp>/f.txt'$"),
    Fault(kind="--device cuda on a machine without an NVIDIA driver (a JAX traceback before)",
          area="run", argv=("run", "simple_pendulum", "--device", "cuda", "--out", OUT),
          patch=lambda mp, tmp: mp.setattr("dyncheck.commands.options.has_cuda", lambda: False),
          answer=r"--device must be cpu on this machine \(no NVIDIA driver found\), "
                 r"got 'cuda'$"),
    Fault(kind="a bogus DYNCHECK_DEVICE in the environment (a Warp traceback before)",
          area="run", argv=("run", "simple_pendulum", "--out", OUT),
          patch=lambda mp, tmp: mp.setenv("DYNCHECK_DEVICE", "bogus"),
          answer=r"DYNCHECK_DEVICE must be cpu, cuda or cuda:N \(the environment\), "
                 r"got 'bogus'$"),
    Fault(kind="a bogus DYNCHECK_DEVICE for check", area="check",
          argv=("check", BRANCHES, "--out", OUT),
          patch=lambda mp, tmp: mp.setenv("DYNCHECK_DEVICE", "gpu9"),
          answer=r"DYNCHECK_DEVICE must be cpu, cuda or cuda:N"),
    Fault(kind="--jobs beyond any machine (check)", area="check",
          argv=("check", BRANCHES, "--jobs", "100000", "--out", OUT),
          answer=r"--jobs must be a positive integer at most 256, got 100000$"),
    Fault(kind="bench --states of 10^11 (745 GiB: a numpy traceback before)", area="bench",
          argv=("bench", "simple_pendulum", "--states", "100000000000", "--out", OUT),
          answer=r"--states must be a positive integer at most 10000000, got 100000000000$"),
    Fault(kind="bench --memory of 10^9 states", area="bench",
          argv=("bench", "--memory", "1000000000", "--out", OUT),
          answer=r"--memory must be a positive integer at most 100000000"),
    Fault(kind="bench --repeats 10^6", area="bench",
          argv=("bench", "--repeats", "1000000", "--out", OUT),
          answer=r"--repeats must be a positive integer at most 100, got 1000000$"),
    Fault(kind="bench --jobs 10^5", area="bench",
          argv=("bench", "--jobs", "100000", "--out", OUT),
          answer=r"--jobs must be a positive integer at most 256"),
    Fault(kind="--engine-memory below the smallest cap", area="check",
          argv=("check", BRANCHES, "--engine-memory", "16", "--out", OUT),
          answer=r"--engine-memory must be 0 \(no cap\) or a size in MiB in \[256, 1048576\], "
                 r"got 16$"),
    Fault(kind="--engine-memory above any machine", area="check",
          argv=("check", BRANCHES, "--engine-memory", "99999999", "--out", OUT),
          answer=r"--engine-memory must be 0 \(no cap\) or a size in MiB"),
    Fault(kind="--engine-seconds zero", area="check",
          argv=("check", BRANCHES, "--engine-seconds", "0", "--out", OUT),
          answer=r"--engine-seconds must be a number of seconds in \[1, 86400\], got 0.0$"),
    Fault(kind="--engine-seconds not a number", area="check",
          argv=("check", BRANCHES, "--engine-seconds", "nan", "--out", OUT),
          answer=r"--engine-seconds must be a number of seconds"),
    Fault(kind="unknown implementation", area="check",
          argv=("check", BRANCHES, "--impl", "bulet", "--out", OUT),
          answer=r"unknown implementation 'bulet'; valid: " + re.escape(CHECKED) + "$"),
    Fault(kind="only the referee chosen", area="check",
          argv=("check", BRANCHES, "--impl", "reference", "--out", OUT),
          answer=r"--impl must be at least one engine"),
    Fault(kind="--against missing", area="check",
          argv=("check", BRANCHES, "--against", "{tmp}/old.urdf", "--out", OUT),
          answer=r"<tmp>/old.urdf: no such file$"),
    Fault(kind="--out below a file", area="check", prepare=_file("file", "keep"),
          argv=("check", BRANCHES, "--out", "{tmp}/file/sub"),
          answer=r"--out must be a folder path \(<tmp>/file is a file\)"),
    # --- diff
    Fault(kind="RUN_A missing", area="diff", argv=("diff", "{tmp}/a", "{tmp}/b"),
          answer=r"RUN_A must be an existing output folder of `run` or `check`, got '<tmp>/a'$"),
    Fault(kind="RUN_A an empty folder", area="diff", prepare=_folder("a"),
          argv=("diff", "{tmp}/a", str(REPORTS)), answer=r"RUN_A .*'<tmp>/a'"),
    Fault(kind="a run against a check", area="diff",
          argv=("diff", str(REPORTS), str(REPORTS / "check")),
          answer=r"RUN_B must be the output of `run`, like RUN_A"),
    Fault(kind="--tolerance below 1", area="diff",
          argv=("diff", str(REPORTS), str(REPORTS), "--tolerance", "0.5"),
          answer=r"--tolerance must be a finite factor > 1, got 0.5$"),
    Fault(kind="--tolerance NaN", area="diff",
          argv=("diff", str(REPORTS), str(REPORTS), "--tolerance", "nan"),
          answer=r"--tolerance must be a finite factor > 1, got nan$"),
    Fault(kind="--markdown a folder", area="diff", prepare=_folder("md"),
          argv=("diff", str(REPORTS), str(REPORTS), "--markdown", "{tmp}/md"),
          answer=r"--markdown must be a file path, not a folder, got '<tmp>/md'$"),
    Fault(kind="a run whose CSV is corrupted", area="diff",
          prepare=lambda tmp: _file("discrepancies.csv", "case,quantity\n\x00\x01,2,3\n")(
              _folder("a")(tmp)),
          argv=("diff", "{tmp}/a", str(REPORTS)), answer=r"RUN_A .*<tmp>/a"),
    # --- versions
    Fault(kind="unknown engine", area="versions", argv=("versions", "--engine", "bullet"),
          answer=r"unknown engine 'bullet'; valid: " + re.escape(VERSIONED) + "$"),
    Fault(kind="unknown case", area="versions", argv=("versions", "--case", "nope"),
          answer=r"unknown case 'nope'"),
    Fault(kind="--jobs 0", area="versions", argv=("versions", "--jobs", "0"),
          answer=r"--jobs must be a positive integer at most 256, got 0$"),
    Fault(kind="--bisect with GOOD equal to BAD", area="versions",
          argv=("versions", "--bisect", "mujoco", "3.2.7", "3.2.7"),
          answer=r"--bisect must be GOOD older than BAD, got '3.2.7 3.2.7'$"),
    Fault(kind="--bisect an unknown engine", area="versions",
          argv=("versions", "--bisect", "bullet", "1", "2"),
          answer=r"unknown engine 'bullet'"),
    Fault(kind="--out a folder", area="versions", prepare=_folder("v"),
          argv=("versions", "--engine", "mujoco", "--out", "{tmp}/v"),
          answer=r"--out must be a file path, not a folder, got '<tmp>/v'$"),
    # --- report
    Fault(kind="--check on a missing folder", area="report",
          argv=("report", "--check", "--out", "{tmp}/none"),
          answer=r"--out must be an existing report folder, got '<tmp>/none'$"),
    Fault(kind="--check on a folder with no report", area="report", prepare=_folder("r"),
          argv=("report", "--check", "--out", "{tmp}/r"),
          answer=r"--out must be a report folder written by `dyncheck run` \(it has no "
                 r"discrepancies.csv\), got '<tmp>/r'$"),
    Fault(kind="--jobs 0", area="report", argv=("report", "--check", "--jobs", "0"),
          answer=r"--jobs must be a positive integer at most 256, got 0$"),
    Fault(kind="--check missing", area="report", argv=("report",),
          answer=r"^dyncheck: error: report: the following arguments are required: --check$"),
    # --- explain, tutorials
    Fault(kind="unknown convention", area="explain", argv=("explain", "nope"),
          answer=r"unknown convention 'nope'; valid: "),
    Fault(kind="--reproducer of a convention that is no engine defect", area="explain",
          argv=("explain", "quaternion-storage-order", "--reproducer", OUT + "/r.py"),
          answer=r"--reproducer must be given with a convention that is an engine's defect: "
          r"one of pinocchio-mjcf-options"),
    Fault(kind="--reproducer into a folder", area="explain",
          argv=("explain", "pinocchio-mjcf-options", "--reproducer", "{tmp}"),
          answer=r"--reproducer must be a file path, not a folder"),
    Fault(kind="--jobs 0 (explain)", area="explain", argv=("explain", "--jobs", "0"),
          answer=r"--jobs must be"),
    Fault(kind="unknown tutorial", area="tutorials", argv=("tutorials", "nope", "--out", OUT),
          answer=r"unknown tutorial 'nope'; valid: 01_quaternion_order"),
    Fault(kind="--out below a file", area="tutorials", prepare=_file("file", "keep"),
          argv=("tutorials", "01_quaternion_order", "--out", "{tmp}/file/sub"),
          answer=r"--out must be a folder path \(<tmp>/file is a file\)"),
    # --- baseline
    Fault(kind="--out an existing folder", area="baseline", prepare=_folder("b"),
          argv=("baseline", "simple_pendulum", "--out", "{tmp}/b"),
          answer=r"--out must be a file path, not a folder, got '<tmp>/b'$"),
    Fault(kind="--out below a file", area="baseline", prepare=_file("file", "keep"),
          argv=("baseline", "simple_pendulum", "--out", "{tmp}/file/b.csv"),
          answer=r"--out must be a directory, got '<tmp>/file'$"),
    Fault(kind="the baseline to replace is corrupted", area="baseline",
          prepare=_file("b.csv", "# dyncheck baseline rows=3\ncase,quantity\n"),
          argv=("baseline", "simple_pendulum", "--out", "{tmp}/b.csv"),
          answer=r"--out .*'<tmp>/b.csv'"),
    Fault(kind="unknown case", area="baseline", argv=("baseline", "nope", "--out", "{tmp}/b.csv"),
          answer=r"unknown case 'nope'"),
    # --- bench
    Fault(kind="unknown case", area="bench", argv=("bench", "nope", "--out", OUT),
          answer=r"unknown case 'nope'"),
    Fault(kind="--states 0", area="bench", argv=("bench", "--states", "0", "--out", OUT),
          answer=r"--states must be a positive integer at most 10000000, got 0$"),
    Fault(kind="--repeats 0", area="bench", argv=("bench", "--repeats", "0", "--out", OUT),
          answer=r"--repeats must be a positive integer at most 100, got 0$"),
    Fault(kind="--memory negative (hung before)", area="bench",
          argv=("bench", "simple_pendulum", "--memory", "-3", "--out", OUT),
          answer=r"--memory must be a positive integer at most 100000000, got -3$"),
    Fault(kind="--memory not a number", area="bench", argv=("bench", "--memory", "abc"),
          answer=r"argument --memory: invalid int value: 'abc'$"),
    # --- the Python API: a case or a model built with impossible values
    Fault(kind="body mass negative", area="Python API", call=lambda t: _body(mass=-1.0),
          answer=r"^b\.mass must be a positive finite number, got -1\.0$"),
    Fault(kind="body mass infinite", area="Python API", call=lambda t: _body(mass=float("inf")),
          answer=r"^b\.mass must be a positive finite number, got inf$"),
    Fault(kind="inertia not positive definite", area="Python API",
          call=lambda t: _body(inertia=((1, 0, 0), (0, 1, 0), (0, 0, -1))),
          answer=r"^b\.inertia must be positive definite"),
    Fault(kind="inertia not symmetric", area="Python API",
          call=lambda t: _body(inertia=((1, 0.5, 0), (0, 1, 0), (0, 0, 1))),
          answer=r"^b\.inertia must be a symmetric"),
    Fault(kind="inertia breaking I1 + I2 >= I3", area="Python API",
          call=lambda t: _body(inertia=((1, 0, 0), (0, 1, 0), (0, 0, 3))),
          answer=r"^b\.inertia must be an inertia whose principal moments obey I1 \+ I2 >= I3"),
    Fault(kind="centre of mass NaN", area="Python API",
          call=lambda t: _body(com=(0, float("nan"), 0)),
          answer=r"^b\.com must be finite \(no NaN or inf\)"),
    Fault(kind="joint position of the wrong shape", area="Python API",
          call=lambda t: _body(joint_pos=(0, 0)), answer=r"^b\.joint_pos must be of shape"),
    Fault(kind="joint type unknown", area="Python API",
          call=lambda t: Joint("j", "universal", Y),  # type: ignore[arg-type]
          answer=r"^j\.type must be one of \('hinge', 'slide', 'ball', 'free'\), got 'universal'$"),
    Fault(kind="joint axis not a unit vector", area="Python API",
          call=lambda t: Joint("j", "hinge", (0.0, 2.0, 0.0)),
          answer=r"^j\.axis must be a unit vector"),
    Fault(kind="joint axis zero", area="Python API",
          call=lambda t: Joint("j", "hinge", (0.0, 0.0, 0.0)),
          answer=r"^j\.axis must be a unit vector"),
    Fault(kind="initial state NaN", area="Python API",
          call=_trajectory("simple_pendulum", q0=(float("nan"),)),
          answer=r"^q0 must be finite \(no NaN or inf\)"),
    Fault(kind="initial velocity infinite", area="Python API",
          call=_trajectory("simple_pendulum", v0=(float("inf"),)), answer=r"^v0 must be finite"),
    Fault(kind="initial state of the wrong length", area="Python API",
          call=_trajectory("simple_pendulum", q0=(0.1, 0.2), v0=(0.0, 0.0)),
          answer=r"^trajectory\.q0 must be 1 value, one per coordinate \('θ',\), "
                 r"got \(0\.1, 0\.2\)$"),
    Fault(kind="initial velocity shorter than the state", area="Python API",
          call=_trajectory("simple_pendulum", v0=()),
          answer=r"^v0 must be 1 value, as many as q0, got \(\)$"),
    Fault(kind="case seed negative (accepted silently before)", area="Python API",
          call=_case("simple_pendulum", seed=-1),
          answer=r"^seed must be a non-negative integer, got -1$"),
    Fault(kind="case sample count zero", area="Python API",
          call=_case("simple_pendulum", n_states=0),
          answer=r"^n_states must be a positive integer, got 0$"),
    Fault(kind="duration zero", area="Python API",
          call=_trajectory("simple_pendulum", duration=0.0),
          answer=r"^duration must be a positive finite number, got 0\.0$"),
    Fault(kind="integrator unknown", area="Python API",
          call=_trajectory("simple_pendulum", steps={"leapfrog": (0.1, 0.05)}),
          answer=r"^integrator must be one of euler, implicitfast"),
    Fault(kind="step size negative", area="Python API",
          call=_trajectory("simple_pendulum", steps={"euler": (-0.1, -0.05)}),
          answer=r"^steps\[euler\] dt must be a positive finite"),
    Fault(kind="one step size (no convergence order)", area="Python API",
          call=_trajectory("simple_pendulum", steps={"euler": (0.1,)}),
          answer=r"^steps\[euler\] must be at least two step sizes"),
    Fault(kind="state on the chart's singular set (spherical pendulum)", area="Python API",
          call=_trajectory("spherical_pendulum", q0=(0.0, 0.3)),
          answer=r"^q0 must be off the singular set of the book's chart \(φ = 0"),
    Fault(kind="state on the z axis (spherical coordinates)", area="Python API",
          call=_trajectory("spherical_coordinates", q0=(1.0, 0.0, 0.2)),
          answer=r"θ = 0 or π, the z axis"),
    Fault(kind="state at the origin (Kepler)", area="Python API",
          call=_trajectory("kepler", q0=(0.0, 1.0, 0.2)), answer=r"ρ = 0, the origin"),
    Fault(kind="state on the axis (cylindrical coordinates)", area="Python API",
          call=_trajectory("cylindrical_coordinates", q0=(0.0, 0.3, 0.5)),
          answer=r"r = 0, the z axis"),
    Fault(kind="case parameter 1e308 (OverflowError before)", area="Python API",
          call=_case("simple_pendulum", m=1e308),
          answer=r"^m must be in \[1e-77, 1e\+77\] .*, got 1e\+308$"),
    Fault(kind="case parameter 1e-300 (silent underflow before)", area="Python API",
          call=_case("simple_pendulum", l=1e-300),
          answer=r"^l must be in \[1e-77, 1e\+77\] .*, got 1e-300$"),
    Fault(kind="case parameter zero", area="Python API", call=_case("atwood", g=0.0),
          answer=r"^g must be a positive finite number, got 0\.0$"),
)

# --- the second probe (#44): MJCF and URDF files other people write, every command's options
REPORTS_DIR = str(REPORTS)


def mj(body: str, extra: str = "") -> str:
    return f"<mujoco>{extra}<worldbody>{body}</worldbody></mujoco>"


HINGE = (
    "<body name='b'><joint name='j' type='hinge' axis='0 1 0'/><geom size='0.1' mass='1'/></body>"
)


def chk(kind, name, content, *more, exit=2, answer="."):
    return Fault(
        kind=kind,
        area="check",
        prepare=_file(name, content),
        argv=("check", "{tmp}/" + name, "--states", "3", *more, "--out", OUT),
        answer=answer,
        exit=exit,
    )


HOSTILE_MODELS: tuple[Fault, ...] = (
    chk(
        "MJCF joint range with min above max",
        "a.xml",
        mj("<body><joint type='hinge' range='1 -1'/><geom size='0.1'/></body>"),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "MJCF free joint inside a child body",
        "a.xml",
        mj(
            "<body><joint type='hinge'/><geom size='0.1'/><body><freejoint/><geom size='0.1'/>"
            "</body></body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: free joint can only be",
    ),
    chk(
        "MJCF inertial mass negative",
        "a.xml",
        mj(
            "<body><joint type='hinge'/><inertial pos='0 0 0' mass='-1' diaginertia='1 1 1'/>"
            "</body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: mass and inertia of mo",
    ),
    chk(
        "MJCF inertial mass NaN",
        "a.xml",
        mj(
            "<body><joint type='hinge'/><inertial pos='0 0 0' mass='nan' diaginertia='1 1 1'/>"
            "</body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: mass and inertia of mo",
    ),
    chk(
        "MJCF diaginertia negative",
        "a.xml",
        mj(
            "<body><joint type='hinge'/><inertial pos='0 0 0' mass='1' diaginertia='-1 1 1'/>"
            "</body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: mass and inertia of mo",
    ),
    chk(
        "MJCF fullinertia not positive definite",
        "a.xml",
        mj(
            "<body><joint type='hinge'/>"
            "<inertial pos='0 0 0' mass='1' fullinertia='1 1 1 2 0 0'/></body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: error 'inertia must ha",
    ),
    chk(
        "MJCF hinge axis zero",
        "a.xml",
        mj("<body><joint type='hinge' axis='0 0 0'/><geom size='0.1'/></body>"),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: axis too small in join",
    ),
    chk(
        "MJCF two joints with one name",
        "a.xml",
        mj(
            "<body><joint name='j' type='hinge'/><geom size='0.1'/><body pos='0 0 1'>"
            "<joint name='j' type='hinge'/><geom size='0.1'/></body></body>"
        ),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: XML Error: Error: repeated na",
    ),
    chk(
        "MJCF gravity NaN",
        "a.xml",
        mj(HINGE, "<option gravity='nan 0 0'/>"),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "MJCF time step negative",
        "a.xml",
        mj(HINGE, "<option timestep='-1'/>"),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF unknown attribute",
        "a.xml",
        mj("<body><joint type='hinge' colour='red'/><geom size='0.1'/></body>"),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: XML Error: Schema violation: ",
    ),
    chk(
        "MJCF moving body with no mass",
        "a.xml",
        mj("<body><joint type='hinge'/><site/></body>"),
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: mass and inertia of mo",
    ),
    chk(
        "MJCF mesh file missing",
        "a.xml",
        "<mujoco><asset><mesh name='m' file='gone.stl'/></asset><worldbody><body>"
        "<joint type='hinge'/><geom type='mesh' mesh='m'/></body></worldbody></mujoco>",
        exit=2,
        answer=r"<tmp>/a\.xml: mujoco refused <tmp>/a\.xml: Error: Error opening file 'go",
    ),
    chk(
        "MJCF include of /etc/passwd",
        "a.xml",
        "<mujoco><include file='/etc/passwd'/></mujoco>",
        exit=2,
        answer=r"<tmp>/a\.xml: /etc/passwd: not XML \(not well-formed \(invalid token\): li",
    ),
    chk(
        "MJCF include of /dev/zero",
        "a.xml",
        "<mujoco><include file='/dev/zero'/></mujoco>",
        exit=2,
        answer=r"<tmp>/a\.xml: <include file='zero'>: not a regular file",
    ),
    chk(
        "MJCF include with no file attribute",
        "a.xml",
        "<mujoco><include/></mujoco>",
        exit=2,
        answer=r"<tmp>/a\.xml: <include> has no file attribute",
    ),
    chk(
        "XML external entity (XXE) reading /etc/passwd",
        "a.xml",
        "<?xml version='1.0'?><!DOCTYPE m [<!ENTITY x SYSTEM 'file:///etc/passwd'>]>"
        "<mujoco model='&x;'><worldbody/></mujoco>",
        exit=2,
        answer=r"<tmp>/a\.xml: not XML \(line 1, column 90\)",
    ),
    chk(
        "XML billion laughs",
        "a.xml",
        "<?xml version='1.0'?><!DOCTYPE l [<!ENTITY a 'aaaaaaaaaa'>"
        "<!ENTITY b '&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;'><!ENTITY c '&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;'>"
        "<!ENTITY d '&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;'><!ENTITY e '&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;'>"
        "<!ENTITY f '&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;'><!ENTITY g '&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;'>"
        "<!ENTITY h '&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;'>]><mujoco model='&h;'/>",
        exit=2,
        answer=r"<tmp>/a\.xml: not XML \(line 1, column 368\)",
    ),
    chk(
        "MJCF in UTF-8 with a byte-order mark",
        "a.xml",
        ("\ufeff" + mj(HINGE)).encode("utf-8"),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF in UTF-16 (declared)",
        "a.xml",
        ("<?xml version='1.0' encoding='UTF-16'?>" + mj(HINGE)).encode("utf-16"),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF in Latin-1 with an accented name (declared)",
        "a.xml",
        (
            "<?xml version='1.0' encoding='ISO-8859-1'?>"
            + mj(HINGE.replace("name='b'", "name='bé'"))
        ).encode("latin-1"),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF declaring an encoding it is not in",
        "a.xml",
        ("<?xml version='1.0' encoding='UTF-16'?>" + mj(HINGE)).encode("utf-8"),
        exit=2,
        answer=r"<tmp>/a\.xml: not XML \(line 1, column 30\)",
    ),
    chk(
        "MJCF declaring an unknown encoding",
        "a.xml",
        ("<?xml version='1.0' encoding='klingon'?>" + mj(HINGE)).encode("utf-8"),
        exit=2,
        answer=r"<tmp>/a\.xml: not XML: it declares an encoding no parser knows \(unknown",
    ),
    chk(
        "MJCF joint name of 10000 characters",
        "a.xml",
        mj(HINGE.replace("name='j'", "name='" + "j" * 10000 + "'")),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF joint name with Markdown and HTML",
        "a.xml",
        mj(HINGE.replace("name='j'", "name='&lt;b&gt;|x|&#10;# h'")),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF with springs (stiffness) and damping",
        "a.xml",
        mj(HINGE.replace("axis='0 1 0'", "axis='0 1 0' stiffness='10' damping='1'")),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF with an actuator and a sensor",
        "a.xml",
        mj(HINGE, "").replace(
            "</mujoco>",
            "<actuator><motor joint='j'/></actuator><sensor><jointpos joint='j'/></sensor>"
            "</mujoco>",
        ),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF with a weld equality",
        "a.xml",
        mj(
            HINGE + "<body name='c' pos='1 0 0'><joint type='slide'/><geom size='0.1'/></body>"
        ).replace("</mujoco>", "<equality><weld body1='b' body2='c'/></equality></mujoco>"),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "MJCF with angles in degrees (compiler)",
        "a.xml",
        mj(
            "<body euler='90 0 0'><joint type='hinge'/><geom size='0.1'/></body>",
            "<compiler angle='degree'/>",
        ),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF with 300 nested bodies",
        "a.xml",
        mj(
            "".join(
                "<body pos='0 0 0.1'><joint type='hinge'/><geom size='0.01'/>" for _ in range(300)
            )
            + "</body>" * 300
        ),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    chk(
        "MJCF mujoco root with no worldbody",
        "a.xml",
        "<mujoco/>",
        exit=2,
        answer=r"<tmp>/a\.xml: has no degrees of freedom \(nothing moves\)",
    ),
    chk(
        "URDF with two root links",
        "a.urdf",
        URDF.replace(
            "</robot>",
            '<link name="stray"><inertial><mass value="1"/>'
            '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>',
        ),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "URDF with a joint to a missing link",
        "a.urdf",
        URDF.replace(
            "</robot>",
            '<joint name="x" type="revolute"><parent link="base"/><child link="ghost"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            '</robot>',
        ),
        exit=2,
        answer=r"<tmp>/a\.urdf: no engine could load it: mujoco refused <tmp>/a\.urdf: XM",
    ),
    chk(
        "URDF with two links of one name",
        "a.urdf",
        URDF.replace("</robot>", '<link name="base"/></robot>'),
        exit=2,
        answer=r"<tmp>/a\.urdf: no engine could load it: mujoco refused <tmp>/a\.urdf: XM",
    ),
    chk(
        "URDF joint axis zero",
        "a.urdf",
        URDF.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>', 1),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "URDF inertia NaN",
        "a.urdf",
        URDF.replace('ixx="0.02"', 'ixx="nan"', 1),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "URDF mass not a number",
        "a.urdf",
        URDF.replace('<mass value="1.5"/>', '<mass value="heavy"/>'),
        exit=2,
        answer=r"<tmp>/a\.urdf: link 'aa_leg': <mass value='heavy'> is not a number",
    ),
    chk(
        "URDF origin with two numbers",
        "a.urdf",
        URDF.replace('rpy="0.1 0.2 0.3"', 'rpy="0.1 0.2"', 1),
        exit=2,
        answer=r"<tmp>/a\.urdf: no engine could load it: mujoco refused <tmp>/a\.urdf: XM",
    ),
    chk(
        "URDF floating joint below a link (was refused: MuJoCo and Pinocchio read it)",
        "a.urdf",
        URDF.replace('type="continuous"', 'type="floating"'),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed, 1 skipped",
    ),
    chk(
        "URDF with no links",
        "a.urdf",
        '<robot name="r"/>',
        exit=2,
        answer=r"<tmp>/a\.urdf: has no degrees of freedom \(nothing moves\)",
    ),
    chk(
        "URDF with xacro macros (not expanded)",
        "a.urdf",
        URDF.replace(
            "</robot>",
            '<xacro:macro name="m" xmlns:xacro="http://www.ros.org/wiki/xacro"/></robot>',
        ),
        exit=2,
        answer=r"<tmp>/a\.urdf: is an unexpanded xacro file \(<xacro:macro>\): the engines",
    ),
    chk(
        "URDF with transmission and gazebo tags",
        "a.urdf",
        URDF.replace("</robot>", '<transmission name="t"/><gazebo reference="base"/></robot>'),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
    chk(
        "URDF robot without a name",
        "a.urdf",
        URDF.replace('<robot name="branches">', "<robot>"),
        exit=1,
        answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed",
    ),
)


def twofiles(a, ca, b, cb):
    def make(tmp):
        _file(a, ca)(tmp)
        _file(b, cb)(tmp)

    return make


def sub_folder(tmp):
    (tmp / "sub").mkdir()
    _file("a.xml", "<mujoco><include file='sub'/></mujoco>")(tmp)


def symloop(tmp):
    os.symlink(tmp / "l2.xml", tmp / "l1.xml")
    os.symlink(tmp / "l1.xml", tmp / "l2.xml")


def dangling(tmp):
    os.symlink(tmp / "gone.xml", tmp / "d.xml")


MJ = mj(HINGE)
MORE_FAULTS: tuple[Fault, ...] = (
    Fault(
        kind="MJCF include of a folder",
        area="check",
        prepare=sub_folder,
        argv=("check", "{tmp}/a.xml", "--out", OUT),
        exit=2,
        answer=r"<tmp>/a\.xml: <include file='sub'>: not a regular file",
    ),
    Fault(
        kind="model path a symlink loop",
        area="check",
        prepare=symloop,
        argv=("check", "{tmp}/l1.xml", "--out", OUT),
        exit=2,
        answer=r"argument PATH: '<tmp>/l1\.xml' is a symlink loop",
    ),
    Fault(
        kind="model path a dangling symlink",
        area="check",
        prepare=dangling,
        argv=("check", "{tmp}/d.xml", "--out", OUT),
        exit=2,
        answer=r"<tmp>/d\.xml: no such file",
    ),
    Fault(
        kind="model path /dev/zero",
        area="check",
        argv=("check", "/dev/zero", "--out", OUT),
        exit=2,
        answer=r"/dev/zero: not a file",
    ),
    Fault(
        kind="model path /dev/stdin (a terminal or pipe)",
        area="check",
        argv=("check", "/dev/stdin", "--out", OUT),
        exit=2,
        answer=r"/dev/stdin: not a file",
    ),
    Fault(
        kind="model with an unknown suffix (.txt)",
        area="check",
        prepare=_file("m.txt", MJ),
        argv=("check", "{tmp}/m.txt", "--out", OUT),
        exit=2,
        answer=r"<tmp>/m\.txt: an MJCF must be named \*\.xml for MuJoCo, which picks its p",
    ),
    Fault(
        kind="model suffix in capitals (.XML)",
        area="check",
        prepare=_file("m.XML", MJ),
        argv=("check", "{tmp}/m.XML", "--states", "3", "--out", OUT),
        exit=2,
        answer=r"<tmp>/m\.XML: an MJCF must be named \*\.xml for MuJoCo, which picks its p",
    ),
    Fault(
        kind="model file name with spaces and accents",
        area="check",
        prepare=_file("mé del.xml", MJ),
        argv=("check", "{tmp}/mé del.xml", "--states", "3", "--out", OUT),
        exit=0,
        answer=r"^mé\ del: \d+ passed, \d+ explained, 0 failed",
    ),
    Fault(
        kind="model file name starting with = (a CSV formula)",
        area="check",
        prepare=_file("=cmd.xml", MJ),
        argv=("check", "{tmp}/=cmd.xml", "--states", "3", "--out", OUT),
        exit=0,
        answer=r"^=cmd: \d+ passed, \d+ explained, 0 failed",
    ),
    Fault(
        kind="--robot empty",
        area="check",
        argv=("check", "--robot", "", "--out", OUT),
        exit=2,
        answer=r"unknown robot ''; valid: TwoDofs, a1, alex_nub_hands, alex_psyonic_han",
    ),
    Fault(
        kind="--case unknown",
        area="check",
        argv=("check", "--case", "nope", "--out", OUT),
        exit=2,
        answer=r"unknown case 'nope'; valid: " + re.escape(CASE_NAMES) + "$",
    ),
    Fault(
        kind="--impl given twice",
        area="check",
        prepare=_file("a.xml", MJ),
        argv=(
            "check",
            "{tmp}/a.xml",
            "--impl",
            "mujoco",
            "--impl",
            "mujoco",
            "--states",
            "3",
            "--out",
            OUT,
        ),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    Fault(
        kind="--impl empty",
        area="check",
        argv=("check", BRANCHES, "--impl", "", "--out", OUT),
        exit=2,
        answer=r"unknown implementation ''; valid: " + re.escape(CHECKED) + "$",
    ),
    Fault(
        kind="--against a folder",
        area="check",
        prepare=_folder("old"),
        argv=("check", BRANCHES, "--against", "{tmp}/old", "--out", OUT),
        exit=2,
        answer=r"<tmp>/old: not a file",
    ),
    Fault(
        kind="--against a file that is not a model",
        area="check",
        prepare=_file("old.xml", "<svg/>"),
        argv=("check", BRANCHES, "--against", "{tmp}/old.xml", "--out", OUT),
        exit=2,
        answer=r"<tmp>/old\.xml: root element <svg> is neither <mujoco> nor <robot>",
    ),
    Fault(
        kind="--json below a file",
        area="check",
        prepare=_file("f", "x"),
        argv=("check", BRANCHES, "--json", "{tmp}/f/out.json", "--out", OUT),
        exit=2,
        answer=r"--json must be a directory, got '<tmp>/f'",
    ),
    Fault(
        kind="--junit below a file",
        area="check",
        prepare=_file("f", "x"),
        argv=("check", BRANCHES, "--junit", "{tmp}/f/out.xml", "--out", OUT),
        exit=2,
        answer=r"--junit must be a directory, got '<tmp>/f'",
    ),
    Fault(
        kind="--json and --junit the same file",
        area="check",
        argv=("check", BRANCHES, "--json", "{tmp}/r", "--junit", "{tmp}/r", "--out", OUT),
        exit=2,
        answer=r"--json must be a file other than --junit's \(one would overwrite the ot",
    ),
    Fault(
        kind="--engine-memory negative",
        area="check",
        argv=("check", BRANCHES, "--engine-memory", "-5", "--out", OUT),
        exit=2,
        answer=r"--engine-memory must be 0 \(no cap\) or a size in MiB in \[256, 1048576\],",
    ),
    Fault(
        kind="--engine-memory not a number",
        area="check",
        argv=("check", BRANCHES, "--engine-memory", "lots", "--out", OUT),
        exit=2,
        answer=r"argument --engine-memory: invalid int value: 'lots'",
    ),
    Fault(
        kind="--engine-seconds negative",
        area="check",
        argv=("check", BRANCHES, "--engine-seconds", "-1", "--out", OUT),
        exit=2,
        answer=r"--engine-seconds must be a number of seconds in \[1, 86400\], got -1\.0",
    ),
    Fault(
        kind="--engine-seconds NaN",
        area="check",
        argv=("check", BRANCHES, "--engine-seconds", "nan", "--out", OUT),
        exit=2,
        answer=r"--engine-seconds must be a number of seconds in \[1, 86400\], got nan",
    ),
    Fault(
        kind="--engine-seconds infinite",
        area="check",
        argv=("check", BRANCHES, "--engine-seconds", "inf", "--out", OUT),
        exit=2,
        answer=r"--engine-seconds must be a number of seconds in \[1, 86400\], got inf",
    ),
    Fault(
        kind="--jobs 0 (check)",
        area="check",
        argv=("check", BRANCHES, "--jobs", "0", "--out", OUT),
        exit=2,
        answer=r"--jobs must be a positive integer at most 256, got 0",
    ),
    Fault(
        kind="--states negative (check)",
        area="check",
        argv=("check", BRANCHES, "--states", "-3", "--out", OUT),
        exit=2,
        answer=r"--states must be an integer in \[1, 100000\], got -3",
    ),
    Fault(
        kind="--states in float notation (check)",
        area="check",
        argv=("check", BRANCHES, "--states", "2.5", "--out", OUT),
        exit=2,
        answer=r"argument --states: invalid int value: '2\.5'",
    ),
    Fault(
        kind="--floating on an MJCF only",
        area="check",
        prepare=_file("a.xml", MJ),
        argv=("check", "{tmp}/a.xml", "--floating", "--states", "3", "--out", OUT),
        exit=0,
        answer=r"^a: \d+ passed, \d+ explained, 0 failed",
    ),
    Fault(
        kind="--out an existing file (check)",
        area="check",
        prepare=_file("f", "x"),
        argv=("check", BRANCHES, "--out", "{tmp}/f"),
        exit=2,
        answer=r"--out must be a directory, got '<tmp>/f'",
    ),
    Fault(
        kind="--out empty (check)",
        area="check",
        argv=("check", BRANCHES, "--out", ""),
        exit=2,
        answer=r"argument --out: an empty path is not a folder or file name",
    ),
    # diff
    Fault(
        kind="RUN_B missing",
        area="diff",
        argv=("diff", REPORTS_DIR, "{tmp}/none"),
        exit=2,
        answer=r"RUN_B must be an existing output folder of `run` or `check`, got '<tmp",
    ),
    Fault(
        kind="RUN_A a file, not a folder",
        area="diff",
        prepare=_file("f.csv", "x"),
        argv=("diff", "{tmp}/f.csv", REPORTS_DIR),
        exit=2,
        answer=r"RUN_A must be a discrepancies\.csv of `run` or a CSV of `check`, got '<",
    ),
    Fault(
        kind="--tolerance negative",
        area="diff",
        argv=("diff", REPORTS_DIR, REPORTS_DIR, "--tolerance", "-2"),
        exit=2,
        answer=r"--tolerance must be a finite factor > 1, got -2\.0",
    ),
    Fault(
        kind="--tolerance infinite",
        area="diff",
        argv=("diff", REPORTS_DIR, REPORTS_DIR, "--tolerance", "inf"),
        exit=2,
        answer=r"--tolerance must be a finite factor > 1, got inf",
    ),
    Fault(
        kind="--tolerance not a number",
        area="diff",
        argv=("diff", REPORTS_DIR, REPORTS_DIR, "--tolerance", "ten"),
        exit=2,
        answer=r"argument --tolerance: invalid float value: 'ten'",
    ),
    Fault(
        kind="--markdown below a file",
        area="diff",
        prepare=_file("f", "x"),
        argv=("diff", REPORTS_DIR, REPORTS_DIR, "--markdown", "{tmp}/f/d.md"),
        exit=2,
        answer=r"--markdown must be a directory, got '<tmp>/f'",
    ),
    # explain / errata / list / tutorials
    Fault(
        kind="explain an empty name",
        area="explain",
        argv=("explain", ""),
        exit=2,
        answer=r"unknown convention ''; valid: ball-joint-velocity-frame, coordinate-or",
    ),
    Fault(
        kind="explain two names, one unknown",
        area="explain",
        argv=("explain", "quaternion-order", "nope"),
        exit=2,
        answer=r"unrecognized arguments: nope",
    ),
    Fault(
        kind="errata unknown formula",
        area="errata",
        argv=("errata", "nope"),
        exit=2,
        answer=r"unrecognized arguments: nope",
    ),
    Fault(
        kind="list with an unknown option",
        area="list",
        argv=("list", "--bogus"),
        exit=2,
        answer=r"unrecognized arguments: --bogus",
    ),
    Fault(
        kind="tutorial name a path (../)",
        area="tutorials",
        argv=("tutorials", "../etc/passwd", "--out", OUT),
        exit=2,
        answer=r"unknown tutorial '\.\./etc/passwd'; valid: 01_quaternion_order, 02_free_",
    ),
    Fault(
        kind="--out an existing file (tutorials)",
        area="tutorials",
        prepare=_file("f", "x"),
        argv=("tutorials", "01_quaternion_order", "--out", "{tmp}/f"),
        exit=2,
        answer=r"--out must be a directory, got '<tmp>/f'",
    ),
    # versions / bench / baseline / report
    Fault(
        kind="--bisect an unknown release",
        area="versions",
        argv=("versions", "--bisect", "mujoco", "99.0.0", "99.1.0", "--out", "{tmp}/v.md"),
        exit=2,
        answer=r"--bisect must be a published release of mujoco, got '99\.0\.0'",
    ),
    Fault(
        kind="--bisect a release that is not a version",
        area="versions",
        argv=("versions", "--bisect", "mujoco", "latest", "3.1.0", "--out", "{tmp}/v.md"),
        exit=2,
        answer=r"--bisect must be a published release of mujoco, got 'latest'",
    ),
    Fault(
        kind="--out below a file (versions)",
        area="versions",
        prepare=_file("f", "x"),
        argv=("versions", "--out", "{tmp}/f/v.md"),
        exit=2,
        answer=r"--out must be a directory, got '<tmp>/f'",
    ),
    Fault(
        kind="--jobs 0 (bench)",
        area="bench",
        argv=("bench", "--jobs", "0"),
        exit=2,
        answer=r"--jobs must be a positive integer at most 256, got 0",
    ),
    Fault(
        kind="--memory 0",
        area="bench",
        argv=("bench", "--memory", "0"),
        exit=2,
        answer=r"--memory must be a positive integer at most 100000000, got 0",
    ),
    Fault(
        kind="--states not a number (bench)",
        area="bench",
        argv=("bench", "--states", "many"),
        exit=2,
        answer=r"argument --states: invalid int value: 'many'",
    ),
    Fault(
        kind="--out below a file (bench)",
        area="bench",
        prepare=_file("f", "x"),
        argv=("bench", "--out", "{tmp}/f/b"),
        exit=2,
        answer=r"--out must be a folder path \(<tmp>/f is a file\), got '<tmp>/f/b'",
    ),
    Fault(
        kind="unknown implementation (baseline)",
        area="baseline",
        argv=("baseline", "--impl", "bullet", "--out", "{tmp}/b.csv"),
        exit=2,
        answer=r"unknown implementation 'bullet'; valid: " + re.escape(RUN_NAMES) + "$",
    ),
    Fault(
        kind="--out in a read-only system folder (baseline)",
        area="baseline",
        argv=("baseline", "--out", "/proc/b.csv"),
        exit=2,
        answer=r"--out must be a writable directory \(No such file or directory\), got '/",
    ),
    Fault(
        kind="--from missing",
        area="report",
        argv=("report", "--check", "--from", "{tmp}/none"),
        exit=2,
        answer=r"--out must be an existing report folder, got 'reports'",
    ),
    # run
    Fault(
        kind="--impl empty (run)",
        area="run",
        argv=("run", "simple_pendulum", "--impl", "", "--out", OUT),
        exit=2,
        answer=r"unknown implementation ''; valid: " + re.escape(RUN_NAMES) + "$",
    ),
    Fault(
        kind="--device bogus",
        area="run",
        argv=("run", "simple_pendulum", "--device", "tpu9", "--out", OUT),
        exit=2,
        answer=r"argument --device: invalid choice: 'tpu9' \(choose from 'cpu', 'cuda'\)",
    ),
    Fault(
        kind="--device cuda without a GPU",
        area="run",
        argv=("run", "simple_pendulum", "--impl", "mjx", "--device", "cuda", "--out", OUT),
        exit=2,
        answer=r"--device must be cpu on this machine \(no NVIDIA driver found\), got 'cu",
    ),
    Fault(
        kind="--junit a folder (run)",
        area="run",
        prepare=_folder("j"),
        argv=("run", "simple_pendulum", "--junit", "{tmp}/j", "--out", OUT),
        exit=2,
        answer=r"--junit must be a file path, not a folder, got '<tmp>/j'",
    ),
    Fault(
        kind="--json and --junit the same file (run)",
        area="run",
        argv=("run", "simple_pendulum", "--json", "{tmp}/r", "--junit", "{tmp}/r", "--out", OUT),
        exit=2,
        answer=r"--json must be a file other than --junit's \(one would overwrite the ot",
    ),
    Fault(
        kind="--out the same as --json (run)",
        area="run",
        argv=("run", "simple_pendulum", "--json", "{tmp}/o", "--out", "{tmp}/o"),
        exit=2,
        answer=r"--json must be a file path other than the --out folder, got '<tmp>/o'",
    ),
    Fault(
        kind="case named twice",
        area="run",
        argv=("run", "simple_pendulum", "simple_pendulum", "--impl", "reference", "--out", OUT),
        exit=0,
        answer=r"0 passed, 0 explained, 0 failed, 0 skipped; report in <tmp>/",
    ),
)

EXTRA_FAULTS: tuple[Fault, ...] = (
    chk("URDF joint limits with lower above upper", "a.urdf",
        URDF.replace('lower="-2" upper="2"', 'lower="2" upper="-2"'),
            exit=1, answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed"),
    chk("URDF inertia with a negative diagonal", "a.urdf",
        URDF.replace('ixx="0.02"', 'ixx="-0.02"', 1),
            exit=1, answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed"),
    chk("URDF moving link of zero mass", "a.urdf",
        URDF.replace('<mass value="1.5"/>', '<mass value="0"/>'),
            exit=1, answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed"),
    chk("MJCF moving body whose geoms give no mass (inertiafromgeom false)", "a.xml",
        mj("<body><joint type='hinge'/><geom size='0.1'/></body>",
           "<compiler inertiafromgeom='false'/>"),
        exit=2, answer=r"mujoco refused <tmp>/a\.xml: Error: mass and inertia of moving"),
    chk("MJCF ball joint (valid)", "a.xml",
        mj("<body><joint type='ball'/><geom size='0.1' pos='0 0 -0.3'/></body>"),
            exit=1, answer=r"^a: \d+ passed, \d+ explained, 1 failed"),
    chk("MJCF with a frame element", "a.xml",
        mj("<frame pos='0 0 1'><body><joint type='hinge'/><geom size='0.1'/></body></frame>"),
        exit=1, answer=r"^a: \d+ passed, \d+ explained, [1-9]\d* failed"),
    chk("URDF continuous joint with a limit element (valid)", "a.urdf",
        URDF.replace('type="continuous"><parent link="base"/><child link="aa_leg"/>',
                     'type="continuous"><parent link="base"/><child link="aa_leg"/>'
                     '<limit effort="1" velocity="1"/>'),
                         exit=0, answer=r"^a: \d+ passed, \d+ explained, 0 failed"),
    Fault(kind="unknown option (explain)", area="explain", argv=("explain", "--bogus"),
          exit=2, answer=r"unrecognized arguments: --bogus$"),
    Fault(kind="unknown option (tutorials)", area="tutorials", argv=("tutorials", "--bogus"),
          exit=2, answer=r"unrecognized arguments: --bogus$"),
    Fault(kind="--out a missing folder (report --check)", area="report",
          argv=("report", "--check", "--out", "{tmp}/none"),
              exit=2, answer=r"--out must be an existing report folder, got '<tmp>/none'$"),
    Fault(kind="--states negative (bench)", area="bench", argv=("bench", "--states", "-1"),
          exit=2, answer=r"--states must be a positive integer at most 10000000, got -1$"),
)

def _model_and_link(tmp: Path) -> None:
    (tmp / "m.urdf").write_text(URDF)
    (tmp / "link.json").symlink_to(tmp / "m.urdf")


def _fifo(tmp: Path) -> None:
    (tmp / "m.urdf").write_text(URDF)
    os.mkfifo(tmp / "pipe.json")


def _odd_names(tmp: Path) -> None:
    with open(os.path.join(os.fsencode(tmp), b"bad\xff.urdf"), "w") as f:  # not UTF-8
        f.write(URDF)
    (tmp / "ctl\x1b[31mred.urdf").write_text(URDF)  # a terminal escape


NAMES = (  # #60: names from the file system decoded with replacement, escaped everywhere
    Fault(kind="a model file name that is not UTF-8 (its page, CSV, JUnit)", area="check",
          prepare=_odd_names, exit=0,
          argv=("check", os.fsdecode(b"{tmp}/bad\xff.urdf"), "--states", "5", "--junit",
                "{tmp}/j.xml", "--out", OUT),
          answer=r"^bad\ufffd: \d+ passed"),
    Fault(kind="a model file name with a terminal escape (its page, JSON, the terminal)",
          area="check", prepare=_odd_names, exit=0,
          argv=("check", "{tmp}/ctl\x1b[31mred.urdf", "--states", "5", "--json",
                "{tmp}/j.json", "--out", OUT),
          answer=r"^ctl\\x1b\[31mred: \d+ passed"),
)

def _nested_mjcf(tmp: Path) -> None:
    bodies = "".join(f'<body name="b{i}" pos="0 0 -0.1"><joint name="j{i}" axis="0 1 0"/>'
                     '<inertial pos="0 0 -0.05" mass="0.1" diaginertia="1e-3 1e-3 1e-4"/>'
                     for i in range(1000))
    (tmp / "deep.xml").write_text(f"<mujoco><worldbody>{bodies}{'</body>' * 1000}"
                                  "</worldbody></mujoco>")


def _chained_urdf(tmp: Path) -> None:
    link = '<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ' \
           'ixy="0" ixz="0" iyz="0"/></inertial></link>'
    joint = '<joint name="j{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>' \
            '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
    parts = [link.format(i=0)] + [link.format(i=i) + joint.format(i=i, p=i - 1)
                                  for i in range(1, 2500)]
    (tmp / "deep.urdf").write_text(f'<robot name="deep">{"".join(parts)}</robot>')


DEEP = (  # #60: a tree deeper than the walks go is refused in one line, no RecursionError
    Fault(kind="MJCF bodies nested 1000 deep", area="check", prepare=_nested_mjcf,
          argv=("check", "{tmp}/deep.xml", "--states", "2", "--out", OUT),
          answer=r"mujoco refused .*Element nesting is too deep"),
    Fault(kind="URDF links chained 2500 deep", area="check", prepare=_chained_urdf,
          argv=("check", "{tmp}/deep.urdf", "--states", "2", "--out", OUT),
          answer=r"links chained 2499 deep \(the check walks trees at most 2000 deep"),
)

OUTPUT_PATHS = (  # #60: an output never replaces an input, a link or a special file
    Fault(kind="--json the model being checked", area="check", prepare=_file("m.urdf", URDF),
          argv=("check", "{tmp}/m.urdf", "--json", "{tmp}/m.urdf", "--out", OUT),
          answer=r"--json must be a file other than the input '<tmp>/m\.urdf' \(it would be "
                 r"overwritten\), got '<tmp>/m\.urdf'$"),
    Fault(kind="--junit the model being checked, by another spelling", area="check",
          prepare=_file("m.urdf", URDF),
          argv=("check", "{tmp}/m.urdf", "--junit", "{tmp}/./m.urdf", "--out", OUT),
          answer=r"--junit must be a file other than the input"),
    Fault(kind="--json a symlink (to the model)", area="check", prepare=_model_and_link,
          argv=("check", "{tmp}/m.urdf", "--json", "{tmp}/link.json", "--out", OUT),
          answer=r"--json must be a regular file path, not a symlink"),
    Fault(kind="--json a named pipe", area="check", prepare=_fifo,
          argv=("check", "{tmp}/m.urdf", "--json", "{tmp}/pipe.json", "--out", OUT),
          answer=r"--json must be a regular file path, not a special file"),
    Fault(kind="--json /dev/stdout (a link to a device)", area="run",
          argv=("run", "simple_pendulum", "--json", "/dev/stdout", "--out", OUT),
          answer=r"--json must be a regular file path, not a symlink"),
    Fault(kind="--junit /dev/null (a device)", area="run",
          argv=("run", "simple_pendulum", "--junit", "/dev/null", "--out", OUT),
          answer=r"--junit must be a regular file path, not a special file"),
    Fault(kind="--markdown one of the runs compared", area="diff",
          prepare=lambda tmp: _file("a.csv", (REPORTS / "baseline.csv").read_text())(tmp),
          argv=("diff", "{tmp}/a.csv", "{tmp}/a.csv", "--markdown", "{tmp}/a.csv"),
          answer=r"--markdown must be a file other than the input"),
    Fault(kind="baseline --out a symlink", area="baseline",
          prepare=lambda tmp: (tmp / "b.csv").symlink_to(tmp / "elsewhere.csv"),
          argv=("baseline", "--out", "{tmp}/b.csv"),
          answer=r"--out must be a regular file path, not a symlink"),
)

MJCF = ('<mujoco model="m">{head}<worldbody><body name="a" pos="0 0 1"><joint name="j" '
        'type="hinge" axis="0 1 0"{ja}/><inertial pos="0 0 -0.3" mass="1.5" '
        'diaginertia="0.02 0.03 0.01"/><body name="b" pos="0 0 -0.6"><joint name="k" '
        'type="hinge" axis="1 0 0"/><inertial pos="0 0.1 -0.2" mass="0.7" '
        'diaginertia="0.01 0.01 0.004"/></body></body></worldbody>{tail}</mujoco>')


def _mjcf(head: str = "", ja: str = "", tail: str = "") -> str:
    return MJCF.format(head=head, ja=ja, tail=tail)


FREE_ARMATURE = ('<mujoco model="m"><worldbody><body name="box" pos="0 0 1"><joint name="root" '
                 'type="free" armature="0.1"/><inertial pos="0.05 0.02 0" mass="2" '
                 'diaginertia="0.1 0.2 0.3"/></body></worldbody></mujoco>')
AGREE = r"^a: \d+ passed, \d+ explained, 0 failed, 0 skipped"
FINDS = r"^a: \d+ passed, \d+ explained, [1-9]\d* failed"
AGREE_BUT_SKIPPED = r"^a: \d+ passed, \d+ explained, 0 failed, [1-9]\d* skipped"
"""Every comparison made agrees; an engine's limit (a constraint it cannot hold) skipped."""
ROUND3 = (  # #59 and #60: readings measured, refusals named, folders held
    chk("URDF floating joint from the world (was refused)", "a.urdf", URDF.replace(
        '<robot name="branches">', '<robot name="branches"><link name="world"/><joint '
        'name="free" type="floating"><parent link="world"/><child link="base"/></joint>'),
        exit=0, answer=AGREE),
    chk("URDF with no <inertial> on any link (validity passed with 0 bodies)", "a.urdf",
        re.sub(r"<inertial>.*?</inertial>", "", URDF),
        answer=r"<tmp>/a\.urdf: no moving link states an <inertial> with a positive mass"),
    chk("URDF every moving link of mass 0", "a.urdf",
        re.sub(r'<mass value="[^"]*"/>', '<mass value="0"/>', URDF),
        answer=r"<tmp>/a\.urdf: no moving link states an <inertial> with a positive mass"),
    chk("URDF massless root link welded to the world (failed validity)", "a.urdf",
        URDF.replace('<mass value="2"/>', '<mass value="0"/>', 1), exit=0, answer=AGREE),
    chk("URDF massless root fixed to a 'world' link", "a.urdf",
        URDF.replace('<mass value="2"/>', '<mass value="0"/>', 1).replace(
            '<robot name="branches">', '<robot name="branches"><link name="world"/><joint '
            'name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>'),
        exit=0, answer=AGREE),
    chk("URDF <limit> without lower and upper (Pinocchio reads (0, 0))", "a.urdf",
        URDF.replace('<limit lower="-2" upper="2" effort="1" velocity="1"/>',
                     '<limit effort="1" velocity="1"/>'), exit=1, answer=FINDS),
    chk("URDF revolute joint without <limit> (Pinocchio refuses)", "a.urdf",
        URDF.replace('<limit lower="-2" upper="2" effort="1" velocity="1"/>', ""), exit=1,
        answer=FINDS),
    chk("URDF limit lower above upper (Drake aborts)", "a.urdf",
        URDF.replace('<limit lower="-2" upper="2"', '<limit lower="2" upper="-2"'), exit=1,
        answer=FINDS),
    chk("URDF axis not of unit length", "a.urdf",
        URDF.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 2 0"/>', 1), exit=0, answer=AGREE),
    chk("URDF link with two <inertial> (MuJoCo refuses)", "a.urdf", URDF.replace(
        '<link name="zz_arm">', '<link name="zz_arm"><inertial><mass value="3"/><inertia '
        'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>', 1), exit=1,
        answer=FINDS),
    chk("URDF mass of 1e-9 kg", "a.urdf",
        URDF.replace('<mass value="1.5"/>', '<mass value="1e-9"/>'), exit=0, answer=AGREE),
    chk("URDF mass of 1e9 kg", "a.urdf",
        URDF.replace('<mass value="1.5"/>', '<mass value="1e9"/>'), exit=0, answer=AGREE),
    chk("URDF origin rpy with four numbers", "a.urdf",
        URDF.replace('rpy="0.1 0.2 0.3"', 'rpy="0.1 0.2 0.3 0.4"'),
        answer=r"no engine could load it: mujoco refused .*attribute 'rpy' has too much data"),
    chk("URDF continuous joint with a <limit>", "a.urdf", URDF.replace(
        '<axis xyz="0 1 0"/></joint>', '<axis xyz="0 1 0"/><limit lower="-1" upper="1" '
        'effort="1" velocity="1"/></joint>', 1), exit=1, answer=FINDS),
    chk("MJCF two top-level <default> blocks (Pinocchio: unordered_map::at)", "a.xml",
        _mjcf(head='<default><default class="x"><joint damping="0.1"/></default></default>'
              '<default><default class="y"><joint damping="0.3"/></default></default>',
              ja=' class="y"'), exit=1, answer=FINDS),
    chk("MJCF free joint with armature (Pinocchio adds it in body axes)", "a.xml",
        FREE_ARMATURE, exit=1, answer=FINDS),
    chk("MJCF <option gravity> zero (Pinocchio ignores it)", "a.xml",
        _mjcf(head='<option gravity="0 0 0"/>'), exit=1, answer=FINDS),
    chk("MJCF ball joint with armature (Drake keeps none)", "a.xml", _mjcf().replace(
        'type="hinge" axis="0 1 0"', 'type="ball" armature="0.05"', 1), exit=1,
        answer=FINDS),
    chk("MJCF slide joint without a range", "a.xml",
        _mjcf().replace('type="hinge" axis="1 0 0"', 'type="slide" axis="1 0 0"'), exit=0,
        answer=AGREE),
    chk("MJCF range with limited=\"false\" (Pinocchio reads the range)", "a.xml",
        _mjcf(ja=' range="-1 1" limited="false"'), exit=1, answer=FINDS),
    chk("MJCF range of no width", "a.xml", _mjcf(ja=' range="0.5 0.5" limited="true"'),
        answer=r"mujoco refused .*range\[0\] should be smaller than range\[1\]"),
    chk("MJCF armature on a joint no actuator drives (Drake keeps none)", "a.xml",
        _mjcf(ja=' armature="0.2"'), exit=1, answer=FINDS),
    chk("MJCF armature with a <general> actuator (Drake reads none)", "a.xml",
        _mjcf(ja=' armature="0.2"', tail='<actuator><general joint="j" gear="2"/></actuator>'),
        exit=1, answer=FINDS),
    chk("MJCF <connect> to the world (refused by Drake's and Pinocchio's parsers, said; "
        "MuJoCo's closed dynamics checked)", "a.xml",
        _mjcf(tail='<equality><connect body1="b" body2="world" anchor="0 0 -0.2"/>'
              "</equality>"), exit=0, answer=AGREE_BUT_SKIPPED),
    chk("MJCF <joint> equality (Drake's and Pinocchio's parsers hold none: found)",
        "a.xml", _mjcf(tail='<equality><joint joint1="j" joint2="k"/></equality>'), exit=1,
        answer=FINDS),
    chk("MJCF model 10^6 m from the origin", "a.xml",
        _mjcf().replace('pos="0 0 1"', 'pos="1000000 0 1"'), exit=0, answer=AGREE),
    chk("MJCF body inertia of 1e-12 kg m^2", "a.xml",
        _mjcf().replace('diaginertia="0.01 0.01 0.004"', 'diaginertia="1e-12 1e-12 1e-12"'),
        exit=0, answer=AGREE),
    Fault(kind="check under ulimit -v 390 MiB (engines failed as if the model had)",
          area="check", patch=lambda mp, tmp: mp.setattr(
              "dyncheck.confinement.address_space_mib", lambda: 390),
          argv=("check", BRANCHES, "--states", "2", "--out", OUT),
          answer=r"^dyncheck: error: ulimit -v must be at least 768 MiB for `dyncheck check`"),
    Fault(kind="run under ulimit -v 1953 MiB (std::bad_alloc, exit 134)", area="run",
          patch=lambda mp, tmp: mp.setattr(
              "dyncheck.confinement.address_space_mib", lambda: 1953),
          argv=("run", "simple_pendulum", "--out", OUT),
          answer=r"^dyncheck: error: ulimit -v must be at least 4096 MiB for `dyncheck run`"),
)

SELF_ATTACHING = """<mujoco>
  <asset><model name="me" file="self.xml"/></asset>
  <worldbody>
    <body name="b"><joint type="hinge"/><geom size="0.1" mass="1"/>
      <attach model="me" body="b" prefix="x"/>
    </body>
  </worldbody>
</mujoco>
"""
"""A model that attaches itself: MuJoCo 4.0's compiler recurses until its stack ends
(SIGSEGV, measured)."""


def _several(**named: str) -> Callable[[Path], Path]:
    """Several files written into the test's folder (a model and the file an option reads;
    a name with a double underscore is written with a dot there: ``a__xml`` → ``a.xml``)."""
    def make(tmp: Path) -> Path:
        for name, content in named.items():
            (tmp / name.replace("__", ".")).write_text(content)
        return tmp
    return make


def _fifos(*names: str) -> Callable[[Path], Path]:
    """A model ``m.urdf`` and named pipes beside it (no writer: a reader blocks forever)."""
    def make(tmp: Path) -> Path:
        (tmp / "m.urdf").write_text(URDF)
        for name in names:
            os.mkfifo(tmp / name)
        return tmp
    return make


def _sparse(name: str, size: int) -> Callable[[Path], Path]:
    """A model ``m.urdf`` and a file of ``size`` bytes that takes no disk (a hole)."""
    def make(tmp: Path) -> Path:
        (tmp / "m.urdf").write_text(URDF)
        with open(tmp / name, "wb") as f:
            f.truncate(size)
        return tmp
    return make


CHAIN_200 = "<mujoco><worldbody>" + "".join(
    f'<body pos="0 0 -0.1"><joint name="j{i}" type="hinge" axis="0 1 0"/>'
    '<geom size="0.05" mass="1"/>' for i in range(200)) + "</body>" * 200 + \
    "</worldbody></mujoco>"
"""A chain of 200 hinges, 203 XML levels deep."""
MASSLESS_URDF = """<robot name="r"><link name="base"/><link name="a"/>
<joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""

FIFO_INPUTS = (  # #81: only regular files are read, whatever option names them
    Fault(kind="run --baseline a FIFO (hung until killed)", area="run", prepare=_fifos("b.csv"),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/b.csv", "--out", OUT),
          answer=r"--baseline must be a regular file \(not a FIFO, device or socket\)"),
    Fault(kind="check --baseline a FIFO (hung until killed)", area="check",
          prepare=_fifos("b.csv"),
          argv=("check", "{tmp}/m.urdf", "--baseline", "{tmp}/b.csv", "--out", OUT),
          answer=r"--baseline must be a regular file \(not a FIFO, device or socket\)"),
    Fault(kind="diff of a FIFO (hung until killed)", area="diff", prepare=_fifos("a.csv"),
          argv=("diff", "{tmp}/a.csv", "{tmp}/a.csv"),
          answer=r"RUN_A must be a regular file \(not a FIFO, device or socket\)"),
    Fault(kind="run --baseline of 2 GiB", area="run", prepare=_sparse("b.csv", 2 << 30),
          argv=("run", "simple_pendulum", "--baseline", "{tmp}/b.csv", "--out", OUT),
          answer=r"--baseline must be a file of at most 1024 MiB \(it has 2048 MiB\)"),
    Fault(kind="check --accept a FIFO", area="check", prepare=_fifos("a.toml"),
          argv=("check", "{tmp}/m.urdf", "--accept", "{tmp}/a.toml", "--out", OUT),
          answer=r"--accept must be an existing TOML file"),
    Fault(kind="check --states-file a FIFO", area="check", prepare=_fifos("s.npy"),
          argv=("check", "{tmp}/m.urdf", "--states-file", "{tmp}/s.npy", "--out", OUT),
          answer=r"--states-file must be an existing regular file"),
    Fault(kind="check --against a FIFO", area="check", prepare=_fifos("old.xml"),
          argv=("check", "{tmp}/m.urdf", "--against", "{tmp}/old.xml", "--out", OUT),
          answer=r"<tmp>/old\.xml: not a file"),
    Fault(kind="a model path that is a FIFO", area="check", prepare=_fifos("p.urdf"),
          argv=("check", "{tmp}/p.urdf", "--out", OUT),
          answer=r"<tmp>/p\.urdf: not a file"),
    Fault(kind="--against a URDF whose moving links are massless (compiled and diffed before)",
          area="check", prepare=_several(old__urdf=MASSLESS_URDF),
          argv=("check", BRANCHES, "--against", "{tmp}/old.urdf", "--out", OUT),
          answer=r"<tmp>/old\.urdf: no moving link states an <inertial> with a positive mass"),
    Fault(kind="--against an MJCF that includes a FIFO", area="check",
          prepare=lambda tmp: (_fifos("inc.xml")(tmp), (tmp / "old.xml").write_text(
              "<mujoco><include file='inc.xml'/><worldbody><body><joint type='hinge'/>"
              "<geom size='0.1' mass='1'/></body></worldbody></mujoco>")),
          argv=("check", BRANCHES, "--against", "{tmp}/old.xml", "--out", OUT),
          answer=r"<tmp>/old\.xml: <include file='inc\.xml'>: not a regular file"),
    Fault(kind="--against an MJCF whose texture is a device", area="check",
          prepare=_several(old__xml="<mujoco><asset><texture name='t' type='2d' "
                           "file='/dev/zero'/></asset><worldbody><body><joint type='hinge'/>"
                           "<geom size='0.1' mass='1'/></body></worldbody></mujoco>"),
          argv=("check", BRANCHES, "--against", "{tmp}/old.xml", "--out", OUT),
          answer=r"names 'zero', which is not a regular file \(a character device\)"),
    Fault(kind="--against an MJCF nested 2100 bodies deep", area="check",
          prepare=_several(old__xml="<mujoco><worldbody>" + "<body><joint type='hinge'/>"
                           "<geom size='0.1' mass='1'/>" * 2100 + "</body>" * 2100
                           + "</worldbody></mujoco>"),
          argv=("check", BRANCHES, "--against", "{tmp}/old.xml", "--out", OUT),
          answer=r"XML elements nested 2103 deep \(the check walks trees at most 2000 deep"),
    Fault(kind="a 200-link chain under a 2 MiB stack whose hard limit is 2 MiB (ulimit -s 2048: "
          "a segmentation fault of dyncheck, exit 139, no message)", area="check",
          prepare=_several(a__xml=CHAIN_200), patch=lambda mp, tmp: mp.setattr(
              "dyncheck.confinement.stack_mib", lambda: 2),
          argv=("check", "{tmp}/a.xml", "--out", OUT),
          answer=r"<tmp>/a\.xml: a tree 203 levels deep needs about 4\.2 MiB of stack, more "
          r"than this process's 2 MiB \(ulimit -s; raise it"),
    Fault(kind="bench --memory 0", area="bench", argv=("bench", "--memory", "0", "--out", OUT),
          answer=r"--memory must be a positive integer at most 100000000, got 0$"),
)




def _memory(size: int) -> Callable[[pytest.MonkeyPatch, Path], None]:
    """The machine's memory as ``size`` bytes (the answer then names the same bound on every
    machine)."""
    def patch(monkeypatch: pytest.MonkeyPatch, _tmp: Path) -> None:
        monkeypatch.setattr("dyncheck.check.inputs.machine_memory", lambda: size)
    return patch


def _fifo_mesh(tmp: Path) -> Path:
    os.mkfifo(tmp / "pipe.stl")
    (tmp / "a.xml").write_text("<mujoco><asset><mesh name='m' file='pipe.stl'/></asset>"
                               "<worldbody><body><joint type='hinge'/><geom size='0.1' "
                               "mass='1'/></body></worldbody></mujoco>")
    return tmp


CHAIN_100 = "<mujoco><worldbody>" + "".join(
    f'<body pos="0 0 -0.1"><joint name="j{i}" type="hinge" axis="0 1 0"/>'
    '<geom size="0.05" mass="1"/>' for i in range(100)) + "</body>" * 100 + \
    "</worldbody></mujoco>"
CHECK_COLUMNS = "model,section,subject,field,impl_a,impl_b,value_a,value_b,error,tolerance,verdict"
ROUND4 = (  # #79 and #81: the CI gate's files, special files, sizes, versions on models
    Fault(kind="check --accept missing", area="check", prepare=_several(a__xml=SMALL_MJCF),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/none.toml", "--out", OUT),
          answer=r"--accept must be an existing TOML file of \[\[accept\]\] entries"),
    Fault(kind="check --accept not TOML", area="check",
          prepare=_several(a__xml=SMALL_MJCF, k__toml="[[accept]\n"),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/k.toml", "--out", OUT),
          answer=r"--accept must be a TOML file \("),
    Fault(kind="check --accept entry without a reason", area="check",
          prepare=_several(a__xml=SMALL_MJCF,
                         k__toml='[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\n'),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/k.toml", "--out", OUT),
          answer=r"accept\[1\]\.reason must be a non-empty string, got None"),
    Fault(kind="check --accept entry with an unknown field", area="check",
          prepare=_several(a__xml=SMALL_MJCF, k__toml='[[accept]]\nmodel="a"\nengine="b"\n'
                         'label="c"\nreason="r"\nuntil=1\n'),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/k.toml", "--out", OUT),
          answer=r"accept\[1\]\.until must be absent"),
    Fault(kind="check --accept expiry not a date", area="check",
          prepare=_several(a__xml=SMALL_MJCF, k__toml='[[accept]]\nmodel="a"\nengine="b"\n'
                         'label="c"\nreason="r"\nexpires="soon"\n'),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/k.toml", "--out", OUT),
          answer=r"accept\[1\]\.expires must be a date, YYYY-MM-DD, got 'soon'"),
    Fault(kind="check --accept a key other than accept", area="check",
          prepare=_several(a__xml=SMALL_MJCF, k__toml="ignore = true\n"),
          argv=("check", "{tmp}/a.xml", "--accept", "{tmp}/k.toml", "--out", OUT),
          answer=r"must be an \[\[accept\]\] table \(the only key\), got 'ignore'"),
    Fault(kind="check --baseline missing", area="check", prepare=_several(a__xml=SMALL_MJCF),
          argv=("check", "{tmp}/a.xml", "--baseline", "{tmp}/none.csv", "--out", OUT),
          answer=r"--baseline must be an existing check baseline CSV \(write one with "
          r"--update-baseline\)"),
    Fault(kind="check --baseline a folder", area="check", prepare=_several(a__xml=SMALL_MJCF),
          argv=("check", "{tmp}/a.xml", "--baseline", "{tmp}", "--out", OUT),
          answer=r"--baseline must be an existing check baseline CSV"),
    Fault(kind="check --baseline of run, not of check", area="check",
          prepare=_several(a__xml=SMALL_MJCF, b__csv="case,quantity,impl_a,impl_b,integrator,"
                         "dt,max_rel_err,tolerance,verdict\n"),
          argv=("check", "{tmp}/a.xml", "--baseline", "{tmp}/b.csv", "--out", OUT),
          answer=r"--baseline must be a check baseline \(missing \["),
    Fault(kind="check --baseline truncated (header says 9 rows)", area="check",
          prepare=_several(a__xml=SMALL_MJCF, b__csv="# dyncheck baseline rows=9\n"
                         + CHECK_COLUMNS + "\n"),
          argv=("check", "{tmp}/a.xml", "--baseline", "{tmp}/b.csv", "--out", OUT),
          answer=r"9 rows as its header says \(0 found: truncated\?\)"),
    Fault(kind="check --update-baseline without --baseline", area="check",
          prepare=_several(a__xml=SMALL_MJCF),
          argv=("check", "{tmp}/a.xml", "--update-baseline", "--out", OUT),
          answer=r"--update-baseline must be given with --baseline FILE"),
    Fault(kind="check --update-baseline onto the model itself", area="check",
          prepare=_several(a__xml=SMALL_MJCF),
          argv=("check", "{tmp}/a.xml", "--baseline", "{tmp}/a.xml", "--update-baseline",
                "--out", OUT),
          answer=r"--baseline"),
    Fault(kind="MJCF mesh that is a FIFO", area="check", prepare=_fifo_mesh,
          argv=("check", "{tmp}/a.xml", "--out", OUT),
          answer=r"<mesh file> names 'pipe\.stl', which is not a regular file \(a FIFO\)"),
    Fault(kind="--against model that <attach>es itself (MuJoCo crashes compiling it)",
          area="check", exit=1,
          prepare=_several(a__xml=SMALL_MJCF, self__xml=SELF_ATTACHING),
          argv=("check", "{tmp}/a.xml", "--against", "{tmp}/self.xml", "--impl", "reference",
                "--impl", "mujoco", "--states", "5", "--out", OUT),
          answer=r"mujoco could not read it: mujoco crashed while loading the model"),
    Fault(kind="--against model MuJoCo refuses (compiled in its own process)", area="check",
          prepare=_several(bad__xml="<mujoco><worldbody><body><joint type='bogus'/>"
                           "<geom size='0.1' mass='1'/></body></worldbody></mujoco>"),
          argv=("check", BRANCHES, "--against", "{tmp}/bad.xml", "--out", OUT),
          answer=r"<tmp>/bad\.xml: mujoco refused"),
    Fault(kind="--against model whose mesh is a FIFO", area="check", prepare=_fifo_mesh,
          argv=("check", BRANCHES, "--against", "{tmp}/a.xml", "--out", OUT),
          answer=r"<mesh file> names 'pipe\.stl', which is not a regular file \(a FIFO\)"),
    chk("MJCF texture that is a device", "a.xml",
        "<mujoco><asset><texture name='t' type='2d' file='/dev/zero'/></asset><worldbody>"
        "<body><joint type='hinge'/><geom size='0.1' mass='1'/></body></worldbody></mujoco>",
        answer=r"names 'zero', which is not a regular file \(a character device\)"),
    Fault(kind="100 000 states of a 100-joint chain (37 GiB of arrays; a machine of 8 GiB)",
          area="check", prepare=_file("a.xml", CHAIN_100), patch=_memory(8 * 2**30),
          argv=("check", "{tmp}/a.xml", "--states", "100000", "--impl", "reference", "--impl",
                "mujoco", "--out", OUT),
          answer=r"--states must be at most 10737 states for this model: 100 degrees of "
          r"freedom at 100000 states need 37\.3 GiB"),
    chk("slide range of ±1e308 (its width overflows)", "a.xml",
        "<mujoco><worldbody><body><joint type='slide' range='-1e308 1e308' limited='true'/>"
        "<geom size='0.1' mass='1'/></body></worldbody></mujoco>", "--impl", "reference",
        "--impl", "mujoco", exit=0, answer=AGREE),
    Fault(kind="versions on models with two engines", area="versions",
          prepare=_several(a__xml=SMALL_MJCF),
          argv=("versions", "{tmp}/a.xml", "--engine", "mujoco", "--engine", "drake"),
          answer=r"--engine must be one engine with model files"),
    Fault(kind="versions on models with --case", area="versions",
          prepare=_several(a__xml=SMALL_MJCF),
          argv=("versions", "{tmp}/a.xml", "--engine", "mujoco", "--case", "atwood"),
          answer=r"--case must be absent with model files"),
    Fault(kind="versions --release without models", area="versions",
          argv=("versions", "--release", "3.3.7"),
          answer=r"--release must be given with model files"),
    Fault(kind="versions --bisect of another engine than --engine", area="versions",
          prepare=_several(a__xml=SMALL_MJCF),
          argv=("versions", "{tmp}/a.xml", "--engine", "mujoco", "--bisect", "drake", "1.40.0",
                "1.51.1"),
          answer=r"--bisect must be the engine of --engine \(mujoco\)"),
)

FAULTS = (*FAULTS, *FIFO_INPUTS, *HOSTILE_MODELS, *MORE_FAULTS, *EXTRA_FAULTS, *OUTPUT_PATHS,
          *NAMES, *DEEP, *ROUND3, *ROUND4)


DEDICATED = (
    ("standard output, error or input closed, or output or error full (/dev/full)",
     "the command's own result and every page (exit 0 on a good model), no traceback — it was "
     "a false refusal ('no engine could load it') and exit 120, or exit 2 after one line",
     "tests/dyncheck/test_cli.py::test_a_closed_or_full_standard_stream_fails_no_model"),
    ("a referee whose two methods disagree (its recursion mutated by 1e-6)",
     "its own row failed naming itself, no engine judged against it, nor its derivatives",
     "tests/dyncheck/referee/test_tree.py::test_a_mutated_recursion_fails_the_tie"),
    ("a URDF floating joint below a moving link", "held in its parent's frame: the referee's "
     "two methods agree to round-off and Pinocchio agrees with it on every dynamics and "
     "derivative row — the referee disagreed with itself (M by 0.87) and Pinocchio's rows "
     "failed 'cause unknown'",
     "tests/dyncheck/referee/test_tree.py::test_a_floating_joint_below_a_moving_link_is_held_in_its_"
     "parents_frame"),
    ("a known finding accepted (--accept), a new one beside it", "the accepted row on the "
     "page as accepted with its reason, exit 0; the new one fails, exit 1",
     "tests/check/test_acceptance.py::test_a_finding_not_accepted_still_fails"),
    ("a change of 1e-6 planted in one engine against a stored baseline", "exit 1, the row "
     "named on baseline.md, JUnit and JSON; a change within tolerance passes",
     "tests/check/test_baseline.py::"
     "test_a_planted_change_fails_named_within_tolerance_passes_update_accepts"),
    ("a run killed with SIGKILL", "the previous report byte-identical, no temp file",
     "tests/dyncheck/test_reliability.py::test_killed_run_leaves_previous_report_intact"),
    ("Pinocchio not importable", "its rows skipped naming `pip install pin`, the rest kept, "
     "exit 0", "tests/dyncheck/test_reliability.py::test_missing_engine_costs_only_its_rows"),
    ("an engine raising inside a simulation", "its trajectory rows failed with the message, "
     "exit 1",
     "tests/dyncheck/test_reliability.py::test_a_crashing_simulation_becomes_failed_rows"),
    ("a simulation that diverges", "an error, not a hang or a silent reset",
     "tests/dyncheck/test_reliability.py::test_divergence_is_an_error_not_a_hang"),
    ("the memory probe's child dies", "an error naming it, not a wait forever",
     "tests/dyncheck/test_reliability.py::test_memory_probe_does_not_wait_on_a_dead_child"),
    ("an engine segfaults loading a user's model", "that engine's rows failed "
     "(`crashed while loading the model (killed by SIGSEGV)`), the others kept",
     "tests/check/test_model_check.py::test_an_engine_that_crashes_or_hangs_costs_only_its_rows"),
    ("an engine segfaults computing the dynamics", "that engine's rows failed, the others kept",
     "tests/check/test_model_check.py::test_an_engine_that_crashes_or_hangs_costs_only_its_rows"),
    ("an engine never answers", "stopped after the time limit, its rows failed",
     "tests/check/test_model_check.py::test_an_engine_that_crashes_or_hangs_costs_only_its_rows"),
    ("a model file unreadable (permissions)", "`cannot be read (Permission denied)`, exit 2",
     "tests/check/test_inputs.py::test_unreadable_file"),
    ("a dask scheduler that dies mid-run", "one line naming `--dask` and the unit it lost, "
     "no traceback (distributed's own log silenced), exit 2 — it was `CancelledError`, exit 1",
     "tests/dyncheck/test_workers.py::"
     "test_a_scheduler_that_dies_mid_run_is_one_line_naming_dask_not_a_failed_check"),
    ("1000 mutated MJCF and URDF files", "each a one-line error or a report, within a time "
     "limit", "tests/check/test_fuzz.py::test_mutated_models_never_traceback_or_hang"),
    ("two entries of JAX's compilation cache swapped", "both deleted before JAX sees the "
     "folder (its manifest does not vouch for them), compiled again, the right values — they "
     "were loaded and run", "tests/dyncheck/cache/test_compiled.py::"
     "test_swapped_jax_entries_are_compiled_again_not_run"),
    ("a compiled-code entry changed, planted, or a link", "deleted before any engine starts "
     "(a link never followed), one line on stderr", "tests/dyncheck/cache/test_compiled.py::"
     "test_swapped_changed_and_planted_entries_are_deleted"),
    ("a compiled-code manifest missing, forged or signed with another key", "nothing in the "
     "folder trusted: every entry compiled again",
     "tests/dyncheck/cache/test_compiled.py::test_without_an_authentic_manifest_nothing_is_"
     "trusted"),
    ("--out in use by another dyncheck", "refused at once, one line naming the process that "
     "holds it, nothing written, exit 2 — two commands interleaved their pages and CSVs",
     "tests/dyncheck/test_cli.py::"
     "test_an_out_folder_in_use_by_another_dyncheck_is_refused_naming_it"),
    ("a refused model in a folder checked with --junit", "a suite of one failed test case "
     "naming the refusal — it was absent (failures=\"0\")",
     "tests/dyncheck/test_ci_outputs.py::test_a_refused_model_is_a_failed_test_case"),
    ("a compiled-code folder others can write", "not used: JAX keeps no persistent cache, "
     "Warp compiles into a temporary folder (it wrote ~/.cache/warp even under --no-cache)",
     "tests/dyncheck/cache/test_compiled.py::test_a_folder_others_can_write_is_not_used"),
    ("a FIFO where the compiled-code manifest lives", "read as no manifest, never opened "
     "blocking: every entry compiled again, at once (it hung run and check until killed)",
     "tests/dyncheck/cache/test_compiled.py::test_a_manifest_that_is_a_fifo_is_no_manifest_"
     "and_never_blocks"),
    ("a valid pendulum 1 km and 1000 km from the origin, with --derivatives", "every "
     "derivative row passes, as at the origin: each engine's round-off bound carries X/l (its "
     "finite differences' 2 dtau/s, a step Jacobian's acceleration) and (X/l)^2 for "
     "Pinocchio's derivatives formed about the world origin (measured) — 11 and 17 rows "
     "failed for every pair of engines",
     "tests/check/test_derivatives.py::test_derivatives_far_from_the_origin_are_judged_by_"
     "bounds_that_travel"),
    ("Ctrl-C at five moments of a four-case run and of check --jobs 2 (its modules loading, "
     "its pool starting, its workers up, after one and two units)", "exit 130 and one line "
     "at each, no traceback, no 'Exception ignored', no process left — a worker forked with "
     "the command's handlers printed its Terminated, an idle worker its pool loop's, a signal "
     "while the modules loaded Python's KeyboardInterrupt, and a half-built finalizer an "
     "AttributeError at exit",
     "tests/dyncheck/test_main.py::test_ctrl_c_ends_every_moment_with_one_line_and_nothing_"
     "left"),
    ("a FIFO where the compiled-code folder's lock lives", "not taken: the command compiles "
     "afresh, as when another holds the folder (it was locked as if a lock file)",
     "tests/dyncheck/cache/test_compiled.py::test_a_lock_that_is_a_fifo_is_not_taken"),
    ("a 200-link chain under a 1 MiB soft stack (ulimit -S -s 1024)", "the command raises "
     "its soft stack limit to 64 MiB before any work and checks the model (exit 0) — a "
     "segmentation fault of dyncheck itself, exit 139, no message",
     "tests/dyncheck/test_confinement.py::test_a_small_soft_stack_is_raised_and_a_deep_chain_"
     "checked"),
    ("bench of 10^7 states (hours of sweeps)", "its time estimated from each implementation "
     "measured on 200 states and said in one line before the first sweep, with the options "
     "that change it (it ran for hours unannounced)",
     "tests/dyncheck/bench/test_engines.py::test_the_estimate_is_said_before_the_work"),
    ("bench --states without --memory", "memory sweeps of --states and ten times it (at most "
     "10^6) — they were 10^5 and 10^6 whatever --states said",
     "tests/dyncheck/bench/test_engines.py::test_the_memory_sweeps_follow_the_states_asked_"
     "for"),
)

OBSERVED: dict[int, tuple[int, str]] = {}
"""The answers seen in this session, by index in :data:`FAULTS` (the page is made of them)."""


def _files(tmp: Path) -> set[Path]:
    return {p for p in tmp.rglob("*")}


def _normalise(text: str, tmp: Path) -> str:
    return (text.replace(str(tmp), "<tmp>").replace(str(MODELS), "<models>")
            .replace(str(ROOT), "<repository>"))


def observe(fault: Fault, tmp: Path) -> tuple[int, str, bool]:
    """Run ``fault``: its exit status, its answer (every line), whether tmp was left as set
    up (nothing written, nothing half-written)."""
    if fault.prepare is not None:
        fault.prepare(tmp)
    before = _files(tmp)
    if fault.call is not None:
        try:
            fault.call(tmp)
        except DyncheckError as exc:
            return 2, _normalise(str(exc), tmp), _files(tmp) == before
        return 0, "(accepted)", _files(tmp) == before
    argv = [a.format(tmp=tmp, models=MODELS) for a in fault.argv]
    out, err = io.StringIO(), io.StringIO()
    cwd = Path.cwd()
    os.chdir(tmp)  # a relative default --out lands in tmp, never in the repository
    try:
        with pytest.MonkeyPatch.context() as mp, redirect_stdout(out), redirect_stderr(err):
            if fault.patch is not None:
                fault.patch(mp, tmp)
            code = main(argv)
    finally:
        os.chdir(cwd)
    answer = err.getvalue() if code not in (0, 1) else out.getvalue()
    after = _files(tmp)
    untouched = after == before if code not in (0, 1) else True
    return code, _normalise(answer, tmp), untouched


def _line(fault: Fault, answer: str) -> str:
    """The answer's line: the only one, or for a check's report (exit 1) its summary line."""
    lines = answer.strip().splitlines() or [""]
    return next((ln for ln in lines if re.search(fault.answer, ln)), lines[0])


@pytest.mark.parametrize("index", range(len(FAULTS)),
                         ids=[f"{f.area}: {f.kind}" for f in FAULTS])
def test_fault_gets_one_line_and_its_exit_status(index, tmp_path):
    """The observed exit status is the one promised (2 for bad input and I/O faults, 130 for
    an interrupt, 1 for a model the check finds wrong), the answer is one line naming the
    field or path, no traceback, and a refused command wrote nothing."""
    fault = FAULTS[index]
    code, answer, untouched = observe(fault, tmp_path)
    lines = answer.strip().splitlines()
    line = _line(fault, answer)
    OBSERVED[index] = (code, line)
    assert "Traceback" not in answer
    assert code == fault.exit, answer
    if fault.exit != 1:
        assert len(lines) == 1, answer
    assert re.search(fault.answer, line), line
    assert untouched, "a refused command changed files"


def render(observed: dict[int, tuple[int, str]]) -> str:
    import pandas as pd

    rows = [{"area": f.area, "input or fault": f.kind, "exit": observed[i][0],
             "answer": f"`{observed[i][1]}`"} for i, f in enumerate(FAULTS)]
    dedicated = pd.DataFrame(DEDICATED, columns=["fault", "answer", "test"])
    kinds = len(FAULTS) + len(DEDICATED)
    return "\n".join([
        "# Reliability: every bad input and fault tried, and the answer",
        "",
        f"{kinds} kinds, none answered with a traceback, a hang or a silent pass. Generated "
        "by `tests/dyncheck/test_faults.py` from the answers dyncheck gave "
        "(`DYNCHECK_WRITE_PAGES=1 pytest tests/dyncheck/test_faults.py` rewrites it); the test "
        "fails when an answer here is no longer the one given. `<tmp>` is the test's "
        "temporary folder, `<repository>` the clone's root. Exit 2: bad input or an I/O "
        "fault, found before any long work, "
        "nothing written; 1: the check found the model wrong (a report is written); "
        "130: interrupted.",
        "",
        "## Commands and the Python API",
        "",
        pd.DataFrame(rows).to_markdown(index=False),
        "",
        "## Faults with their own tests (a run, a killed process, a crashing engine)",
        "",
        dedicated.to_markdown(index=False),
        "",
    ])


def test_reliability_page_lists_the_answers_given(tmp_path):
    """``reports/reliability.md`` is the table of the answers observed (faults not run yet in
    this session are run here); every dedicated fault names a test that exists."""
    for index, fault in enumerate(FAULTS):
        if index not in OBSERVED:
            tmp = tmp_path / str(index)
            tmp.mkdir()
            code, answer, _ = observe(fault, tmp)
            OBSERVED[index] = (code, _line(fault, answer))
    for _kind, _answer, test in DEDICATED:
        path, name = test.split("::")
        assert f"def {name}(" in (ROOT / path).read_text(), test
    page = render(OBSERVED)
    if os.environ.get("DYNCHECK_WRITE_PAGES") == "1":
        PAGE.write_text(page)
    assert len(FAULTS) + len(DEDICATED) >= 250  # #44: at least 250 kinds, each answered
    assert PAGE.read_text() == page, "reports/reliability.md is stale: DYNCHECK_WRITE_PAGES=1"
