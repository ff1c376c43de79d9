#!/usr/bin/env python3
"""Charts and tables from the benchmark outputs in docs/bench.

Reads first_hit.json and scene_build.json (Google Benchmark JSON) and anytime.json, writes
first_hit_vs_size.png, speed_accuracy.png, anytime.png, scene_build.png, and the Markdown tables
between the BEGIN/END markers of docs/PERFORMANCE.md.
"""
import json
import os
import re
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BENCH = sys.argv[1] if len(sys.argv) > 1 else "docs/bench"
PERF = sys.argv[2] if len(sys.argv) > 2 else "docs/PERFORMANCE.md"
COLORS = {"ours": "tab:blue", "ours_wide": "tab:purple", "rtree": "tab:orange", "embree": "tab:red", "brute": "tab:gray", "opencv": "tab:green"}
# ours: first_hit (boundary section) and closest_point; ours_wide: first_hit_wide (the wide index alone; first hits only).
METHODS = ["ours", "ours_wide", "rtree", "embree", "brute"]


def load_gbench(name):
    path = os.path.join(BENCH, name)
    if not os.path.exists(path):
        return []
    rows = json.load(open(path))["benchmarks"]
    return [r for r in rows if r.get("run_type", "iteration") == "iteration"]


def load_json(name):
    """A JSON file of the bench folder, or None when that bench has not run."""
    path = os.path.join(BENCH, name)
    return json.load(open(path)) if os.path.exists(path) else None


TOLERANCE_CUT = load_json("tolerance_cut.json")


