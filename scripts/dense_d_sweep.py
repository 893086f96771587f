#!/usr/bin/python3
"""Convergence in d of campaign units: the extrapolated drag and the check of each run's estimate.

Reads `draglab campaign export NAME --csv` files of campaigns that differ only in their
resolution (data/campaigns/dense_d_sweep_8/), groups the units by (phi, Re, realization) and, per
group with at least two finished resolutions:
  - the Richardson value of the two finest d at order 2 (the interpolated wall's order), and,
    with three d whose differences keep their sign, the observed order p and the Richardson value
    at p; the extrapolation's spread is the distance between the finest F and the values at order
    2 and at p (the largest of the two), which is how far the finest run may still be off;
  - each run's true error against the reference (the order-2 Richardson value where the sequence
    is monotone, else the finest run, its spread then the last refinement's move) beside its
    recorded error_estimate, and whether it is within.

With --plot FILE.png, a figure: per (phi, Re) the drag against 1/d^2 (an order-2 wall is a
straight line there) with each run's error estimate as its bar (clipped at 25 %, the bar of an
under-resolved run runs off the panel), the reference at 1/d^2 = 0, at the panel's foot a cross
for each diverged (failed) run and a circle for each run still going on, and, with --draglab BIN,
the published laws of the comparison (`draglab law eval`) as horizontal lines.

Usage: scripts/dense_d_sweep.py CSV... [--out FILE] [--plot FILE.png [--draglab BIN]]
"""
import argparse
import csv
import io
import math
import subprocess
import sys

LAWS = ("bvk2007", "tang2015", "tenneti2011")


def read_units(path):
    """The finished and failed units of an exported campaign CSV (its '#' header skipped)."""
    with open(path, encoding="utf-8") as f:
        text = "".join(line for line in f if not line.startswith("#"))
    units = []
    for row in csv.DictReader(io.StringIO(text)):
        units.append({
            "phi": float(row["phi"]),
            "re": float(row["re_target"]),
            "realization": int(row["realization"]),
            "d": float(row["resolution"]),
            "status": row["status"],
            "F": float(row["F"]) if row["F"] else math.nan,
            "estimate": float(row["error_estimate"]) if row["error_estimate"] else math.nan,
            "steps": int(row["steps"]) if row["steps"] else 0,
            "wall_s": float(row["wall_s"]) if row["wall_s"] else math.nan,
            "diagnosis": row["diagnosis"],
            "file": path,
        })
    return units


def observed_order(d, F):
    """Order p with F(d) = F_inf + C d^-p through three points (d ascending), or None."""
    h = [1.0 / x for x in d]
    a, b = F[0] - F[1], F[1] - F[2]
    if a == 0.0 or b == 0.0 or (a > 0) != (b > 0):
        return None
    target = a / b

    def ratio(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p)

    lo, hi = 0.05, 8.0
    if not (ratio(lo) - target) * (ratio(hi) - target) < 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (ratio(lo) - target) * (ratio(mid) - target) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def richardson(d1, F1, d2, F2, p):
    """Extrapolated value from two resolutions d1 < d2 at order p."""
    r = (d2 / d1) ** p
    return (r * F2 - F1) / (r - 1.0)


def reduce(units):
    groups = {}
    for u in units:
        groups.setdefault((u["phi"], u["re"], u["realization"]), []).append(u)
    table = []
    for key in sorted(groups):
        runs = sorted(groups[key], key=lambda u: u["d"])
        done = [u for u in runs if u["status"] == "done"]
        ref = rich2 = richp = p = None
        spread = None
        if len(done) >= 2:
            a, b = done[-2], done[-1]
            rich2 = richardson(a["d"], a["F"], b["d"], b["F"], 2.0)
            monotone = True
            if len(done) >= 3:
                c = done[-3]
                p = observed_order([c["d"], a["d"], b["d"]], [c["F"], a["F"], b["F"]])
                monotone = p is not None
                if p is not None:
                    richp = richardson(a["d"], a["F"], b["d"], b["F"], p)
            if monotone:
                ref = rich2
                spread = max(abs(b["F"] - rich2), abs(b["F"] - richp) if richp is not None else 0.0)
            else:  # no extrapolation: the finest run, as far off as the last refinement moved it
                ref, rich2 = b["F"], None
                spread = abs(b["F"] - a["F"])
        for u in runs:
            true_error = (u["F"] / ref - 1.0) if (ref and u["status"] == "done") else math.nan
            table.append({
                "phi": key[0], "re": key[1], "realization": key[2], "d": u["d"],
                "status": u["status"], "F": u["F"], "error_estimate": u["estimate"],
                "true_error": true_error,
                "within": ("" if math.isnan(true_error) or u is done[-1]
                           else int(abs(true_error) <= u["estimate"])),
                "reference": ref if ref is not None else math.nan,
                "richardson_order2": rich2 if rich2 is not None else math.nan,
                "observed_order": p if p is not None else math.nan,
                "richardson_observed": richp if richp is not None else math.nan,
                "extrapolation_spread": spread if spread is not None else math.nan,
                "steps": u["steps"], "wall_s": u["wall_s"], "diagnosis": u["diagnosis"],
            })
    return table


