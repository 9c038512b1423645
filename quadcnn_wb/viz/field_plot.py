"""Picture of the frame field stage, like the paper's Figures 1b-d and 4b: crosses,
singular points by valence, streamlines, and the label-1 frame vectors in red."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection

from .figure import draw_boundary, new_axes, save_png

VALENCE_COLOURS = {3: "#d62728", 5: "#1f77b4"}


def plot_field(domain, mesh, field, streamlines, path, labels=None, title=None) -> None:
    counts = field.valences()
    fig, ax = new_axes(title or f"frame field: {counts[3]} valence-3, {counts[5]} valence-5, "
                                f"{len(streamlines)} streamlines")
    ax.triplot(mesh.nodes[:, 0], mesh.nodes[:, 1], mesh.triangles, color="#d0d7e0",
               linewidth=0.2, zorder=0)
    half = 0.3 * mesh.element_size
    frames = field.frames
    segs = []
    for v in (frames[:, 0:2], frames[:, 2:4]):
        segs.append(np.stack([mesh.nodes - half * v, mesh.nodes + half * v], axis=1))
    ax.add_collection(LineCollection(np.concatenate(segs), colors="#6b7b8c", linewidths=0.35,
                                     zorder=1))
    if labels is not None:
        red = []
        for col, v in ((0, frames[:, 0:2]), (1, frames[:, 2:4])):
            on = labels[:, col] == 1
            red.append(np.stack([mesh.nodes[on] - half * v[on], mesh.nodes[on] + half * v[on]],
                                axis=1))
        ax.add_collection(LineCollection(np.concatenate(red), colors="#e8302a",
                                         linewidths=0.9, zorder=2))
    draw_boundary(ax, domain)
    for line in streamlines:
        ax.plot(line.points[:, 0], line.points[:, 1], color="#1a9e3a", linewidth=1.4, zorder=4)
    for sing in field.singularities:
        ax.plot(*sing.xy, "o", color=VALENCE_COLOURS[sing.valence], markersize=7, zorder=5,
                markeredgecolor="black", markeredgewidth=0.6)
    for corner in field.corner_sources:
        ax.plot(*corner.xy, "s", color="#ff9f1c", markersize=6, zorder=5,
                markeredgecolor="black", markeredgewidth=0.6)
    save_png(fig, path)
