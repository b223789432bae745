#!/usr/bin/python3
"""Chart of graspsim_peers' output: cost per step against the number of boxes
(tools/bench/README.md, "Peers").

    tools/plot_scale.py DIR     reads DIR/scale.csv, writes DIR/scale.png and prints the
                                growth exponents

scale.png: one log-log panel per layout present (apart, island, tower, pyramid, pile), the
median of a step's thread CPU time (cpu_us_step_median; the wall median us_step_median where
the CSV has no CPU column), microseconds, against n, the boxes built (a pyramid's n is
the triangular number graspsim_peers rounded down to), one line per engine, graspsim drawn
heaviest. Each legend entry carries the engine's growth exponent in that panel: the
least-squares slope of log cost against log n over the engine's rows that did not fail, from
n = 16 on (FIT_FROM), with the range of n it was fitted over. Rows that failed (`failed` other than `no`) are left out of
the lines and the fit and drawn as red crosses, at their cost where they have one, else at the
panel's top edge. When the file holds more than one physics rate or gap, each (engine, rate,
gap) is a line of its own. Repeated header lines (files concatenated) are skipped; a later row
for the same engine, layout, n, rate and gap replaces an earlier one.
Exit 2, nothing written, when the file is missing or malformed.
Needs Debian's python3-matplotlib and python3-numpy (run with /usr/bin/python3).
"""
import csv
import math
import sys

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

LAYOUTS = ["apart", "island", "tower", "pyramid", "pile"]
# (colour, marker, line width, z order): graspsim on top and heaviest, the peers thinner.
ENGINES = {
    "graspsim": ("tab:red", "o", 2.4, 4),
    "ode": ("tab:blue", "s", 1.1, 3),
    "mujoco": ("tab:green", "^", 1.1, 3),
    "bullet": ("tab:orange", "D", 1.1, 3),
}
OTHER = ("tab:grey", "v", 1.1, 3)
NAMES = {"graspsim": "graspsim", "ode": "ODE", "mujoco": "MuJoCo", "bullet": "Bullet"}
COLUMNS = ["engine", "layout", "n", "rate", "gap", "us_step_median", "failed"]
# The growth exponent is fitted from 16 boxes on: a single box has no box-to-box contact at all
# (0.9 us against 150 us for an island of 16), and would steepen every slope but apart's.
FIT_FROM = 16


def fail(message):
    print(f"plot_scale: {message}", file=sys.stderr)
    sys.exit(2)


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    if rows and not set(COLUMNS) <= set(rows[0].keys()):
        fail(f"{path}: expected columns {', '.join(COLUMNS)}")
    latest = {}
    for r in rows:
        if r["engine"] == "engine":
            continue
        n = number(r["n"])
        if not n >= 1:
            fail(f"{path}: a row with n = {r['n']!r}")
        r["n"] = int(n)
        # The step's thread CPU time where the CSV has it: on a shared machine the wall median
        # counts the time the scheduler gave other processes, more for longer steps.
        r["cpu"] = bool(r.get("cpu_us_step_median"))
        r["cost"] = number(r["cpu_us_step_median"] if r["cpu"] else r["us_step_median"])
        r["ok"] = r["failed"] == "no" and 0 < r["cost"] < math.inf
        latest[(r["engine"], r["layout"], r["n"], r["rate"], r["gap"])] = r
    return list(latest.values())


def order(values, first):
    """The values, those in `first` in its order, then the others as they came."""
    values = list(dict.fromkeys(values))
    return [v for v in first if v in values] + [v for v in values if v not in first]


def exponent(points):
    """(slope of log cost against log n, smallest n, largest n) over (n, cost) points, or None
    with fewer than two distinct n."""
    points = [(n, c) for n, c in points if n >= FIT_FROM]
    ns = sorted({n for n, _ in points})
    if len(ns) < 2:
        return None
    x = np.log([n for n, _ in points])
    y = np.log([c for _, c in points])
    slope = np.polyfit(x, y, 1)[0]
    return float(slope), ns[0], ns[-1]


def series(rows):
    """The lines of the chart: (key, label, style) per (engine, rate, gap), the rate and gap named
    only when the rows hold more than one of them."""
    rates = order((r["rate"] for r in rows), [])
    gaps = order((r["gap"] for r in rows), [])
    out = []
    for engine in order((r["engine"] for r in rows), list(ENGINES)):
        for rate in rates:
            for gap in gaps:
                if not any(r["engine"] == engine and r["rate"] == rate and r["gap"] == gap for r in rows):
                    continue
                label = NAMES.get(engine, engine)
                if len(rates) > 1:
                    label += f" {rate} Hz"
                if len(gaps) > 1:
                    label += f" gap {gap} m"
                out.append(((engine, rate, gap), label, ENGINES.get(engine, OTHER)))
    return out


