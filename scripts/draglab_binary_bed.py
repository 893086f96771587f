#!/usr/bin/python3
"""Bubble and segregation of a bed of two sizes, per drag law, from a sensitivity study.

Usage: /usr/bin/python3 draglab_binary_bed.py SENSITIVITY.json --out DIR [--table TABLE.md]
                                              [--csv SERIES.csv]

SENSITIVITY.json is what `draglab sensitivity SCENE --realizations N` writes for a DPM scene
with size classes (data/scenes/dpm_binary.toml): per law, the runs of N packings (seeds), each
with its series of samples, among them the segregation index (mean height of the smallest size
class minus that of the largest, over the mean height of all particles; docs/dpm.md). Writes
  - DIR/binary_bed.png: (a) the segregation index against time per law, the mean over the
    packings with a band of one standard error; (b) the bubble diameter against time, the same;
  - the table (stdout, and TABLE.md with --table): per law the bubble diameter at t_ref (the
    study's estimate with its uncertainty: the packings' spread and the grid's cell), and the
    segregation index at t_ref and at the end of the run, mean +- standard error over the
    packings, its change over the run, and that change minus the first law's on the same packing
    (paired: the packings' own spread cancels), mean +- standard error;
  - with --csv, every run's series: law, seed, t_s, bubble_diameter_m, segregation_index.
Needs python3-matplotlib and python3-numpy (Debian; run with /usr/bin/python3). A file without
a law, runs or the segregation series stops the script with one line naming the key: exit 2.
"""
import json
import math
import os
import sys
import tempfile

import numpy as np


def fail(message):
    sys.stderr.write("draglab_binary_bed.py: " + message + "\n")
    sys.exit(2)


def mean_se(values):
    v = np.asarray(values, dtype=float)
    if v.size < 2:
        return float(v.mean()), float("nan")
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size))


def load(path):
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        fail("%s: %s" % (path, e))
    laws = data.get("laws")
    if not laws:
        fail("%s: no 'laws'" % path)
    out = []
    for law in laws:
        runs = law.get("runs") or fail("%s: law %s has no 'runs'" % (path, law.get("law")))
        series = []
        for r in runs:
            s = r.get("series", {})
            if "segregation_index" not in s:
                fail("%s: law %s, seed %s: no series.segregation_index (a bed of one size?)"
                     % (path, law.get("law"), r.get("seed")))
            series.append((np.asarray(s["t_s"]), np.asarray(s["segregation_index"]),
                           np.asarray(s["bubble_diameter_m"]), r.get("seed")))
        out.append((law, series))
    return data, out


def main(argv):
    args = argv[1:]
    if not args or args[0].startswith("--"):
        fail("usage: SENSITIVITY.json --out DIR [--table TABLE.md] [--csv SERIES.csv]")
    path = args[0]
    opts = dict(zip(args[1::2], args[2::2]))
    if "--out" not in opts:
        fail("--out DIR is required")
    data, laws = load(path)
    t_ref = data.get("t_ref_s")
    rows = []
    first_change = None
    for law, series in laws:
        n = min(len(t) for t, _, _, _ in series)
        t = series[0][0][:n]
        seg = np.array([s[:n] for _, s, _, _ in series])
        i_ref = int(np.argmin(np.abs(t - t_ref))) if t_ref is not None else n - 1
        at_ref = mean_se(seg[:, i_ref])
        at_end = mean_se(seg[:, -1])
        changes = seg[:, -1] - seg[:, 0]
        change = mean_se(changes)
        paired = None
        if first_change is None:
            first_change = changes
        elif len(changes) == len(first_change):
            paired = mean_se(changes - first_change)
        rows.append((law["law"], law.get("d_estimate_m"), law.get("uncertainty_m"), len(series),
                     at_ref, at_end, change, paired))
    first = rows[0][0]
    lines = ["| law | packings | bubble D at t_ref | segregation at t_ref | at the end | "
             "change over the run | change minus %s's, per packing |" % first,
             "|---|---|---|---|---|---|---|"]
    for name, d, u, k, ref, end, change, paired in rows:
        dtxt = "%.1f ± %.1f mm" % (1e3 * d, 1e3 * u) if d is not None and u is not None else "-"
        ptxt = "%+.4f ± %.4f" % paired if paired is not None else ""
        lines.append("| %s | %d | %s | %+.4f ± %.4f | %+.4f ± %.4f | %+.4f ± %.4f | %s |"
                     % (name, k, dtxt, ref[0], ref[1], end[0], end[1], change[0], change[1], ptxt))
    print("\n".join(lines))
    if "--table" in opts:
        with open(opts["--table"], "w") as f:
            f.write("\n".join(lines) + "\n")

    if "--csv" in opts:
        with open(opts["--csv"], "w") as f:
            f.write("law,seed,t_s,bubble_diameter_m,segregation_index\n")
            for law, series in laws:
                for t, seg, d, seed in series:
                    for k in range(len(t)):
                        f.write("%s,%s,%.6g,%.6g,%.6g\n" % (law["law"], seed, t[k], d[k], seg[k]))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    for law, series in laws:
        n = min(len(t) for t, _, _, _ in series)
        t = series[0][0][:n]
        for ax, k in ((ax1, 1), (ax2, 2)):
            v = np.array([s[k][:n] for s in series]) * (1e3 if k == 2 else 1.0)
            m = v.mean(axis=0)
            se = v.std(axis=0, ddof=1) / math.sqrt(v.shape[0]) if v.shape[0] > 1 else 0 * m
            line, = ax.plot(t, m, label=law["law"])
            ax.fill_between(t, m - se, m + se, color=line.get_color(), alpha=0.25)
    ax1.set_xlabel("t after the jet start [s]")
    ax1.set_ylabel("segregation index (h_small - h_large)/h")
    ax1.set_title("(a) segregation, mean ± s.e. over the packings")
    ax2.set_xlabel("t after the jet start [s]")
    ax2.set_ylabel("bubble diameter [mm]")
    ax2.set_title("(b) bubble diameter, mean ± s.e.")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("%s: bed of two sizes, per drag law" % data.get("scene", ""))
    fig.tight_layout()
    os.makedirs(opts["--out"], exist_ok=True)
    target = os.path.join(opts["--out"], "binary_bed.png")
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=opts["--out"])
    os.close(fd)
    fig.savefig(tmp, dpi=130)
    os.replace(tmp, target)
    print("wrote %s" % target)


if __name__ == "__main__":
    main(sys.argv)
