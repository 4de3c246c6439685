"""The certifier of a robot in a world, chosen once.

:func:`certifier_for` is the one place that turns a robot, its world and a caller's
options into the object that decides edges:

- a rigid robot (SE(2), SE(3)): :class:`~kcplan.certification.certifier.EdgeCertifier`
  (``backend="python"``, on python-fcl) or its compiled twin
  :class:`~kcplan.certification.kernel.KernelCertifier` (``"kernel"``, on coal);
- an arm, whose world is a :class:`kcplan.arm.ArmWorld`:
  :class:`~kcplan.certification.arm_certifier.ArmEdgeCertifier` or its compiled twin
  :class:`~kcplan.certification.kernel.KernelArmCertifier`.

The two twins of a kind decide every edge alike (the agreement tests hold them to it).
Every certifier has ``backend``, ``n`` (the floats of a state), ``fallback``,
``certificates``, ``counters``, ``covered``, ``state_valid(q)`` and ``check(q1, q2,
resolution)`` on numpy states (a rigid robot's flat pose, an arm's joint vector).

Each kind has its own options (:data:`RIGID_OPTIONS`, :data:`ARM_OPTIONS`): an option of
the other kind is refused in one line, never ignored.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from kcplan.arm.world import ArmWorld
from kcplan.certification.arm_certifier import (
    ARM_CERTIFICATES,
    DEFAULT_ARM_CERTIFICATES,
    DEFAULT_KC_INFLATION,
    ArmEdgeCertifier,
)
from kcplan.certification.certifier import DEFAULT_PROBES, EdgeCertifier
from kcplan.certification.kernel import KernelArmCertifier, KernelCertifier
from kcplan.certification.ladder import GuardLadder
from kcplan.geometry.robot import Robot
from kcplan.world.collision import CollisionWorld

__all__ = ["ARM_OPTIONS", "RIGID_OPTIONS", "Certifier", "certifier_for"]

RIGID_OPTIONS = (
    "certificates", "fallback", "inflations", "horizon", "max_guards", "sweep_test",
    "probes", "learn_schedule",
)  # fmt: skip
"""The options of a rigid robot's certifier (:func:`certifier_for`)."""
ARM_OPTIONS = (
    "certificates", "inflations", "max_guards", "probes", "part_balls", "first_order",
    "guard_cache",
)  # fmt: skip
"""The options of an arm's certifier (:func:`certifier_for`)."""

Certifier = EdgeCertifier | KernelCertifier | ArmEdgeCertifier | KernelArmCertifier
"""What :func:`certifier_for` returns."""

BACKENDS = ("kernel", "python")


def certifier_for(robot, world, backend: str | None = None, **options) -> Certifier:
    """The certifier of ``robot`` in ``world`` (see the module docstring).

    Parameters
    ----------
    robot : Robot or array_like or ArmModel
        A rigid robot (:class:`kcplan.geometry.robot.Robot`, or the semi-axes ``(2,)`` or
        ``(3,)`` of one ellipse or ellipsoid at the origin), or an arm
        (:class:`kcplan.arm.ArmModel`) with ``world`` its :class:`kcplan.arm.ArmWorld`.
    world : CollisionWorld or ArmWorld or object
        What the robot must not touch. The compiled kernel needs a
        :class:`kcplan.CollisionWorld` (whose own robot it certifies) or an ``ArmWorld``;
        a world written in Python (``in_collision``, ``safe_body_clearances``, ...) is
        certified by the Python reference.
    backend : {"kernel", "python"}, optional
        Default: the kernel where the world has one.
    **options
        A rigid robot's (:data:`RIGID_OPTIONS`):

        certificates : sequence of str
            Default ``("region",)``, or ``("rotation",)`` when the world has no
            ``free_regions`` (:data:`kcplan.certification.certifier.CERTIFICATE_SETS`).
        fallback : {"bisection", "discrete"}
            For the part of an edge the endpoint guards leave open: more guards (exact,
            the default) or sampling at OMPL's resolution.
        inflations : sequence of float
            The ``polytope`` certificate's guard ladder
            (:data:`kcplan.certification.ladder.DEFAULT_LADDER`).
        horizon : float
            Region horizon, length units (default the largest semi-axis).
        max_guards : int
            Guards per edge before it is rejected as not proven (default 64).
        sweep_test : bool
            Reject an edge whose robot core sweeps into an obstacle first (default: when
            the world can tell).
        probes : int
            Collision queries on an edge before its guards
            (:data:`kcplan.certification.certifier.DEFAULT_PROBES`; 0: none).
        learn_schedule : bool
            Test the occupancy grid's cells only while the grid pays (default True).

        An arm's (:data:`ARM_OPTIONS`):

        certificates : sequence of str
            ``"ball"``, then any of ``"kc"`` and ``"region"``
            (:data:`kcplan.certification.arm_certifier.ARM_CERTIFICATES`; default all).
        inflations : sequence of float
            One number: the KC guards' inflation ``eps``
            (:data:`kcplan.certification.arm_certifier.DEFAULT_KC_INFLATION`).
        max_guards : int
            Guards per edge (default 256: joint-space edges are long).
        probes : int
            Probe an edge's open stretch before its guards when positive (default on).
        part_balls : bool
            Kernel: decide the self pairs of two links far apart at once by balls around
            their bodies (the same decisions; False is the ablation).
        first_order : bool
            Bound each body's motion by its twist at a guard as well (False: ablation).
        guard_cache : bool
            Remember every state's guard and validity across edges (default); False
            remembers one of each (the ablation: an edge's end guards measured again at
            every edge that shares the state).

    Raises
    ------
    ValueError
        One line naming the option and what is expected, e.g. an option of the other
        kind of robot, or a kernel asked for a world written in Python.
    """
    arm = isinstance(world, ArmWorld)
    allowed, others = (ARM_OPTIONS, RIGID_OPTIONS) if arm else (RIGID_OPTIONS, ARM_OPTIONS)
    for name in options:
        if name not in allowed:
            kind = "rigid robots" if arm else "arms"
            what = f"an option of {kind} only" if name in others else "not an option"
            raise ValueError(
                f"{name}: {what}; the options of {'arms' if arm else 'rigid robots'} are "
                f"{', '.join(allowed)}"
            )
    if backend not in (None, *BACKENDS):
        raise ValueError(f"backend: expected 'kernel' or 'python', got {backend!r}")
    if arm:
        return _arm_certifier(robot, world, backend or "kernel", **options)
    return _rigid_certifier(robot, world, backend, **options)


