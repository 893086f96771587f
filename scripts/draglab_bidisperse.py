#!/usr/bin/python3
"""Reduce the bidisperse campaign (issue 36) to a per-species dataset, and draw F_i/F against y.

Usage:
  /usr/bin/python3 draglab_bidisperse.py reduce SPECIES.csv MONO.csv --out POINTS.csv
  /usr/bin/python3 draglab_bidisperse.py figure POINTS.csv --out FIG.png
                                           [--refit a0,a1,b0,b1,c0,c1] [--table TABLE.md]
  /usr/bin/python3 draglab_bidisperse.py compare-re STOKES_TABLE.csv RE_TABLE.csv --out TABLE.md
  /usr/bin/python3 draglab_bidisperse.py merge POINTS.csv POINTS.csv [...] --out POINTS.csv

SPECIES.csv and MONO.csv are what scripts/bidisperse_campaign.sh writes (with units.csv beside them:
each unit's engine error estimate): each size class of each finished unit (campaign, size_ratio, x_small, unit, phi, re_target, re, resolution, realization,
y, x, spheres, F_i, F_i_standard_error, F) and every unit of the monodisperse reference campaign
(campaign export --csv).

reduce: one point per (campaign, phi, Re, size class): the mean over the packings of
S = F_i/F_mono, F_mono the monodisperse campaign's mean F at the same phi and target Re, with
  - the standard error of that mean over the packings, combined with F_mono's own;
  - a discretisation error: the engine's error estimate of the worse-resolved of the unit and
    the monodisperse reference (made at the smallest diameter in lattice units);
and writes a `draglab fit` dataset (the columns of draglab's dataset CSV plus y) whose F is
F_bvk2007(phi, Re) * S, Re the mixture's achieved Re (on the Sauter mean diameter; in Stokes flow
F_vdh2005(phi), van der Hoef et al. 2005): the measured size factor carried onto the monodisperse
level every polydisperse law in the comparison shares.
So a fit of bvk2007_polyfit (F_bvk2007 [a(phi) y + b(phi) y^2 + c(phi) y^3], each coefficient
linear in phi) to it fits the size factor alone. Extra columns (campaign, size_ratio, x_small, x, S, mono_F) follow y;
`draglab fit` reads only its own columns, so they are dropped before it (the `fit` rows below).

figure: F_i/F_mono against y, one panel per phi, the data with 1-sigma error bars (standard
error and discretisation error combined), and each law's size factor: van der Hoef et al. (2005)
(1 - phi) y + phi y^2; Beetstra et al. (2007) with + 0.064 (1 - phi) y^3; Yin & Sundaresan
(MFiX HYS) [1/eps + (F - 1/eps)(a y + (1 - a) y^2)]/F with F = F_vdh2005(phi); and, with
--refit, the fitted (a0 + a1 phi) y + (b0 + b1 phi) y^2 + (c0 + c1 phi) y^3. --table writes the per-phi
table of the points (markdown).

compare-re: each finite-Re point's S against the Stokes point of the same mixture, phi and size
class (both *_table.csv files of reduce), as a markdown table with S_Re/S_Stokes. Needs python3-matplotlib and python3-numpy (Debian; run with
/usr/bin/python3). Bad input: exit 2 with one line naming the file and the column.
"""
import csv
import math
import os
import sys
import tempfile

import numpy as np


def fail(message):
    sys.stderr.write("draglab_bidisperse.py: " + message + "\n")
    sys.exit(2)


def read_rows(path):
    try:
        with open(path, newline="") as f:
            lines = [line for line in f if not line.startswith("#")]
    except OSError as e:
        fail("%s: %s" % (path, e.strerror))
    rows = list(csv.DictReader(lines))
    if not rows:
        fail("%s: no data rows" % path)
    return rows


def column(rows, path, name, kind=float):
    try:
        return [kind(r[name]) for r in rows]
    except KeyError:
        fail("%s: no column '%s'" % (path, name))
    except (TypeError, ValueError):
        fail("%s: column '%s' holds a value that is not a number" % (path, name))


def sha256_of(path):
    import hashlib
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def vdh2005(phi):
    eps = 1.0 - phi
    return 10.0 * phi / eps ** 2 + eps ** 2 * (1.0 + 1.5 * math.sqrt(phi))


def bvk2007(phi, re):
    """F of Beetstra et al. (2007) as drag_db/src/laws/bvk2007.h writes it (= vdh2005 at Re 0)."""
    eps = 1.0 - phi
    if re <= 0.0:
        return vdh2005(phi)
    numerator = re * (1.0 / eps + 3.0 * phi * eps) + 8.4 * re ** (1.0 - 0.343)
    denominator = 1.0 + 10.0 ** (3.0 * phi) * re ** (-(1.0 + 4.0 * phi) / 2.0)
    return vdh2005(phi) + 0.413 / (24.0 * eps ** 2) * numerator / denominator


