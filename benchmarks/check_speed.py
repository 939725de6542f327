"""How long ``dyncheck check`` takes on the models of issues #42 and #44, each command in a
fresh process (wall seconds on this machine), and where the time goes (the page's own
per-implementation seconds: the referee against the slowest engine).

    python benchmarks/check_speed.py [--out reports/benchmark-check.md] [--repeats 3]

Models: a 29-joint floating humanoid (example-robot-data's ``g1_29dof_rev_1_0``, extra
``robots``) at 1000 states; a chain of 200 hinges (written here) at 10 states; every book
case's MJCF at 100 states (``--case all``); the humanoid with ``--derivatives`` at 100 states;
the chain with ``--derivatives`` at 10 states; a ladder of 66 hinges closed by 5 connects
(written here) and the same ladder open, at 100 states. Targets from the issues: the
humanoid's whole command ≤ 2 s, its referee ≤ 5× the slowest engine; the chain ≤ 10 s; with
derivatives ≤ 5 s, the referee's derivatives ≤ 3× the slowest engine's own (#58); the chain
with derivatives ≤ 10 s (#58); the closed ladder ≤ 2× the open one (#78).

Then the referee's scale, in this process: its derivatives (:func:`dyncheck.check.derivatives.
referee`, the recursive algorithm differentiated by a complex step, with the curvatures
that bound an engine's finite differences) and its dynamics (M and h at every state), seconds
per state on chains of 10 … 400 hinges and floating trees of 30 … 100 joints (MuJoCo's
reading of files written here), with the exponent p of time ∝ nᵖ fitted by least squares on
the logarithms (#58: p ≤ 2).
"""

from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd


def chain(n: int) -> str:
    """An MJCF chain of ``n`` hinges, each link 0.1 m below the last."""
    link = ('<body name="b{i}" pos="0 0 {z}"><joint name="j{i}" type="hinge" axis="0 1 0"/>'
            '<inertial pos="0 0 -0.05" mass="0.1" diaginertia="1e-3 1e-3 1e-4"/>')
    body = "".join(link.format(i=i, z=-0.1 if i else 0) for i in range(n)) + "</body>" * n
    return f'<mujoco model="chain{n}"><worldbody>{body}</worldbody></mujoco>'


def ladder(n: int, loops: int, *, closed: bool = True) -> str:
    """A planar ladder: ``loops`` + 1 hanging chains of ``n`` hinges side by side, each chain's
    last link held to the next one's by a ``<connect>`` (``closed``; without: the same tree
    open, the check as it was before closures were checked)."""
    def chain(k: int) -> str:
        links = "".join(
            f'<body name="b{k}_{i}" pos="{0.3 * k if i == 0 else 0} 0 {0 if i == 0 else -0.2}">'
            f'<joint name="b{k}_{i}" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.2"'
            ' size=".02" mass="0.3"/>' for i in range(n))
        return links + "</body>" * n
    held = "".join(f'<connect body1="b{k}_{n - 1}" body2="b{k + 1}_{n - 1}" '
                   'anchor="0.15 0 -0.2"/>' for k in range(loops))
    return ('<mujoco model="ladder"><worldbody><body name="ground">'
            + "".join(chain(k) for k in range(loops + 1)) + "</body></worldbody>"
            + (f"<equality>{held}</equality>" if closed else "") + "</mujoco>")


