"""Self pairs of an arm proven apart over its whole joint box, once per robot.

An arm's SRDF (MoveIt's setup assistant) disables the link pairs that it never saw touch
in random samples; the others are checked at every state and bounded at every guard.
Many of them cannot touch at all within the joint limits, and a proof says which: the
compiled kernel's branch and bound (``kcplan/_kernel/pair_proof.hpp``) splits the joint
box until the pair's certain clearance at each sub-box's centre exceeds the most its
relative motion can close within the sub-box (Schwarzer, Saha and Latombe's chain bound,
:func:`kcplan.arm.bounds.relative_speeds`), or finds a configuration where the pair
touches. A pair proven apart is never checked again (:class:`kcplan.arm.ArmWorld`); one
that touches, or whose proof ran out of boxes, is checked as before.

The proofs depend on the arm alone (bodies, joints, limits), so they are computed once
per :class:`kcplan.arm.ArmModel` and kept with it for the process's life.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.model import ArmModel

__all__ = ["MAX_BOXES", "PairProof", "prove_pairs"]

MAX_BOXES = 4000
"""Box centres measured per pair before its proof gives up (``unknown``): about 70 ms of
the Panda's hulls per pair; the MBM Panda's 21 checked pairs take 0.04 s in all."""

_PROOFS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class PairProof:
    """What the proof found for one self pair.

    Attributes
    ----------
    bodies : tuple of int
        The pair's body indices ``(i, j)`` into :attr:`ArmModel.bodies`.
    links : tuple of str
        Their links.
    verdict : {"apart", "touches", "unknown"}
        Apart over the whole joint box; touching at ``witness``; or not decided within
        :data:`MAX_BOXES`.
    boxes : int
        Distance queries the proof made.
    least : float
        ``apart``: the least certain clearance at a box centre (metres); else 0.
    witness : tuple of float
        ``touches``: joint values (the arm's state order) where the pair's certain
        clearance is 0; else empty.
    """

    bodies: tuple[int, int]
    links: tuple[str, str]
    verdict: str
    boxes: int
    least: float
    witness: tuple[float, ...] = ()


def prove_pairs(
    arm: ArmModel, pairs: NDArray[np.int64] | Sequence | None = None, max_boxes: int = MAX_BOXES
) -> list[PairProof]:
    """The proof of each body pair of ``pairs`` ``(m, 2)`` (default: every self pair of
    ``arm``, :attr:`ArmModel.self_pairs`), computed once per arm and budget (module
    docstring) and then remembered."""
    from kcplan._kernel import _core, kernel_chain

    pairs = np.asarray(arm.self_pairs if pairs is None else pairs, dtype=np.int64).reshape(-1, 2)
    known = _PROOFS.setdefault(arm, {})
    todo = [(int(i), int(j)) for i, j in pairs if (int(i), int(j), max_boxes) not in known]
    if todo:
        world = _core.ArmWorld(kernel_chain(arm), todo, 0.0, 0.0)
        for (i, j), (verdict, boxes, least, witness) in zip(
            todo, _core.prove_pairs_apart(world, max_boxes), strict=True
        ):
            links = (arm.bodies[i].link, arm.bodies[j].link)
            known[i, j, max_boxes] = PairProof(
                (i, j), links, verdict, int(boxes), float(least), tuple(witness)
            )
    return [known[int(i), int(j), max_boxes] for i, j in pairs]
