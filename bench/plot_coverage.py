#!/usr/bin/env python3
"""Chart and table of bench/coverage.sh's CSV: coverage of the curves' length per picture for the
raster hand, the explorer hand, and the explorer in grooves mode.

Usage: plot_coverage.py coverage.csv --outdir DIR [--doc docs/PERFORMANCE.md]
Writes DIR/coverage.png; with --doc, the table between <!-- BEGIN coverage --> and <!-- END coverage -->.
"""
import argparse
import csv
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--outdir", default=".")
    ap.add_argument("--doc")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    names = [r["picture"] for r in rows]
    series = [("raster", "raster (one pass)", "#999999"), ("explorer", "explorer, 120 s", "#1f77b4"),
              ("explorer_grooves", "explorer, 120 s, grooves", "#2ca02c")]
    present = [s for s in series if any(r[s[0]] for r in rows)]
    fig, ax = plt.subplots(figsize=(13, 4.8))
    w = 0.8 / len(present)
    for i, (key, label, color) in enumerate(present):
        ys = [100 * float(r[key]) if r[key] else 0 for r in rows]
        ax.bar([x + (i - (len(present) - 1) / 2) * w for x in range(len(rows))], ys, w, label=label, color=color)
    ax.axhline(80, color="red", lw=1, ls="--", label="target 80 %")
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels(names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("curve length within 1 mm of the proxy [%]")
    ax.set_ylim(0, 105)
    ax.set_title("Coverage per picture (summary.json coverage.length_fraction)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.42), ncol=4)
    fig.tight_layout()
    fig.savefig(os.path.join(a.outdir, "coverage.png"), dpi=110)
    if a.doc:
        lines = ["| picture | raster | explorer 120 s | explorer 120 s, grooves |", "|---|---:|---:|---:|"]
        for r in rows:
            g = f"{100 * float(r['explorer_grooves']):.1f} %" if r["explorer_grooves"] else "to be measured"
            lines.append(f"| {r['picture']} | {100 * float(r['raster']):.1f} % | {100 * float(r['explorer']):.1f} % | {g} |")
        n = sum(1 for r in rows if float(r["explorer"]) >= 0.8)
        g80 = sum(1 for r in rows if r["explorer_grooves"] and float(r["explorer_grooves"]) >= 0.8)
        lines.append(f"| **≥ 80 %** | {sum(1 for r in rows if float(r['raster']) >= 0.8)} of {len(rows)} | {n} of {len(rows)} | {g80} of {len(rows)} |")
        doc = open(a.doc).read()
        doc = re.sub(r"(<!-- BEGIN coverage -->\n).*?(\n<!-- END coverage -->)", lambda m: m.group(1) + "\n".join(lines) + m.group(2),
                     doc, flags=re.S)
        open(a.doc, "w").write(doc)


if __name__ == "__main__":
    main()
