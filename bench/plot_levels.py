#!/usr/bin/env python3
"""Charts of bench_levels' JSON: levels used against hand speed, and tick time against picture size.

Usage: plot_levels.py levels.json --outdir DIR
Writes DIR/levels_vs_speed.png and DIR/tick_vs_complexity.png.
"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("--outdir", default=".")
    a = ap.parse_args()
    d = json.load(open(a.json))
    pics = d["pictures"]
    edges = pics[0]["speed_bin_edges_m_per_s"]
    mids = [1e3 * (edges[i] + edges[i + 1]) / 2 if i + 2 < len(edges) else 1e3 * edges[i] * 1.5 for i in range(len(edges) - 1)]
    pol = d["policy"]

    fig, ax = plt.subplots(1, 2, figsize=(13, 4.5))
    # Left: share of ticks at each level per speed bin, all pictures (stacked bars).
    levels = len(pics[0]["level_ticks"])
    totals = [sum(sum(p["level_ticks_per_speed_bin"][b]) for p in pics) for b in range(len(edges) - 1)]
    bottom = [0.0] * len(totals)
    labels = [f"{1e3*edges[i]:.0f}–{1e3*edges[i+1]:.0f}" if i + 2 < len(edges) else f"≥{1e3*edges[i]:.0f}" for i in range(len(edges) - 1)]
    cmap = plt.get_cmap("viridis")
    for lv in range(levels):
        share = [100.0 * sum(p["level_ticks_per_speed_bin"][b][lv] for p in pics) / t if t else 0.0 for b, t in enumerate(totals)]
        ax[0].bar(labels, share, bottom=bottom, color=cmap(lv / max(1, levels - 1)), label=f"level {lv}")
        bottom = [x + y for x, y in zip(bottom, share)]
    ax[0].set_xlabel("handle speed [mm/s]")
    ax[0].set_ylabel("ticks at each level [%]")
    ax[0].set_title(f"Level in use against hand speed ({len(pics)} pictures)")
    ax[0].legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    ax[0].tick_params(axis="x", labelsize=7)

    # Right: mean level per speed bin for a few pictures, against the policy's target level (coarsest level
    # whose error bound is under e(v) = e_rest + v·t_blur) for the same pictures.
    for p in pics[:: max(1, len(pics) // 5)][:5]:
        xs, ys = [], []
        for b in range(len(edges) - 1):
            h = p["level_ticks_per_speed_bin"][b]
            n = sum(h)
            if n > 50:
                xs.append(mids[b])
                ys.append(sum(l * c for l, c in enumerate(h)) / n)
        line, = ax[1].plot(xs, ys, "o-", label=p["picture"])
        vs = [v / 1000 for v in range(1, 500, 2)]
        target = []
        for v in vs:
            tol = pol["error_at_rest_m"] + v * pol["blur_time_s"]
            lv = 0
            running = 0.0
            for l, e in enumerate(p["level_error_m"]):
                running = max(running, e)
                if running <= tol:
                    lv = l
            target.append(lv)
        ax[1].plot([1e3 * v for v in vs], target, "--", color=line.get_color(), alpha=0.5)
    ax[1].set_xscale("log")
    ax[1].set_xlabel("handle speed [mm/s]")
    ax[1].set_ylabel("mean level in use (dashed: policy target)")
    ax[1].set_title("Mean level per speed bin")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.outdir, "levels_vs_speed.png"), dpi=110)

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    xs = [p["segments_after_budget"] for p in pics]
    ax.plot(xs, [p["tick_us"]["p50"] for p in pics], "o", label="p50")
    ax.plot(xs, [p["tick_us"]["p99"] for p in pics], "s", label="p99")
    for p in pics:
        ax.annotate(p["picture"].split(".")[0], (p["segments_after_budget"], p["tick_us"]["p99"]), fontsize=6)
    ax.set_xscale("log")
    ax.set_xlabel("level-0 segments in the scene (after the budget)")
    ax.set_ylabel("servo tick work [µs]")
    ax.set_title("Tick time against picture complexity (levels from hand speed)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(a.outdir, "tick_vs_complexity.png"), dpi=110)


if __name__ == "__main__":
    main()
