"""The perception experiment's figure (``rough experiment analyze --plot``): the
percentage of answers that judged each test surface rougher than its reference, with
the Wilson score interval of each proportion
(:func:`rough.experiment.proportion_interval`).
"""

import math

import numpy as np

from ..experiment.analysis import percentages, proportion_interval
from .common import pyplot, styled


@styled
def percentage_figure(study, set_ids, title=None):
    """For each reference set, the percentage of answers that judged each test surface
    rougher than the reference, grouped by Rq and coloured by D (the paper's Figures
    4 and 5), each bar with its number of answers n and the 95 % Wilson score
    interval of the proportion as an error bar. ``title``: e.g. the study's name."""
    plt = pyplot()
    figure, axes = plt.subplots(1, len(set_ids), figsize=(5.5 * len(set_ids), 4.6), squeeze=False)
    for axis, set_id in zip(axes[0], set_ids):
        cells = percentages(study, set_id)
        entry = next(s for s in study.sets if s["id"] == set_id)
        reference = study.surfaces[entry["reference"]]
        levels_rq = sorted({round(rq, 12) for _, _, rq, _, _ in cells} | {round(reference["rq"], 12)})
        levels_d = sorted({d for _, d, _, _, _ in cells} | {reference["dimension"]})
        width = 0.8 / len(levels_d)
        colours = plt.get_cmap("viridis")(np.linspace(0.15, 0.85, len(levels_d)))
        for k, dimension in enumerate(levels_d):
            label = f"D = {dimension:g}"
            for g, rq in enumerate(levels_rq):
                cell = next(
                    (c for c in cells if math.isclose(c[1], dimension) and math.isclose(c[2], rq, rel_tol=1e-6)), None
                )
                if cell is None:
                    continue
                x = g + (k - (len(levels_d) - 1) / 2) * width
                percent, answers = cell[3], cell[4]
                if not answers:
                    axis.text(x, 1, "n = 0", ha="center", va="bottom", fontsize=6.5, color="0.4")
                    continue
                axis.bar(x, percent, width, color=colours[k], label=label)
                low, high = (100 * p for p in proportion_interval(round(percent * answers / 100), answers))
                axis.errorbar(
                    x,
                    percent,
                    yerr=[[max(0.0, percent - low)], [max(0.0, high - percent)]],
                    fmt="none",
                    ecolor="0.2",
                    elinewidth=0.8,
                    capsize=2,
                )
                axis.text(x, high + 1.5, f"{percent:.0f} %\nn = {answers}", ha="center", va="bottom", fontsize=6.5)
                label = None
        axis.axhline(50, color="0.5", lw=0.8, ls="--")
        axis.set_xticks(range(len(levels_rq)), [f"Rq {rq * 1e3:.4g} mm" for rq in levels_rq])
        axis.set_ylim(0, 128)
        axis.set_yticks(range(0, 101, 20))
        axis.grid(False, axis="x")
        axis.set_ylabel("judged rougher than the reference (%)")
        axis.set_title(
            f"set {set_id}: reference D = {reference['dimension']:g}, Rq = {reference['rq'] * 1e3:.4g} mm\n"
            "bars: 95 % Wilson interval; n: answers",
            fontsize=9,
        )
        handles, labels = axis.get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        axis.legend(unique.values(), unique.keys(), loc="upper left", ncols=len(unique))
    if title:
        figure.suptitle(title)
    return figure
