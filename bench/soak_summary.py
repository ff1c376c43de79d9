#!/usr/bin/env python3
"""Summary of a bench_soak run from its samples (CSV) and, optionally, its log.

Usage: bench/soak_summary.py SOAK.csv [SOAK.log] [--warmup-s S]

Prints duration, servo ticks, missed deadlines and worst lateness, the RSS least-squares slope after
the warm-up, the descriptor and thread counts seen, and the scripted day's counts. Give the log for runs
made before bench_soak read ServoThread::totals(): the servo counters were then reset at every visitor,
and the ticks and misses of each visitor's session are in the log's "session: servo N ticks, M missed
deadlines, ... max X us" lines, which are added to the samples'.
"""
import csv
import re
import sys

args = [a for a in sys.argv[1:] if not a.startswith("--")]
warm = 600.0
if "--warmup-s" in sys.argv:
    warm = float(sys.argv[sys.argv.index("--warmup-s") + 1])
    args = [a for a in args if a != sys.argv[sys.argv.index("--warmup-s") + 1]]
if not args:
    sys.exit(__doc__)
rows = list(csv.DictReader(open(args[0])))
log = open(args[1]).read() if len(args) > 1 else ""
sess = re.findall(r"session: servo (\d+) ticks, (\d+) missed deadlines, lateness p50 (\d+) p99 (\d+) max (\d+) us", log)
ticks = sum(int(r["ticks"]) for r in rows) + sum(int(s[0]) for s in sess)
missed = sum(int(r["missed_deadlines"]) for r in rows) + sum(int(s[1]) for s in sess)
late = max([float(r["lateness_max_us"]) for r in rows] + [float(s[4]) for s in sess])
t_end = float(rows[-1]["t_s"])
after = [r for r in rows if float(r["t_s"]) >= warm]
xs = [float(r["t_s"]) / 3600 for r in after]
ys = [float(r["rss_kib"]) for r in after]
n = len(xs)
mx, my = sum(xs) / n, sum(ys) / n
slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
print(f"duration {t_end:.0f} s, samples {len(rows)}, visitor sessions in the log {len(sess)}")
print(f"servo ticks {ticks} (due ~{t_end * 1000:.0f}), missed deadlines {missed}, worst lateness {late / 1000:.1f} ms")
print(f"RSS after warm-up {after[0]['rss_kib']} KiB, end {after[-1]['rss_kib']} KiB, min {min(ys):.0f}, max {max(ys):.0f}, "
      f"least-squares slope {slope:.0f} KiB/h")
print("descriptors", sorted({int(r["fds"]) for r in after}), "threads", sorted({int(r["threads"]) for r in after}))
print("visitors", rows[-1]["visitors"], "sticks", rows[-1]["sticks"], "operator applies", rows[-1]["applies"],
      "device states", sorted({r["device"] for r in rows}))
if log:
    print("warnings and errors in the log:", len(re.findall(r"\[(warning|error)\]", log)))
