"""Arms from example-robot-data, the Pinocchio ecosystem's robot collection, by name.

PyPI's ``example-robot-data`` (optional: ``pip install "kcplan[robots]"``) installs its
URDFs, SRDFs and meshes under the ``share/example-robot-data/robots`` folder of the cmeel
prefix that holds Pinocchio; their meshes are ``package://example-robot-data/robots/...``
URIs, which :func:`kcplan.arm.model.package_folders` resolves. A scenario names one of
:data:`EXAMPLE_ARMS` as ``robot: {example: NAME, joints: [...]}`` instead of a URDF.

This module reads no file itself; it imports neither OMPL nor FCL.
"""

from __future__ import annotations

from pathlib import Path

from kcplan.arm.model import ArmError

__all__ = ["EXAMPLE_ARMS", "example_folder", "example_robot"]

EXAMPLE_ARMS: dict[str, tuple[str, str | None, tuple[str, ...]]] = {
    "panda": (
        "panda_description/urdf/panda.urdf",
        "panda_description/srdf/panda.srdf",
        tuple(f"panda_joint{i}" for i in range(1, 8)),
    ),
    "ur5": (
        "ur_description/urdf/ur5_joint_limited_robot.urdf",
        "ur_description/srdf/ur5_joint_limited_robot.srdf",
        ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
         "wrist_2_joint", "wrist_3_joint"),
    ),  # fmt: skip
    "ur10": (
        "ur_description/urdf/ur10_joint_limited_robot.urdf",
        None,
        ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
         "wrist_2_joint", "wrist_3_joint"),
    ),  # fmt: skip
    "xarm7": (
        "xarm_description/urdf/xarm7.urdf",
        "xarm_description/srdf/xarm7.srdf",
        tuple(f"joint{i}" for i in range(1, 8)),
    ),
    "ur3": (
        "ur_description/urdf/ur3_joint_limited_robot.urdf",
        None,
        ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
         "wrist_2_joint", "wrist_3_joint"),
    ),  # fmt: skip
    # two arms on one torso (a tree: self pairs across its branches); its SRDF's disabled
    # pairs hold, its groups name another robot's joints ("baxter/left_s0")
    "baxter": (
        "baxter_description/urdf/baxter.urdf",
        "baxter_description/srdf/baxter_manipulation.srdf",
        tuple(f"{side}_{joint}" for side in ("left", "right")
              for joint in ("s0", "s1", "e0", "e1", "w0", "w1", "w2")),
    ),  # fmt: skip
    # a base that drives (its SRDF's planar virtual joint, with robot.base), a torso and two
    # arms; the arm's forearm and wrist roll joints are continuous: angles that wrap
    "pr2": (
        "pr2_description/urdf/pr2.urdf",
        "pr2_description/srdf/pr2.srdf",
        ("torso_lift_joint",
         *(f"r_{joint}_joint" for joint in ("shoulder_pan", "shoulder_lift", "upper_arm_roll",
                                            "elbow_flex", "forearm_roll", "wrist_flex",
                                            "wrist_roll"))),
    ),  # fmt: skip
}
"""Arms of example-robot-data 6.0.0 that kcplan plans: ``NAME: (URDF, SRDF or None, the
arm's joints in state order)``, paths relative to :func:`example_folder`; Baxter's are
both arms, the PR2's its torso and right arm. Left out: the Z1 and the SO-100 (a
link and a fixed joint of one name, which Pinocchio's ``buildReducedModel`` refuses)."""


def example_folder() -> Path:
    """example-robot-data's ``robots`` folder.

    Raises
    ------
    ArmError
        When the package is not installed.
    """
    import pinocchio as pin

    folder = Path(pin.__file__).resolve().parents[4] / "share" / "example-robot-data" / "robots"
    if not folder.is_dir():
        raise ArmError(
            "robot.example: expected PyPI's example-robot-data (pip install "
            f'"kcplan[robots]"), found no {folder}'
        )
    return folder


def example_robot(name: str) -> tuple[Path, Path | None, tuple[str, ...]]:
    """The URDF, the SRDF (None where the collection has none for it) and the arm's
    joints of :data:`EXAMPLE_ARMS` ``name``.

    Raises
    ------
    ArmError
        For a name not in :data:`EXAMPLE_ARMS`, or when the package is not installed.
    """
    if name not in EXAMPLE_ARMS:
        raise ArmError(
            f"robot.example: expected one of {', '.join(sorted(EXAMPLE_ARMS))}, got {name!r}"
        )
    urdf, srdf, joints = EXAMPLE_ARMS[name]
    folder = example_folder()
    return folder / urdf, None if srdf is None else folder / srdf, joints
