#!/usr/bin/python3
"""Charts of bench_stability's JSON: stability where methods fail.

Usage: /usr/bin/python3 bench/plot_stability.py [docs/bench/stability.json] [--outdir DIR]

Writes, next to the JSON unless --outdir is given:
  stability.png   — (a) largest stable wall stiffness against servo rate, log-log: the measured limits
                    (push and let-go, shipped 16384-count encoder and an ideal one), the Colgate–Schenkel
                    passivity bound 2b/T and the exact limit of the linearised sampled-data loop;
                    (b), (c) the stable / limit-cycle / unstable map over (rate, stiffness) for the push and
                    let-go cases with the shipped encoder.
  stability_profiles.png — per device profile (part 3, JSON "profiles"): stable / limit-cycle / unstable
                    over stiffness for push and let-go on the profile's model, with its default stiffness
                    and the limit its settings allow.
  tunnelling.png  — (a) failing strokes (proxy tunnelled or contact missed) against hand speed per shape,
                    SceneStep with a kinematic handle and through the simulated device, with the wall-blind
                    control that the checker must catch; (b) how hard the strokes were: handle jump per
                    servo tick and handle depth behind the wall while the proxy held, against the 0.2 mm
                    thickness of the thin curve.
Uses the Debian matplotlib (run with /usr/bin/python3).
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

CLASS_STYLE = {
    "stable": dict(marker="o", color="#2a9d3f", label="stable"),
    "limit_cycle": dict(marker="s", color="#f0a020", label="limit cycle in contact (> 2 encoder steps)"),
    "unstable": dict(marker="x", color="#d62728", label="unstable (bouncing / energy growth / energy created)"),
}


def series(stiff, mode, counts):
    return sorted((s for s in stiff["series"] if s["mode"] == mode and s["encoder_counts_per_rev"] == counts), key=lambda s: s["rate_hz"])


def plot_limits(ax, stiff):
    rates = np.array([r["rate_hz"] for r in stiff["rates"]])
    fine_rates = np.geomspace(rates.min() * 0.8, rates.max() * 1.25, 50)
    b = stiff["device"]["handle_damping_n_s_per_m"]
    ax.plot(fine_rates, 2 * b * fine_rates, "k--", lw=1.5, label=f"passivity bound 2b/T (b = {b:g} N·s/m)")
    ax.plot(rates, [r["linear_limit_push_n_per_m"] for r in stiff["rates"]], ":", color="#1f5fbf", lw=1.5,
            label="linear model limit, push (b + b_hand, Jury)")
    ax.plot(rates, [r["linear_limit_let_go_n_per_m"] for r in stiff["rates"]], ":", color="#c0392b", lw=1.5,
            label="linear model limit, device alone (≈ 2b/T)")
    default = stiff["device"]["encoder_counts_per_rev"]
    ideal = stiff["device"]["ideal_encoder_counts_per_rev"]
    styles = [
        ("push", default, dict(marker="o", color="#1f5fbf", mfc="#1f5fbf"), f"push, {default}-count encoder"),
        ("push", ideal, dict(marker="o", color="#1f5fbf", mfc="white"), "push, ideal encoder"),
        ("let_go", default, dict(marker="s", color="#c0392b", mfc="#c0392b"), f"let-go bounce, {default}-count encoder"),
        ("let_go", ideal, dict(marker="s", color="#c0392b", mfc="white"), "let-go bounce, ideal encoder"),
    ]
    for mode, counts, st, label in styles:
        ss = series(stiff, mode, counts)
        if not ss:
            continue
        x = np.array([s["rate_hz"] for s in ss]) * (1.04 if counts == ideal else 0.96)  # side by side
        ax.plot(x, [s["largest_stable_n_per_m"] for s in ss], ls="-", lw=1, ms=7, label=label, **st)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(rates)
    ax.set_xticklabels([f"{r:g}" for r in rates])
    ax.minorticks_off()
    ax.set_xlabel("servo rate [Hz]")
    ax.set_ylabel("largest stable wall stiffness K [N/m]")
    ax.set_title("(a) Largest stable stiffness vs servo rate\n(each limit bisected to 0.2 %; every smaller K tested was stable)")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)


def plot_map(ax, stiff, mode, title):
    default = stiff["device"]["encoder_counts_per_rev"]
    ss = series(stiff, mode, default)
    rates = [s["rate_hz"] for s in ss]
    seen = set()
    for i, s in enumerate(ss):
        for case in s["grid"]:
            st = CLASS_STYLE[case["class"]]
            label = st["label"] if case["class"] not in seen else None
            seen.add(case["class"])
            ax.scatter(i, case["stiffness_n_per_m"], marker=st["marker"], color=st["color"], s=28, label=label)
    b = stiff["device"]["handle_damping_n_s_per_m"]
    xs = np.arange(len(rates))
    ax.plot(xs, [2 * b * r for r in rates], "k--", lw=1.5, label="2b/T")
    key = "linear_limit_push_n_per_m" if mode == "push" else "linear_limit_let_go_n_per_m"
    by_rate = {r["rate_hz"]: r for r in stiff["rates"]}
    ax.plot(xs, [by_rate[r][key] for r in rates], ":", color="#1f5fbf", lw=1.5, label="linear model limit")
    ax.plot(xs, [s["largest_stable_n_per_m"] for s in ss], "-", color="#555555", lw=1, label="largest stable (bisected)")
    ax.set_yscale("log")
    ax.set_xticks(xs)
    ax.set_xticklabels([f"{r:g}" for r in rates])
    ax.set_xlim(-0.5, len(rates) - 0.5)
    ax.set_xlabel("servo rate [Hz]")
    ax.set_ylabel("wall stiffness K [N/m]")
    ax.set_title(title)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)


def plot_stability(d, out_png):
    stiff = d["stiffness"]
    fig, axes = plt.subplots(1, 3, figsize=(18, 7.2), gridspec_kw=dict(width_ratios=[1.25, 1, 1]))
    plot_limits(axes[0], stiff)
    counts = stiff["device"]["encoder_counts_per_rev"]
    plot_map(axes[1], stiff, "push", f"(b) Push: hand leans on the wall (target 5 mm behind, 2 N)\n{counts}-count encoder, 2 s per case")
    plot_map(axes[2], stiff, "let_go", f"(c) Let-go: free handle bounces off the wall\n{counts}-count encoder, worst of 4 phases")
    fig.suptitle("Virtual wall stability on the simulated pantograph (m = %g kg, b = %g N·s/m, no force or torque clamp)"
                 % (stiff["device"]["handle_mass_kg"], stiff["device"]["handle_damping_n_s_per_m"]), fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


SCENE_STYLE = {
    "straight_wall": dict(color="#1f5fbf", marker="o", label="straight wall"),
    "thin_closed": dict(color="#d62728", marker="D", label="thin closed curve (0.2 mm)"),
    "wedge_30": dict(color="#2a9d3f", marker="^", label="30° wedge"),
    "wedge_10": dict(color="#9b59b6", marker="v", label="10° wedge"),
}


def plot_tunnelling(d, out_png):
    tun = d["tunnelling"]
    fig, axes = plt.subplots(1, 2, figsize=(15, 6))
    ax = axes[0]
    n_offset = {name: i for i, name in enumerate(SCENE_STYLE)}
    max_strokes = 1
    for sc in tun["scenes"]:
        st = SCENE_STYLE.get(sc["name"], dict(color="grey", marker="o", label=sc["name"]))
        off = 0.06 * (n_offset.get(sc["name"], 0) - 1.5)  # small vertical offsets so equal lines stay visible
        for drive, ls, mfc in (("kinematic", "-", st["color"]), ("device", "--", "white")):
            rows = sc[drive]
            v = [r["speed_m_per_s"] for r in rows]
            fails = [r["strokes_tunnelled"] + r["strokes_missed_contact"] for r in rows]
            max_strokes = max(max_strokes, max(r["strokes"] for r in rows))
            ax.plot(v, np.array(fails) + off, ls=ls, marker=st["marker"], color=st["color"], mfc=mfc, ms=6,
                    label=f"{st['label']}, {'SceneStep, kinematic handle' if drive == 'kinematic' else 'simulated device'}")
    ctrl = tun.get("control_wall_blind_proxy", [])
    if ctrl:
        ax.scatter([0.5] * len(ctrl), [c["strokes_tunnelled"] for c in ctrl], marker="*", s=160, color="black", zorder=5,
                   label="control: wall-blind proxy at 0.5 m/s (all strokes fail)")
    first_k = tun.get("first_failure_speed_kinematic_m_per_s")
    first_d = tun.get("first_failure_speed_device_m_per_s")
    vmax = max(tun["speeds_m_per_s"])
    msg = ("no failure up to %g m/s (kinematic) and %g m/s (device)" % (vmax, max(tun["device_speeds_m_per_s"]))
           if first_k is None and first_d is None else
           "first failure: kinematic %s m/s, device %s m/s" % (first_k, first_d))
    ax.text(0.02, 0.97, msg, transform=ax.transAxes, va="top", fontsize=10,
            bbox=dict(boxstyle="round", fc="white", ec="#999999"))
    ax.set_xscale("log")
    ax.set_ylim(-0.6, max_strokes + 1.5)
    ax.set_xlabel("hand speed [m/s] (device: target speed)")
    ax.set_ylabel("failing strokes (tunnelled or missed contact) per speed")
    ax.set_title("(a) God-object failures vs hand speed, 1 kHz, level 0\n(9 strokes per speed for wall and thin curve, 3 per wedge)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7.5, loc="center left")

    ax = axes[1]
    sc0 = tun["scenes"][0]
    v = [r["speed_m_per_s"] for r in sc0["kinematic"]]
    ax.plot(v, [1e3 * r["max_handle_step_m"] for r in sc0["kinematic"]], "k-o", ms=5, label="handle jump per 1 ms tick (kinematic)")
    for sc in tun["scenes"]:
        st = SCENE_STYLE.get(sc["name"], dict(color="grey", marker="o", label=sc["name"]))
        dv = [r.get("mean_impact_speed_m_per_s", r["speed_m_per_s"]) for r in sc["device"]]
        ax.plot(dv, [1e3 * r["max_depth_in_contact_m"] for r in sc["device"]], ls="--", marker=st["marker"], color=st["color"], mfc="white",
                label=f"{st['label']}: deepest handle behind the wall, device (x: impact speed)")
    thick_m = next((sc["thickness_m"] for sc in tun["scenes"] if "thickness_m" in sc), None)
    if thick_m:
        ax.axhline(1e3 * thick_m, color="#d62728", lw=1, ls=":", label=f"thin curve width {1e3 * thick_m:g} mm")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(0.03, 300)
    ax.set_xlabel("hand speed [m/s]")
    ax.set_ylabel("distance [mm]")
    ax.set_title("(b) How hard the strokes were: the handle jumps and sinks\nfar past walls the proxy must hold")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper left")
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def plot_profiles(d, out_png):
    profiles = d["profiles"]["profiles"]
    fig, ax = plt.subplots(figsize=(9, 2.0 + 0.8 * len(profiles)))
    rows, labels = [], []
    for i, p in enumerate(profiles):
        for j, mode in enumerate(("push", "let_go")):
            y = 2 * i + j
            rows.append(y)
            labels.append(f"{p['name']}, {mode.replace('_', '-')}")
            cases = p[mode]["grid"] + p[mode]["refinement"]
            for cls, style in CLASS_STYLE.items():
                ks = [c["stiffness_n_per_m"] for c in cases if c["class"] == cls]
                ax.scatter(ks, [y] * len(ks), marker=style["marker"], color=style["color"], s=22,
                           label=style["label"] if (i == 0 and j == 0) else None)
        ax.plot([p["default_n_per_m"]] * 2, [2 * i - 0.4, 2 * i + 1.4], color="black", lw=2,
                label="default stiffness" if i == 0 else None)
        ax.plot([p["profile_limit_n_per_m"]] * 2, [2 * i - 0.4, 2 * i + 1.4], color="#d62728", lw=1.5, ls="--",
                label="largest the settings allow" if i == 0 else None)
    ax.set_xscale("log")
    ax.set_yticks(rows)
    ax.set_yticklabels(labels)
    ax.invert_yaxis()
    ax.set_xlabel("wall stiffness [N/m] (workspace frame)")
    ax.set_title("Stable wall stiffness on each device profile's model at its servo rate (1 kHz)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.4, -0.22), ncol=3)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", nargs="?", default="docs/bench/stability.json")
    ap.add_argument("--outdir", default=None, help="where the PNGs go (default: the JSON's folder)")
    a = ap.parse_args()
    try:
        with open(a.json) as f:
            d = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        print(f"plot_stability: '{a.json}': {e}", file=sys.stderr)
        return 1
    outdir = a.outdir or os.path.dirname(os.path.abspath(a.json))
    os.makedirs(outdir, exist_ok=True)
    wrote = []
    if "stiffness" in d:
        plot_stability(d, os.path.join(outdir, "stability.png"))
        plot_tunnelling(d, os.path.join(outdir, "tunnelling.png"))
        wrote += ["stability.png", "tunnelling.png"]
    if "profiles" in d:
        plot_profiles(d, os.path.join(outdir, "stability_profiles.png"))
        wrote.append("stability_profiles.png")
    print("wrote " + ", ".join(os.path.join(outdir, w) for w in wrote))
    return 0


if __name__ == "__main__":
    sys.exit(main())
