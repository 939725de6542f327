"""``check_model`` on small models written for these tests: every installed engine and the
reference must agree (the expected values are the other engines' and the book's general
method's — three independent computations); corrupted copies must fail, naming the body and
the field; engines that order the joints differently must still agree."""

from __future__ import annotations

import importlib.util
import io
import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from dyncheck.adapters import Registration
from dyncheck.check.model_check import check_model
from dyncheck.check.verdicts import Agreement, per_engine

MODELS = Path(__file__).parent / "models"
ROOT = Path(__file__).resolve().parents[2]
CASES = [
    ("mixed.xml", False),
    ("floating_arm.xml", False),
    ("branches.urdf", True),
    ("branches.urdf", False),
]
DRAKE = importlib.util.find_spec("pydrake") is not None


def _rows(result, **where):
    frame = result.rows
    for key, value in where.items():
        frame = frame[frame[key] == value]
    return frame


@pytest.fixture(scope="module", params=CASES, ids=lambda c: f"{c[0]}-floating{c[1]}")
def agreeing(request):
    name, floating = request.param
    return check_model(MODELS / name, floating=floating, states=40)


def test_engines_and_reference_agree(agreeing):
    assert agreeing.ok, agreeing.failures()
    dynamics = _rows(agreeing, section="dynamics")
    pairs = set(zip(dynamics["impl_a"], dynamics["impl_b"], strict=True))
    assert ("reference", "mujoco") in pairs and ("reference", "pinocchio") in pairs
    assert ("mujoco", "pinocchio") in pairs
    if DRAKE:
        assert ("reference", "drake") in pairs and ("mujoco", "drake") in pairs
    assert set(dynamics["subject"]) == {
        "mass_matrix", "bias_forces", "forward_dynamics", "inverse_dynamics",
        "kinetic_energy", "potential_energy", "referee",
    }
    # the referee's two methods tied on this tree (reference/recursive.py against the
    # general method of reference/tree.py): one passing row
    tie = _rows(agreeing, section="dynamics", subject="referee")
    assert list(tie["verdict"]) == ["passed"], tie


def test_missing_engine_is_skipped_not_passed(monkeypatch):
    """An engine whose extra is not installed (simulated: its module cannot be imported)
    gives a skipped row naming the extra, and no dynamics rows."""
    from dyncheck.check import engines

    missing = Registration(package="", integrators=(), extra="drake",
                           model="dyncheck.adapters.no_such_module:X")
    monkeypatch.setitem(engines.ENGINES, "drake", missing)
    result = check_model(MODELS / "branches.urdf", states=5)
    load = _rows(result, section="load", impl_a="drake")
    assert list(load["verdict"]) == ["skipped"] and "'drake' extra" in load["note"].iloc[0]
    assert _rows(result, section="dynamics", impl_b="drake").empty
    assert result.ok


@pytest.mark.skipif(not DRAKE, reason="needs the 'drake' extra")
def test_drake_ball_joint_is_mapped_through_roll_pitch_yaw():
    """Drake's BallRpyJoint (q = roll, pitch, yaw; v = ω in the parent-side frame) mapped to
    the canonical quaternion and local ω: its dynamics match the referee's (the book's
    method on MuJoCo's tree) on a free base carrying a ball joint; without the map (ω read as
    rpy rates, or in the child's axes) the bias forces would differ at order |ω|²."""
    result = check_model(MODELS / "mixed.xml", states=10)
    load = _rows(result, section="load", impl_a="drake")
    assert list(load["verdict"]) == ["passed"]
    drake = _rows(result, section="dynamics", impl_a="reference", impl_b="drake")
    assert len(drake) == 6 and set(drake["verdict"]) == {"passed"}


def test_engines_ordering_joints_differently_still_agree():
    """MuJoCo's URDF compiler follows the file's joint order, Pinocchio's parser the links'
    (measured): the two order this tree differently, and the check matches by name."""
    result = check_model(MODELS / "branches.urdf", floating=True, states=20)
    order = _rows(result, field="joint order", impl_b="pinocchio")
    assert len(order) == 1 and order["value_a"].iloc[0] != order["value_b"].iloc[0]
    assert result.ok, result.failures()


