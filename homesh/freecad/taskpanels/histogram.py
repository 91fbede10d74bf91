"""The quality histogram of a task panel: per-element scaled Jacobians as bars in the view's
colours (matplotlib in a Qt canvas). Gui only."""


def histogram_canvas():
    """(figure, canvas) of an empty histogram, sized for a task panel."""
    from matplotlib.backends.backend_qt5agg import FigureCanvasQTAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=(3.2, 1.8), dpi=90)
    canvas = FigureCanvasQTAgg(figure)
    canvas.setMinimumHeight(150)
    return figure, canvas


def draw_histogram(figure, values):
    """Histogram of per-element scaled Jacobians on ``figure``: bars in the view's colours,
    invalid elements (<= 0) in their own bar."""
    import numpy as np
    from ...tessellation import quality_colors
    values = np.asarray(values, dtype=float)
    figure.clear()
    axes = figure.add_subplot(111)
    edges = np.linspace(0.0, 1.0, 21)
    counts, _ = np.histogram(np.clip(values, 1e-12, 1.0), bins=edges)
    centres = 0.5 * (edges[:-1] + edges[1:])
    axes.bar(centres, counts, width=0.05, color=quality_colors(centres), edgecolor="#333333",
             linewidth=0.4)
    invalid = int((values <= 0.0).sum())
    if invalid:
        axes.bar([-0.05], [invalid], width=0.05, color=quality_colors([-1.0]),
                 edgecolor="#333333", linewidth=0.4)
    axes.set_xlim(-0.1 if invalid else 0.0, 1.0)
    axes.set_xlabel("scaled Jacobian", fontsize=7)
    axes.set_title("%d elements, %d invalid" % (len(values), invalid), fontsize=7)
    axes.set_ylabel("elements", fontsize=7)
    axes.tick_params(labelsize=7)
    figure.tight_layout()
