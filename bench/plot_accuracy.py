#!/usr/bin/python3
"""Charts of bench_accuracy's JSON (accuracy against size).

    /usr/bin/python3 bench/plot_accuracy.py [docs/bench/accuracy.json] [--outdir docs/bench]

writes
  accuracy.png      error against vertex fraction, one line per method (pseudocoiflet = ours,
                    Douglas-Peucker, uniform arc length, linear (2,2) wavelet); left max deviation
                    (symmetric Hausdorff), right RMS; solid = median over curves, dashed = 90th
                    percentile; one marker per level of our model (the other methods are run at the
                    same vertex count per curve, so their markers sit at the same x except where
                    Douglas-Peucker reaches zero error with fewer vertices).
  box_tightness.png the widest error box half-width of each level against the true max deviation
                    of the level polyline, per curve (left) and as a ratio per level (right).
Needs matplotlib and numpy (Debian's python3-matplotlib).
"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

STYLE = {  # method key -> colour, marker
    "ours": ("#d62728", "o"),
    "dp": ("#1f77b4", "s"),
    "uniform": ("#7f7f7f", "^"),
    "linear22": ("#2ca02c", "D"),
}
# Douglas-Peucker keeps original vertices, so at fine levels it can be exact (error 0), which a log
# axis cannot show: such points are drawn hollow at this floor and labelled.
FLOOR_MM = 3e-3


def percent(x, _pos):
    return f"{100 * x:.3g}%"


def accuracy_chart(doc, out_path):
    labels = {m["key"]: m["label"] for m in doc["methods"]}
    rows = doc["aggregate"]
    n_curves = max(r["curves"] for r in rows)
    n_images = len(doc["images"])
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.6), sharex=True)
    panels = [("max_dev_mm", "max deviation (symmetric Hausdorff) [mm]", "Max deviation from the original curve"),
              ("rms_mm", "RMS deviation [mm]", "RMS deviation from the original curve")]
    for ax, (field, ylabel, title) in zip(axes, panels):
        floored_any = False
        for key in ["ours", "dp", "uniform", "linear22"]:
            mine = sorted((r for r in rows if r["method"] == key), key=lambda r: r["level"])
            if not mine:
                continue
            colour, marker = STYLE[key]
            x = np.array([r["mean_vertex_fraction"] for r in mine])
            med = np.array([r[field]["median"] for r in mine])
            p90 = np.array([r[field]["p90"] for r in mine])
            ax.plot(x, np.maximum(med, FLOOR_MM), "-", color=colour, marker=marker, ms=6, lw=1.8, label=f"{labels[key]}: median")
            ax.plot(x, np.maximum(p90, FLOOR_MM), "--", color=colour, marker=marker, ms=4, lw=1.0, mfc="none", alpha=0.8,
                    label=f"{labels[key]}: 90th percentile")
            zero = med < FLOOR_MM
            if zero.any():
                floored_any = True
                ax.plot(x[zero], np.full(zero.sum(), FLOOR_MM), marker, ms=10, mfc="white", mec=colour, mew=1.5, ls="none")
            if key == "ours":  # level numbers next to our markers
                for r, xi, yi in zip(mine, x, med):
                    ax.annotate(f"L{r['level']}", (xi, max(yi, FLOOR_MM)), textcoords="offset points", xytext=(-4, 8), fontsize=8,
                                color=colour, ha="right")
        if floored_any:
            ax.annotate(f"large hollow squares at {FLOOR_MM:g} mm: Douglas-Peucker exact\n(error 0; it keeps fewer vertices than the others there)",
                        (0.98, 0.97), xycoords="axes fraction", ha="right", va="top", fontsize=8, color=STYLE["dp"][0])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xticks([0.02, 0.05, 0.1, 0.2, 0.5, 1.0])
        ax.xaxis.set_major_formatter(FuncFormatter(percent))
        ax.xaxis.set_minor_formatter(FuncFormatter(lambda *_: ""))
        ax.set_xlabel("vertices kept, fraction of the original pixel chain (mean over curves, log scale)")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.35)
        ax.grid(True, which="minor", alpha=0.12)
    handles, leg_labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, leg_labels, loc="lower center", ncol=4, fontsize=8.5, frameon=False)
    fig.suptitle(f"Accuracy against size: {n_curves} curves from {n_images} pictures, equal vertex counts per curve and level "
                 f"(L0 = level 0, the resampled curve)", fontsize=11)
    fig.tight_layout(rect=(0, 0.1, 1, 0.95))
    fig.savefig(out_path, dpi=130)
    plt.close(fig)


def box_chart(doc, out_path):
    half, dev, level = [], [], []
    for c in doc["curves"]:
        for lv in c["levels"]:
            d = lv["methods"]["ours"]["max_dev_mm"]
            if d < doc["settings"]["hausdorff_tolerance_mm"]:  # straight chain: no meaningful ratio
                continue
            half.append(lv["box_half_width_mm"])
            dev.append(d)
            level.append(lv["level"])
    half, dev, level = np.array(half), np.array(dev), np.array(level)
    levels = sorted(set(level.tolist()))
    cmap = plt.get_cmap("viridis", len(levels))

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.6))
    for i, lv in enumerate(levels):
        sel = level == lv
        ax1.scatter(dev[sel], half[sel], s=9, color=cmap(i), alpha=0.6, label=f"level {lv} ({sel.sum()} curves)")
    lo = min(dev.min(), half.min()) * 0.8
    hi = max(dev.max(), half.max()) * 1.25
    ax1.plot([lo, hi], [lo, hi], "k-", lw=1, label="half-width = deviation")
    ax1.plot([lo, hi], [2 * lo, 2 * hi], "k:", lw=1, label="half-width = 2 × deviation")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_xlim(lo, hi)
    ax1.set_ylim(lo, hi)
    ax1.set_xlabel("true max deviation of the level polyline from the original [mm]")
    ax1.set_ylabel("widest error box half-width at that level [mm]")
    ax1.set_title("Error boxes against the true deviation, per curve and level")
    ax1.grid(True, which="major", alpha=0.35)
    ax1.legend(fontsize=8, loc="upper left", markerscale=2)

    ratios = [half[level == lv] / dev[level == lv] for lv in levels]
    ax2.boxplot(ratios, positions=levels, widths=0.55, whis=(10, 90), showfliers=True,
                flierprops={"marker": ".", "ms": 3, "alpha": 0.5})
    ax2.axhline(1.0, color="k", lw=1)
    for lv, r in zip(levels, ratios):
        below = r < 1
        if below.any():  # the cases where the half-width does not cover the worst point: make them stand out
            ax2.plot(np.full(below.sum(), lv), r[below], "x", color="#d62728", ms=8, mew=2,
                     label="half-width < deviation (overshoot at a corner, along the segment)")
        txt = f"n={len(r)}" + (f", {int(below.sum())} < 1" if below.any() else "")
        ax2.annotate(txt, (lv, 0.98), xycoords=("data", "axes fraction"), ha="center", va="top", fontsize=8)
    if any((r < 1).any() for r in ratios):
        ax2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, 0.93))
    ax2.set_xlabel("level of our model (0 = resampled original)")
    ax2.set_ylabel("box half-width / true max deviation")
    ax2.set_title("Tightness ratio per level (box: quartiles, whiskers: 10th–90th pct)")
    ax2.grid(True, axis="y", alpha=0.35)
    ax2.set_ylim(min(0.85, min(r.min() for r in ratios) * 0.95), max(r.max() for r in ratios) * 1.08)
    fig.suptitle("Collision-tree error boxes (pseudocoiflet model): ratio ≥ 1 means the widest box covers the worst deviation",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(out_path, dpi=130)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", nargs="?", default="docs/bench/accuracy.json")
    ap.add_argument("--outdir", default=None, help="default: the JSON's folder")
    a = ap.parse_args()
    with open(a.json) as f:
        doc = json.load(f)
    outdir = a.outdir or os.path.dirname(os.path.abspath(a.json))
    os.makedirs(outdir, exist_ok=True)
    accuracy_chart(doc, os.path.join(outdir, "accuracy.png"))
    box_chart(doc, os.path.join(outdir, "box_tightness.png"))
    print(f"wrote {os.path.join(outdir, 'accuracy.png')} and {os.path.join(outdir, 'box_tightness.png')}")


if __name__ == "__main__":
    main()
