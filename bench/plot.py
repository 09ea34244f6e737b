#!/usr/bin/env python3
"""Draw the plots of a `treelod bench` output directory.

usage: python3 bench/plot.py DIR [--out OUTDIR]

DIR/plots.json lists the plots the bench wrote data for; each entry names its CSV file, the PNG
to write, the CSV columns on the x and y axes, the title, axis labels and log axes:

  {"plots": [{"csv": "frame-time.csv", "png": "frame-time.png", "x": "time_s", "y": "frame_ms",
              "title": "...", "xLabel": "...", "yLabel": "...", "logX": false, "logY": true,
              "markers": false}]}

Each CSV has a header line, a `series` column (rows of one series form one line, in file order)
and a `label` column (its legend text). An empty or non-finite value is a gap in the line, and on
a log axis so is a value <= 0. A row whose `marker` column (optional) is not empty is a single
labelled point drawn with that matplotlib marker (o, s, ^, x, D) in black, not part of a line:
the trade plot's polygonal reference and floors. Rows whose `on_front` column (optional) is 1 are
the Pareto front: a thin grey step line through them, in order of x, and a circle round each. A
plot without data still gets its axes and title, and reads "no data".

Needs matplotlib (Debian: apt install python3-matplotlib); exits 3 without it.
"""
import argparse
import csv
import json
import math
import os
import sys


def number(text):
    """The CSV value as a float; NaN when empty or not a number."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def drawable(value, log):
    return math.isfinite(value) and (not log or value > 0.0)


def read_series(path, x_column, y_column, log_x, log_y):
    """(lines, markers, front): lines as [(label, xs, ys)] in order of first appearance, gaps as
    NaN; markers as [(label, x, y, shape)]; front as [(x, y)] sorted by x."""
    lines = {}
    markers = []
    front = []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            x, y = number(row.get(x_column)), number(row.get(y_column))
            if not (drawable(x, log_x) and drawable(y, log_y)):
                x = y = math.nan
            if (row.get("on_front") or "").strip() == "1" and math.isfinite(x):
                front.append((x, y))
            shape = (row.get("marker") or "").strip()
            if shape:
                if math.isfinite(x):
                    markers.append((row.get("label", ""), x, y, shape))
                continue
            key = row.get("series", "")
            if key not in lines:
                lines[key] = (row.get("label") or key, [], [])
            lines[key][1].append(x)
            lines[key][2].append(y)
    return list(lines.values()), markers, sorted(front)


def draw(plt, ticker, directory, out_directory, spec):
    log_x, log_y = bool(spec.get("logX")), bool(spec.get("logY"))
    lines, markers, front = read_series(os.path.join(directory, spec["csv"]), spec["x"], spec["y"], log_x, log_y)
    figure, axes = plt.subplots(figsize=(9.6, 6.0), dpi=100)
    has_data = False
    for i, (label, xs, ys) in enumerate(lines):
        has_data = has_data or any(math.isfinite(v) for v in xs)
        # Past the colour cycle's ten colours, dashed then dotted: no two lines look alike.
        axes.plot(xs, ys, label=label or None, linewidth=2.0, marker="o" if spec.get("markers", True) else None,
                  markersize=5, linestyle=("-", "--", ":")[(i // 10) % 3])
    for label, x, y, shape in markers:
        has_data = True
        axes.plot([x], [y], linestyle="none", marker=shape, markersize=9, color="black",
                  markerfacecolor="none" if shape != "x" else "black", markeredgewidth=1.5, label=label or None)
    if front:
        # Behind the data; each step keeps a point's error up to the next point's frame time.
        axes.plot([x for x, _ in front], [y for _, y in front], drawstyle="steps-post", color="grey",
                  linewidth=0.8, marker="o", markersize=15, markerfacecolor="none", markeredgecolor="grey",
                  markeredgewidth=1.0, label="Pareto front", zorder=1)
    for log, axis, scale in ((log_x, axes.xaxis, axes.set_xscale), (log_y, axes.yaxis, axes.set_yscale)):
        if log and has_data:
            scale("log")
            # Plain numbers (20, 300) rather than 2x10^1; in-between ticks labelled on short ranges.
            axis.set_major_formatter(ticker.LogFormatter())
            axis.set_minor_formatter(ticker.LogFormatter(labelOnlyBase=False, minor_thresholds=(2, 0.5)))
    axes.set_title(spec.get("title", ""), fontsize=11)
    axes.set_xlabel(spec.get("xLabel", ""))
    axes.set_ylabel(spec.get("yLabel", ""))
    axes.grid(True, which="major", color="#dddddd")
    if has_data:
        if any(label for label, _, _ in lines) or any(m[0] for m in markers):
            axes.legend(loc="best", fontsize=9)
    else:
        axes.text(0.5, 0.5, "no data", transform=axes.transAxes, ha="center", va="center", fontsize=14)
    figure.tight_layout()
    path = os.path.join(out_directory, spec["png"])
    figure.savefig(path)
    plt.close(figure)
    return path


def main():
    parser = argparse.ArgumentParser(description="Draw the plots of a treelod bench output directory.")
    parser.add_argument("directory", help="the bench's output directory (holds plots.json)")
    parser.add_argument("--out", help="where to write the PNGs (default: the directory)")
    parser.add_argument("-v", "--verbose", action="store_true", help="print each PNG written")
    args = parser.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import matplotlib.ticker as ticker
    except ImportError:
        print("plot.py: needs matplotlib (Debian: apt install python3-matplotlib)", file=sys.stderr)
        return 3
    manifest = os.path.join(args.directory, "plots.json")
    try:
        with open(manifest) as f:
            plots = json.load(f)["plots"]
    except (OSError, ValueError, KeyError) as e:
        print(f"plot.py: {manifest}: {e}", file=sys.stderr)
        return 2
    out_directory = args.out or args.directory
    os.makedirs(out_directory, exist_ok=True)
    for spec in plots:
        path = draw(plt, ticker, args.directory, out_directory, spec)
        if args.verbose:
            print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
