r"""The convex lower bound of the KC C-space (paper Sec. 4, 7.1, 8.1), made provably sound.

The paper approximates the set of relative poses ``xi = [omega, tau]`` that keep
``E_a`` inside ``E_b = (1 + eps) E_a`` by the convex first-order region
``F = {xi : G(1, omega, tau) <= 1}`` and a polytope spanned by points of its boundary,
where

.. math:: G(\alpha, \omega, \tau) = \max_{|u|\le 1}
          \| B^{-1} ((\alpha I + \hat\omega) A u + \tau) \|

(:func:`kcplan.geometry.linearised_margin`). In 3D ``F`` is not inside the true KC set
(points of ``F`` reach exact margins above 1), so a polytope spanned by points of
``F`` may contain colliding poses. :class:`ConvexLowerBound` replaces "vertex in F" by a
vertex test that implies containment for the whole polytope.

Soundness rule (proof)
----------------------
Let ``P = conv(V)`` and ``Theta >= max_{v in V} |omega_v|`` (``< pi``). Take any
``xi = (omega, tau)`` in ``P``, ``t = |omega| <= Theta`` (the norm is convex, so its
maximum over ``P`` is at a vertex), ``k = omega / t``, ``c = cos t``,
``sigma = sin t / t``. Rodrigues' formula gives
``exp(hat(omega)) = c I + sigma hat(omega) + (1 - c) k k^T``, hence, by the triangle
inequality,

.. math:: m(\xi) \le G(c, \sigma\omega, \tau) + (1 - c)\,|B^{-1}k|\,|A k|.

with ``kappa = max_{|k|=1} |B^{-1}k||Ak| = (r + 1/r) / (2 (1 + eps))``,
``r = max(a)/min(a)`` (Kantorovich's inequality); in 2D the last term is absent
(``exp(hat(theta)) = c I + sigma hat(theta)`` exactly) and ``kappa = 0``. So
``m(xi) <= H(c, sigma omega, tau)`` with

.. math:: H(\alpha, \omega', \tau) = G(\alpha, \omega', \tau) + (1 - \alpha)\kappa,

which is convex in ``(alpha, omega', tau)`` (``G`` is a maximum of norms of affine
maps). ``(c, sigma)`` lies in the box ``[cos Theta, 1] x [sin Theta / Theta, 1]``
(``Theta <= 2 < pi``), so ``(c, sigma omega, tau)`` is a convex combination, with
weights that depend on ``(c, sigma)`` only, of the four points
``(alpha, gamma omega, tau)``, ``alpha in {cos Theta, 1}``,
``gamma in {sin Theta / Theta, 1}``; and since ``xi`` is a convex combination of
vertices, each of those is the same combination of the ``(alpha, gamma omega_v, tau_v)``.
By convexity of ``H``,

.. math:: m(\xi) \le \max_{v \in V,\ \alpha,\ \gamma} H(\alpha, \gamma\omega_v, \tau_v).

Each vertex is placed on a ray by bisection so that its four corner values of ``H``
are ``<= 1`` (less a 1e-10 safety), hence ``m <= 1`` on all of ``P``: **every point of
the polytope is an exact containment**. The corner ``alpha = gamma = 1`` is the paper's
own first-order test (no penalty there), so ``P`` is also inside ``F``. The penalty
at ``alpha = cos Theta`` is about ``(1 - cos Theta)(kappa - 1/(1+eps))``, small for
small rotations, which is why the sound 3D polytope keeps most of the paper's volume.

``Theta`` depends on the vertices and the vertices on ``Theta``; the constructor
iterates and keeps only a vertex set whose rotation extent does not exceed the
``Theta`` used to place it.

Vertices
--------
Vertices are the points where rays from the origin leave the sound region. Ray
directions are the patterns ``{-1, 0, 1}^d`` restricted to at most ``max_nonzero``
non-zero entries, scaled by the region's extent along each coordinate axis.
``max_nonzero = 1`` gives the axis extremes (the paper's "+/- eps a_i" and extreme
rotations, 6 vertices in 2D, 12 in 3D); the default 2 adds the extremes in every
coordinate plane: **18 vertices in 2D and 72 in 3D**, against the paper's 10 (2D)
and 44 (3D). Qhull then keeps those on the hull (all of them, in practice).
"""

from __future__ import annotations

from functools import cached_property
from itertools import combinations, product

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import ConvexHull

from kcplan.geometry.containment import linearised_margin, ray_extent
from kcplan.geometry.ellipsoid import as_inflation, as_semi_axes
from kcplan.geometry.rotations import kc_dimension, rotation_dimension

__all__ = ["ConvexLowerBound", "direction_patterns"]

# Absolute slack subtracted from every vertex level, so that rounding in the margin
# and in the hull's half-spaces cannot push a boundary point across m = 1.
_SAFETY = 1e-10