def mean_and_error(values):
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, 0.0
    var = sum((v - mean) ** 2 for v in values) / (n - 1)
    return mean, math.sqrt(var / n)


def reduce_points(species_path, mono_path, out_path):
    species = read_rows(species_path)
    mono = read_rows(mono_path)
    for name in ("phi", "re_target", "F", "error_estimate", "status"):
        column(mono, mono_path, name, str)
    mono_by_phi = {}
    for r in mono:
        if r["status"] != "done":
            continue
        mono_by_phi.setdefault((float(r["phi"]), float(r["re_target"])), []).append(
            (float(r["F"]), float(r["error_estimate"])))
    units = {}
    for name in ("campaign", "size_ratio", "x_small", "unit", "phi", "re_target", "y", "x",
                 "F_i"):
        column(species, species_path, name, str)
    errors = {}
    for r in species:
        key = (r["campaign"], float(r["phi"]), float(r["re_target"]), round(float(r["y"]), 12))
        units.setdefault(key, []).append(r)
    # The engine's error estimate per unit is in the unit export, not in the species rows:
    # units.csv beside SPECIES.csv (campaign, id, error_estimate).
    units_path = os.path.join(os.path.dirname(os.path.abspath(species_path)), "units.csv")
    for r in read_rows(units_path):
        if r["error_estimate"]:  # empty for a unit that has not finished
            errors[(r["campaign"], r["id"])] = float(r["error_estimate"])
    out = []
    for (campaign, phi, re_target, y), rows in sorted(units.items()):
        if (phi, re_target) not in mono_by_phi:
            fail("%s: no finished monodisperse unit at phi = %g, Re = %g" % (mono_path, phi,
                                                                            re_target))
        mono_F, mono_se = mean_and_error([f for f, _ in mono_by_phi[(phi, re_target)]])
        mono_err = max(e for _, e in mono_by_phi[(phi, re_target)])
        # The mixture's achieved Re (on the Sauter mean diameter), the same for both classes.
        re = sum(float(r["re"]) for r in rows) / len(rows) if re_target > 0.0 else 0.0
        ratios = [float(r["F_i"]) / mono_F for r in rows]
        S, se = mean_and_error(ratios)
        se_rel = math.hypot(se / S, mono_se / mono_F)
        unit_err = max([errors.get((campaign, r["unit"]), 0.0) for r in rows] + [0.0])
        disc_rel = max(unit_err, mono_err)
        level = bvk2007(phi, re)
        out.append({
            "phi": phi, "re_target": re_target, "re": re, "F": level * S,
            "F_standard_error": level * S * se_rel,
            "F_discretisation_error": level * S * disc_rel,
            "F_uncertainty": level * S * math.hypot(se_rel, disc_rel),
            "realizations": len(rows), "y": y, "campaign": campaign,
            "size_ratio": float(rows[0]["size_ratio"]), "x_small": float(rows[0]["x_small"]),
            "x": float(rows[0]["x"]), "S": S, "S_uncertainty": S * math.hypot(se_rel, disc_rel),
            "mono_F": mono_F})
    with open(out_path, "w") as f:
        f.write("# per-species size factor S = F_i/F_mono of the bidisperse campaign, carried onto "
                "the bvk2007 level at the mixture's Re (vdh2005 in Stokes flow): "
                "F = F_bvk2007(phi, Re) S\n")
        f.write("# from %s and %s by scripts/draglab_bidisperse.py reduce (sha256 of the inputs: %s, "
                "%s)\n" % (os.path.basename(species_path), os.path.basename(mono_path),
                           sha256_of(species_path)[:16], sha256_of(mono_path)[:16]))
        f.write("phi,re_target,re,F,F_standard_error,F_discretisation_error,F_uncertainty,"
                "realizations,y\n")
        for p in out:
            f.write("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%.17g\n" % (
                p["phi"], p["re_target"], p["re"], p["F"], p["F_standard_error"],
                p["F_discretisation_error"], p["F_uncertainty"], p["realizations"], p["y"]))
    with open(out_path[:-4] + "_table.csv" if out_path.endswith(".csv") else out_path + ".table",
              "w") as f:
        f.write("# the points of %s per size class: S = F_i/F_mono and its uncertainty "
                "(scripts/draglab_bidisperse.py reduce)\n" % os.path.basename(out_path))
        f.write("campaign,size_ratio,x_small,phi,re_target,re,y,x,realizations,S,S_uncertainty,"
                "mono_F\n")
        for p in out:
            f.write("%s,%g,%g,%g,%g,%.3f,%.6f,%.4f,%d,%.5f,%.5f,%.5f\n" % (
                p["campaign"], p["size_ratio"], p["x_small"], p["phi"], p["re_target"], p["re"],
                p["y"], p["x"],
                p["realizations"], p["S"], p["S_uncertainty"], p["mono_F"]))
    print("wrote %s (%d points)" % (out_path, len(out)))