def test_armature_kinetic_energy_is_explained_with_its_size():
    """Pinocchio's computeKineticEnergy leaves out the rotor inertia that its M includes."""
    result = check_model(MODELS / "mixed.xml", states=20)
    row = _rows(result, subject="kinetic_energy", impl_a="mujoco", impl_b="pinocchio")
    assert row["verdict"].iloc[0] == "explained" and "rotor" in row["note"].iloc[0]


def _corrupt(tmp_path: Path, old: str, new: str) -> Path:
    text = (MODELS / "branches.urdf").read_text()
    assert old in text
    path = tmp_path / "corrupted.urdf"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    ("old", "new", "subject", "field"),
    [
        ('<mass value="1.5"/>', '<mass value="1.515"/>', "leg_joint", "mass"),
        ('<axis xyz="0 1 0"/>', '<axis xyz="0 -1 0"/>', "leg_joint", "axis"),
        ('ixx="0.03" ixy="0.001"', 'ixx="0.0303" ixy="0.001"', "leg_joint", "inertia"),
    ],
    ids=["mass-x1.01", "axis-flipped", "inertia-x1.01"],
)
def test_corrupted_copy_fails_naming_body_and_field(tmp_path, old, new, subject, field):
    corrupted = _corrupt(tmp_path, old, new)
    result = check_model(corrupted, floating=True, states=10, against=MODELS / "branches.urdf")
    assert not result.ok
    failed = _rows(result, verdict="failed")
    assert ((failed["subject"] == subject) & (failed["field"] == field)).any(), failed


def test_indefinite_inertia_fails_naming_the_link(tmp_path):
    corrupted = _corrupt(
        tmp_path,
        '<inertia ixx="0.03" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.01"/>',
        '<inertia ixx="0.03" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="-0.01"/>',
    )
    result = check_model(corrupted, floating=True, states=10)
    failed = _rows(result, verdict="failed", section="validity")
    assert ((failed["subject"] == "aa_leg") & (failed["field"] == "inertia")).any(), failed
    # MuJoCo refuses the file; Pinocchio accepts it silently (its rigid group is indefinite).
    assert _rows(result, section="load", impl_a="mujoco")["verdict"].iloc[0] == "failed"
    assert ((failed["impl_a"] == "pinocchio") & (failed["field"] == "inertia")).any()


def test_a_triangle_breaking_inertia_gives_its_fix_and_what_follows_from_it_names_it(tmp_path):
    """#48: a failure that follows from another names it, every known cause has a fix, an
    engine's message is quoted whole. Principal moments 0.03, 0.03, 0.07 break I1 + I2 >= I3
    ((2.2.39)); which engines then read the link differently is theirs to decide."""
    corrupted = _corrupt(
        tmp_path,
        '<inertia ixx="0.03" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.01"/>',
        '<inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.07"/>',
    )
    result = check_model(corrupted, floating=True, states=10)
    broken = _rows(result, verdict="failed", section="validity", subject="aa_leg",
                   field="triangle")
    assert len(broken) and broken["note"].str.contains("fix: raise the smaller").all()
    read = _rows(result, verdict="failed", section="description")
    leg = read[read["note"].str.contains("aa_leg")]
    assert (leg["note"].str.startswith("follows from aa_leg's invalid inertia")).all()
    assert len(read) == len(leg)  # nothing else is read differently
    if DRAKE:  # Drake repairs the tensor (Pinocchio keeps it): the leg's inertia differs
        assert len(leg) and leg["note"].str.contains("validity row: file: triangle").all()
        # and its parser warns: its words reach the page whole, past their first colon
        assert any("did not pass the test CouldBePhysicallyValid()" in n
                   and "triangle inequality" in n for n in result.notes), result.notes


def test_check_model_is_deterministic():
    a = check_model(MODELS / "mixed.xml", states=10, impls=("reference", "mujoco"))
    b = check_model(MODELS / "mixed.xml", states=10, impls=("reference", "mujoco"))
    assert a.rows.equals(b.rows)