def chart(rows, out):
    layouts = order((r["layout"] for r in rows), LAYOUTS)
    lines = series(rows)
    cols = min(len(layouts), 3)
    nrows = (len(layouts) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.0 * cols, 4.2 * nrows), squeeze=False)
    table = {}   # (layout, line label) -> exponent or None
    failed_rows = []
    for ax, layout in zip(axes.flat, layouts):
        mine = [r for r in rows if r["layout"] == layout]
        finite = [r["cost"] for r in mine if 0 < r["cost"] < math.inf]
        top = max(finite) * 2 if finite else 1.0
        for key, label, (colour, marker, width, z) in lines:
            pts = sorted((r for r in mine if (r["engine"], r["rate"], r["gap"]) == key), key=lambda r: r["n"])
            if not pts:
                continue
            ok = [(r["n"], r["cost"]) for r in pts if r["ok"]]
            fit = exponent(ok)
            table[(layout, label)] = fit
            if fit:
                legend = f"{label}: {fit[0]:.2f} (n {fit[1]}–{fit[2]})"
            elif ok:
                legend = f"{label}: one n"
            else:
                legend = f"{label}: all failed"
            ax.plot([p[0] for p in ok], [p[1] for p in ok], marker=marker, color=colour, linewidth=width,
                    markersize=3 + width, zorder=z, label=legend)
            for r in pts:
                if r["ok"]:
                    continue
                failed_rows.append(r)
                y = r["cost"] if 0 < r["cost"] < math.inf else top
                ax.plot([r["n"]], [y], marker="x", color="red", markersize=8, markeredgewidth=2,
                        linestyle="none", zorder=5)
        ax.set_xscale("log")
        ax.set_yscale("log")
        # The n measured as the ticks, written out (a decade's 10^k says little over 1 to 1000).
        ns = sorted({r["n"] for r in mine})
        ax.set_xticks(ns)
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%d"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        # Plain numbers on y too; within two decades also at 2 and 5 times each power of ten, or
        # a panel spanning less than a decade would have one label or none.
        if finite:
            decades = math.log10(max(finite) / min(finite))
            ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0,) if decades > 2 else (1.0, 2.0, 5.0)))
            ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(layout, fontsize=10)
        ax.set_xlabel("boxes n", fontsize=8)
        cpu = all(r["cpu"] for r in rows)
        ax.set_ylabel("cost per step (µs, %s median)" % ("thread CPU" if cpu else "wall"), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", linewidth=0.3)
        ax.legend(fontsize=7, loc="upper left", title="growth exponent", title_fontsize=7)
    for ax in list(axes.flat)[len(layouts):]:
        ax.axis("off")
    rates = order((r["rate"] for r in rows), [])
    at = f"{rates[0]} Hz" if len(rates) == 1 else "rates as labelled"
    title = (f"Cost per physics step against the number of boxes ({at}; "
             "growth exponent: slope of log cost against log n)")
    if failed_rows:
        handle = plt.Line2D([], [], marker="x", color="red", linestyle="none", markeredgewidth=2)
        fig.legend([handle], ["failed (at the top edge when it has no cost)"], loc="lower center", fontsize=8)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0, 0.04 if failed_rows else 0, 1, 0.96))
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return layouts, [label for _, label, _ in lines], table, failed_rows


def print_table(layouts, labels, table):
    print("growth exponent: slope of log(cost per step) against log(n), n >= %d, rows that did not fail" % FIT_FROM)
    cells = [["layout"] + labels]
    for layout in layouts:
        row = [layout]
        for label in labels:
            if (layout, label) not in table:
                row.append("")
                continue
            fit = table[(layout, label)]
            row.append(f"{fit[0]:.2f} (n {fit[1]}-{fit[2]})" if fit else "-")
        cells.append(row)
    widths = [max(len(c[i]) for c in cells) for i in range(len(cells[0]))]
    for c in cells:
        print("  ".join(text.ljust(w) for text, w in zip(c, widths)).rstrip())


def main():
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        fail("usage: plot_scale.py DIR (with DIR/scale.csv)")
    d = sys.argv[1]
    rows = read(f"{d}/scale.csv")
    if not rows:
        print("wrote nothing (no rows)")
        return
    layouts, labels, table, failed_rows = chart(rows, f"{d}/scale.png")
    print_table(layouts, labels, table)
    for r in failed_rows:
        print(f"failed: {r['engine']} {r['layout']} n {r['n']} at {r['rate']} Hz: {r['failed']}")
    print(f"wrote {d}/scale.png")


if __name__ == "__main__":
    main()
