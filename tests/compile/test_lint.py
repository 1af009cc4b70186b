"""The compiler's check of what it writes: `lint_urdf` and the external validators.

Every lint rule is exercised by a deliberately broken xacro template in tests/data/broken/,
rendered through the real `xacro` package, with the exact problem text asserted.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
import xacro

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run from anywhere, installed or not
    sys.path.insert(0, str(REPO))

from assistive_compiler.compile.external_checks import (  # noqa: E402
    check_with_urdfdom,
    check_with_yourdfpy,
    find_check_urdf,
    pybullet_load_warnings,
)
from assistive_compiler.compile.lint import (  # noqa: E402
    LintError,
    LintProblem,
    check_urdf_or_raise,
    lint_urdf,
    pybullet_crash_risks,
)

BROKEN = Path(__file__).resolve().parents[1] / "data" / "broken"
SHAPES = REPO / "templates" / "common" / "shapes.xacro"

# A tetrahedron, so the valid URDF can reference a mesh that exists (an OBJ: PyBullet 3.2.7
# found "nothing useful" in an ASCII STL).
TETRAHEDRON_OBJ = """# tetrahedron
v 0 0 0
v 0.05 0 0
v 0 0.05 0
v 0 0 0.05
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
"""

INERTIAL = (
    '<inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="{m}"/>'
    '<inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial>'
)

VALID_URDF = f"""<?xml version="1.0"?>
<robot name="small_arm">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base">
    {INERTIAL.format(m=2.0, i=0.01)}
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry><material name="grey"/></visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper_arm"/>
    <origin xyz="0 0 0.05" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1.57" upper="1.57" effort="30" velocity="1.5"/>
    <dynamics damping="0.1" friction="0.0"/>
  </joint>
  <link name="upper_arm">
    {INERTIAL.format(m=1.0, i=0.004)}
    <visual><origin xyz="0 0 0.1" rpy="0 0 0"/>
      <geometry><cylinder radius="0.03" length="0.2"/></geometry></visual>
    <collision><origin xyz="0 0 0.1" rpy="0 0 0"/>
      <geometry><cylinder radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <joint name="wrist" type="continuous">
    <parent link="upper_arm"/><child link="hand"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit effort="5" velocity="3"/>
  </joint>
  <link name="hand">
    {INERTIAL.format(m=0.3, i=0.0005)}
    <visual><geometry><mesh filename="meshes/tetra.obj"/></geometry></visual>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="hand"/><child link="finger"/>
    <axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/>
  </joint>
  <link name="finger">
    {INERTIAL.format(m=0.05, i=0.00001)}
    <collision><geometry><box size="0.01 0.01 0.04"/></geometry></collision>
  </link>
  <joint name="tool_mount" type="fixed">
    <parent link="finger"/><child link="tool_frame"/>
    <origin xyz="0 0 0.02" rpy="0 0 0"/>
  </joint>
  <link name="tool_frame">
    {INERTIAL.format(m=0.01, i=0.000001)}
  </link>
</robot>
"""


def _valid_template(folder: Path) -> Path:
    """A template in the project's style, built from the shared macros of shapes.xacro."""
    text = f"""<?xml version="1.0"?>
<robot name="valid_arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{SHAPES}"/>
  <xacro:arg name="upper_len" default="0.3"/>
  <xacro:property name="L" value="$(arg upper_len)"/>
  <xacro:materials/>
  <link name="base">
    <xacro:inertial_box m="3.0" x="0.2" y="0.2" z="0.1"/>
    <xacro:box_shapes x="0.2" y="0.2" z="0.1" material="metal"/>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper_arm"/>
    <origin xyz="0 0 0.05" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1.57" upper="1.57" effort="40" velocity="1.2"/>
  </joint>
  <link name="upper_arm">
    <xacro:inertial_capsule m="1.5" r="0.04" l="${{L}}" xyz="0 0 ${{L/2}}"/>
    <xacro:capsule_shapes r="0.04" l="${{L}}" xyz="0 0 ${{L/2}}" material="skin"/>
  </link>
  <joint name="elbow" type="continuous">
    <parent link="upper_arm"/><child link="forearm"/>
    <origin xyz="0 0 ${{L}}" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit effort="20" velocity="2"/>
  </joint>
  <link name="forearm">
    <xacro:inertial_cylinder m="1.0" r="0.03" l="0.25" xyz="0 0 0.125"/>
    <xacro:cylinder_shapes r="0.03" l="0.25" xyz="0 0 0.125" material="skin"/>
  </link>
  <joint name="wrist" type="fixed">
    <parent link="forearm"/><child link="hand"/>
    <origin xyz="0 0 0.25" rpy="0 0 0"/>
  </joint>
  <link name="hand">
    <xacro:inertial_sphere m="0.4" r="0.045"/>
    <xacro:sphere_shapes r="0.045" material="skin"/>
  </link>
</robot>
"""
    path = folder / "valid_arm.urdf.xacro"
    path.write_text(text)
    return path


