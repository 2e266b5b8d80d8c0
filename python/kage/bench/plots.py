"""The benchmark report's figures, as PNG bytes (kage.bench.report writes them under DIR/report/plots/).

    curves_<pair>.png         per plain pair: success_once of the train-config ("Train", #1f77b4) and
                              eval-config ("Eval", #d62728) evaluations against environment steps, each the
                              per-step mean over the pair's runs with a band of one SEM (alpha 0.18), as the
                              original's plot_all_configs.py draws them (spec 5.6)
    curves_<pair>_return.png  the same for the return
    drop_per_axis.png         the success_once drop per axis (%), the drop of the axis means
    sweep_<sweep>.png         per sweep: eval success_once against the swept value (mean ± SEM over seeds),
                              the train config's value as a dashed line

The curves take every run's evaluation rows, finished or not: at each step the mean is over the runs that
reached it, so an unfinished run stops contributing after its last evaluation; the title then says how many
runs are unfinished. The drop bars have no error bars: the drop is a ratio of two means computed on the same
pairs, whose errors are correlated, and the per-axis table gives each mean's SEM. An undefined drop (train
success 0, or no finished run) is a missing bar marked n/a.

matplotlib is imported when a figure is drawn, and draws through its Agg canvas without pyplot, so no
display or backend setting is involved.
"""
import io
from typing import List, Optional, Sequence, Tuple

TRAIN_COLOUR, EVAL_COLOUR = "#1f77b4", "#d62728"
BAND_ALPHA = 0.18
SIZE, DPI = (4.2, 3.0), 200


def new_figure():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=SIZE)
    FigureCanvasAgg(figure)
    return figure, figure.add_subplot()


def legend(ax) -> None:
    if ax.get_legend_handles_labels()[0]:  # nothing drawn: no legend (and no warning)
        ax.legend(fontsize=8)


def png_bytes(figure) -> bytes:
    out = io.BytesIO()
    figure.savefig(out, format="png", dpi=DPI, bbox_inches="tight")
    return out.getvalue()


def training_curves(title: str, train: Sequence[Tuple[float, dict]], evaluated: Sequence[Tuple[float, dict]],
                    ylabel: str, ylim: Optional[Tuple[float, float]] = None) -> bytes:
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
    return png_bytes(figure)


def drop_per_axis(axes: List[str], drops: List[Optional[float]]) -> bytes:
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
    return png_bytes(figure)


def sweep_response(title: str, names: List[str], evaluated: List[dict], train: dict) -> bytes:
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
    return png_bytes(figure)