def test_readme_pytest_recipe_names_the_plugin_s_options_and_fixture():
    """The README's recipe uses what the plugin defines (its run: test_pytest_plugin.py)."""
    from dyncheck import pytest_plugin

    readme = (Path(__file__).parents[2] / "README.md").read_text()
    source = Path(pytest_plugin.__file__).read_text()
    for name in ("--dyncheck-model", "--dyncheck-floating", "dyncheck_model"):
        assert name in readme and name in source


CRASHES = {
    "CrashOnLoad": "crashed while loading the model (killed by SIGSEGV)",
    "AbortOnLoad": "crashed while loading the model (exit status 1: Failure at parser.cc:104 "
                   "in Read(): condition 'mass > 0' failed.)",
    "CrashOnDynamics": "crashed while computing the dynamics (killed by SIGSEGV)",
    "HangOnDynamics": "gave no answer within 1 s while computing the dynamics (stopped)",
}
"""tests/check/crashing_engine.py's engines, and the words of the one row each must fail
(an engine's own last words on stderr quoted: the page says why)."""


@pytest.fixture(scope="module")
def forked_checks() -> dict[str, pd.DataFrame]:
    """:func:`crash_check` of every crashing engine with forked processes, forked from a
    fresh interpreter, as the command's own process forks them: this test process may hold
    JAX or Warp, whose threads make a fork unsafe (why :func:`workers.start_method` spawns
    there). One interpreter for the three checks."""
    code = ("import json; from tests.check.test_model_check import CRASHES, crash_check; "
            "print(json.dumps({c: crash_check(c, 'fork').to_json(orient='records') "
            "for c in CRASHES}))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, timeout=120, check=True).stdout
    return {c: pd.read_json(io.StringIO(rows), orient="records", dtype=False)
            for c, rows in json.loads(out).items()}


@pytest.mark.parametrize(
    ("engine_class", "method"),
    [*((c, "fork") for c in CRASHES), ("CrashOnDynamics", "spawn")],
)
def test_an_engine_that_crashes_or_hangs_costs_only_its_rows(forked_checks, engine_class,
                                                             method):
    """A segfault or a hang in one engine (tests/check/crashing_engine.py) fails that engine's
    rows; the other engines' rows are those of a check without it (all pass on this model).
    Forked, each crashing engine; spawned (where this process runs JAX or Warp), a crash — the
    start method is all that differs, the crash and hang handling being the same code."""
    rows = forked_checks[engine_class] if method == "fork" else crash_check(engine_class, method)
    mine = rows[(rows.impl_a == "crashing") | (rows.impl_b == "crashing")]
    failed = mine[mine.verdict == "failed"]
    assert len(failed) == 1 and CRASHES[engine_class] in failed.note.iloc[0], mine
    assert not ((mine.section == "dynamics") & (mine.verdict == "passed")).any()
    others = rows.drop(mine.index)
    assert {"mujoco", "pinocchio", "reference"} <= set(others.impl_a) | set(others.impl_b)
    assert not (others.verdict == "failed").any(), others[others.verdict == "failed"]


def crash_check(engine_class: str, method: str) -> pd.DataFrame:
    """The rows of a check of mixed.xml with the crashing engine ``engine_class`` beside the
    reference, MuJoCo and Pinocchio, its processes started by ``method``."""
    from dyncheck.check import engines, model_check

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(engines, "start_method", lambda: method)
        mp.setitem(engines.ENGINES, "crashing",
                   Registration(package="", integrators=(),
                                model=f"tests.check.crashing_engine:{engine_class}"))
        mp.setattr(model_check, "IMPLEMENTATIONS", (*engines.IMPLEMENTATIONS, "crashing"))
        mp.setattr(engines, "TIMEOUT_S", 1.0)  # a batch of 5 states: milliseconds
        result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco", "pinocchio",
                                                          "crashing"), states=5)
    return result.rows


