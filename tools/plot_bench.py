#!/usr/bin/python3
"""Charts of graspsim_bench's output (README.md, "Speed against error").

    tools/plot_bench.py DIR     reads DIR/bench.csv and DIR/stability.csv, writes
                                DIR/work_precision.png and DIR/stability.png

work_precision.png: error against cost (wall seconds per simulated second), log-log, one panel
per case and one curve per gyroscopic option (the hard cases) or per integration scheme, paper or
implicit (the contact accuracy cases, whose rows differ in `scheme`), each point labelled with its
physics rate in Hz. Rows a model was refused for (status "refused: ...") have no cost and are left
out.
Unstable runs are drawn as red crosses (at the panel's top edge when their error is not finite);
the finest rate of a convergence case is its own reference (error 0) and is left out.
stability.png: the corner drop's largest stable floor stiffness against the physics rate, with
the rocking-mode estimate. Exit 2, nothing written, when a file is missing or malformed.
Needs Debian's python3-matplotlib (run with /usr/bin/python3).
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"neglect": ("tab:blue", "o"), "explicit": ("tab:orange", "s"), "implicit": ("tab:green", "^")}
SCHEME_STYLE = {"paper": ("tab:red", "D"), "implicit": ("tab:purple", "v")}
# The contact accuracy targets, in each case's error unit (tools/bench/README.md, "Contact accuracy").
TARGETS = {"cube_rest": 1e-4, "slope_stick": 1e-5, "slope_slide": 0.005, "cube_settle": 1e-4}


def curves(rows):
    """(column, value, label, colour, marker) of each curve of a panel: by scheme where its rows
    have more than one, else by gyroscopic option."""
    if len({r.get("scheme", "") for r in rows}) > 1:
        return [("scheme", k, f"{k} scheme", c, m) for k, (c, m) in SCHEME_STYLE.items()]
    return [("integrator", k, f"gyroscopic {k}", c, m) for k, (c, m) in STYLE.items()]


def fail(message):
    print(f"plot_bench: {message}", file=sys.stderr)
    sys.exit(2)


def read(path, columns):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    if rows and not set(columns) <= set(rows[0].keys()):
        fail(f"{path}: expected columns {', '.join(columns)}")
    return rows


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def work_precision(rows, out):
    cases = list(dict.fromkeys(r["case"] for r in rows))
    if not cases:
        return []
    cols = 2 if len(cases) > 1 else 1
    nrows = (len(cases) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 4.0 * nrows), squeeze=False)
    for ax, case in zip(axes.flat, cases):
        every = [r for r in rows if r["case"] == case]
        mine = [r for r in every if not r["status"].startswith("refused")]
        refused = []
        finite = [number(r["error"]) for r in mine if 0 < number(r["error"]) < math.inf]
        top = max(finite) * 3 if finite else 1.0
        for column, key, label, colour, marker in curves(every):
            pts = [r for r in mine if r.get(column) == key and number(r["error"]) != 0]
            pts.sort(key=lambda r: int(r["rate_hz"]))
            ok = [r for r in pts if r["status"] == "ok"]
            if not pts:
                if any(r.get(column) == key for r in every):
                    refused.append(label)
                continue
            ax.plot([number(r["wall_per_sim_s"]) for r in ok], [number(r["error"]) for r in ok],
                    marker=marker, color=colour, label=label, linewidth=1, markersize=5)
            # The spread of the repeats (min to max wall time): where it is as wide as the steps
            # between rates, the order of the points along x is noise, not cost.
            spread = [r for r in ok if r.get("wall_min") and r.get("wall_max")]
            if spread:
                xs = [number(r["wall_per_sim_s"]) for r in spread]
                ax.errorbar(xs, [number(r["error"]) for r in spread],
                            xerr=[[x - number(r["wall_min"]) for x, r in zip(xs, spread)],
                                  [number(r["wall_max"]) - x for x, r in zip(xs, spread)]],
                            fmt="none", ecolor=colour, elinewidth=0.8, alpha=0.5, capsize=2)
            for r in pts:
                err = number(r["error"])
                y = err if 0 < err < math.inf else top
                x = number(r["wall_per_sim_s"])
                if r["status"] != "ok":
                    ax.plot([x], [y], marker="x", color="red", markersize=8, markeredgewidth=2, linestyle="none")
                ax.annotate(r["rate_hz"], (x, y), textcoords="offset points", xytext=(3, 3), fontsize=6,
                            color=colour)
        if case in TARGETS:
            ax.axhline(TARGETS[case], color="grey", linestyle="--", linewidth=1, label="target")
        if refused:
            ax.text(0.02, 0.02, "refused by validate(): " + ", ".join(refused), transform=ax.transAxes,
                    fontsize=7, color="grey")
        ax.set_xscale("log")
        ax.set_yscale("log")
        costs = [number(r["wall_per_sim_s"]) for r in mine if r["status"] == "ok" and number(r["error"]) != 0]
        title = case
        if costs and max(costs) < 2 * min(costs):
            # A scene whose cost the physics rate barely moves (the lift: the 3 kHz servo and
            # 500 Hz haptic loops dominate): say so, or the zig-zag reads as a trade-off.
            title += ("\ncost within %.1fx over all physics rates (set by the other loops);"
                      "\nbars: min to max of the repeats" % (max(costs) / min(costs)))
        ax.set_title(title, fontsize=10 if title == case else 7.5)
        ax.set_xlabel("wall s per simulated s (median)", fontsize=8)
        ax.set_ylabel(mine[0]["error_measure"] if mine else "error", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", linewidth=0.3)
    for ax in list(axes.flat)[len(cases):]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat:
        for h, label in zip(*ax.get_legend_handles_labels()):
            if label not in labels:
                handles.append(h)
                labels.append(label)
    handles.append(plt.Line2D([], [], marker="x", color="red", linestyle="none", markeredgewidth=2))
    labels.append("unstable")
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=8)
    fig.suptitle("graspsim work-precision (labels: physics rate, Hz)", fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return [out]


def stability(rows, out):
    if not rows:
        return []
    fig, ax = plt.subplots(figsize=(5.5, 4.0))
    for integrator, (colour, marker) in STYLE.items():
        pts = sorted((int(r["rate_hz"]), number(r["k_max_n_per_m"])) for r in rows if r["integrator"] == integrator)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=marker, color=colour, label=f"measured, {integrator}",
                linewidth=1, markersize=5)
    est = sorted({(int(r["rate_hz"]), number(r["estimate_n_per_m"])) for r in rows})
    ax.plot([p[0] for p in est], [p[1] for p in est], "k--", linewidth=1, label="estimate (rocking mode)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("physics rate (Hz)", fontsize=8)
    ax.set_ylabel("largest stable floor stiffness (N/m per vertex)", fontsize=8)
    ax.set_title("corner drop: stability boundary", fontsize=10)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return [out]


def main():
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        fail("usage: plot_bench.py DIR (with DIR/bench.csv and DIR/stability.csv)")
    d = sys.argv[1]
    bench = read(f"{d}/bench.csv", ["case", "rate_hz", "integrator", "status", "wall_per_sim_s", "error",
                                    "error_measure"])
    stab = read(f"{d}/stability.csv", ["rate_hz", "integrator", "k_max_n_per_m", "estimate_n_per_m"])
    written = work_precision(bench, f"{d}/work_precision.png") + stability(stab, f"{d}/stability.png")
    print("wrote " + (" and ".join(written) if written else "nothing (no rows)"))


if __name__ == "__main__":
    main()
