#!/usr/bin/env python3
"""Plots for docs/ from the evaluation and benchmark outputs (matplotlib,
Debian python3-matplotlib):

  pose error over time per robot       mrclam_eval ... --out-dir DIR  (errors_robotR_seedS.csv)
  ATE distribution over segment starts mrclam_eval ... --segments 60 --out-dir DIR  (segments.csv)
  end-to-end latency histogram         bench_latency --out DIR/latency.csv

Usage: scripts/plot_results.py DIR [--out-dir docs/plots] [--seed N]
Writes mrclam_error_over_time.png, mrclam_segment_ate.png, latency_histogram.png
for whichever inputs DIR holds (a missing one is named and skipped). Exit
status: 0 at least one plot written, 1 none (no input), 2 usage error.
"""
import argparse
import csv
import glob
import os
import re
import sys


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def column(rows, name):
    return [float(r[name]) for r in rows]


def quantile(sorted_values, q):
    """Linear interpolation between ranks, as mrclam_eval's summaries."""
    rank = q * (len(sorted_values) - 1)
    lo = int(rank)
    hi = min(lo + 1, len(sorted_values) - 1)
    return sorted_values[lo] + (rank - lo) * (sorted_values[hi] - sorted_values[lo])


def sorted_column(indir, name, col):
    """The column of indir/name sorted, or None when the file is absent or empty."""
    path = os.path.join(indir, name)
    if not os.path.exists(path):
        return None
    values = sorted(column(read_csv(path), col))
    return values or None


def mark_quantiles(ax, values, marks, y_of, unit_format):
    """A dashed line and a label at each (q, label) of marks; y_of(i) places label i."""
    for i, (q, label) in enumerate(marks):
        v = quantile(values, q)
        ax.axvline(v, linestyle="--", color="grey", linewidth=0.8)
        ax.text(v, y_of(i), f" {label} {unit_format.format(v)}", fontsize=8)


def save(plt, fig, out, name):
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def error_over_time(plt, indir, seed, out):
    files = [f for f in sorted(glob.glob(os.path.join(indir, f"errors_robot*_seed{seed}.csv"))) if read_csv(f)]
    if not files:
        return None
    fig, (ax_pos, ax_head) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    for path in files:
        robot = re.search(r"errors_robot(\d+)_seed", path).group(1)
        rows = read_csv(path)
        t = column(rows, "t_s")
        line, = ax_pos.plot(t, column(rows, "position_m"), linewidth=1, label=f"robot {robot}")
        ax_pos.plot(t, column(rows, "dr_position_m"), linewidth=0.8, linestyle=":", color=line.get_color())
        ax_head.plot(t, [abs(h) for h in column(rows, "heading_deg")], linewidth=1, color=line.get_color())
    ax_pos.set_ylabel("position error [m]")
    ax_pos.set_ylim(0, 2.0)
    ax_pos.set_title(f"Dataset6, filter (solid) and dead reckoning (dotted), seed {seed}")
    ax_pos.legend(loc="upper left", ncol=5, fontsize=8)
    ax_pos.grid(alpha=0.3)
    ax_head.set_ylabel("|heading error| [deg]")
    ax_head.set_xlabel("time since the robot's first ground-truth pose [s]")
    ax_head.grid(alpha=0.3)
    return save(plt, fig, out, "mrclam_error_over_time.png")


def segment_distribution(plt, indir, out):
    ate = sorted_column(indir, "segments.csv", "ate_m")
    if ate is None:
        return None
    n = len(ate)
    fig, (ax_hist, ax_cdf) = plt.subplots(1, 2, figsize=(11, 4))
    ax_hist.hist(ate, bins=30, color="#4c72b0")
    ax_hist.set_xlabel("ATE of the restarted run [m]")
    ax_hist.set_ylabel("segment starts")
    ax_hist.set_title(f"{n} restarts from the truth every 60 s")
    ax_cdf.plot(ate, [(i + 1) / n for i in range(n)], color="#4c72b0")
    mark_quantiles(ax_cdf, ate, ((0.5, "median"), (0.9, "p90")), lambda i: (0.05, 0.15)[i], "{:.3f} m")
    ax_cdf.set_xlabel("ATE [m]")
    ax_cdf.set_ylabel("fraction of segment starts")
    ax_cdf.set_title(f"mean {sum(ate) / n:.3f} m, worst {ate[-1]:.3f} m")
    ax_cdf.grid(alpha=0.3)
    return save(plt, fig, out, "mrclam_segment_ate.png")


def latency_histogram(plt, indir, out):
    lat = sorted_column(indir, "latency.csv", "latency_ms")
    if lat is None:
        return None
    n = len(lat)
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.hist(lat, bins=40, color="#55a868")
    mark_quantiles(ax, lat, ((0.5, "p50"), (0.99, "p99")), lambda i: ax.get_ylim()[1] * (0.9, 0.7)[i], "{:.2f} ms")
    ax.set_xlabel("Odometry published -> MapState received [ms]")
    ax.set_ylabel("samples")
    ax.set_title(f"end-to-end latency through slam_estimator on loopback, {n} samples")
    return save(plt, fig, out, "latency_histogram.png")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    parser.add_argument("dir", help="the folder of mrclam_eval --out-dir (and latency.csv)")
    parser.add_argument("--out-dir", default="docs/plots", help="where the PNGs go (default docs/plots)")
    parser.add_argument("--seed", type=int, default=1, help="the seed of the error-over-time plot (default 1)")
    args = parser.parse_args()
    if not os.path.isdir(args.dir):
        parser.error(f"{args.dir}: not a folder")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_results: matplotlib missing (apt install python3-matplotlib)", file=sys.stderr)
        return 1
    os.makedirs(args.out_dir, exist_ok=True)
    written = 0
    for name, make in (("errors_robot*_seed%d.csv" % args.seed, lambda: error_over_time(plt, args.dir, args.seed, args.out_dir)),
                       ("segments.csv", lambda: segment_distribution(plt, args.dir, args.out_dir)),
                       ("latency.csv", lambda: latency_histogram(plt, args.dir, args.out_dir))):
        path = make()
        if path:
            print(f"plot_results: {path}")
            written += 1
        else:
            print(f"plot_results: no (or an empty) {name} in {args.dir}: skipped", file=sys.stderr)
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