def test_a_daemonic_worker_checks_in_process_and_says_so():
    """A daemonic process cannot start processes: the check runs its engines in the process
    (the same rows as an isolated check — those of engines in their own processes) and its
    notes say that a crash would not be contained."""
    import multiprocessing as mp

    from dyncheck.check.engines import IN_PROCESS_NOTE

    isolated = check_model(MODELS / "mixed.xml", states=10, impls=("reference", "mujoco"))
    here = mp.current_process()
    daemon = here._config.get("daemon")
    here._config["daemon"] = True  # what a dask nanny's worker process is
    try:
        inside = check_model(MODELS / "mixed.xml", states=10, impls=("reference", "mujoco"))
    finally:
        if daemon is None:
            del here._config["daemon"]
        else:
            here._config["daemon"] = daemon
    assert IN_PROCESS_NOTE in inside.notes and IN_PROCESS_NOTE not in isolated.notes
    assert inside.rows.equals(isolated.rows)


INERTIA = '<inertia ixx="{0}" ixy="0" ixz="0" iyy="{0}" iyz="0" izz="{1}"/>'
WELDED = (
    '<robot name="welded"><link name="world"/><link name="base"><inertial><mass value="2"/>'
    + INERTIA.format(0.1, 0.1) + '</inertial><visual><geometry><mesh '
    'filename="meshes/gone.stl"/></geometry></visual></link><link name="arm"><inertial>'
    '<origin xyz="0 0 -0.2"/><mass value="1"/>' + INERTIA.format(0.02, 0.002)
    + '</inertial></link><joint name="fix" type="fixed"><parent link="world"/><child '
    'link="base"/></joint><joint name="shoulder" type="continuous"><parent link="base"/>'
    '<child link="arm"/><axis xyz="0 1 0"/></joint></robot>'
)


def test_floating_is_not_applied_to_a_urdf_welded_to_world_and_a_missing_mesh_is_a_note(
        tmp_path):
    """A root link named ``world`` welds the robot in the file itself: MuJoCo would float
    the first link below it and Pinocchio the world link, Drake neither — so ``--floating``
    is not applied, said once, and the engines agree. A mesh file that is not there is never
    read (geometry is removed first): a note, and the model checked."""
    path = tmp_path / "welded.urdf"
    path.write_text(WELDED)
    result = check_model(path, floating=True, states=10)
    assert result.ok, result.failures()
    assert any("--floating not applied" in n for n in result.notes)
    assert any("'meshes/gone.stl'" in n for n in result.notes)
    assert set(_rows(result, section="load", verdict="passed")["impl_a"]) == {
        "mujoco", "pinocchio", *(("drake",) if DRAKE else ())}