def law_value(draglab, law, phi, re):
    """F of a stored law at (phi, Re), or None where it does not apply."""
    run = subprocess.run([draglab, "--json", "law", "eval", law, "--phi", repr(phi), "--re",
                          repr(re)], capture_output=True, text=True, check=False)
    if run.returncode != 0:
        return None
    import json
    return json.JSONDecoder().raw_decode(run.stdout.lstrip())[0].get("F")


def plot(table, path, draglab):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    keys = sorted({(r["phi"], r["re"]) for r in table}, key=lambda k: (k[1], k[0]))
    fig, axes = plt.subplots(1, len(keys), figsize=(3.6 * len(keys), 3.6), squeeze=False)
    for ax, (phi, re) in zip(axes[0], keys):
        rows = [r for r in table if r["phi"] == phi and r["re"] == re]
        done = [r for r in rows if r["status"] == "done"]
        x = [1.0 / r["d"] ** 2 for r in done]
        y = [r["F"] for r in done]
        err = [min(r["error_estimate"], 0.25) * r["F"] for r in done]
        ax.errorbar(x, y, yerr=err, fmt="o", color="C0", capsize=3, label="LBM, estimate as bar")
        for r in done:
            ax.annotate("d %g" % r["d"], (1.0 / r["d"] ** 2, r["F"]), textcoords="offset points",
                        xytext=(5, -10), fontsize=7)
        ref = rows[0]["reference"]
        if not math.isnan(rows[0]["richardson_order2"]):
            ax.plot([0.0], [ref], "*", color="C3", markersize=10, label="order-2 Richardson")
        elif not math.isnan(ref):
            ax.plot([0.0], [ref], "_", color="C3", markersize=12, label="finest run (reference)")
        lo = min(y) if y else 0.0
        hi = max(y) if y else 1.0
        if draglab:
            for i, law in enumerate(LAWS):
                v = law_value(draglab, law, phi, re)
                if v is not None:
                    ax.axhline(v, color="C%d" % (i + 4), ls="--", lw=1, label=law)
                    lo, hi = min(lo, v), max(hi, v)
        for r in rows:
            if r["status"] != "done":
                # failed: the run diverged or stopped; otherwise it is still running (in parts)
                what, mark = ("diverged", "x") if r["status"] == "failed" else ("running", "o")
                ax.plot([1.0 / r["d"] ** 2], [lo - 0.04 * (hi - lo)], mark, color="k",
                        fillstyle="none")
                ax.annotate("d %g %s" % (r["d"], what), (1.0 / r["d"] ** 2, lo - 0.04 * (hi - lo)),
                            textcoords="offset points", xytext=(-20, 6), fontsize=7)
        pad = 0.12 * (hi - lo) + 0.02 * hi
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_xlim(left=-0.00005)
        ax.set_title("phi %g, Re %g" % (phi, re), fontsize=10)
        ax.set_xlabel("1/d^2")
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("F (drag-only, canonical)")
    axes[0][0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--out")
    ap.add_argument("--plot")
    ap.add_argument("--draglab", help="draglab binary for the laws' values in the plot")
    args = ap.parse_args()
    units = []
    for path in args.csv:
        units += read_units(path)
    if not units:
        print("error: no units in " + ", ".join(args.csv), file=sys.stderr)
        return 2
    table = reduce(units)
    fields = list(table[0].keys())
    out = open(args.out, "w", encoding="utf-8", newline="") if args.out else sys.stdout
    if args.out:
        out.write("# scripts/dense_d_sweep.py " + " ".join(args.csv) + "\n")
    w = csv.DictWriter(out, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    for row in table:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    if args.out:
        out.close()
    if args.plot:
        plot(table, args.plot, args.draglab)
    checked = [r for r in table if r["within"] != ""]
    beyond = [r for r in checked if r["within"] == 0]
    print("%d runs checked against their reference, %d beyond their estimate" %
          (len(checked), len(beyond)), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
