"""What a reader sees on a matplotlib Figure, for the figure tests (test_figures.py,
test_figures_more.py): its words by place, texts cut off at its edge, markers and their limits,
the data a legend covers, the tick labels of an axis."""
import numpy as np
from matplotlib.axes import Axes


def _texts(fig) -> dict:
    """The words a reader sees on a figure or one of its axes, by place: 'labels' (axis labels,
    titles, colour bar labels), 'legend' (entries and titles), 'notes' (texts on the axes and
    on the figure)."""
    out = {"labels": [], "legend": [], "notes": []}
    if isinstance(fig, Axes):
        fig, axes = fig.figure, [fig]
    else:
        axes = fig.axes
    for ax in axes:
        out["labels"] += [ax.xaxis.label, ax.yaxis.label, ax.title]
        out["notes"] += ax.texts
        if ax.get_legend():
            out["legend"] += [*ax.get_legend().get_texts(), ax.get_legend().get_title()]
    if axes == fig.axes:
        for leg in fig.legends:
            out["legend"] += [*leg.get_texts(), leg.get_title()]
        out["labels"] += [t for t in (fig._suptitle, fig._supylabel) if t is not None]
        out["notes"] += fig.texts
    return {k: [t for t in v if t.get_visible() and t.get_text()] for k, v in out.items()}


def _words(fig, where=("labels", "legend", "notes")) -> str:
    return " | ".join(t.get_text() for k in where for t in _texts(fig)[k])


def _renderer(fig):
    """The figure's renderer after one draw (layout done); a figure is drawn once."""
    if not getattr(fig, "_figtools_drawn", False):
        fig.draw_without_rendering()
        fig._figtools_drawn = True
    return fig._get_renderer()


def _cut_off(fig) -> list:
    """The labels, titles, legend entries, notes and tick labels that reach past the figure's
    edge."""
    r = _renderer(fig)
    w, h = fig.bbox.width, fig.bbox.height
    ticks = [t for ax in fig.axes for axis in (ax.xaxis, ax.yaxis)
             for tick in axis.get_major_ticks() if _shown(axis, tick.get_loc())
             for t in (tick.label1, tick.label2) if t.get_visible() and t.get_text()]
    return [t.get_text() for ts in [*_texts(fig).values(), ticks] for t in ts
            if not (lambda b: b.x0 >= -1 and b.y0 >= -1 and b.x1 <= w + 1 and b.y1 <= h + 1)(
                t.get_window_extent(r))]


def _points(ax) -> np.ndarray:
    """The (x, y) of every marker of the axes' scatter collections."""
    offs = [c.get_offsets() for c in ax.collections if hasattr(c, "get_offsets")
            and len(c.get_offsets())]
    return np.vstack(offs) if offs else np.empty((0, 2))


def _inside(ax, x, y):
    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
    x, y = np.asarray(x, float), np.asarray(y, float)
    return bool((x0 <= x.min()) & (x.max() <= x1) & (y0 <= y.min()) & (y.max() <= y1))


def _markers(ax, lines=False) -> np.ndarray:
    """The (x, y) data of every marker the axes draw: lines with a marker, scatter points;
    with `lines`, every point of every line too."""
    xy = [np.c_[ln.get_xdata(), ln.get_ydata()] for ln in ax.get_lines()
          if ln.get_visible() and (lines or ln.get_marker() not in (None, "", " ", "None"))]
    return np.vstack([np.empty((0, 2)), *xy, _points(ax)]).astype(float)


def _covered(ax, legend=None, lines=False) -> list:
    """What the legend (the axes' own, or a figure legend) covers on the axes: the (x, y) of
    markers (with `lines`: of every line's points) and the bars (patches) within its box."""
    r = _renderer(ax.figure)
    box = (legend or ax.get_legend()).get_window_extent(r)
    xy = _markers(ax, lines)
    hits = [tuple(p) for p, d in zip(xy, ax.transData.transform(xy)) if box.contains(*d)]
    return hits + [p for p in ax.patches if p.get_visible() and
                   p.get_window_extent(r).overlaps(box)]


def _notes_over_data(fig) -> list:
    """The notes (boxed texts of an axes) whose box covers a plotted point of any axes of the
    figure: a marker or a point of a line within the axes' limits, or a colour map."""
    r = _renderer(fig)
    out = []
    for note in (t for ax in fig.axes for t in ax.texts if t.get_bbox_patch() is not None):
        box = note.get_bbox_patch().get_window_extent(r)
        for ax in fig.axes:
            xy = _markers(ax, lines=True)
            (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
            xy = xy[(x0 <= xy[:, 0]) & (xy[:, 0] <= x1) & (y0 <= xy[:, 1]) & (xy[:, 1] <= y1)]
            shown = ax.transData.transform(xy) if len(xy) else np.empty((0, 2))
            if any(box.contains(*d) for d in shown) or any(
                    im.get_window_extent(r).overlaps(box) for im in ax.get_images()):
                out.append(note.get_text())
                break
    return out


def _shown(axis, v) -> bool:
    lo, hi = sorted(axis.get_view_interval())
    return lo <= v <= hi


def _visible_ticks(axis) -> list:
    """The tick values an axis shows (within its limits)."""
    return [v for v in axis.get_majorticklocs() if _shown(axis, v)]


def _crowded(fig) -> list:
    """The tick labels (major and minor) of an axis that overlap one another or the axis'
    label, as pairs of texts."""
    r = _renderer(fig)
    out = []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            texts = [t for tick in axis.get_major_ticks() + axis.get_minor_ticks()
                     if _shown(axis, tick.get_loc())
                     for t in (tick.label1, tick.label2) if t.get_visible() and t.get_text()]
            texts += [axis.label] if axis.label.get_visible() and axis.label.get_text() else []
            boxes = [(t.get_text(), t.get_window_extent(r)) for t in texts]
            out += [(a, b) for i, (a, box) in enumerate(boxes) for b, other in boxes[i + 1:]
                    if box.overlaps(other)]
    return out


def _legend_over_words(fig) -> list:
    """The legends (the axes' and the figure's) that overlap a title, an axis label or the
    figure's title, as (legend's first entry, the text)."""
    r = _renderer(fig)
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()] + list(fig.legends)
    words = _texts(fig)["labels"]
    return [(leg.get_texts()[0].get_text(), t.get_text()) for leg in legends for t in words
            if leg.get_window_extent(r).overlaps(t.get_window_extent(r))]