FLOATING_JOINT = """<robot name="fl">
  <link name="world"/>
  <link name="base"><inertial><origin xyz="0.01 0.02 0"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>
  <joint name="root" type="floating"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1"/></joint>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0.2 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_a_urdf_floating_joint_is_checked_as_a_free_joint(tmp_path):
    """#59: a URDF ``floating`` joint was refused ("not checked") although MuJoCo and
    Pinocchio read it as a free joint (nq 8 with the hinge) and Drake leaves its link a free
    body (its warning). Now checked: every engine holds 'root' as a free joint, reads alike,
    and computes what it read (the referee on the same free body)."""
    path = tmp_path / "fl.urdf"
    path.write_text(FLOATING_JOINT)
    result = check_model(path, states=20)
    rows = result.rows
    loads = rows[rows["section"] == "load"]
    assert set(loads["note"]) == {"nq=8 nv=7"}, loads
    assert result.ok, result.failures()
    assert not (rows["verdict"] == "skipped").any()


BRANCHES = (Path(__file__).parent / "models" / "branches.urdf").read_text()
ROOT_INERTIAL = ('<link name="base"><inertial><mass value="2"/>'
                 '<inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/>'
                 '</inertial></link>')


@pytest.mark.parametrize("world", [False, True], ids=["root", "world-fixed"])
def test_a_massless_link_welded_to_the_world_is_no_finding(tmp_path, world):
    """#59: PyBullet's "mass 0 = fixed base" idiom — the root link (or a link fixed to
    'world') states mass 0. It never moves, so its inertia enters none of the compared
    dynamics (2.2.23): no validity row fails for it, the page says it is not checked. The
    control: freed with --floating, the same link moves and its mass 0 fails."""
    assert ROOT_INERTIAL in BRANCHES
    text = BRANCHES.replace('<mass value="2"/>', '<mass value="0"/>', 1)
    if world:
        text = text.replace('<robot name="branches">', '<robot name="branches"><link '
                            'name="world"/><joint name="fix" type="fixed"><parent link="world"/>'
                            '<child link="base"/></joint>')
    path = tmp_path / "m.urdf"
    path.write_text(text)
    result = check_model(path, states=10)
    assert result.ok, result.failures()
    assert any(n.startswith("links welded to the world (base") for n in result.notes)
    if not world:
        freed = check_model(path, states=10, floating=True).rows
        validity = freed[(freed["section"] == "validity") & (freed["subject"] == "base")]
        assert "failed" in set(validity["verdict"]), validity


def test_a_urdf_without_any_moving_inertial_is_refused_before_the_engines(tmp_path):
    """#59: no <inertial> on any link: every engine read massless bodies (MuJoCo refused,
    the others returned non-finite or raised) while validity "passed" with 0 bodies. Now a
    one-line refusal naming the file and the fix, exit 2, before any engine starts."""
    import re

    path = tmp_path / "none.urdf"
    path.write_text(re.sub(r"<inertial>.*?</inertial>", "", BRANCHES))
    done = subprocess.run([sys.executable, "-m", "dyncheck", "check", str(path), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "none.urdf: no moving link states an <inertial>" in lines[0]
    assert not (tmp_path / "out").exists()


def test_dynamics_undefined_on_the_model_as_read_are_not_a_computing_finding(tmp_path):
    """#59: a moving leaf link of mass 0 and inertia 0 (example-robot-data's romeo has such
    finger links): M is singular, forward dynamics undefined — the referee's on the same
    reading are not finite. Pinocchio's non-finite answer and Drake's refusal are then not
    "computes differently" (a false finding): their lines say not compared, naming why; the
    model's own fault is one failed row, the referee's, naming the singular M and the fix."""
    text = BRANCHES.replace('<mass value="0.5"/>', '<mass value="0"/>').replace(
        'ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"',
        'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"')
    assert text.count('<mass value="0"/>') == 1
    path = tmp_path / "m.urdf"
    path.write_text(text)
    result = check_model(path, states=5, impls=("reference", "pinocchio", "drake"))
    lines = {v.engine: v for v in per_engine(result.rows, result.impls)}
    for engine in ("pinocchio", "drake"):
        assert lines[engine].agreement is Agreement.NOT_COMPARED, lines[engine].line()
        assert "not defined on the model as read" in lines[engine].agreement_why
    rows = result.rows
    failed = rows[rows["verdict"] == "failed"]
    assert list(failed["impl_a"]) == ["reference"], failed
    assert "M is singular" in failed["note"].iloc[0] and not result.ok


def test_a_defect_of_dyncheck_costs_one_model_one_line(tmp_path, monkeypatch, capsys):
    """An exception of dyncheck's own inside a model's check (planted: the closure rows raise
    KeyError, as they once did on a file an engine names otherwise) is one line naming the
    model and asking for a report; with two models, the other's page is still written and
    the broken one is a line of the index — never a traceback."""
    from dyncheck.__main__ import main
    from dyncheck.check import closure_rows

    chain = ('<mujoco model="{n}"><worldbody><body name="a" pos="0 0 1"><joint name="j" '
             'axis="0 1 0"/><geom type="sphere" size="0.1" pos="0.2 0 0"/></body></worldbody>'
             '</mujoco>')
    for name in ("first", "second"):
        (tmp_path / f"{name}.xml").write_text(chain.format(n=name))
    real = closure_rows.rows

    def planted(model, *args, **kwargs):
        if model == "first":
            raise KeyError("planted")
        return real(model, *args, **kwargs)
    monkeypatch.setattr(closure_rows, "rows", planted)
    code = main(["check", str(tmp_path / "first.xml"), str(tmp_path / "second.xml"),
                 "--states", "3", "--impl", "mujoco", "--out", str(tmp_path / "out"),
                 "--jobs", "1"])
    err = capsys.readouterr().err
    assert code != 0
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if "defect of its own" in line]
    assert len(lines) == 1 and "first.xml" in lines[0] and "KeyError" in lines[0], err
    assert (tmp_path / "out" / "second.md").is_file()
    assert "defect of its own" in (tmp_path / "out" / "index.md").read_text()