def _rigid_certifier(
    robot,
    world,
    backend: str | None,
    certificates: Sequence[str] | None = None,
    fallback: str = "bisection",
    inflations: Sequence[float] | None = None,
    horizon: float | None = None,
    max_guards: int = 64,
    sweep_test: bool | None = None,
    probes: int = DEFAULT_PROBES,
    learn_schedule: bool = True,
) -> EdgeCertifier | KernelCertifier:
    robot = Robot.of(robot)
    ladder = None
    if certificates is not None and "polytope" in certificates:
        ladder = GuardLadder(robot.semi_axes, inflations)
    compiled = isinstance(world, CollisionWorld)
    backend = backend or ("kernel" if compiled else "python")
    if backend == "kernel" and not compiled:
        raise ValueError(
            "backend: 'kernel' needs a kcplan.CollisionWorld, got "
            f"{type(world).__name__} (use backend='python' for a world written in Python)"
        )
    if backend == "kernel":
        if world.robot is not robot and robot.to_spec() != world.robot.to_spec():
            raise ValueError("robot: the kernel certifies the world's own robot; got another")
        return KernelCertifier(
            world, certificates, ladder, horizon, fallback, max_guards, sweep_test,
            probes=probes, learn_schedule=learn_schedule,
        )  # fmt: skip
    return EdgeCertifier(
        world, robot, certificates, ladder, horizon, fallback, max_guards, sweep_test,
        probes=probes, learn_schedule=learn_schedule,
    )  # fmt: skip


def _arm_certifier(
    arm,
    world: ArmWorld,
    backend: str,
    certificates: Sequence[str] | None = None,
    inflations: Sequence[float] | None = None,
    max_guards: int = 256,
    probes: int = DEFAULT_PROBES,
    part_balls: bool = True,
    first_order: bool = True,
    guard_cache: bool = True,
) -> ArmEdgeCertifier | KernelArmCertifier:
    if arm is not world.arm:
        raise ValueError("robot: an ArmWorld certifies its own arm; got another robot")
    chosen = DEFAULT_ARM_CERTIFICATES if certificates is None else tuple(certificates)
    if (
        not chosen
        or chosen[0] != "ball"
        or not set(chosen[1:]) <= {"kc", "region"}
        or len(set(chosen)) != len(chosen)
    ):
        raise ValueError(
            f"certificates: arms have {ARM_CERTIFICATES}: 'ball', then any of the others "
            f"(default {DEFAULT_ARM_CERTIFICATES}); got {certificates!r}"
        )
    kc_inflation = 0.0
    if "kc" in chosen:
        kc_inflation = DEFAULT_KC_INFLATION if not inflations else float(inflations[0])
        if not (math.isfinite(kc_inflation) and kc_inflation > 0.0):
            raise ValueError(f"inflations: expected a KC inflation > 0, got {inflations!r}")
    planes = "region" in chosen
    cache = {} if guard_cache else {"cache_entries": 1}
    if backend == "kernel":
        return KernelArmCertifier(
            world, max_guards, probes=probes > 0, part_balls=part_balls,
            first_order=first_order, kc_inflation=kc_inflation, planes=planes, **cache,
        )  # fmt: skip
    return ArmEdgeCertifier(
        world, max_guards, probes=probes > 0, first_order=first_order,
        kc_inflation=kc_inflation, planes=planes, **cache,
    )  # fmt: skip
