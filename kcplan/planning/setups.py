"""How a problem is put into OMPL for each kind of robot: one concept, two implementations.

:func:`kcplan.planning.problem.plan` plans every scenario the same way; what depends on
the robot's kind lives here, behind :class:`ProblemSetup`:

* :class:`RigidSetup`: a rigid robot (one or several ellipsoids, or a mesh's cover) in
  SE(2) or SE(3) within the scenario's bounds, states as flat poses;
* :class:`ArmSetup`: an arm's planning group in its joint box (the limits), states as
  joint vectors.

Each says what its states are (the OMPL space, how a state is read and written), who
checks a state (the kernel's compiled query, python-fcl, or Pinocchio for
``rrtconnect-pin``), which certifier decides an edge (a :class:`KCMotionValidator` for
the ``kc-*`` and ``ca-*`` planners, chosen once by
:func:`kcplan.certification.certifiers.certifier_for`), the kc planners' range, and how a
solved path is timed. :func:`setup_for` picks the implementation from the scenario.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from ompl import geometric as og

from kcplan.arm.scenario import ArmScenario
from kcplan.arm.world import ArmWorld
from kcplan.certification.arm_certifier import DEFAULT_ARM_CERTIFICATES
from kcplan.certification.certifier import CERTIFICATE_SETS
from kcplan.geometry.robot_model import RobotModel
from kcplan.planning.lazy import LAZY_SCREEN_STEP, RIGID_SCREEN_STEP
from kcplan.planning.names import ARM_RANGE, RIGID_RANGE
from kcplan.planning.states import (
    joint_reader,
    joint_space,
    joint_writer,
    set_state,
    state_pose,
    state_space,
)
from kcplan.planning.validator import KCMotionValidator
from kcplan.world.collision import CollisionWorld
from kcplan.world.scenario import Scenario

if TYPE_CHECKING:
    from kcplan.planning.problem import PlannerSpec

__all__ = ["ArmSetup", "ProblemSetup", "RigidSetup", "kernel_state_checker", "setup_for"]

ARM_CERTIFICATES_OF = {CERTIFICATE_SETS["ca"]: ("ball",)}
"""An arm's certificates for a planner's certificate set when the planner names none
(``PlannerSpec.arm_certificates``): ``ca-*`` the clearance balls alone; any other set
:data:`kcplan.certification.arm_certifier.DEFAULT_ARM_CERTIFICATES`."""


class ProblemSetup:
    """A scenario's problem in OMPL: what :func:`~kcplan.planning.problem.plan` needs of
    a robot kind (module docstring). Built by a subclass; :func:`setup_for` picks it.

    Attributes
    ----------
    space, ss, si
        The OMPL state space, ``SimpleSetup`` and ``SpaceInformation``.
    robot : RobotModel
        The robot (:class:`kcplan.geometry.robot_model.RobotModel`: a rigid
        :class:`~kcplan.geometry.robot.Robot` or an :class:`~kcplan.arm.ArmModel`).
    world
        The collision world the queries go through (its ``counters``).
    validator : KCMotionValidator or None
        The motion validator of a ``kc-*`` or ``ca-*`` planner (installed in ``si``);
        None for a stock planner, which keeps OMPL's discrete validator.
    state_valid : callable
        ``state_valid(state) -> bool`` for an OMPL state: the validity checker to install.
    backend : str
        Who checks: ``"kernel"`` (compiled, on coal), ``"python"`` (python-fcl) or
        ``"pin"`` (Pinocchio).
    joints : tuple of str or None
        An arm's planning group (the states' order); None for a rigid robot.
    screen_step : float
        A lazy planner's first screening step (:mod:`kcplan.planning.lazy`).
    kc_range : float
        The kc planners' range, a fraction of the space's maximum extent
        (:data:`~kcplan.planning.names.RIGID_RANGE`, :data:`~kcplan.planning.names.ARM_RANGE`).
    """

    space: object
    ss: object
    si: object
    robot: RobotModel
    world: object
    validator: KCMotionValidator | None = None
    state_valid: Callable
    backend: str
    joints: tuple[str, ...] | None = None
    kc_range: float
    screen_step: float

    def read(self, state) -> NDArray[np.float64]:
        """The state's values: a flat pose, or a joint vector."""
        raise NotImplementedError

    def write(self, state, values) -> None:
        """Set an OMPL state from a flat pose or a joint vector."""
        raise NotImplementedError

    def timed(self, states: list, velocity_limits=None, acceleration_limits=None):
        """The solved path ``states`` timed within the limits (``plan(trajectory=True)``)."""
        raise NotImplementedError

    def _open(self, space) -> None:
        self.space = space
        self.ss = og.SimpleSetup(space)
        self.si = self.ss.getSpaceInformation()


def _require_kernel_for_padding(scenario, spec: PlannerSpec) -> None:
    """The padding is kept by the compiled kernel's queries alone (World::set_padding)."""
    padded = scenario.padding > 0 or any(getattr(scenario, "link_padding", {}).values())
    if padded and spec.backend != "kernel":
        raise ValueError(
            f"padding: kept by the compiled kernel only; {spec.backend} planners ignore it "
            "(use a kernel planner, or no padding)"
        )