def factor_bvk(phi, y, g=0.064):
    return (1 - phi) * y + phi * y * y + g * (1 - phi) * y ** 3


def factor_refit(phi, y, c):
    return ((c[0] + c[1] * phi) * y + (c[2] + c[3] * phi) * y * y
            + (c[4] + c[5] * phi) * y ** 3)


def factor_hys(phi, y, re=0.0):
    eps = 1.0 - phi
    a = 1 - 2.66 * phi + 9.096 * phi ** 2 - 11.338 * phi ** 3
    F = bvk2007(phi, re)
    return (1 / eps + (F - 1 / eps) * (a * y + (1 - a) * y * y)) / F


def figure(points_path, fig_path, refit, table_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = read_rows(points_path)
    phi = np.array(column(rows, points_path, "phi"))
    y = np.array(column(rows, points_path, "y"))
    F = np.array(column(rows, points_path, "F"))
    U = np.array(column(rows, points_path, "F_uncertainty"))
    re_target = np.array(column(rows, points_path, "re_target"))
    re = np.array(column(rows, points_path, "re"))
    level = np.array([bvk2007(p, r) for p, r in zip(phi, re)])
    S, dS = F / level, U / level
    panels = sorted(set(zip(phi, re_target)))
    cols = 3
    nrows = int(math.ceil(len(panels) / cols))
    fig, axes = plt.subplots(nrows, cols, figsize=(12, 4 * nrows), squeeze=False)
    yy = np.linspace(0.2, max(2.6, float(y.max()) * 1.04), 200)
    for k, (p, r) in enumerate(panels):
        ax = axes[k // cols][k % cols]
        m = (phi == p) & (re_target == r)
        ax.errorbar(y[m], S[m], yerr=dS[m], fmt="o", ms=4, color="k", label="LBM (this work)")
        ax.plot(yy, factor_bvk(p, yy, g=0.0), "--", label="van der Hoef 2005")
        ax.plot(yy, factor_bvk(p, yy), "-", label="Beetstra 2007 (bvk2007_poly)")
        re_mean = float(re[m].mean())
        ax.plot(yy, factor_hys(p, yy, re_mean), ":", label="Yin-Sundaresan (MFiX HYS)")
        if refit:
            ax.plot(yy, factor_refit(p, yy, refit), "-", lw=2, label="refit (bvk2007_polyfit)")
        ax.set_title("phi = %g" % p if r == 0 else "phi = %g, Re = %g" % (p, r))
        ax.set_xlabel("y = d_i/<d>")
        ax.set_ylabel("F_i / F(phi)")
        ax.set_xlim(0.2, float(yy[-1]))
        ax.grid(alpha=0.3)
        if k == 0:
            ax.legend(fontsize=8)
    for k in range(len(panels), nrows * cols):
        axes[k // cols][k % cols].axis("off")
    flow = "Stokes flow" if not re_target.any() else "finite Re"
    fig.suptitle("Bidisperse random arrays, %s: each size class's drag over the "
                 "monodisperse F at the same phi and Re" % flow)
    fig.tight_layout()
    d = os.path.dirname(os.path.abspath(fig_path))
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=d)
    os.close(fd)
    fig.savefig(tmp, dpi=130)
    os.replace(tmp, fig_path)
    print("wrote %s" % fig_path)
    if table_path:
        with open(table_path, "w") as f:
            f.write("| phi | Re | y | F_i/F (LBM) | vdH 2005 | BVK 2007 | HYS |%s\n"
                    % (" refit |" if refit else ""))
            f.write("|---|---|---|---|---|---|---|%s\n" % ("---|" if refit else ""))
            for i in np.lexsort((y, re_target, phi)):
                f.write("| %g | %g | %.3f | %.3f ± %.3f | %.3f | %.3f | %.3f |%s\n" % (
                    phi[i], re_target[i], y[i], S[i], dS[i], factor_bvk(phi[i], y[i], g=0.0),
                    factor_bvk(phi[i], y[i]), factor_hys(phi[i], y[i], re[i]),
                    (" %.3f |" % factor_refit(phi[i], y[i], refit)) if refit else ""))
        print("wrote %s" % table_path)


def compare_re(stokes_path, re_path, out_path):
    """Markdown: each finite-Re point's size factor S against the Stokes one of the same mixture,
    phi and size class (the *_table.csv files reduce writes), with the ratio's uncertainty."""
    def table(path):
        rows = read_rows(path)
        for name in ("campaign", "size_ratio", "x_small", "phi", "re_target", "re", "y", "S",
                     "S_uncertainty"):
            column(rows, path, name, str)
        return rows
    key = lambda r: (float(r["size_ratio"]), float(r["x_small"]), float(r["phi"]),
                     round(float(r["y"]), 3))
    stokes = {key(r): r for r in table(stokes_path) if float(r["re_target"]) == 0.0}
    lines = ["| size ratio | phi | y | S, Stokes | Re | S at Re | S_Re / S_Stokes |",
             "|---|---|---|---|---|---|---|"]
    matched = 0
    for r in sorted(table(re_path), key=lambda r: key(r) + (float(r["re_target"]),)):
        base = stokes.get(key(r))
        if base is None or float(r["re_target"]) == 0.0:
            continue
        s0, u0 = float(base["S"]), float(base["S_uncertainty"])
        s1, u1 = float(r["S"]), float(r["S_uncertainty"])
        ratio = s1 / s0
        lines.append("| %g | %g | %.3f | %.3f ± %.3f | %.1f | %.3f ± %.3f | %.3f ± %.3f |" % (
            float(r["size_ratio"]), float(r["phi"]), float(r["y"]), s0, u0, float(r["re"]),
            s1, u1, ratio, ratio * math.hypot(u0 / s0, u1 / s1)))
        matched += 1
    if matched == 0:
        fail("%s: no point matches a Stokes point of %s (same mixture, phi and y)" % (re_path,
                                                                                    stokes_path))
    with open(out_path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote %s (%d points)" % (out_path, matched))


def merge_points(paths, out_path):
    """One `draglab fit` dataset from several reduce outputs (same columns), e.g. the Stokes and
    the finite-Re points, so that one fit covers both."""
    header = None
    rows = []
    for path in paths:
        try:
            with open(path) as f:
                lines = [line for line in f if not line.startswith("#")]
        except OSError as e:
            fail("%s: %s" % (path, e.strerror))
        if not lines:
            fail("%s: no header" % path)
        if header is None:
            header = lines[0]
        elif lines[0] != header:
            fail("%s: its columns differ from %s's" % (path, paths[0]))
        rows += lines[1:]
    with open(out_path, "w") as f:
        f.write("# per-species size factors, merged by scripts/draglab_bidisperse.py merge from "
                + ", ".join("%s (sha256 %s)" % (p, sha256_of(p)[:16]) for p in paths) + "\n")
        f.write(header)
        f.writelines(rows)
    print("wrote %s (%d points)" % (out_path, len(rows)))


def main(argv):
    if len(argv) < 2 or argv[1] not in ("reduce", "figure", "compare-re", "merge"):
        fail("usage: reduce SPECIES.csv MONO.csv --out POINTS.csv | figure POINTS.csv --out "
             "FIG.png [--refit a0,a1,b0,b1,c0,c1] [--table TABLE.md] | compare-re "
             "STOKES_TABLE.csv RE_TABLE.csv --out TABLE.md | merge POINTS.csv POINTS.csv... "
             "--out POINTS.csv")
    args = argv[2:]
    opts = {}
    positional = []
    i = 0
    while i < len(args):
        if args[i].startswith("--"):
            if i + 1 >= len(args):
                fail("%s needs a value" % args[i])
            opts[args[i]] = args[i + 1]
            i += 2
        else:
            positional.append(args[i])
            i += 1
    if "--out" not in opts:
        fail("--out is required")
    if argv[1] == "reduce":
        if len(positional) != 2:
            fail("reduce takes SPECIES.csv MONO.csv")
        reduce_points(positional[0], positional[1], opts["--out"])
    elif argv[1] == "merge":
        if len(positional) < 2:
            fail("merge takes two or more POINTS.csv")
        merge_points(positional, opts["--out"])
    elif argv[1] == "compare-re":
        if len(positional) != 2:
            fail("compare-re takes STOKES_TABLE.csv RE_TABLE.csv (the *_table.csv of reduce)")
        compare_re(positional[0], positional[1], opts["--out"])
    else:
        if len(positional) != 1:
            fail("figure takes POINTS.csv")
        refit = None
        if "--refit" in opts:
            try:
                refit = [float(v) for v in opts["--refit"].split(",")]
            except ValueError:
                refit = []
            if len(refit) != 6:
                fail("--refit takes a0,a1,b0,b1,c0,c1 (six numbers)")
        figure(positional[0], opts["--out"], refit, opts.get("--table"))


if __name__ == "__main__":
    main(sys.argv)