def _render(path: Path) -> str:
    return xacro.process_file(str(path)).toprettyxml()


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


# --------------------------------------------------------------------------- valid input


def test_small_valid_urdf_passes_lint_and_all_external_checks(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "tetra.obj").write_text(TETRAHEDRON_OBJ)
    path = _write(tmp_path, "small_arm.urdf", VALID_URDF)

    assert lint_urdf(VALID_URDF, template="small_arm", base_dir=tmp_path) == []
    check_urdf_or_raise(VALID_URDF, template="small_arm", base_dir=tmp_path)
    assert check_with_urdfdom(path) == []
    assert check_with_yourdfpy(path) == []
    assert pybullet_load_warnings(path) == []
    assert pybullet_load_warnings(path, use_fixed_base=False) == []


def test_valid_template_renders_lints_and_passes_external_checks(tmp_path: Path) -> None:
    xml = _render(_valid_template(tmp_path))
    assert lint_urdf(xml, template="valid_arm.urdf.xacro") == []
    path = _write(tmp_path, "valid_arm.urdf", xml)
    assert check_with_urdfdom(path) == []
    assert check_with_yourdfpy(path) == []
    assert pybullet_load_warnings(path) == []


# --------------------------------------------------------------------------- one test per rule

BROKEN_CASES = {
    "negative_mass": ["link 'forearm': mass is -1.0 kg; expected a positive mass"],
    "zero_mass": ["link 'forearm': mass is 0.0 kg; expected a positive mass"],
    "inertia_not_positive_definite": [
        "link 'forearm': inertia is not positive-definite: principal moments are "
        "(-0.1, 0.1, 0.3) kg*m^2; expected all principal moments > 0"
    ],
    "inertia_triangle": [
        "link 'forearm': principal moments (0.1, 0.1, 0.3) kg*m^2 break the triangle "
        "inequality: 0.3 > 0.1 + 0.1; expected each moment <= the sum of the other two"
    ],
    "limits_reversed": ["joint 'elbow': lower limit 1.5 is not below upper limit -1.5; expected lower < upper"],
    "zero_axis": ["joint 'elbow': axis is (0.0, 0.0, 0.0); expected a non-zero unit vector"],
    "non_unit_axis": [
        "joint 'elbow': axis (0.0, 0.0, 2.0) has length 2; expected a unit vector (length 1 within 1e-6)"
    ],
    "no_effort_velocity": [
        "joint 'elbow': <limit> has no effort; expected effort > 0",
        "joint 'elbow': <limit> has no velocity; expected velocity > 0",
    ],
    "visual_without_collision": [
        "link 'forearm': has a <visual> but no <collision>; expected at least one "
        "<collision> so the link takes part in contacts"
    ],
    "capsule_geometry": [
        "link 'forearm': collision 1: capsule geometry is not standard URDF; write a capsule "
        "as a cylinder plus two spheres (capsule_shapes in templates/common/shapes.xacro)"
    ],
    "missing_mesh": [
        "link 'forearm': visual 1: mesh file 'meshes/missing_forearm.stl' does not exist "
        f"(looked for {BROKEN / 'meshes' / 'missing_forearm.stl'}); "
        "expected an existing mesh file"
    ],
    "two_roots": [
        "robot 'two_roots': has 2 root links ('base', 'stray'); expected exactly one root "
        "link (connect the others with joints)"
    ],
}


def test_every_broken_template_is_covered() -> None:
    on_disk = {p.name.removesuffix(".urdf.xacro") for p in BROKEN.glob("*.urdf.xacro")}
    assert on_disk == set(BROKEN_CASES)


@pytest.mark.parametrize("name", sorted(BROKEN_CASES))
def test_broken_template_gives_exact_problem(name: str) -> None:
    template = f"broken/{name}.urdf.xacro"
    xml = _render(BROKEN / f"{name}.urdf.xacro")
    problems = lint_urdf(xml, template=template, base_dir=BROKEN)
    assert [str(p) for p in problems] == [f"{template}: {text}" for text in BROKEN_CASES[name]]
    with pytest.raises(LintError) as raised:
        check_urdf_or_raise(xml, template=template, base_dir=BROKEN)
    assert raised.value.problems == problems
    assert str(raised.value) == "\n".join(str(p) for p in problems)


