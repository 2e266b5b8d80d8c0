"""The benchmark report's figures, as PNG bytes (kage.bench.report writes them under DIR/report/plots/).

    curves_<pair>.png         per plain pair: success_once of the train-config ("Train", #1f77b4) and
                              eval-config ("Eval", #d62728) evaluations against environment steps, each the
                              per-step mean over the pair's runs with a band of one SEM (alpha 0.18), as the
                              original's plot_all_configs.py draws them (spec 5.6)
    curves_<pair>_return.png  the same for the return
    drop_per_axis.png         the success_once drop per axis (%), the drop of the axis means
    sweep_<sweep>.png         per sweep: eval success_once against the swept value (mean ± SEM over seeds),
                              the train config's value as a dashed line
    intervals.png             rliable's interval plot: per axis and over all pairs, the IQM of eval success and
                              the success drop (or of --metric), each a bar over its 95 % interval with a tick at
                              the point (kage.bench compare: one bar per method)
    profile_<metric>.png      performance profiles: the fraction of runs whose success_once (or --metric) exceeds
                              each threshold, with a 95 % band; eval (and train, dashed) in the report, eval per
                              method in compare

The curves take every run's evaluation rows, finished or not: at each step the mean is over the runs that
reached it, so an unfinished run stops contributing after its last evaluation; the title then says how many
runs are unfinished. The drop bars have no error bars: the drop is a ratio of two means computed on the same
pairs, whose errors are correlated, and the per-axis table gives each mean's SEM. An undefined drop (train
success 0, or no finished run) is a missing bar marked n/a.

Every function takes `interim`: the line an interim report (--partial) prints in red above the figure.

matplotlib is imported when a figure is drawn, and draws through its Agg canvas without pyplot, so no
display or backend setting is involved.
"""
import io
from typing import Dict, List, Optional, Sequence, Tuple

from kage.fields import SUCCESS_SHOWN

TRAIN_COLOUR, EVAL_COLOUR = "#1f77b4", "#d62728"
METHOD_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f")
BAND_ALPHA = 0.18
SIZE, DPI = (4.2, 3.0), 200


def new_figure(size: Tuple[float, float] = SIZE, columns: int = 1):
    """A figure and its axes: one, or a list of `columns` side by side."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=size)
    FigureCanvasAgg(figure)
    if columns == 1:
        return figure, figure.add_subplot()
    return figure, [figure.add_subplot(1, columns, i + 1) for i in range(columns)]


def legend(ax) -> None:
    if ax.get_legend_handles_labels()[0]:  # nothing drawn: no legend (and no warning)
        ax.legend(fontsize=8)


def png_bytes(figure, interim: Optional[str] = None) -> bytes:
    """The figure as PNG; an interim report's figure says so above everything, in red."""
    if interim:
        figure.text(0.5, 1.0, interim, color="#b00000", ha="center", va="bottom", fontsize=8)
    out = io.BytesIO()
    figure.savefig(out, format="png", dpi=DPI, bbox_inches="tight")
    return out.getvalue()


def training_curves(title: str, train: Sequence[Tuple[float, dict]], evaluated: Sequence[Tuple[float, dict]],
                    ylabel: str, ylim: Optional[Tuple[float, float]] = None, interim: Optional[str] = None) -> bytes:
    """Train and Eval curves from [(global_step, {"mean", "sem", "n"})], steps in millions."""
    figure, ax = new_figure()
    for name, points, colour in (("Train", train, TRAIN_COLOUR), ("Eval", evaluated, EVAL_COLOUR)):
        points = [(step / 1e6, s["mean"], s["sem"]) for step, s in points if s["mean"] is not None]
        if not points:
            continue
        x, mean, sem = zip(*points)
        ax.plot(x, mean, color=colour, label=name, linewidth=1.5)
        ax.fill_between(x, [m - e for m, e in zip(mean, sem)], [m + e for m, e in zip(mean, sem)], color=colour,
                        alpha=BAND_ALPHA, linewidth=0)
    ax.set_xlabel("environment steps (M)")
    ax.set_ylabel(ylabel)
    if ylim:
        ax.set_ylim(*ylim)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    legend(ax)
    return png_bytes(figure, interim)


def drop_per_axis(axes: List[str], drops: List[Optional[float]], interim: Optional[str] = None) -> bytes:
    """One bar per axis: the success_once drop in percent; None is a missing bar marked n/a."""
    figure, ax = new_figure()
    positions = range(len(axes))
    ax.bar([i for i in positions if drops[i] is not None], [d for d in drops if d is not None], color=EVAL_COLOUR)
    for i, drop in zip(positions, drops):
        text = "n/a" if drop is None else f"{drop:.1f}"
        ax.annotate(text, (i, drop or 0.0), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=8)
    ax.axhline(0, color="black", linewidth=0.8)
    ax.set_xticks(list(positions), axes, rotation=30, ha="right")
    ax.set_ylabel("success drop (%)")
    ax.set_title("success_once drop per axis, 100 (train - eval) / train", fontsize=10)
    if None in drops:
        ax.set_xlabel("n/a: train success 0, or no finished run", fontsize=8)
    return png_bytes(figure, interim)