def floating(n: int) -> str:
    """An MJCF floating tree of ``n`` joints: a free base and four limbs of hinges (n − 1 in
    all), each link 0.1 m from the last, axes turning x, y, z along a limb."""
    limbs = []
    per = [(n - 1) // 4 + (1 if i < (n - 1) % 4 else 0) for i in range(4)]
    count = 0
    for limb, length in enumerate(per):
        direction = ["0.1 0 0", "-0.1 0 0", "0 0.1 0", "0 -0.1 0"][limb]
        body = ""
        for i in range(length):
            axis = ["1 0 0", "0 1 0", "0 0 1"][i % 3]
            body += (f'<body name="l{count}" pos="{direction}"><joint name="j{count}" '
                     f'type="hinge" axis="{axis}"/><inertial pos="0.05 0.01 0" mass="0.2" '
                     'diaginertia="2e-3 1.5e-3 1e-3"/>')
            count += 1
        limbs.append(body + "</body>" * length)
    return (f'<mujoco model="floating{n}"><worldbody><body name="base"><freejoint '
            'name="root"/><inertial pos="0 0 0" mass="5" diaginertia="0.1 0.2 0.3"/>'
            + "".join(limbs) + "</body></worldbody></mujoco>")


def scale(folder: Path, repeats: int) -> tuple[pd.DataFrame, dict[str, float]]:
    """The referee's seconds per state against the number of joints, and the fitted
    exponents (per family and kind of work)."""
    import numpy as np

    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical
    from dyncheck.adapters.mujoco.model import MujocoModel
    from dyncheck.check.sampling import sample
    from dyncheck.referee.derivatives import referee
    from dyncheck.referee.tree import ReferenceModel

    rows = []
    families = {"chain": (chain, (10, 25, 50, 100, 200, 400)),
                "floating tree": (floating, (30, 50, 75, 100))}
    for family, (write, sizes) in families.items():
        for n in sizes:
            path = folder / f"{family.replace(' ', '_')}{n}.xml"
            path.write_text(write(n))
            tree = MujocoModel(read(path)).tree
            canon = canonical(tree)
            states = sample(canon, tree, 4 if n > 100 else 10, 0)
            for work, call in (
                    ("derivatives", lambda t=tree, s=states: referee(t, s)),
                    ("dynamics", lambda t=tree, s=states: ReferenceModel(t).recursive
                     .at_states(s.q, s.v))):
                call()  # warm: numpy's first calls
                seconds = []
                for _ in range(repeats):
                    start = time.perf_counter()
                    call()
                    seconds.append(time.perf_counter() - start)
                rows.append({"family": family, "joints": n, "nv": tree.nv, "work": work,
                             "states": len(states.q),
                             "seconds_per_state": statistics.median(seconds) / len(states.q)})
    frame = pd.DataFrame(rows)
    exponents = {}
    for (family, work), part in frame.groupby(["family", "work"], sort=False):
        slope = np.polyfit(np.log(part["nv"]), np.log(part["seconds_per_state"]), 1)[0]
        exponents[f"{work}, {family}"] = round(float(slope), 2)
    return frame, exponents


def _page_seconds(page: Path) -> dict[str, float]:
    """The page's table of seconds (load, reference, each engine)."""
    lines = page.read_text().splitlines()
    at = lines.index("## Time (seconds on this machine, loading and evaluating)")
    names = [c.strip() for c in lines[at + 2].strip("|").split("|")]
    values = [float(c) for c in lines[at + 4].strip("|").split("|")]
    return dict(zip(names, values, strict=True))


def measure(repeats: int) -> pd.DataFrame:
    rows = []
    with tempfile.TemporaryDirectory(prefix="dyncheck-check-speed-") as tmp:
        (Path(tmp) / "chain200.xml").write_text(chain(200))
        (Path(tmp) / "ladder.xml").write_text(ladder(10, 5))
        (Path(tmp) / "ladder_open.xml").write_text(ladder(10, 5, closed=False))
        commands = {
            "29-joint floating humanoid, 1000 states": (
                ["--robot", "g1_29dof_rev_1_0", "--floating", "--states", "1000"],
                "g1_29dof_rev_1_0", 2.0),
            "200-hinge chain, 10 states": ([f"{tmp}/chain200.xml", "--states", "10"],
                                           "chain200", 10.0),
            "every book case, 100 states": (["--case", "all"], "", 30.0),
            "29-joint floating humanoid with --derivatives, 100 states": (
                ["--robot", "g1_29dof_rev_1_0", "--floating", "--states", "100",
                 "--derivatives"], "g1_29dof_rev_1_0", 5.0),
            "200-hinge chain with --derivatives, 10 states": (
                [f"{tmp}/chain200.xml", "--states", "10", "--derivatives"], "chain200", 10.0),
            "66-hinge ladder without its 5 connects, 100 states": (
                [f"{tmp}/ladder_open.xml"], "", 0.0),
            "66-hinge ladder closed by 5 connects (#78: ≤ 2× open), 100 states": (
                [f"{tmp}/ladder.xml"], "", 0.0),
        }
        for what, (args, page, target) in commands.items():
            seconds = []
            for _ in range(repeats):
                start = time.perf_counter()
                done = subprocess.run([sys.executable, "-m", "dyncheck", "check", *args,
                                       "--out", f"{tmp}/out"], capture_output=True, text=True)
                seconds.append(time.perf_counter() - start)
            row: dict[str, object] = {"command": f"dyncheck check {what}",
                                      "seconds": round(statistics.median(seconds), 2),
                                      "target_s": target, "exit": done.returncode}
            if page and (Path(tmp) / "out" / f"{page}.md").is_file():
                parts = _page_seconds(Path(tmp) / "out" / f"{page}.md")
                engines = [v for k, v in parts.items() if k not in ("load", "reference")
                           and not k.startswith("d") and k != "derivatives"]
                row |= {"referee_s": parts.get("reference"),
                        "slowest_engine_s": max(engines),
                        "referee_over_engine": round(parts.get("reference", 0) / max(engines), 1)}
                own = [v for k, v in parts.items() if k.startswith("d ")
                       and k not in ("d reference", "d map")]
                if own:  # the referee's derivatives against the slowest engine's own
                    row |= {"derivatives_s": parts["derivatives"],
                            "d_referee_s": parts["d reference"],
                            "slowest_engine_derivatives_s": max(own),
                            "d_referee_over_engine": round(parts["d reference"] / max(own),
                                                           1)}
            rows.append(row)
    frame = pd.DataFrame(rows)
    is_open = frame["command"].str.contains("without its 5 connects")
    closed = frame["command"].str.contains("closed by 5 connects")
    frame.loc[closed, "target_s"] = 2 * float(frame.loc[is_open, "seconds"].iloc[0])
    frame.loc[is_open, "target_s"] = None
    return frame


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("reports/benchmark-check.md"))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    table = measure(args.repeats)
    with tempfile.TemporaryDirectory(prefix="dyncheck-scale-") as tmp:
        sizes, exponents = scale(Path(tmp), args.repeats)
    text = "\n".join([
        "# dyncheck check: seconds on this machine",
        "",
        "Generated by `python benchmarks/check_speed.py`: each command in a fresh process, "
        f"the median of {args.repeats} runs, wall-clock seconds on this machine "
        f"({platform.machine()}, {platform.platform()}); `referee_s` and `slowest_engine_s` "
        "from the page's own table (the engines run in processes of their own, beside the "
        "referee).",
        "",
        table.to_markdown(index=False, floatfmt=".3g"),
        "",
        "## The referee's time per state against the number of joints",
        "",
        "In this process, the median of the repeats: `derivatives` is the referee's five "
        "derivatives with the curvatures that bound an engine's finite differences (the "
        "recursive Newton-Euler algorithm differentiated by a complex step, each body "
        "evaluated on its ancestors' columns), `dynamics` its M and h. Fitted exponent p of "
        "seconds per state ∝ nvᵖ (target for derivatives: p ≤ 2):",
        "",
        pd.DataFrame([{"work, family": k, "exponent p": v} for k, v in exponents.items()])
        .to_markdown(index=False),
        "",
        sizes.pivot_table(index=["family", "joints", "nv"], columns="work",
                          values="seconds_per_state").reset_index().to_markdown(
                              index=False, floatfmt=".3g"),
        "",
    ])
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
