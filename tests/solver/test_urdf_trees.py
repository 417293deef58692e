"""URDF documents pinocchio's parser crashed on, misread or answered unsaid (a fourth round of
hostile inputs): closed chains, two mimics, gear ratios, speeds and lengths out of bounds, a
joint named as a link, a one-joint chain, a planar joint, mesh files outside the share folder.

Fixtures are example-robot-data's UR5 URDF edited in the test, and small chains written here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from solver.core.dtf import dtf
from solver.core.exceptions import InvalidInputError, RobotModelError
from solver.core.kinematics import jacobian_in_base, tool_pose_in_base
from solver.core.robots import example_robot_data_dir
from solver.families import robot_from_urdf
from solver.path.cell.robot_geometry import robot_geometry

ROOT = Path(__file__).resolve().parents[2]
UR5_FILE = example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf"
UR5 = UR5_FILE.read_text()
FRAMES = {"base_frame": "base", "tool_frame": "tool0"}
LIMIT = '<limit lower="-3" upper="3" effort="1" velocity="2"/>'


def joint(name: str, parent: str, child: str, extra: str = "", kind: str = "revolute") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<axis xyz="0 0 1"/>{LIMIT}{extra}</joint>'
    )


def added(*elements: str) -> str:
    """The UR5 with ``elements`` before its end."""
    return UR5.replace("</robot>", "".join(elements) + "</robot>")


def refusal(urdf: str) -> str:
    with pytest.raises(RobotModelError) as error:
        robot_from_urdf(urdf, **FRAMES)
    assert error.value.field == "robot.urdf"
    return error.value.message


_LOOP = f"""
from solver.core.exceptions import RobotModelError
from solver.families import robot_from_urdf
urdf = open({str(UR5_FILE)!r}).read().replace(
    "</robot>", {joint("closing", "wrist_3_link", "shoulder_link")!r} + "</robot>"
)
try:
    robot_from_urdf(urdf, base_frame="base", tool_frame="tool0")
except RobotModelError as error:
    print(error.message)
"""


def test_a_closed_chain_is_refused_naming_the_link_not_a_crash() -> None:
    """A joint from the wrist back to the shoulder link: pinocchio's parser ended the process
    (SIGSEGV). Run in a process of its own, which a crash ends with a signal."""
    done = subprocess.run(
        [sys.executable, "-c", _LOOP], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert done.returncode == 0, (done.returncode, done.stderr[-500:])
    assert done.stdout.startswith(
        "cannot read the URDF: link 'shoulder_link' is the child of 2 joints "
        "('shoulder_pan_joint', 'closing'): a URDF is a tree"
    )


def test_a_link_with_two_parent_joints_is_refused_not_read_as_one_of_them() -> None:
    """Two joints to one new link: the parser read one of them twice and dropped the other."""
    urdf = added(
        '<link name="a"/><link name="b"/>',
        joint("ja", "tool0", "a"),
        joint("jb", "a", "b"),
        joint("jc", "tool0", "b"),
    )
    assert "link 'b' is the child of 2 joints ('jb', 'jc')" in refusal(urdf)


def test_joints_in_a_loop_of_their_own_are_refused() -> None:
    """Two links each the other's child: one parent each, no root among them."""
    urdf = added('<link name="a"/><link name="b"/>', joint("ja", "a", "b"), joint("jb", "b", "a"))
    assert "lead back to link" in refusal(urdf)
    assert "no loop of joints" in refusal(urdf)


def with_joint_edit(name: str, extra: str = "", old: str = "", new: str = "") -> str:
    """The UR5 with ``extra`` added to joint ``name`` and ``old`` replaced by ``new`` in it."""
    start = UR5.index(f'<joint name="{name}" type=')
    end = UR5.index("</joint>", start)
    return UR5[:start] + UR5[start:end].replace(old, new) + extra + UR5[end:]


