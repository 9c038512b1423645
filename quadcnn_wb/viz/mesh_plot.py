"""Picture of the quad mesh with its blocks coloured and the streamlines drawn, like the
paper's Figures 9 and 12-13."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PolyCollection

from .field_plot import VALENCE_COLOURS
from .figure import draw_boundary, new_axes, save_png


def plot_mesh(result, path, title=None) -> None:
    q = result.quality
    fig, ax = new_axes(title or f"{q['quads']} quads in {q['blocks']} blocks, min scaled "
                                f"Jacobian {q['min_scaled_jacobian']:.3f}, "
                                f"{q['irregular_vertices']} irregular vertices")
    mesh = result.mesh
    rng = np.random.default_rng(7)
    palette = rng.uniform(0.55, 0.95, size=(max(q["blocks"], 1), 3))
    colours = palette[mesh.block_of_quad % len(palette)]
    colours[mesh.block_of_quad < 0] = 0.8  # quads in no block: grey
    ax.add_collection(PolyCollection(mesh.nodes[mesh.quads], facecolors=colours,
                                     edgecolors="#33415c", linewidths=0.3, zorder=1))
    draw_boundary(ax, result.domain)
    for line in result.streamlines:
        ax.plot(line.points[:, 0], line.points[:, 1], color="#1a9e3a", linewidth=1.0,
                zorder=3, alpha=0.8)
    for s in result.reference.field.singularities:
        ax.plot(*s.xy, "o", color=VALENCE_COLOURS[s.valence], markersize=5, zorder=4,
                markeredgecolor="black", markeredgewidth=0.5)
    ax.autoscale_view()
    save_png(fig, path)
