"""A model file as dyncheck reads it (adapters/formats/files.py)."""

from __future__ import annotations

from dyncheck.adapters.formats import files, parsing
from dyncheck.adapters.formats.files import read, urdf_inertials, urdf_links, urdf_welded

URDF = """<robot name="two">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="plate"><inertial><mass value="0.5"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/>
    <inertia ixx="0.2" iyy="0.3" izz="0.4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="bolt" type="fixed"><parent link="base"/><child link="plate"/></joint>
  <joint name="hinge" type="revolute"><parent link="plate"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_a_urdf_s_readers_parse_its_text_once(tmp_path, monkeypatch):
    """#76: the check asks a URDF for its welded links, inertials and links several times;
    its text is parsed once for all of them. Expected values: the file written here (its
    root and the link bolted to it are welded; three links, three inertials)."""
    path = tmp_path / "two.urdf"
    path.write_text(URDF, encoding="utf-8")
    source = read(path)
    files._urdf.cache_clear()
    parsed = []
    monkeypatch.setattr(parsing, "root", lambda raw: parsed.append(1) or parsing.ET.fromstring(raw))
    for _ in range(3):
        assert urdf_welded(source) == {"base", "plate"}
        assert [i.link for i in urdf_inertials(source)] == ["base", "plate", "arm"]
        assert urdf_links(source) == {"base", "plate", "arm"}
    assert len(parsed) == 1