def test_a_joint_with_two_mimics_is_refused() -> None:
    """The parser couples it to its first leader; the limits were narrowed through the last."""
    urdf = with_joint_edit(
        "wrist_3_joint", '<mimic joint="wrist_2_joint"/><mimic joint="wrist_1_joint"/>'
    )
    assert refusal(urdf) == (
        "cannot read the URDF: joint 'wrist_3_joint' has 2 <mimic> elements; a joint mimics "
        "one joint"
    )


@pytest.mark.parametrize("multiplier", ["1e308", "-2e6", "1e-300"])
def test_a_mimic_multiplier_outside_the_gear_ratios_is_refused(multiplier: str) -> None:
    """1e308 was refused as 'joint 5 limit 2e-308 rad/s must be > 0', naming the leader only."""
    urdf = with_joint_edit(
        "wrist_3_joint", f'<mimic joint="wrist_2_joint" multiplier="{multiplier}"/>'
    )
    assert "joint 'wrist_3_joint': its mimic multiplier" in refusal(urdf)


def test_a_negative_velocity_limit_is_refused_naming_the_joint() -> None:
    """The parser's own refusal ('Some components of min_velocity ...') named no joint."""
    start = UR5.index('<joint name="elbow_joint" type=')
    velocity = UR5.index('velocity="', start) + len('velocity="')
    urdf = UR5[:velocity] + "-" + UR5[velocity:]
    assert refusal(urdf) == (
        "cannot read the URDF: joint 'elbow_joint': its velocity limit -3.15 is negative"
    )


@pytest.mark.parametrize(("offset", "read"), [("1e8", False), ("-101", False), ("100", True)])
def test_a_joint_origin_beyond_100_m_is_refused_and_100_m_reads(offset: str, read: bool) -> None:
    """At 1e8 m the DTF's LP answered a twist 11 % off, at 1e10 m HiGHS failed (a 500)."""
    urdf = with_joint_edit(
        "elbow_joint",
        old='<origin rpy="0.0 0.0 0.0" xyz="0.0 -0.1197 0.425"/>',
        new=f'<origin rpy="0.0 0.0 0.0" xyz="0.0 -0.1197 {offset}"/>',
    )
    assert urdf != UR5
    if read:
        robot = robot_from_urdf(urdf, **FRAMES)
        assert np.linalg.norm(tool_pose_in_base(robot, np.zeros(6))[:3, 3]) > 99.0
    else:
        assert "joint 'elbow_joint': its origin xyz has a value beyond +-100 m" in refusal(urdf)


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ('name="wrist_3_link-tool0_fixed_joint"', 'name="tool0"'),
        ('<joint name="wrist_3_joint" type=', '<joint name="tool0" type='),
    ],
    ids=["the fixed joint to tool0", "the last revolute joint"],
)
def test_a_joint_named_as_a_link_leaves_the_link_its_name(old: str, new: str) -> None:
    """Two frames named tool0: the lookup raised 'Several frames match' (a 500). The link is
    the frame named; the arm's forward kinematics are the UR5's (pinocchio's own model of the
    unedited file, read here without the service)."""
    import pinocchio as pin

    urdf = UR5.replace(old, new)
    assert urdf.count(new) == UR5.count(new) + 1
    robot = robot_from_urdf(urdf, **FRAMES)
    plain = pin.buildModelFromXML(UR5)
    data = plain.createData()
    base, tool = plain.getFrameId("base"), plain.getFrameId("tool0")
    for q in np.random.default_rng(6).uniform(-3.0, 3.0, (4, 6)):
        pin.framesForwardKinematics(plain, data, q)
        expected = (data.oMf[base].inverse() * data.oMf[tool]).homogeneous
        np.testing.assert_allclose(tool_pose_in_base(robot, q), expected, atol=1e-12)
    assert robot.model.existFrame("tool0 (joint)")


