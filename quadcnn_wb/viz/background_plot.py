"""Picture of the background mesh (the paper's Figure 1a) with boundary and corners."""

from __future__ import annotations

import numpy as np

from .figure import draw_boundary, new_axes, save_png


def plot_background(domain, mesh, path, title: str | None = None) -> None:
    fig, ax = new_axes(title or f"background mesh: {mesh.n_nodes} nodes, "
                                f"{len(mesh.triangles)} triangles")
    ax.triplot(mesh.nodes[:, 0], mesh.nodes[:, 1], mesh.triangles, color="#7a8ca0",
               linewidth=0.3, zorder=1)
    draw_boundary(ax, domain)
    b = mesh.nodes[mesh.boundary_nodes]
    ax.plot(b[:, 0], b[:, 1], ".", color="#1f4e99", markersize=2.5, zorder=4)
    for node, angle in zip(mesh.corner_nodes, mesh.corner_angles):
        degrees = float(np.degrees(angle))
        concave = degrees > 180.0
        x, y = mesh.nodes[node]
        ax.plot(x, y, "o", color="#d62728" if concave else "#2ca02c", markersize=7, zorder=5)
        ax.annotate(f"{degrees:.0f}°", (x, y), textcoords="offset points", xytext=(5, 5),
                    fontsize=8, zorder=6)
    save_png(fig, path)