def direction_patterns(d: int, max_nonzero: int) -> NDArray[np.float64]:
    """All vectors of ``{-1, 0, 1}^d`` with 1 to ``max_nonzero`` non-zero entries.

    Returns
    -------
    ndarray, shape (m, d)
    """
    rows = []
    for k in range(1, max_nonzero + 1):
        for idx in combinations(range(d), k):
            for signs in product((-1.0, 1.0), repeat=k):
                v = np.zeros(d)
                v[list(idx)] = signs
                rows.append(v)
    return np.array(rows)


class ConvexLowerBound:
    """Convex polytope of relative poses that keep ``E_a`` inside ``(1 + eps) E_a``.

    Parameters
    ----------
    semi_axes : array_like, shape (n,)
        Robot semi-axes ``a`` (n = 2 or 3), any length unit.
    inflation : float
        ``eps > 0``; the guard has semi-axes ``b = (1 + eps) a``.
    max_nonzero : int, optional
        Ray directions have up to this many non-zero coordinates (1 to ``d``); more
        vertices give a larger polytope with more half-spaces.
    sound : bool, optional
        True (default): vertices pass the soundness rule of the module docstring, so
        every point of the polytope is an exact containment. False: the paper's
        construction, vertices on the boundary of the first-order region ``F``; kept
        for comparison only (not sound in 3D).

    Attributes
    ----------
    vertices : ndarray, shape (m, d)
        Polytope vertices in KC coordinates ``[omega, tau]`` (radians, length unit).
    halfspaces : tuple of ndarray
        ``(A, c)`` with shapes (f, d), (f,): ``xi`` is inside iff ``A xi <= c``; rows of
        ``A`` have unit norm and ``c > 0``.
    rotation_extent : float
        ``Theta``, the largest rotation angle of a vertex (radians).
    level : float
        The bound every vertex corner value satisfies (module docstring).

    Notes
    -----
    The polytope depends only on ``(a, eps)``, never on a guard pose: build it once
    per robot and inflation and reuse it.
    """

    def __init__(
        self,
        semi_axes: ArrayLike,
        inflation: float,
        max_nonzero: int = 2,
        sound: bool = True,
    ) -> None:
        self.a = as_semi_axes(semi_axes)
        self.inflation = as_inflation(inflation)
        self.b = (1.0 + self.inflation) * self.a
        self.n = self.a.shape[0]
        self.d = kc_dimension(self.n)
        self.r = rotation_dimension(self.n)
        if not 1 <= int(max_nonzero) <= self.d:
            raise ValueError(
                f"max_nonzero: expected an integer in [1, {self.d}], got {max_nonzero}"
            )
        self.sound = bool(sound)
        ratio = self.a.max() / self.a.min()
        self.kappa = (ratio + 1.0 / ratio) / (2.0 * (1.0 + self.inflation)) if self.n == 3 else 0.0

        first_order = self._first_order_test()
        axes = np.vstack([np.eye(self.d), -np.eye(self.d)])
        scale = ray_extent(first_order, axes, upper=self.b.max())
        scale = np.maximum(scale[: self.d], scale[self.d :])
        self.directions = direction_patterns(self.d, int(max_nonzero)) * scale
        if self.sound:
            self.vertices, self.rotation_extent, self.level = self._sound_vertices()
        else:
            t = ray_extent(first_order, self.directions, upper=1.0)
            self.vertices = t[:, None] * self.directions
            self.rotation_extent = float(self._rotation_norms(self.vertices).max())
            self.level = 1.0
        self._hull = ConvexHull(self.vertices)
        A = self._hull.equations[:, :-1]
        c = -self._hull.equations[:, -1]
        # Qhull splits non-simplicial facets; keep one row per distinct hyperplane.
        _, keep = np.unique(np.round(np.c_[A, c], 12), axis=0, return_index=True)
        self.halfspaces = (A[np.sort(keep)], c[np.sort(keep)])

    # -- construction ---------------------------------------------------------------

    def _rotation_norms(self, X: NDArray) -> NDArray:
        return np.linalg.norm(X[:, : self.r], axis=1)

    def _first_order_test(self):
        a, b = self.a, self.b
        return lambda X: linearised_margin(a, b, np.ones(X.shape[0]), X)

    def _corner_test(self, theta: float):
        """Largest corner value ``max G(alpha, gamma omega, tau) + (1 - alpha) kappa`` per point."""
        a, b, r, kappa = self.a, self.b, self.r, self.kappa
        alphas = (1.0, float(np.cos(theta)))
        gammas = (1.0, float(np.sin(theta) / theta)) if theta > 0 else (1.0,)

        corners = list(product(alphas, gammas))
        alpha = np.array([al for al, _ in corners])
        gamma = np.array([ga for _, ga in corners])

        def test(X: NDArray) -> NDArray:
            # every corner's points in one stack: one SVD and one secular solve per call
            k = X.shape[0]
            Y = np.tile(X, (len(corners), 1))
            Y[:, :r] *= np.repeat(gamma, k)[:, None]
            value = linearised_margin(a, b, np.repeat(alpha, k), Y).reshape(len(corners), k)
            return (value + ((1.0 - alpha) * kappa)[:, None]).max(axis=0)

        return test

    def _rotation_cap(self) -> float:
        """Largest ``Theta`` (at most 2 rad) whose corner value at ``xi = 0`` stays halfway
        between the centred margin ``1 / (1 + eps)`` and 1, so that every ray has room."""
        rho = 1.0 / (1.0 + self.inflation)
        grid = np.linspace(0.0, 2.0, 2001)
        origin = rho * np.cos(grid) + self.kappa * (1.0 - np.cos(grid))
        ok = np.maximum(origin, rho) <= 0.5 * (1.0 + rho)
        return float(grid[ok].max())

    def _sound_vertices(self) -> tuple[NDArray, float, float]:
        axis_rot = ray_extent(
            self._first_order_test(),
            np.vstack([np.eye(self.d)[: self.r], -np.eye(self.d)[: self.r]]),
            upper=1.0,
        )
        cap = self._rotation_cap()
        theta = min(float(axis_rot.max()), cap)
        level = 1.0 - _SAFETY
        best = None
        # The extent f(theta) of the vertices placed for Theta = theta falls as theta grows;
        # a pair is sound when f(theta) <= theta, and the smallest such theta (the fixed
        # point) gives the largest polytope. Plain iteration theta <- f(theta) oscillates
        # about it (by a factor near -0.8 for a flat robot: 40 rounds, 4 s a polytope);
        # once two rounds bracket it, regula falsi on g = f - theta (Illinois) settles it
        # in a few. Any pair kept has passed f(theta) <= theta, whatever the steps.
        sound = unsound = None  # (theta, g) with g <= 0 and g > 0
        for _ in range(40):
            t = ray_extent(self._corner_test(theta), self.directions, level=level, upper=1.0)
            vertices = t[:, None] * self.directions
            # Shrinking a vertex towards 0 keeps it valid (the test is convex and holds at 0).
            norms = self._rotation_norms(vertices)
            vertices *= np.minimum(1.0, cap / np.maximum(norms, 1e-300))[:, None]
            extent = float(self._rotation_norms(vertices).max())
            g = extent - theta
            if g <= 0:
                if best is None or theta < best[1]:
                    best = (vertices, theta, level)
                if -g <= 1e-6 * theta:  # within a millionth of the best polytope
                    break
                if sound is not None and unsound is not None and sound[1] < 0:
                    unsound = (unsound[0], 0.5 * unsound[1])  # Illinois: the stale end halved
                sound = (theta, g)
            else:
                if sound is not None and unsound is not None and unsound[1] > 0:
                    sound = (sound[0], 0.5 * sound[1])
                unsound = (theta, g)
            if sound is None or unsound is None:
                theta = extent
            else:
                (t0, g0), (t1, g1) = sound, unsound
                theta = t0 - g0 * (t1 - t0) / (g1 - g0)
        if best is None:  # pragma: no cover - the iteration above always converges
            raise RuntimeError("ConvexLowerBound: the rotation extent did not settle")
        return best

    # -- queries --------------------------------------------------------------------

    def contains(self, xi: ArrayLike) -> NDArray[np.bool_] | bool:
        """True for KC coordinates inside the polytope.

        Parameters
        ----------
        xi : array_like, shape (k, d) or (d,)

        Returns
        -------
        bool or ndarray of bool, shape (k,)
        """
        X = np.asarray(xi, dtype=float)
        A, c = self.halfspaces
        inside = np.all(np.atleast_2d(X) @ A.T <= c, axis=1)
        return bool(inside[0]) if X.ndim == 1 else inside

    def reach(self, direction: ArrayLike) -> NDArray[np.float64] | float:
        """Gauge: the largest ``lam >= 0`` with ``lam * direction`` inside the polytope.

        ``min over rows with A_i . v > 0 of c_i / (A_i . v)`` (``inf`` for ``v = 0``).

        Parameters
        ----------
        direction : array_like, shape (k, d) or (d,)
        """
        V = np.asarray(direction, dtype=float)
        A, c = self.halfspaces
        proj = np.atleast_2d(V) @ A.T
        with np.errstate(divide="ignore"):
            ratio = np.where(proj > 0, c / np.where(proj > 0, proj, 1.0), np.inf)
        lam = ratio.min(axis=1)
        return float(lam[0]) if V.ndim == 1 else lam

    def volume(self) -> float:
        """Lebesgue volume of the polytope in KC coordinates (rad^r * length^n)."""
        return float(self._hull.volume)

    @cached_property
    def n_vertices(self) -> int:
        """Number of vertices on the hull."""
        return int(len(self._hull.vertices))

    def __repr__(self) -> str:
        return (
            f"ConvexLowerBound(semi_axes={self.a.tolist()}, inflation={self.inflation}, "
            f"vertices={self.n_vertices}, halfspaces={len(self.halfspaces[1])}, sound={self.sound})"
        )
