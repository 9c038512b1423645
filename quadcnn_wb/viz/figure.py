"""Shared figure set-up and atomic PNG saving for the stage pictures."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from ..core.atomic import write_atomic  # noqa: E402


def new_axes(title: str, size: float = 7.0):
    fig, ax = plt.subplots(figsize=(size, size))
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_axis_off()
    return fig, ax


def save_png(fig, path, dpi: int = 150) -> None:
    try:
        write_atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=dpi,
                                                   bbox_inches="tight"))
    finally:
        plt.close(fig)


def draw_boundary(ax, domain, color="black", width=1.6) -> None:
    """The exact boundary curves, densely sampled."""
    for loop in domain.loops:
        for curve in loop:
            n = 2 if curve.kind == "line" else 64
            pts = curve.sample(n)
            ax.plot(pts[:, 0], pts[:, 1], color=color, linewidth=width, zorder=3)