def test_a_chain_of_one_joint_has_its_dtf() -> None:
    """A hinge about z, the tool 0.4 m out along x: a tool speed v along y turning at v / 0.4
    about z needs qdot = v / 0.4, so V_max = 0.4 * qdot_max (geometry). The Jacobian came as a
    vector (eigenpy's 6 x 1 matrix) and was refused as 'jacobian' (a field no request has)."""
    urdf = (
        '<robot name="hinge"><link name="base"/><link name="arm"/><link name="tool0"/>'
        + joint("hinge", "base", "arm")
        + '<joint name="f" type="fixed"><parent link="arm"/><child link="tool0"/>'
        '<origin xyz="0.4 0 0"/></joint></robot>'
    )
    robot = robot_from_urdf(urdf, **FRAMES)
    jacobian = jacobian_in_base(robot, np.array([0.0]))
    assert jacobian.shape == (6, 1)
    answer = dtf(jacobian, u_T=[0, 1, 0], u_R=[0, 0, 1], h=0.4, qdot_max=[2.0])
    assert answer.v_max == pytest.approx(0.8, rel=1e-9)
    stuck = dtf(jacobian, u_T=[1, 0, 0], u_R=None, h=np.inf, qdot_max=[2.0])
    assert str(stuck.v_max) == "0.0"  # not HiGHS's -0.0


def test_a_planar_joint_is_refused_naming_it() -> None:
    urdf = with_joint_edit("elbow_joint", old='type="revolute"', new='type="planar"')
    assert refusal(urdf).startswith("joint 'elbow_joint' moves in 3 degrees of freedom")


_STL = (
    "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.05 0 0\nvertex 0 0.05 0\n"
    "endloop\nendfacet\nfacet normal 1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0.05 0\n"
    "vertex 0 0 0.05\nendloop\nendfacet\nendsolid t\n"
)


def test_a_mesh_outside_the_share_folder_is_not_read(tmp_path: Path) -> None:
    """A request's URDF named any file of the server, and the answer's approximated links said
    whether it was a readable mesh. Now a readable file, a missing one, a file:// one and a
    package:// one climbing out of the share folder all leave the link approximated alike,
    and the UR5's own package:// meshes are read (no link approximated)."""
    mesh = tmp_path / "part.stl"
    mesh.write_text(_STL)
    share = example_robot_data_dir().parent.parent
    climbing = "package://" + "../" * (len(share.parts) + 2) + str(mesh).lstrip("/")
    approximated = {}
    for label, name in [
        ("readable", str(mesh)),
        ("missing", str(tmp_path / "none.stl")),
        ("file", f"file://{mesh}"),
        ("climbing", climbing),
    ]:
        start = UR5.index('<link name="forearm_link">')
        element = UR5.index("<mesh filename=", UR5.index("<collision>", start))
        end = UR5.index("/>", element)
        urdf = UR5[:element] + f'<mesh filename="{name}"' + UR5[end:]
        robot = robot_from_urdf(urdf, **FRAMES)
        approximated[label] = robot_geometry(robot, tool=None, link_radii=None).approximated
    assert set(approximated.values()) == {("elbow_joint",)}, approximated
    plain = robot_from_urdf(UR5, **FRAMES)
    assert robot_geometry(plain, tool=None, link_radii=None).approximated == ()


def test_link_radii_of_a_chain_with_a_mimic_joint_name_every_joint() -> None:
    urdf = added(
        '<link name="finger"/>',
        joint("finger_joint", "tool0", "finger", '<mimic joint="wrist_3_joint"/>'),
        '<link name="tip"/><joint name="tip_fixed" type="fixed"><parent link="finger"/>'
        '<child link="tip"/></joint>',
    )
    robot = robot_from_urdf(urdf, base_frame="base", tool_frame="tip")
    with pytest.raises(InvalidInputError) as error:
        robot_geometry(robot, tool=None, link_radii=(0.05,) * 3)
    assert error.value.message.endswith(
        "give 8, the base's and one per joint (shoulder_pan_joint, shoulder_lift_joint, "
        "elbow_joint, wrist_1_joint, wrist_2_joint, wrist_3_joint, finger_joint)"
    )
