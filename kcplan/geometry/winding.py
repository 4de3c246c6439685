"""Winding numbers of closed boundaries: which points a polygon or a closed mesh encloses.

The winding number of a point ``p`` with respect to a closed, consistently oriented
boundary is the signed number of times the boundary wraps around ``p``: the sum of the
signed angles (2D, edges) or solid angles (3D, triangles) that its pieces subtend at
``p``, over ``2 pi`` or ``4 pi``. It is ``+-1`` inside a simple solid and 0 outside,
however close to the boundary, and it needs no ray casting (no special cases for rays
through vertices). *On* the boundary it is undefined: about 1/2 on a triangle's face, 0,
1/2 or 1 on a polygon's edge, depending on the sign of a rounded zero.

The solid angle of a triangle is Van Oosterom and Strackee's formula
("The solid angle of a plane triangle", IEEE Trans. Biomed. Eng. 30, 1983)::

    tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a . b)|c| + (b . c)|a| + (c . a)|b|)

with ``a, b, c`` the corners relative to ``p``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["winding_numbers"]

_CHUNK = 2**21
"""Point-simplex pairs evaluated at once (bounds the temporary arrays to tens of MB)."""


def winding_numbers(points: ArrayLike, simplices: ArrayLike) -> NDArray[np.float64]:
    """Winding numbers of points with respect to a closed boundary.

    Parameters
    ----------
    points : array_like, shape (m, n)
    simplices : array_like, shape (k, n, n)
        The boundary: oriented segments ``(k, 2, 2)`` of a polygon (counter-clockwise
        outer boundary gives +1 inside) or oriented triangles ``(k, 3, 3)`` of a closed
        mesh (outward normals give +1 inside).

    Returns
    -------
    ndarray, shape (m,)
    """
    P = np.atleast_2d(np.asarray(points, dtype=float))
    S = np.asarray(simplices, dtype=float)
    n = P.shape[1]
    if S.ndim != 3 or S.shape[1:] != (n, n):
        raise ValueError(f"simplices: expected shape (k, {n}, {n}), got {S.shape}")
    out = np.empty(len(P))
    step = max(1, _CHUNK // max(len(S), 1))
    for start in range(0, len(P), step):
        block = P[start : start + step]
        corners = S[None, :, :, :] - block[:, None, None, :]  # (b, k, n, n)
        if n == 2:
            a, b = corners[:, :, 0], corners[:, :, 1]
            cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
            angle = np.arctan2(cross, np.einsum("bki,bki->bk", a, b))
            out[start : start + step] = angle.sum(axis=1) / (2.0 * np.pi)
        else:
            a, b, c = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
            la, lb, lc = (np.linalg.norm(v, axis=-1) for v in (a, b, c))
            det = np.einsum("bki,bki->bk", a, np.cross(b, c))
            den = (
                la * lb * lc
                + np.einsum("bki,bki->bk", a, b) * lc
                + np.einsum("bki,bki->bk", b, c) * la
                + np.einsum("bki,bki->bk", c, a) * lb
            )
            out[start : start + step] = (2.0 * np.arctan2(det, den)).sum(axis=1) / (4.0 * np.pi)
    return out