class RigidSetup(ProblemSetup):
    """SE(2) or SE(3) within the scenario's bounds; states checked by the kernel's (or
    python-fcl's) collision query; the validator's certificates those of the planner."""

    kc_range = RIGID_RANGE

    def __init__(self, scenario: Scenario, spec: PlannerSpec, world: CollisionWorld | None):
        self.n = n = scenario.dimension
        _require_kernel_for_padding(scenario, spec)
        self.world = world or CollisionWorld(scenario)
        self.robot = self.world.robot
        self.screen_step = RIGID_SCREEN_STEP * self.robot.smallest_semi_axis
        self.world.reset_counters()
        self.backend = spec.backend
        self._open(state_space(*scenario.bounds))
        if spec.kc:
            self.validator = KCMotionValidator(
                self.si,
                self.world.robot,
                self.world,
                spec.certificates,
                backend=spec.backend,
                fallback=spec.fallback,
                probes=spec.probes,
                learn_schedule=spec.learn_schedule,
            )
            self.si.setMotionValidator(self.validator)
            self.state_valid = self.validator.state_valid  # shares the validator's cache
        elif spec.backend == "kernel":
            self.state_valid = kernel_state_checker(self.world.kernel, n)
        else:
            world = self.world

            def state_valid(state) -> bool:
                return not world.in_collision(state_pose(state, n))

            self.state_valid = state_valid

    def read(self, state) -> NDArray[np.float64]:
        return state_pose(state, self.n)

    def write(self, state, values) -> None:
        set_state(state, values, self.n)

    def timed(self, states: list, velocity_limits=None, acceleration_limits=None):
        from kcplan.trajectory import certified as trajectory

        return trajectory.timed_rigid_path(states, self.n, velocity_limits, acceleration_limits)


class ArmSetup(ProblemSetup):
    """The group's joint box (the limits); states checked by the covers' or hulls'
    collision query, compiled (``backend="kernel"``, on coal), on python-fcl, or with
    Pinocchio (``rrtconnect-pin``). For arms the ``ca-*`` planners certify with the
    chain's clearance balls, the other ``kc-*`` ones with the KC guards and the planes
    as well (:mod:`kcplan.certification.arm_certifier`; inflation: the scenario's
    ``robot.inflation``, else :data:`~kcplan.certification.arm_certifier.DEFAULT_KC_INFLATION`);
    stock planners check states discretely, every ``joint_step`` radians where the
    planner sets one."""

    kc_range = ARM_RANGE
    screen_step = LAZY_SCREEN_STEP

    def __init__(self, scenario: ArmScenario, spec: PlannerSpec, world: ArmWorld | None):
        arm = self.robot = self.arm = scenario.arm
        _require_kernel_for_padding(scenario, spec)
        self.world = world or ArmWorld(
            arm, scenario.obstacles, allowed=scenario.allowed, padding=scenario.padding,
            link_padding=scenario.link_padding,
        )  # fmt: skip
        self.world.reset_counters()
        self.backend, self.joints = spec.backend, arm.joints
        self._open(joint_space(arm.lower, arm.upper, arm.wraps))
        self._joints = joint_reader(arm.dof, arm.wraps)  # one layout for every state read
        self._write = joint_writer(arm.dof, arm.wraps)
        if spec.kc:
            certificates = spec.arm_certificates or ARM_CERTIFICATES_OF.get(
                spec.certificates, DEFAULT_ARM_CERTIFICATES
            )
            self.validator = KCMotionValidator(
                self.si, arm, self.world, certificates=certificates,
                inflations=[scenario.inflation] if scenario.inflation > 0 else None,
                backend=spec.backend, probes=spec.probes, part_balls=spec.part_balls,
                first_order=spec.first_order, guard_cache=spec.guard_cache,
            )  # fmt: skip
            self.si.setMotionValidator(self.validator)
            self.state_valid = self.validator.state_valid
        elif spec.backend == "pin":  # rrtconnect-pin: Pinocchio's computeCollisions, by hand
            from kcplan.planning.pin_checker import PinChecker

            self.state_valid = PinChecker(arm, scenario.obstacles, scenario.allowed).is_valid
        elif spec.backend == "kernel":
            kernel, admits = self.world.kernel, self.world.kernel.chain.admits
            joints = self._joints  # as the kc validator reads them: a fair comparison

            def state_valid(state) -> bool:
                q = joints(state)
                return admits(q) and not kernel.in_collision(q)

            self.state_valid = state_valid
        else:
            world, joints = self.world, self._joints

            def state_valid(state) -> bool:
                q = np.array(joints(state))
                return arm.within_limits(q) and not world.in_collision(q)

            self.state_valid = state_valid
        if spec.joint_step is not None:  # at most joint_step between checked states (L2, rad)
            step = spec.joint_step / self.space.getMaximumExtent()
            self.si.setStateValidityCheckingResolution(step)

    def read(self, state) -> NDArray[np.float64]:
        return np.array(self._joints(state))

    def write(self, state, values) -> None:
        self._write(state, values)

    def timed(self, states: list, velocity_limits=None, acceleration_limits=None):
        from kcplan.trajectory import certified as trajectory

        return trajectory.certified_trajectory(  # a wrapping angle unwrapped along the path
            self.world, self.arm.continuous(states), velocity_limits, acceleration_limits
        )


def setup_for(scenario: Scenario | ArmScenario, spec: PlannerSpec, world=None) -> ProblemSetup:
    """The :class:`ProblemSetup` of ``scenario``'s robot kind for the planner ``spec``
    (``world``: a collision world to reuse, of that kind, or None)."""
    if isinstance(scenario, ArmScenario):
        return ArmSetup(scenario, spec, world)
    return RigidSetup(scenario, spec, world)


def kernel_state_checker(kernel, n: int) -> Callable:
    """A state validity checker on the kernel's collision query of a rigid robot in
    ``n`` D (one call per state, reading the OMPL state's fields directly)."""
    if n == 2:
        collides2 = kernel.in_collision_se2
        return lambda s: not collides2(s.getX(), s.getY(), s.getYaw())
    collides3 = kernel.in_collision_se3

    def state_valid(s) -> bool:
        r = s.rotation()
        return not collides3(s.getX(), s.getY(), s.getZ(), r.x, r.y, r.z, r.w)

    return state_valid