def ns(r):
    """Mean per-iteration time in ns whatever the benchmark's unit."""
    scale = {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[r.get("time_unit", "ns")]
    return r["real_time"] * scale


def replace_block(text, key, block):
    pattern = re.compile(r"(<!-- BEGIN %s -->\n).*?(<!-- END %s -->)" % (key, key), re.S)
    if not pattern.search(text):
        return text + "\n<!-- BEGIN %s -->\n%s\n<!-- END %s -->\n" % (key, block, key)
    return pattern.sub(lambda m: m.group(1) + block + "\n" + m.group(2), text)


tables = {}
fh = load_gbench("first_hit.json")

# 1. First hit and closest point against scene size.
size_rows = defaultdict(dict)
for r in fh:
    m = re.match(r"BM_(FirstHit|Closest)/(\w+)/(\d+)/manual_time", r["name"])
    if m:
        size_rows[(m.group(1), int(m.group(3)))][m.group(2)] = r
# The first-hit methods side by side, round by round (BM_FirstHitPaired/<segments>; absent in older runs): each
# method at its best round (fastest block, lowest p99), the ratios of those.
paired_fh = {}
for r in fh:
    m = re.match(r"BM_FirstHitPaired/(\d+)", r["name"])
    if m:
        paired_fh[int(m.group(1))] = r
if size_rows:
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for ax, kind in zip(axes, ["FirstHit", "Closest"]):
        for method in METHODS:
            pts = sorted((n, rows[method]) for (k, n), rows in size_rows.items() if k == kind and method in rows)
            if not pts:
                continue
            xs = [p[0] for p in pts]
            ax.plot(xs, [ns(p[1]) for p in pts], "o-", color=COLORS[method], label=f"{method} mean")
            ax.plot(xs, [p[1]["p99_ns"] for p in pts], "s--", color=COLORS[method], alpha=0.6, label=f"{method} p99")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("segments in the scene (level 0)")
        ax.set_ylabel("time per query [ns]")
        ax.set_title({"FirstHit": "First hit of the handle's sweep", "Closest": "Closest point"}[kind])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Servo queries against peers, tiled scenes from real pictures, random-walk hand at 1 kHz")
    fig.tight_layout()
    fig.savefig(os.path.join(BENCH, "first_hit_vs_size.png"), dpi=110)
    def versus(r, peer):
        """'2.10x faster' or '1.30x slower': ours against a peer, by mean."""
        if peer is None:
            return ""
        return "%.2fx faster" % (ns(peer) / ns(r)) if ns(r) < ns(peer) else "%.2fx slower" % (ns(r) / ns(peer))

    lines = ["| query | segments | method | mean ns | p50 ns | p99 ns | max ns | build ms | bytes/segment | ours vs rtree (mean) | ours vs embree (mean) | ours p99 / rtree p99 |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for (kind, n) in sorted(size_rows):
        rows = size_rows[(kind, n)]
        for method in METHODS:
            if method not in rows:
                continue
            r = rows[method]
            vs_r = vs_e = p99_ratio = ""
            if method in ("ours", "ours_wide"):
                vs_r, vs_e = versus(r, rows.get("rtree")), versus(r, rows.get("embree"))
                if "rtree" in rows:
                    p99_ratio = "%.2f" % (r["p99_ns"] / rows["rtree"]["p99_ns"])
            lines.append("| %s | %d | %s | %.0f | %.0f | %.0f | %.0f | %s | %s | %s | %s | %s |" % (
                kind, n, method, ns(r), r["p50_ns"], r["p99_ns"], r["max_ns"],
                "%.1f" % r["build_ms"] if "build_ms" in r else "", "%.0f" % r["bytes_per_segment"] if "bytes_per_segment" in r else "",
                vs_r, vs_e, p99_ratio))
    tables["first_hit"] = "\n".join(lines)

# 2. Pictures: the explore sweeps.
pic = defaultdict(dict)
for r in fh:
    m = re.match(r"BM_Picture/(\w+)/(.+)/manual_time", r["name"])
    if m:
        pic[m.group(2)][m.group(1)] = r
if pic:
    lines = ["| picture | segments | ours mean / p99 ns | ours_wide mean / p99 ns | rtree mean / p99 ns | embree mean / p99 ns | brute mean / p99 ns |", "|---|---|---|---|---|---|---|"]
    for name in sorted(pic):
        rows = pic[name]
        cell = lambda m: "%.0f / %.0f" % (ns(rows[m]), rows[m]["p99_ns"]) if m in rows else ""
        lines.append("| %s | %d | %s | %s | %s | %s | %s |" % (name, rows["ours"]["segments"], cell("ours"), cell("ours_wide"), cell("rtree"), cell("embree"), cell("brute")))
    tables["pictures"] = "\n".join(lines)

# 3. Speed against accuracy: per method and level, p99 over four pictures against max deviation.
def accuracy_per_vertex(ax, lvl, lines):
    """Right panel: vertices against max deviation on the same four pictures, for our levels, the
    tolerance cut (tolerance_cut.json: the joined cut's vertices and its measured error), each
    curve at its own coarsest level within the target (what level_mode = "tolerance" renders) and
    Douglas-Peucker at the same targets (the left panel has the cut's queries on the time axis). A level's vertices are counted as its segments plus one per curve (the
    open curves' last vertex; an upper bound). Appends the cut's rows to the table `lines`."""
    names = ("horse", "camera", "fruits", "sudoku")
    tc_rows = [r for r in TOLERANCE_CUT["rows"] if r["picture"] in names] if TOLERANCE_CUT else []
    curves = sum({r["picture"]: r["curves"] for r in tc_rows}.values())
    ours = [(sum(r["segments"] for r in lvl["ours"][level]) + curves, max(r["max_error_mm"] for r in lvl["ours"][level]), level)
            for level in sorted(lvl["ours"])]
    ax.plot([p[0] for p in ours], [p[1] for p in ours], "o-", color=COLORS["ours"], label="ours, levels")
    for p in ours:
        ax.annotate("L%d" % p[2], (p[0], p[1]), textcoords="offset points", xytext=(4, 3), fontsize=7, color=COLORS["ours"])
    by_tol = defaultdict(list)
    for r in tc_rows:
        by_tol[r["tolerance_mm"]].append(r)
    cut, dp, per_curve = [], [], []
    for tol in sorted(by_tol):
        rows = by_tol[tol]
        if len(rows) != len(names):
            continue
        if all("curve_levels_vertices" in r for r in rows):
            per_curve.append((sum(r["curve_levels_vertices"] for r in rows), max(r["curve_levels_error_mm"] for r in rows), tol))
        cut.append((sum(r["cut_vertices"] for r in rows), max(r["cut_error_mm"] for r in rows), tol))
        dp.append((sum(r["dp_vertices"] for r in rows), max(r["dp_error_mm"] for r in rows), tol))
        lines.append("| tolerance cut at %.1f mm, joined, its tolerance searched per curve (bench_tolerance_cut) | — | — | %.3f | %d vertices (DP: %d at %.3f mm) |" % (
            tol, cut[-1][1], cut[-1][0], dp[-1][0], dp[-1][1]))
    if cut:
        ax.plot([p[0] for p in cut], [p[1] for p in cut], "s--", color="tab:cyan", label="ours, tolerance cut")
        ax.plot([p[0] for p in dp], [p[1] for p in dp], "^:", color="black", label="Douglas–Peucker")
        for p in cut:
            ax.annotate("%.1f mm" % p[2], (p[0], p[1]), textcoords="offset points", xytext=(4, -9), fontsize=7, color="tab:cyan")
    if per_curve:
        ax.plot([p[0] for p in per_curve], [p[1] for p in per_curve], "d-.", color="tab:olive", label="ours, each curve at its level within T")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("vertices, sum over the four pictures")
    ax.set_ylabel("max deviation from the original curve [mm]")
    ax.set_title("Accuracy per vertex: levels, tolerance cut, Douglas–Peucker")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()

lvl = defaultdict(lambda: defaultdict(list))
cuts = defaultdict(lambda: defaultdict(list))  # method -> tolerance step -> rows (BM_Cut: queries at the tolerance cut)
for r in fh:
    m = re.match(r"BM_Level/(\w+)/(\d+)/(\w+)/manual_time", r["name"])
    if m:
        lvl[m.group(1)][int(m.group(2))].append(r)
    m = re.match(r"BM_Cut/(\w+)/(\d+)/(\w+)/manual_time", r["name"])
    if m:
        cuts[m.group(1)][int(m.group(2))].append(r)
if lvl:
    fig, (ax, ax_v) = plt.subplots(1, 2, figsize=(14, 5))
    lines = ["| method | level | p99 ns (mean of 4 pictures) | max deviation mm (max of 4) | segments (sum) |", "|---|---|---|---|---|"]
    for method in [m for m in METHODS if lvl[m]]:
        pts = []
        for level in sorted(lvl[method]):
            rows = lvl[method][level]
            p99 = sum(r["p99_ns"] for r in rows) / len(rows)
            err = max(r["max_error_mm"] for r in rows)
            pts.append((p99, err, level))
            lines.append("| %s | %d | %.0f | %.3f | %d |" % (method, level, p99, err, sum(r["segments"] for r in rows)))
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=COLORS[method], label=method)
        for p in pts:
            ax.annotate("L%d" % p[2], (p[0], p[1]), textcoords="offset points", xytext=(4, 3), fontsize=7, color=COLORS[method])
    # Queries at the tolerance cut (ours: first_hit at the cut's level id; the peers over the cut's joined pieces): a point per
    # step, its measured error on the y axis as for the levels.
    for method in [m for m in METHODS if cuts[m]]:
        pts = []
        for step in sorted(cuts[method]):
            rows = cuts[method][step]
            if len(rows) != 4:
                continue
            p99 = sum(r["p99_ns"] for r in rows) / len(rows)
            err = max(r["max_error_mm"] for r in rows)
            tol = rows[0]["tolerance_mm"]
            pts.append((p99, err, tol))
            lines.append("| %s, tolerance cut | T = %.2f mm | %.0f | %.3f | %d |" % (method, tol, p99, err, sum(r["segments"] for r in rows)))
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "s--", color=COLORS[method], alpha=0.7, label=method + ", tolerance cut")
        for p in pts:
            ax.annotate("%.2g mm" % p[2], (p[0], p[1]), textcoords="offset points", xytext=(4, -9), fontsize=6, color=COLORS[method])
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("query time per tick, p99 [ns]")
    ax.set_ylabel("max deviation of the level from the original curve [mm]")
    ax.set_title("Speed against accuracy (horse, camera, fruits, sudoku; explore sweeps)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    accuracy_per_vertex(ax_v, lvl, lines)
    fig.tight_layout()
    fig.savefig(os.path.join(BENCH, "speed_accuracy.png"), dpi=110)
    tables["speed_accuracy"] = "\n".join(lines)

# 4. Anytime.
any_path = os.path.join(BENCH, "anytime.json")
if os.path.exists(any_path):
    data = json.load(open(any_path))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    lines = ["| scene | box-test budget | answered exactly | mean level reached | mean error mm | p99 ns | ns per box test |", "|---|---|---|---|---|---|---|"]
    for sc in data:
        rows = [r for r in sc["rows"] if r["box_budget"] > 0]
        xs = [r["box_budget"] for r in rows]
        axes[0].plot(xs, [r["exact_fraction"] for r in rows], "o-", label="%s (%d segments)" % (sc["scene"], sc["segments"]))
        axes[1].plot(xs, [max(r["mean_error_mm"], 1e-4) for r in rows], "o-", label=sc["scene"])
        for r in sc["rows"]:
            lines.append("| %s | %s | %.3f | %.2f | %.3f | %.0f | %.1f |" % (sc["scene"], "none" if r["box_budget"] == 0 else "%d" % r["box_budget"],
                                                                             r["exact_fraction"], r["mean_level"], r["mean_error_mm"], r["p99_ns"],
                                                                             r["ns_per_box_test"]))
    axes[0].set_ylabel("fraction answered exactly at level 0")
    axes[1].set_ylabel("mean error of the level reached [mm]")
    axes[1].set_yscale("log")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel("box-test budget [box tests]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Anytime collision query from a cold boundary section")
    fig.tight_layout()
    fig.savefig(os.path.join(BENCH, "anytime.png"), dpi=110)
    tables["anytime"] = "\n".join(lines)

# 5. Scene build against OpenCV.
sb = defaultdict(dict)
# With --benchmark_repetitions (bench.sh runs 5), each picture and method has several
# runs: the fastest is kept, the run least disturbed by the shared machine (its counters with it).
# BM_SceneBuildPaired/<picture> runs the three side by side and gives each one's fastest single build
# [ms] (absent in older runs); over repetitions, the fastest of each.
PAIRED = ("ours", "opencv", "opencv_same_edges")
paired = defaultdict(dict)
for r in load_gbench("scene_build.json"):
    m = re.match(r"BM_SceneBuild/(\w+)/(.+)", r["name"])
    if m and (m.group(1) not in sb[m.group(2)] or ns(r) < ns(sb[m.group(2)][m.group(1)])):
        sb[m.group(2)][m.group(1)] = r
    m = re.match(r"BM_SceneBuildPaired/(.+)", r["name"])
    if m and all(k + "_fastest_ms" in r for k in PAIRED):
        for k in PAIRED:
            paired[m.group(1)][k] = min(paired[m.group(1)].get(k, float("inf")), r[k + "_fastest_ms"])
if sb:
    names = sorted(sb)
    ratios = [ns(sb[n]["ours"]) / ns(sb[n]["opencv"]) for n in names]
    # OpenCV given the thresholds ours chose, so that both find the same edges (absent in older runs).
    same = [ns(sb[n]["ours"]) / ns(sb[n]["opencv_same_edges"]) if "opencv_same_edges" in sb[n] else float("nan") for n in names]
    fig, ax = plt.subplots(figsize=(11, 4.5))
    x = list(range(len(names)))
    ax.bar([i - 0.2 for i in x], ratios, width=0.4, color="tab:blue", label="OpenCV with Canny 50/150")
    ax.bar([i + 0.2 for i in x], same, width=0.4, color="tab:orange", label="OpenCV with our thresholds (same edges)")
    ax.axhline(1.5, color="k", ls="--", label="target: every picture ≤ 1.5x")
    ax.axhline(1.2, color="k", ls=":", label="target: median ≤ 1.2x")
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("our build time / OpenCV blur+Canny+findContours")
    ax.set_title("Picture → collision trees, against OpenCV's own contour extraction (same grey image)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(BENCH, "scene_build.png"), dpi=110)
    # Phases (bench_scene_build's counters, mean ms per build; absent in older runs): ours' edges + linking,
    # the part OpenCV's pipeline also does, against OpenCV's blur + Canny + findContours with our thresholds;
    # and ours' model, which OpenCV has no counterpart for (chains to curves in metres, multiresolution, trees).
    # The last two columns: each one's fastest single build with the three run side by side (BM_SceneBuildPaired).
    lines = ["| picture | ours ms | OpenCV ms | ratio | OpenCV, our thresholds ms | ratio | ours: edges + linking ms | ours: curves + multires + trees ms "
             "| side by side, fastest: ratio | same edges: ratio |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for n, q, q2 in zip(names, ratios, same):
        t2 = "%.2f" % (ns(sb[n]["opencv_same_edges"]) / 1e6) if "opencv_same_edges" in sb[n] else ""
        o = sb[n]["ours"]
        front = "%.2f" % (o["edges_ms"] + o["linking_ms"]) if "edges_ms" in o else ""
        model = "%.2f" % (o["curves_ms"] + o["multires_ms"] + o["tree_ms"]) if "tree_ms" in o else ""
        pr = paired.get(n)
        side = ("%.2f | %.2f" % (pr["ours"] / pr["opencv"], pr["ours"] / pr["opencv_same_edges"])) if pr else " | "
        lines.append("| %s | %.2f | %.2f | %.2f | %s | %.2f | %s | %s | %s |" % (n, ns(o) / 1e6, ns(sb[n]["opencv"]) / 1e6, q, t2, q2, front, model, side))
    tables["scene_build"] = "\n".join(lines)

# 6. The performance targets, each with this run's figures (first_hit.json, scene_build.json, accuracy.json,
#    tolerance_cut.json, servo_tick.json).
def median(xs):
    xs = sorted(xs)
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


if size_rows:
    rows2 = ["| target | figures in this run | met |", "|---|---|---|"]

    def ratio_cells(kind, sizes, f):
        return [(n, f(size_rows[(kind, n)])) for n in sizes if (kind, n) in size_rows and all(m in size_rows[(kind, n)] for m in ("ours", "rtree", "embree"))]

    big = [10 ** 5, 10 ** 6]
    def wide_cells(f):
        return [(n, f(size_rows[("FirstHit", n)])) for n in big if ("FirstHit", n) in size_rows and "ours_wide" in size_rows[("FirstHit", n)]]

    fh_mean = ratio_cells("FirstHit", big, lambda r: ns(r["rtree"]) / ns(r["ours"]))
    fh_p99 = ratio_cells("FirstHit", big, lambda r: r["ours"]["p99_ns"] / r["rtree"]["p99_ns"])
    fh_emb = ratio_cells("FirstHit", big, lambda r: ns(r["embree"]) / ns(r["ours"]))
    fw_mean = wide_cells(lambda r: ns(r["rtree"]) / ns(r["ours_wide"]))
    fw_p99 = wide_cells(lambda r: r["ours_wide"]["p99_ns"] / r["rtree"]["p99_ns"])
    fw_emb = wide_cells(lambda r: ns(r["embree"]) / ns(r["ours_wide"]))
    cp_mean = ratio_cells("Closest", big, lambda r: ns(r["rtree"]) / ns(r["ours"]))
    cp_p99 = ratio_cells("Closest", big, lambda r: r["ours"]["p99_ns"] / r["rtree"]["p99_ns"])
    # The same ratios from the batch means (blocks of queries timed as a whole, no clock read per query;
    # absent in older runs).
    bm = lambda r: r.get("batch_mean_ns", float("nan"))
    has_batch = all("batch_mean_ns" in r[m] for r in size_rows.values() for m in ("ours", "rtree", "embree") if m in r)
    fh_mean_b = ratio_cells("FirstHit", big, lambda r: bm(r["rtree"]) / bm(r["ours"])) if has_batch else []
    fw_mean_b = wide_cells(lambda r: bm(r["rtree"]) / bm(r["ours_wide"])) if has_batch else []
    fh_emb_b = ratio_cells("FirstHit", big, lambda r: bm(r["embree"]) / bm(r["ours"])) if has_batch else []
    fw_emb_b = wide_cells(lambda r: bm(r["embree"]) / bm(r["ours_wide"])) if has_batch else []
    cp_mean_b = ratio_cells("Closest", big, lambda r: bm(r["rtree"]) / bm(r["ours"])) if has_batch else []
    # And from the per-query means less the clock's own cost, measured in the same benchmark (net_mean_ns;
    # absent in older runs): the same timed queries as the percentiles, without the two clock reads.
    nm = lambda r: r.get("net_mean_ns", float("nan"))
    has_net = all("net_mean_ns" in r[m] for r in size_rows.values() for m in ("ours", "rtree", "embree") if m in r)
    fh_mean_n = ratio_cells("FirstHit", big, lambda r: nm(r["rtree"]) / nm(r["ours"])) if has_net else []
    fw_mean_n = wide_cells(lambda r: nm(r["rtree"]) / nm(r["ours_wide"])) if has_net else []
    cp_mean_n = ratio_cells("Closest", big, lambda r: nm(r["rtree"]) / nm(r["ours"])) if has_net else []
    clock_ns = sorted(r[m]["clock_ns"] for r in size_rows.values() for m in r if "clock_ns" in r[m])
    fmt = lambda cells, unit: ", ".join("%.2f%s at 10^%d" % (v, unit, len(str(n)) - 1) for n, v in cells)
    yes = lambda ok: "yes" if ok else "no"

    def batch_txt(cells, wide_cells_, unit, ok, label="first_hit ",
                  what="batch means (no clock read per query)", short="batch"):
        """The figures and the verdict from the batch (or net) means, to append to a row's cells ("" when absent)."""
        if not cells:
            return "", ""
        txt = "; %s: %s%s" % (what, label, fmt(cells, unit))
        met = "; %s: %s%s" % (short, label, yes(all(ok(v) for _, v in cells)))
        if wide_cells_:
            txt += ", first_hit_wide %s" % fmt(wide_cells_, unit)
            met += ", first_hit_wide %s" % yes(all(ok(v) for _, v in wide_cells_))
        return txt, met
    wide_txt = lambda cells, unit: ("; first_hit_wide (wide index alone): %s" % fmt(cells, unit)) if cells else ""
    wide_met = lambda cells, ok: ("; first_hit_wide: %s" % yes(all(ok(v) for _, v in cells))) if cells else ""
    net_what = ("per-query means less the clock's own cost (%.0f–%.0f ns, measured in each benchmark)" % (clock_ns[0], clock_ns[-1])
                if clock_ns else "")
    nt, nmet = batch_txt(fh_mean_n, fw_mean_n, "x", lambda v: v >= 6, what=net_what, short="net")
    bt, bmet = batch_txt(fh_mean_b, fw_mean_b, "x", lambda v: v >= 6)
    paired_cells = lambda key: [(n, paired_fh[n][key]) for n in big if n in paired_fh]
    paired_rounds = ", ".join(sorted({"%d" % paired_fh[n]["rounds"] for n in paired_fh}))

    def paired_txt(key, unit, ok, what):
        """The side-by-side figures and verdict (BM_FirstHitPaired) for a row, first_hit then first_hit_wide ("" when absent)."""
        return batch_txt(paired_cells(key), paired_cells(key + "_wide"), unit, ok,
                         what="side by side (BM_FirstHitPaired: the methods in turn, %s rounds, each at its best round; %s)" % (paired_rounds, what),
                         short="side by side")
    pt, pmet = paired_txt("rtree_over_ours_batch", "x", lambda v: v >= 6, "batch means")
    rows2.append("| first hit: mean ≥ 6x faster than the R-tree at 10^5 and 10^6 | R-tree mean / ours, per query with its clock reads: first_hit (boundary section) %s%s%s%s%s | per query: first_hit %s%s%s%s%s |" % (
        fmt(fh_mean, "x"), wide_txt(fw_mean, "x"), nt, bt, pt, yes(all(v >= 6 for _, v in fh_mean)), wide_met(fw_mean, lambda v: v >= 6), nmet, bmet, pmet))
    pt, pmet = paired_txt("ours_p99_over_rtree", "", lambda v: v <= 0.5, "lowest p99s")
    rows2.append("| first hit: p99 ≤ 0.5x the R-tree's | ours p99 / R-tree p99: first_hit %s%s%s | first_hit: %s%s%s |" % (
        fmt(fh_p99, ""), wide_txt(fw_p99, ""), pt, yes(all(v <= 0.5 for _, v in fh_p99)), wide_met(fw_p99, lambda v: v <= 0.5), pmet))
    pic_faster = sum(1 for rows in pic.values() if "embree" in rows and ns(rows["ours"]) < ns(rows["embree"]))
    pic_wide = [rows for rows in pic.values() if "embree" in rows and "ours_wide" in rows]
    wide_pic_faster = sum(1 for rows in pic_wide if ns(rows["ours_wide"]) < ns(rows["embree"]))
    wide_pic_txt = (", pictures where it is faster: %d of %d" % (wide_pic_faster, len(pic_wide))) if fw_emb and pic_wide else ""
    wide_pic_met = (" on the tiled scenes; on every picture: %s" % yes(wide_pic_faster == len(pic_wide))) if fw_emb and pic_wide else (
        " on the tiled scenes (not run on the pictures)" if fw_emb else "")
    bt, bmet = batch_txt(fh_emb_b, fw_emb_b, "x", lambda v: v > 1)
    pt, pmet = paired_txt("embree_over_ours_batch", "x", lambda v: v > 1, "batch means, the tiled scenes")
    rows2.append("| first hit: faster than Embree on the same streams | Embree mean / ours: first_hit %s, pictures where it is faster: %d of %d%s%s%s%s | first_hit: %s%s%s%s |" % (
        fmt(fh_emb, "x"), pic_faster, len(pic), wide_txt(fw_emb, "x"), wide_pic_txt, bt, pt, yes(all(v > 1 for _, v in fh_emb) and pic_faster == len(pic)),
        wide_met(fw_emb, lambda v: v > 1) + wide_pic_met, bmet, pmet))
    cpb, cpb_met = batch_txt(cp_mean_b, [], "x", lambda v: v >= 3, label="")
    cpn, cpn_met = batch_txt(cp_mean_n, [], "x", lambda v: v >= 3, label="", what=net_what, short="net")
    rows2.append("| closest point: mean ≥ 3x faster than the R-tree | R-tree mean / ours, per query with its clock reads: %s%s%s | per query: %s%s%s |" % (
        fmt(cp_mean, "x"), cpn, cpb, yes(all(v >= 3 for _, v in cp_mean)), cpn_met, cpb_met))
    rows2.append("| closest point: p99 ≤ 0.5x the R-tree's | ours p99 / R-tree p99: %s | %s |" % (fmt(cp_p99, ""), yes(all(v <= 0.5 for _, v in cp_p99))))
    bps = [size_rows[("FirstHit", n)]["ours"]["bytes_per_segment"] for n in big if ("FirstHit", n) in size_rows]
    # The boundary section's own storage (one per servo thread; the peers keep no state between queries), when the
    # run has it: beside the figure, not in it, since the target counts the levels.
    sbps = [size_rows[("FirstHit", n)]["ours"]["section_bytes_per_segment"] for n in big
            if ("FirstHit", n) in size_rows and "section_bytes_per_segment" in size_rows[("FirstHit", n)]["ours"]]
    section_txt = ("; the boundary section's own storage, one per servo thread, not in the figure: %s bytes per segment" %
                   ", ".join("%.1f" % b for b in sbps)) if len(sbps) == len(bps) and bps else ""
    rows2.append("| memory: all levels ≤ 64 bytes per level-0 segment | %s bytes per segment (R-tree %.0f, Embree %.0f at 10^6)%s | %s |" % (
        ", ".join("%.0f" % b for b in bps), size_rows[("FirstHit", 10 ** 6)]["rtree"]["bytes_per_segment"] if ("FirstHit", 10 ** 6) in size_rows else float("nan"),
        size_rows[("FirstHit", 10 ** 6)]["embree"]["bytes_per_segment"] if ("FirstHit", 10 ** 6) in size_rows else float("nan"), section_txt,
        yes(all(b <= 64 for b in bps))))
    if sb:
        sbr = [ns(sb[n]["ours"]) / ns(sb[n]["opencv"]) for n in sorted(sb)]
        same_txt = ""
        if all("opencv_same_edges" in sb[n] for n in sb):
            sbs = [ns(sb[n]["ours"]) / ns(sb[n]["opencv_same_edges"]) for n in sorted(sb)]
            same_txt = "; with the Canny thresholds ours chose (both find the same edges): median %.2f, worst %.2f, %d of %d ≤ 1.5x" % (
                median(sbs), max(sbs), sum(1 for q in sbs if q <= 1.5), len(sbs))
        if all("opencv_same_edges" in sb[n] and "edges_ms" in sb[n]["ours"] for n in sb):
            front = [(sb[n]["ours"]["edges_ms"] + sb[n]["ours"]["linking_ms"]) / (ns(sb[n]["opencv_same_edges"]) / 1e6) for n in sorted(sb)]
            model = [(sb[n]["ours"]["curves_ms"] + sb[n]["ours"]["multires_ms"] + sb[n]["ours"]["tree_ms"]) / (ns(sb[n]["ours"]) / 1e6) for n in sorted(sb)]
            same_txt += ("; ours' edges + linking alone against OpenCV's whole pipeline (same edges): median %.2f, worst %.2f; "
                         "ours' model (curves, multiresolution, trees; no OpenCV counterpart): median %.0f %% of our build" % (
                             median(front), max(front), 100 * median(model)))
        paired_txt, paired_met = "", ""
        if paired:
            pn = sorted(paired)
            p50 = [paired[n]["ours"] / paired[n]["opencv"] for n in pn]
            psame = [paired[n]["ours"] / paired[n]["opencv_same_edges"] for n in pn]
            paired_txt = ("; each one's fastest single build, the three run side by side (BM_SceneBuildPaired): against 50/150 "
                          "median %.2f, worst %.2f, %d of %d ≤ 1.5x; with the same edges median %.2f, worst %.2f, %d of %d ≤ 1.5x" % (
                              median(p50), max(p50), sum(1 for q in p50 if q <= 1.5), len(p50),
                              median(psame), max(psame), sum(1 for q in psame if q <= 1.5), len(psame)))
            paired_met = "; side by side: %s (same edges: %s)" % (yes(max(p50) <= 1.5 and median(p50) <= 1.2),
                                                                   yes(max(psame) <= 1.5 and median(psame) <= 1.2))
        same_met = " (same edges: %s)" % yes(max(sbs) <= 1.5 and median(sbs) <= 1.2) if same_txt else ""
        rows2.append("| scene build: ≤ 1.5x OpenCV on every picture, median ≤ 1.2x | ours / OpenCV (Canny 50/150): median %.2f, worst %.2f, %d of %d pictures ≤ 1.5x%s%s | %s%s%s |" % (
            median(sbr), max(sbr), sum(1 for q in sbr if q <= 1.5), len(sbr), same_txt, paired_txt, yes(max(sbr) <= 1.5 and median(sbr) <= 1.2), same_met, paired_met))
    st_path = os.path.join(BENCH, "servo_tick.json")
    st = [r for r in json.load(open(st_path)) if r["requested_segments"] == 10 ** 6] if os.path.exists(st_path) else []
    if st:
        own = [r["per_tick_min"]["p999_ns"] / 1e3 for r in st]
        raw = [run["p999_ns"] / 1e3 for r in st for run in r["runs"]]
        rows2.append("| servo tick p99.9 ≤ 10 µs on a tiled scene of 10^6 segments, headless | the tick's own cost (each tick's fastest of %d runs): %s µs; "
                     "single runs: %.1f–%.1f µs, %d of %d ≤ 10 µs (host stalls) | %s |" % (
                         len(st[0]["runs"]), ", ".join("%.1f (%s)" % (v, r["hand"]) for v, r in zip(own, st)), min(raw), max(raw),
                         sum(1 for v in raw if v <= 10), len(raw), "own cost: " + yes(all(v <= 10 for v in own)) + "; every single run: " + yes(all(v <= 10 for v in raw))))
    else:
        rows2.append("| servo tick p99.9 ≤ 10 µs on a tiled scene of 10^6 segments, headless | not measured (docs/bench/servo_tick.json missing) | — |")
    acc_path = os.path.join(BENCH, "accuracy.json")
    if os.path.exists(acc_path):
        bt = json.load(open(acc_path))["box_tightness"]
        meds = [(b["level"], b["ratio"]["median"]) for b in bt]
        rows2.append("| error boxes: median half-width ≤ 1.05x the true max deviation under it | median per level (0–%d): %s; all pictures' curves | %s |" % (
            meds[-1][0], ", ".join("%.3f" % m for _, m in meds), yes(all(m <= 1.05 for _, m in meds))))
    if TOLERANCE_CUT:
        worst = TOLERANCE_CUT["worst"]
        # The traced polygons (absent in older runs): sharp corners alone, where the dyadic smoothing's limit shows.
        polys = TOLERANCE_CUT.get("polygons", [])
        poly_txt = ""
        if polys:
            by_shape = {}
            for r in polys:
                by_shape.setdefault(r["polygon"], []).append(r["ratio"])
            poly_txt = "; traced polygons (corners only; DP keeps exactly the corners): %s, so not reachable by a cut through this tree" % ", ".join(
                "%s %.1f–%.1fx" % (n, min(v), max(v)) for n, v in by_shape.items())
        rows2.append("| tolerance cut: ≤ 1.2x Douglas–Peucker's vertices for the same max error, every picture | worst joined cut / DP per target error: %s%s | %s |" % (
            ", ".join("%.2f at %.1f mm" % (w["worst_ratio"], w["tolerance_mm"]) for w in worst), poly_txt, yes(all(w["worst_ratio"] <= 1.2 for w in worst))))
        if all("worst_curve_levels_ratio" in w for w in worst):
            rows2.append("| the level policy may pick a tolerance, no crossings at changes | built at curve granularity (`level_mode = \"tolerance\"`: each curve at the coarsest of its levels within the step; "
                         "worst vertices / DP per target error: %s) and per segment (`level_mode = \"cut\"`: the walls are the joined tolerance cut, the row above); "
                         "crossings, wrong sides and force steps 0 in the level-change test on all 22 pictures in both modes | "
                         "yes (both) |" % ", ".join("%.2f at %.1f mm" % (w["worst_curve_levels_ratio"], w["tolerance_mm"]) for w in worst))
    tables["round_two"] = "\n".join(rows2)

# Finding and rectifying a page in a camera frame (bench_rectify): time per frame size, and the corner error.
rect = {}
for r in load_gbench("rectify.json"):
    parts = r["name"].split("/")  # BM_<what>/<width>/<height>
    if len(parts) >= 3:
        rect.setdefault((int(parts[1]), int(parts[2])), {})[parts[0]] = r
if rect:
    rows = ["| frame | find_page + rectify_page | find_page | rectify_page | mean corner error |", "|---|---|---|---|---|"]
    for (w, h), by in sorted(rect.items()):
        def cell(name):
            return "%.*f ms" % (2 if ns(by[name]) < 1e6 else 1, ns(by[name]) / 1e6) if name in by else "—"
        both = by.get("BM_FindAndRectify", {})
        err = "%.3f %%" % both["corner_error_pct"] if "corner_error_pct" in both else "—"
        rows.append("| %d × %d | %s | %s | %s | %s |" % (w, h, cell("BM_FindAndRectify"), cell("BM_FindPage"), cell("BM_RectifyPage"), err))
    tables["rectify"] = "\n".join(rows)

if os.path.exists(PERF):
    text = open(PERF).read()
    for key, block in tables.items():
        text = replace_block(text, key, block)
    open(PERF, "w").write(text)
print("plot_bench: wrote", ", ".join(sorted(tables)))
