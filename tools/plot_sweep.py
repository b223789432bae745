#!/usr/bin/python3
"""Plot a graspsim sweep's pass/fail over its first two grid axes.

    tools/plot_sweep.py DIR/sweep.csv --out DIR/sweep.png

`graspsim sweep` runs it after writing its table (README.md "Sweeps"). The grid axes are the
table's columns between `run` and `seed` (or `status`). Each cell is one point of the first two
axes: the runs there (every seed, every value of later axes) that met every expectation (status
`pass`) out of all of them, as "k/n" on a colour from red (none) to green (all); a run that
ended in an error counts as not passing and is marked "!". With one axis the other is the seed,
with none the seed alone.

Exit status: 0 written, 2 bad input (missing or unreadable table, no runs), 1 when
python3-matplotlib is missing. Needs Debian's python3-matplotlib, hence /usr/bin/python3.
"""

import argparse
import csv
import os
import sys
import tempfile


def fail(message, status=2):
    print(f"plot_sweep.py: {message}", file=sys.stderr)
    sys.exit(status)


def read_table(path):
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
            header = list(rows[0].keys()) if rows else []
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    if not rows or header[0] != "run" or "status" not in header:
        fail(f"{path}: not a graspsim sweep table (no runs, or no run and status columns)")
    end = header.index("seed") if "seed" in header else header.index("status")
    return header[1:end], rows


def ordered(values):
    seen = []
    for v in values:
        if v not in seen:
            seen.append(v)
    return seen


def main():
    parser = argparse.ArgumentParser(description="Plot a graspsim sweep's pass/fail.")
    parser.add_argument("table")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    axes, rows = read_table(args.table)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("needs python3-matplotlib (Debian package)", 1)

    x_name = axes[0] if axes else "seed"
    y_name = axes[1] if len(axes) > 1 else ("seed" if axes and "seed" in rows[0] else None)
    xs = ordered(r[x_name] for r in rows)
    ys = ordered(r[y_name] for r in rows) if y_name else [""]
    fig, ax = plt.subplots(figsize=(1.2 * len(xs) + 2.5, 0.8 * len(ys) + 1.8))
    cmap = plt.get_cmap("RdYlGn")
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            cell = [r for r in rows if r[x_name] == x and (not y_name or r[y_name] == y)]
            if not cell:
                continue
            passed = sum(r["status"] == "pass" for r in cell)
            errors = sum(r["status"] == "error" for r in cell)
            ax.add_patch(plt.Rectangle((i - 0.5, j - 0.5), 1, 1, color=cmap(passed / len(cell))))
            ax.text(i, j, f"{passed}/{len(cell)}" + (" !" if errors else ""), ha="center", va="center", color="white",
                    fontsize=10)
    ax.set_xlim(-0.5, len(xs) - 0.5)
    ax.set_ylim(-0.5, len(ys) - 0.5)
    ax.set_xticks(range(len(xs)), xs)
    ax.set_yticks(range(len(ys)), ys)
    ax.set_xlabel(x_name)
    if y_name:
        ax.set_ylabel(y_name)
    ax.set_title("runs meeting every expectation, of runs", fontsize=10)
    fig.tight_layout()
    # Written beside the output and renamed, so an earlier plot is replaced only by a whole one.
    folder = os.path.dirname(os.path.abspath(args.out))
    try:
        fd, partial = tempfile.mkstemp(suffix=".png", dir=folder)
        os.close(fd)
        fig.savefig(partial, dpi=100)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(partial, 0o666 & ~umask)   # as an ordinary new file, not mkstemp's 0600
        os.replace(partial, args.out)
    except OSError as e:
        fail(f"{args.out}: cannot write: {e.strerror}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