def sweep_response(title: str, names: List[str], evaluated: List[dict], train: dict,
                   interim: Optional[str] = None) -> bytes:
    """Eval success_once ({"mean", "sem"} per eval config) against the swept value: float(name) where every
    name is a number, else the names in order; the train config's value as a dashed line with its SEM band."""
    figure, ax = new_figure()
    try:
        x = [float(n) for n in names]
    except ValueError:
        x = list(range(len(names)))
        ax.set_xticks(x, names, rotation=30, ha="right", fontsize=7)
    points = [(xi, s["mean"], s["sem"]) for xi, s in zip(x, evaluated) if s["mean"] is not None]
    if points:
        px, mean, sem = zip(*points)
        ax.errorbar(px, mean, yerr=sem, color=EVAL_COLOUR, marker="o", capsize=3, label="Eval")
    if train["mean"] is not None:
        ax.axhline(train["mean"], color=TRAIN_COLOUR, linestyle="--", label="Train config")
        ax.axhspan(train["mean"] - train["sem"], train["mean"] + train["sem"], color=TRAIN_COLOUR, alpha=BAND_ALPHA,
                   linewidth=0)
    ax.set_ylim(0, 1.1)
    ax.set_xlabel("eval config")
    ax.set_ylabel("success rate (success_once)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    legend(ax)
    return png_bytes(figure, interim)


def interval_estimates(methods: Dict[str, List[dict]], metric: str = SUCCESS_SHOWN,
                       interim: Optional[str] = None) -> bytes:
    """Per row of kage.bench.intervals (the axes, then all pairs), a bar over each method's 95 % interval and a
    black tick at its point: the IQM of eval `metric` on the left, its drop (%) on the right. `methods` maps a
    name ("" for the report's one method) to its rows, the same rows in the same order for every method."""
    names = [r["name"] for r in next(iter(methods.values()))]
    figure, panels = new_figure((8.4, 1.2 + 0.42 * len(names) * max(1, len(methods) / 2)), columns=2)
    height = 0.8 / len(methods)
    for panel, key, xlabel in ((panels[0], "eval_iqm", f"IQM of eval {metric}"),
                               (panels[1], "drop_pct", f"{metric} drop (%)")):
        for i, (method, rows) in enumerate(methods.items()):
            colour = METHOD_COLOURS[i % len(METHOD_COLOURS)]
            for y, row in enumerate(rows):
                estimate, centre = row[key], y + (i - (len(methods) - 1) / 2) * height
                if estimate is None or estimate["point"] is None:
                    continue
                if estimate["low"] is not None:
                    panel.barh(centre, estimate["high"] - estimate["low"], left=estimate["low"], height=0.85 * height,
                               color=colour, alpha=0.75, label=method if method and y == 0 else None)
                panel.plot([estimate["point"]] * 2, [centre - 0.42 * height, centre + 0.42 * height], color="black",
                           linewidth=1.5)
        panel.set_yticks(range(len(names)), names if panel is panels[0] else [""] * len(names))
        panel.set_ylim(len(names) - 0.5, -0.5)
        panel.set_xlabel(xlabel)
        panel.grid(axis="x", alpha=0.3)
    shown = [r["eval_iqm"] for rows in methods.values() for r in rows if r["eval_iqm"]]
    panels[0].set_xlim(min([-0.02] + [e["low"] for e in shown]), max([1.02] + [e["high"] for e in shown]))
    panels[1].axvline(0, color="black", linewidth=0.8)
    figure.suptitle("95 % bootstrap intervals (bars) and point estimates (ticks)", fontsize=10)
    legend(panels[0])
    return png_bytes(figure, interim)


def performance_profiles(taus: Sequence[float], curves: Dict[str, dict], dashed: Sequence[str] = (),
                         metric: str = SUCCESS_SHOWN, interim: Optional[str] = None) -> bytes:
    """Per curve ({"point", "low", "high"} per threshold), the fraction of runs whose `metric` exceeds each
    threshold tau, with its 95 % band; the curves named in `dashed` drawn dashed."""
    figure, ax = new_figure()
    for i, (name, curve) in enumerate(curves.items()):
        colour = {"eval": EVAL_COLOUR, "train": TRAIN_COLOUR}.get(name, METHOD_COLOURS[i % len(METHOD_COLOURS)])
        ax.plot(taus, curve["point"], color=colour, label=name, linewidth=1.5,
                linestyle="--" if name in dashed else "-")
        ax.fill_between(taus, curve["low"], curve["high"], color=colour, alpha=BAND_ALPHA, linewidth=0)
    ax.set_xlabel(f"{metric} threshold τ")
    ax.set_ylabel(f"fraction of runs with {metric} > τ")
    ax.set_ylim(0, 1.05)
    ax.set_title(f"performance profile of {metric} (95 % bands)", fontsize=10)
    ax.grid(alpha=0.3)
    legend(ax)
    return png_bytes(figure, interim)
