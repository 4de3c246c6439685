"""Objects held by an arm's link (kcplan.arm.attach, issue 39 item 4): the object is one
more piece of its link, checked against the scene and the other links, certified with the
arm, and every accepted edge is free on the meshes with the object (kcplan.arm.verify,
which knows nothing of the certificate)."""

import numpy as np
import pytest
from conftest import PANDA, PANDA_GROUP

from kcplan.arm import ArmError, ArmWorld, load_arm
from kcplan.arm.attach import Attached, attach, detach
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.scenarios import check_start_goal, parse_scenario
from kcplan.world import ScenarioError

FINGERS = ("panda_leftfinger", "panda_rightfinger")
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]


def _part(kind: str = "cylinder") -> dict:
    """A part held between the fingers, its fields in the hand's frame."""
    shapes = {
        "cylinder": {"center": [0.0, 0.0, 0.12], "radius": 0.03, "height": 0.15},
        "box": {"center": [0.0, 0.0, 0.12], "size": [0.05, 0.05, 0.2],
                "quaternion": [0.0, 0.0, 0.38268343, 0.92387953]},
        "sphere": {"center": [0.0, 0.0, 0.12], "radius": 0.05},
    }  # fmt: skip
    return {"link": "panda_hand", "name": "part", kind: shapes[kind], "touch": list(FINGERS)}


def _scenario(goal, attached, obstacles=()) -> dict:
    return {
        "name": "held",
        "robot": {"urdf": str(PANDA / "panda.urdf"), "srdf": str(PANDA / "panda.srdf"),
                  "joints": PANDA_GROUP},
        "start": {"joints": READY}, "goal": {"joints": goal},
        "obstacles": list(obstacles), "attached": attached,
    }  # fmt: skip


@pytest.fixture(scope="module")
def held():
    """The bundled Panda's hulls holding a cylinder between its fingers."""
    return parse_scenario(_scenario(READY, [_part()]), "held.yaml", PANDA, check=False).arm


def test_an_attached_part_is_a_piece_of_its_link(held):
    arm = load_arm(PANDA / "panda.urdf", PANDA_GROUP, srdf=PANDA / "panda.srdf")
    assert len(held.bodies) == len(arm.bodies) + 1 and held.bodies[-1].link == "part"
    hand = next(b for b in arm.bodies if b.link == "panda_hand")
    assert held.bodies[-1].joint == hand.joint and held.bodies[-1].hull is not None
    partners = {held.bodies[j if i == len(arm.bodies) else i].link
                for i, j in held.self_pairs if len(arm.bodies) in (i, j)}  # fmt: skip
    assert "panda_link5" in partners and not partners & {"panda_hand", *FINGERS}
    world = ArmWorld(held, ())  # link7 is fixed to the hand: the pair is proven apart
    assert world.proven_apart >= 1
    kept = {held.bodies[i].link for i, j in world.self_pairs} | {
        held.bodies[j].link for i, j in world.self_pairs}
    assert "part" in kept
    back = detach(held)
    assert len(back.bodies) == len(arm.bodies) and len(back.self_pairs) == len(arm.self_pairs)
    assert back.attached == () and len(held.attached) == 1  # the held arm is unchanged
    with pytest.raises(ArmError, match=r"detach: 'nope' is not attached \(part\)"):
        detach(held, ["nope"])


def test_attaching_refuses_what_it_cannot_hold(held):
    shape = held.attached[0].shape
    with pytest.raises(ArmError, match=r"attached.x: 'panda_palm' is not a link"):
        attach(held, [Attached("x", "panda_palm", shape)])
    with pytest.raises(ArmError, match=r"attached.part: the name is a link's or taken"):
        attach(held, [Attached("part", "panda_hand", shape)])
    covered = load_arm(PANDA / "panda.urdf", PANDA_GROUP, bodies_per_link=1)
    with pytest.raises(ArmError, match="expected an arm of hulls"):
        attach(covered, [Attached("x", "panda_hand", shape)])
    bad = _scenario(READY, [{"link": "panda_hand", "box": {"center": [0, 0, 0], "size": [1, 1, 1]},
                             "sphere": {"center": [0, 0, 0], "radius": 1}}])  # fmt: skip
    with pytest.raises(ScenarioError, match=r"attached\[0\]: expected one shape of box, "):
        parse_scenario(bad, "bad.yaml", PANDA, check=False)


def test_a_goal_where_only_the_part_collides_is_refused():
    """A wall the arm clears at the goal but the part it holds does not."""
    goal = READY
    wall = {"box": {"center": [0.307, 0.0, 0.43], "size": [0.1, 0.1, 0.02]}}  # the part's
    free = parse_scenario(_scenario(goal, [], [wall]), "w.yaml", PANDA, check=False)
    check_start_goal(free)  # the arm alone is clear
    with pytest.raises(ScenarioError, match=r"start: the arm's links touch an obstacle or "
                       r"each other \(on their own collision meshes too\): part and an obstacle$"):
        check_start_goal(parse_scenario(_scenario(goal, [_part()], [wall]), "w.yaml", PANDA,
                                        check=False))  # fmt: skip


@pytest.mark.parametrize("kind", ["cylinder", "box", "sphere"])
def test_every_edge_accepted_with_a_part_is_free_on_the_meshes_with_it(kind):
    """Random edges of every length in a cluttered scene, the part held: each accepted
    edge re-checked without gaps on the links' meshes and the part's own solid."""
    obstacles = [
        {"box": {"center": [0.45, -0.3, 0.4], "size": [0.3, 0.05, 0.5]}},
        {"sphere": {"center": [0.3, 0.35, 0.6], "radius": 0.12}},
        {"cylinder": {"center": [-0.3, 0.3, 0.3], "radius": 0.05, "height": 0.6}},
    ]
    scenario = parse_scenario(_scenario(READY, [_part(kind)], obstacles), "s.yaml", PANDA,
                              check=False)  # fmt: skip
    arm = scenario.arm
    world = ArmWorld(arm, scenario.obstacles)
    states = np.random.default_rng(8).uniform(arm.lower, arm.upper, size=(300, arm.dof))
    free = [q for q in states if not world.in_collision(q)]
    kernel = KernelArmCertifier(world)
    rng = np.random.default_rng(9)
    accepted = 0
    for _ in range(70):
        q1, q2 = free[rng.integers(len(free))], free[rng.integers(len(free))]
        q2 = q1 + rng.choice([0.05, 0.2, 0.6]) * (q2 - q1)
        if kernel.check(q1, q2):
            accepted += 1
            assert not verify_arm_path(arm, scenario.obstacles, [q1, q2]).collides, (q1, q2)
    assert accepted >= 20