# --------------------------------------------------------------------------- more lint rules


def _one_link(body: str, name: str = "solo") -> str:
    return f'<robot name="r"><link name="{name}">{body}</link></robot>'


def _two_links(joint: str) -> str:
    inertial = INERTIAL.format(m=1.0, i=0.01)
    return f'<robot name="r"><link name="a">{inertial}</link><link name="b">{inertial}</link>{joint}</robot>'


def _messages(xml: str, **kwargs) -> list[str]:
    return [f"{p.element}: {p.message}" for p in lint_urdf(xml, template="t", **kwargs)]


def test_problem_str_and_error_format() -> None:
    problem = LintProblem("robots/jaco.urdf.xacro", "joint 'elbow'", "something")
    assert str(problem) == "robots/jaco.urdf.xacro: joint 'elbow': something"
    error = LintError([problem, LintProblem("t", "link 'x'", "other")])
    assert str(error) == "robots/jaco.urdf.xacro: joint 'elbow': something\nt: link 'x': other"


def test_malformed_document_is_one_problem() -> None:
    problems = lint_urdf("<robot><link name='a'></robot>", template="t")
    assert len(problems) == 1
    assert problems[0].element == "document"
    assert problems[0].message.startswith("is not well-formed XML (mismatched tag")


def test_missing_inertial_and_non_finite_numbers() -> None:
    assert _messages(_one_link("")) == [
        "link 'solo': has no <inertial>; expected an <inertial> with a positive <mass value> and an <inertia>"
    ]
    body = INERTIAL.format(m="nan", i=0.01).replace('xyz="0 0 0"', 'xyz="0 inf 0"')
    assert _messages(_one_link(body)) == [
        "link 'solo': <origin xyz> is '0 inf 0'; expected 3 finite numbers",
        "link 'solo': <mass value> is 'nan'; expected a finite number",
    ]


def test_geometry_sizes_and_unknown_shapes() -> None:
    inertial = INERTIAL.format(m=1.0, i=0.01)
    body = (
        inertial
        + '<collision><geometry><box size="0.1 0 0.1"/></geometry></collision>'
        + '<collision><geometry><sphere radius="-0.1"/></geometry></collision>'
        + '<collision><geometry><cone radius="0.1"/></geometry></collision>'
        + '<visual><geometry><cylinder radius="0.1"/></geometry></visual>'
    )
    assert _messages(_one_link(body)) == [
        "link 'solo': collision 1: box size is (0.1, 0.0, 0.1); expected three positive sizes",
        "link 'solo': collision 2: sphere radius is -0.1; expected a positive radius",
        "link 'solo': collision 3: geometry <cone> is not supported; expected one of box, cylinder, sphere, mesh",
        "link 'solo': visual 1: cylinder has no length; expected a positive length in metres",
    ]


def test_package_urls_refused_and_absolute_mesh_paths_accepted(tmp_path: Path) -> None:
    mesh = tmp_path / "part.obj"
    mesh.write_text(TETRAHEDRON_OBJ)
    inertial = INERTIAL.format(m=1.0, i=0.01)
    body = (
        inertial
        + '<collision><geometry><mesh filename="package://arm/part.stl"/></geometry></collision>'
        + f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'
    )
    assert _messages(_one_link(body)) == [
        "link 'solo': collision 1: mesh filename 'package://arm/part.stl' uses package://, "
        "which needs ROS to resolve; expected an absolute path (or one relative to the "
        "URDF's folder)"
    ]


def test_require_collision_callable_decides() -> None:
    inertial = INERTIAL.format(m=1.0, i=0.01)
    xml = _one_link(inertial, name="handle")
    assert _messages(xml) == []  # no visual: nothing to collide by default
    assert _messages(xml, require_collision=lambda name: name == "handle") == [
        "link 'handle': has no <collision>; expected at least one <collision> for this link"
    ]
    visual = '<visual><geometry><sphere radius="0.1"/></geometry></visual>'
    assert _messages(_one_link(inertial + visual), require_collision=lambda name: False) == []


