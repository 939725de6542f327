"""Joints matched across engines that name them otherwise (dyncheck/check/alignment.py): what
refers to a joint by name moves with it. Expected: what each engine's parser names (measured:
Pinocchio names an unnamed MJCF free joint after its body, 'box_free'; MuJoCo leaves it
unnamed)."""

from __future__ import annotations

from dyncheck.check.model_check import check_model

CONNECTED_BOX = """<mujoco model="connected_box"><worldbody>
  <body name="box" pos="1 0 1"><freejoint/><geom type="box" size=".5 .1 .1" mass="1"/></body>
</worldbody><equality><connect body1="box" anchor="-0.5 0 0"/></equality></mujoco>"""
"""mujoco_warp's jdotv/connect_2d.xml: a box on an unnamed free joint held at one end."""


def test_a_closure_names_the_joints_of_its_aligned_tree(tmp_path):
    """Pinocchio's free joint, named after its body, is matched to MuJoCo's unnamed one; the
    <connect> Pinocchio holds names it too, and must be renamed with it: the closure rows
    judge Pinocchio against the referee (the check once raised KeyError 'box_free' here)."""
    path = tmp_path / "connected_box.xml"
    path.write_text(CONNECTED_BOX)
    rows = check_model(path, states=6, impls=("reference", "mujoco", "pinocchio"),
                       isolate=False).rows
    closures = rows[(rows["section"] == "closures") & (rows["impl_b"] == "pinocchio")]
    assert not closures.empty
    assert (closures["verdict"] != "failed").all(), closures[["subject", "note"]]
