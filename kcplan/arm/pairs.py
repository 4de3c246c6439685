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
per robot and kept for the process's life (by :func:`kcplan._kernel.arm_digest`: an arm
loaded again from the same files finds them), and on disk in the per-user cache
(:func:`kcplan.cover.cache.cache_folder`, subfolder ``pairs``), keyed by everything the
kernel reads of the arm, the pairs, the budget and a digest of the compiled kernel
itself: a robot of thousands of pairs (a PR2's 1,044 take 5 s, a TIAGo
dual's 6,877 45 s on one core) pays once per machine, not once per ``kcplan plan``; and
from :data:`PARALLEL_PAIRS` pairs on they are proven on every core.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from kcplan.arm.model import ArmModel

__all__ = ["MAX_BOXES", "PairProof", "prove_pairs"]

MAX_BOXES = 4000
"""Box centres measured per pair before its proof gives up (``unknown``): about 70 ms of
the Panda's hulls per pair; the MBM Panda's 21 checked pairs take 0.04 s in all."""

_PROOFS: dict[str, dict] = {}
"""The proofs made in this process, by arm (:func:`kcplan._kernel.arm_digest`), pair and
budget."""


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
    from kcplan._kernel import _core, arm_digest, kernel_chain

    pairs = np.asarray(arm.self_pairs if pairs is None else pairs, dtype=np.int64).reshape(-1, 2)
    known = _PROOFS.setdefault(arm_digest(arm), {})
    todo = [(int(i), int(j)) for i, j in pairs if (int(i), int(j), max_boxes) not in known]
    if todo:
        chain = kernel_chain(arm)
        path = _cache_path(arm, todo, max_boxes)
        results = _read(path, len(todo), arm.dof)
        if results is None:
            results = _prove(_core, chain, todo, max_boxes)
            _write(path, results, arm.dof)
        for (i, j), (verdict, boxes, least, witness) in zip(todo, results, strict=True):
            links = (arm.bodies[i].link, arm.bodies[j].link)
            known[i, j, max_boxes] = PairProof(
                (i, j), links, verdict, int(boxes), float(least), tuple(witness)
            )
    return [known[int(i), int(j), max_boxes] for i, j in pairs]


VERDICTS = ("apart", "touches", "unknown")

PARALLEL_PAIRS = 256
"""Pairs from which the proofs run in a thread per core (at most 4), each on its own world
of the chain (the kernel lets go of the GIL); their verdicts are the same as in one
thread (each pair's random samples are seeded by its place in the whole list)."""


def _prove(core, chain, pairs: list[tuple[int, int]], max_boxes: int) -> list:
    """The kernel's proofs of ``pairs``, in parts on threads when there are many."""
    parts = min(4, os.cpu_count() or 1) if len(pairs) >= PARALLEL_PAIRS else 1
    size = -(-len(pairs) // parts)
    starts = range(0, len(pairs), size)
    worlds = [core.ArmWorld(chain, pairs[k : k + size], 0.0, 0.0) for k in starts]
    if len(worlds) == 1:
        return core.prove_pairs_apart(worlds[0], max_boxes)
    with ThreadPoolExecutor(len(worlds)) as pool:
        done = pool.map(lambda wk: core.prove_pairs_apart(wk[0], max_boxes, wk[1]),
                        zip(worlds, starts, strict=True))  # fmt: skip
        return [proof for part in done for proof in part]


def _cache_path(arm: ArmModel, pairs: list[tuple[int, int]], max_boxes: int) -> Path:
    """Where the proofs of ``pairs`` are cached: a digest of the arm as the kernel reads it
    and of the kernel (:func:`kcplan._kernel.arm_digest`), the pairs and the budget."""
    from kcplan._kernel import arm_digest
    from kcplan.cover.cache import cache_folder

    h = hashlib.sha256(arm_digest(arm).encode())
    h.update(repr(max_boxes).encode() + np.asarray(pairs, dtype=np.int64).tobytes())
    return cache_folder() / "pairs" / f"{h.hexdigest()}.npz"


def _read(path: Path, count: int, dof: int) -> list | None:
    """The cached results of ``count`` pairs, or None (no file, or one unreadable)."""
    try:
        with np.load(path) as data:
            verdicts, boxes = data["verdicts"], data["boxes"]
            least, witness = data["least"], data["witness"]
    except (OSError, ValueError, KeyError):
        return None
    if len(verdicts) != count or witness.shape != (count, dof):
        return None
    return [(VERDICTS[v], int(b), float(m), tuple(w) if VERDICTS[v] == "touches" else ())
            for v, b, m, w in zip(verdicts, boxes, least, witness, strict=True)]  # fmt: skip


def _write(path: Path, results: list, dof: int) -> None:
    """Keep ``results`` at ``path`` (atomically); a cache that cannot be written is skipped."""
    from kcplan.files import atomic_output

    witness = np.zeros((len(results), dof))
    for k, (_, _, _, w) in enumerate(results):
        if len(w):
            witness[k] = w
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(path) as tmp, open(tmp, "wb") as f:
            verdicts = np.array([VERDICTS.index(r[0]) for r in results], dtype=np.int8)
            boxes = np.array([r[1] for r in results], dtype=np.int64)
            least = np.array([r[2] for r in results], dtype=float)
            np.savez(f, verdicts=verdicts, boxes=boxes, least=least, witness=witness)
    except OSError:
        pass