def test_joint_types_limits_and_continuous_joints() -> None:
    floating = '<joint name="free" type="floating"><parent link="a"/><child link="b"/></joint>'
    assert _messages(_two_links(floating)) == [
        "joint 'free': type 'floating' is not allowed in generated scenes; expected one of "
        "revolute, continuous, prismatic, fixed"
    ]
    no_limit = '<joint name="spin" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>'
    assert _messages(_two_links(no_limit)) == [
        "joint 'spin': continuous joint has no <limit>; expected <limit effort velocity> with "
        "effort > 0 and velocity > 0"
    ]
    zero_effort = (
        '<joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 0 1"/><limit lower="0" upper="0.1" effort="0" velocity="-1"/></joint>'
    )
    assert _messages(_two_links(zero_effort)) == [
        "joint 'slide': <limit> effort is 0.0; expected effort > 0",
        "joint 'slide': <limit> velocity is -1.0; expected velocity > 0",
    ]


def test_structure_names_parents_and_cycles() -> None:
    missing = '<joint name="j" type="fixed"><parent link="a"/><child link="ghost"/></joint>'
    assert _messages(_two_links(missing)) == [
        "joint 'j': child link 'ghost' does not exist; expected the name of a link in this document",
        "robot 'r': has 2 root links ('a', 'b'); expected exactly one root link (connect the others with joints)",
    ]
    cycle = (
        '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>'
    )
    assert _messages(_two_links(cycle)) == [
        "robot 'r': has no root link (every link is the child of a joint, so the joints form "
        "a cycle); expected exactly one root link"
    ]
    twice = (
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'
    )
    assert _messages(_two_links(twice)) == [
        "joint 'j': name is used by 2 joints; expected unique joint names",
        "link 'b': is the child of 2 joints ('j', 'j'); expected at most one parent joint",
    ]
    inertial = INERTIAL.format(m=1.0, i=0.01)
    link = f'<link name="a">{inertial}</link>'
    duplicate = f'<robot name="r">{link}{link}</robot>'
    assert _messages(duplicate) == ["link 'a': name is used by 2 links; expected unique link names"]


# --------------------------------------------------------------------------- external checks


def test_urdfdom_reports_joint_with_missing_link(tmp_path: Path) -> None:
    broken = VALID_URDF.replace('<child link="hand"/>', '<child link="no_such_link"/>')
    path = _write(tmp_path, "broken.urdf", broken)
    problems = check_with_urdfdom(path)
    assert problems, "check_urdf accepted a joint whose child link does not exist"
    assert any("no_such_link" in line for line in problems), problems
    # yourdfpy refuses it too, and pybullet fails cleanly with its own error lines.
    assert check_with_yourdfpy(path)
    warnings = pybullet_load_warnings(path)
    assert "loadURDF failed: Cannot load URDF file." in warnings


def test_urdfdom_reports_capsule_even_with_exit_status_zero(tmp_path: Path) -> None:
    capsule = VALID_URDF.replace('<sphere radius="0.03"/>', '<capsule radius="0.03" length="0.1"/>')
    path = _write(tmp_path, "capsule.urdf", capsule)
    assert any("Could not parse collision element" in line for line in check_with_urdfdom(path))
    assert any("capsule" in line for line in check_with_yourdfpy(path))


def test_pybullet_warnings_are_captured_and_fds_restored(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    no_inertial = (
        '<robot name="r"><link name="base"/><link name="tip"/>'
        '<joint name="j" type="fixed"><parent link="base"/><child link="tip"/></joint></robot>'
    )
    path = _write(tmp_path, "no_inertial.urdf", no_inertial)
    capfd.readouterr()
    warnings = pybullet_load_warnings(path)
    assert any("No inertial data for link" in w and "[tip]" in w for w in warnings), warnings
    # Nothing leaked to the real stdout/stderr, and both fds work again afterwards.
    leaked = capfd.readouterr()
    assert "b3Warning" not in leaked.out + leaked.err
    os.write(1, b"fd1 ok\n")
    os.write(2, b"fd2 ok\n")
    restored = capfd.readouterr()
    assert restored.out == "fd1 ok\n"
    assert restored.err == "fd2 ok\n"


def test_pybullet_is_not_asked_to_load_a_forest(tmp_path: Path) -> None:
    # PyBullet 3.2.7 segfaults on several root links; the check reports instead of loading.
    xml = _render(BROKEN / "two_roots.urdf.xacro")
    assert [p.element for p in pybullet_crash_risks(xml)] == ["robot 'two_roots'"]
    path = _write(tmp_path, "two_roots.urdf", xml)
    warnings = pybullet_load_warnings(path)
    assert len(warnings) == 1
    assert warnings[0].startswith("error: not loaded (pybullet crashes on links that do not ")
    assert check_with_urdfdom(path)


def test_missing_check_urdf_names_the_pip_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(FileNotFoundError, match="cmeel-urdfdom"):
        find_check_urdf()
