"""The figure of ``kcplan pick-place``: joint noise, required inflation, parts entropy."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from kcplan.views.plots import plt, save_figure

__all__ = ["plot_noise_inflation_entropy"]


def plot_noise_inflation_entropy(
    rows: Sequence[dict], target_inflation: float, path: str | os.PathLike
) -> None:
    """Two panels over the joint noise sigma (degrees): the inflation that contains the
    error space (median and 10-90 % band over trials; exact margin and geometric lower
    bound) and the parts entropy at the median exact inflation (true KC volume and
    geometric lower bound). ``rows`` are the per-sigma rows of :func:`summarize_trials`."""
    sig = np.array([r["sigma_deg"] for r in rows])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for key, label, color in (
        ("exact", "exact containment margin", "#1f77b4"),
        ("geometric", "geometric lower bound", "#d62728"),
    ):
        med = np.array([r[f"eps_{key}_median"] for r in rows])
        lo = np.array([r[f"eps_{key}_p10"] for r in rows])
        hi = np.array([r[f"eps_{key}_p90"] for r in rows])
        ax1.plot(sig, med, "o-", color=color, label=label)
        ax1.fill_between(sig, lo, hi, color=color, alpha=0.2)
    ax1.axhline(target_inflation, color="k", ls=":", label=f"target inflation {target_inflation:g}")
    ax1.set_xlabel("joint noise sigma [deg]")
    ax1.set_ylabel("required inflation eps")
    ax1.set_title("(I) inflation that contains the error space")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    keep = np.array([np.isfinite(r["entropy_true"]) for r in rows])
    for key, label, color in (
        ("entropy_true", "true KC volume", "#1f77b4"),
        ("entropy_geometric", "geometric lower bound", "#d62728"),
    ):
        ax2.plot(
            sig[keep],
            [r[key] for r, k in zip(rows, keep, strict=True) if k],
            "s-",
            color=color,
            label=label,
        )
    ax2.set_xlabel("joint noise sigma [deg]")
    ax2.set_ylabel("parts entropy S = log V  [V in rad^3 m^3]")
    ax2.set_title("(II) entropy at the required inflation")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)
