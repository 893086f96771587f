#!/usr/bin/python3
"""Render the figures and the Markdown summary of `draglab report` from its bundle.

Usage: /usr/bin/python3 draglab_report.py BUNDLE.json OUT_DIR [--quiet]

The bundle (written by `draglab report`, format "draglab_report_bundle" version 1, described in
docs/report.md) holds the dataset, every law evaluated on smooth curves and at the data points,
the residual statistics and the campaign's units; this script only draws. It needs Debian's
python3-matplotlib (run it with /usr/bin/python3) and nothing else.

Writes into OUT_DIR: fig3_seed.png (the seed paper's Fig. 3 and a Stokes panel), parity.png,
residuals.png, work_precision.png (only if the bundle has finished campaign units) and report.md
linking them. Conventions: canonical drag-only F = F_d/(3 pi mu d eps u), superficial
Re = rho eps d u/mu, beta d^2/mu = 18 phi eps F.
"""
import json
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # no display on build machines
    import matplotlib.pyplot as plt
except ImportError as exc:  # the C++ side checks first; this is for direct use
    sys.stderr.write(
        "error: matplotlib is not importable by %s (%s); install the Debian package "
        "python3-matplotlib and run this script with /usr/bin/python3\n" % (sys.executable, exc)
    )
    sys.exit(1)

BUNDLE_FORMAT = "draglab_report_bundle"
FIGURES = ("fig3_seed.png", "parity.png", "residuals.png", "work_precision.png")
# Line styles by law role/name: the fit is the solid line, the literature laws are told apart by
# dashes so that colour can stay the phi of the curve (as in the seed's Fig. 3).
KNOWN_STYLES = {"vdh2004": "--", "ergun": ":", "hill_koch_ladd": "-.", "bvk2007": (0, (6, 2, 1, 2, 1, 2))}
EXTRA_STYLES = [(0, (1, 1)), (0, (3, 1, 1, 1, 1, 1)), (0, (8, 2)), (0, (2, 2))]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<", ">"]


def log(quiet, message):
    if not quiet:
        sys.stderr.write(message + "\n")


def finite(x):
    return x is not None and isinstance(x, (int, float)) and math.isfinite(x)


def law_styles(laws):
    styles, extra = {}, 0
    for law in laws:
        if law.get("role") == "fit":
            styles[law["reference"]] = "-"
        elif law.get("name") in KNOWN_STYLES:
            styles[law["reference"]] = KNOWN_STYLES[law["name"]]
        else:
            styles[law["reference"]] = EXTRA_STYLES[extra % len(EXTRA_STYLES)]
            extra += 1
    return styles


def phi_colours(phis):
    cmap = plt.get_cmap("viridis")
    n = len(phis)
    return {phi: cmap(0.85 * i / max(n - 1, 1)) for i, phi in enumerate(phis)}


def split_validity(xs, ys, outside):
    """(inside, outside) copies of ys with NaN where the other part is, joined at the boundary."""
    inside_y, outside_y = [], []
    for i, y in enumerate(ys):
        y = y if finite(y) else float("nan")
        out = bool(outside[i]) if outside else False
        inside_y.append(float("nan") if out else y)
        # Outside part keeps its neighbours inside the box so that the dotted piece joins the line.
        near = out or (i > 0 and outside and outside[i - 1]) or (
            i + 1 < len(ys) and outside and outside[i + 1])
        outside_y.append(y if near else float("nan"))
    return inside_y, outside_y


def plot_law_line(ax, xs, ys, outside, colour, style, label, width):
    inside_y, outside_y = split_validity(xs, ys, outside)
    ax.plot(xs, inside_y, linestyle=style, color=colour, lw=width, label=label)
    if outside and any(outside):
        ax.plot(xs, outside_y, linestyle=style, color=colour, lw=0.6, alpha=0.5)


def primary_laws(bundle):
    """Laws shown in the parity and residual plots: the fitted ones, else every law."""
    fits = [law for law in bundle["laws"] if law.get("role") == "fit"]
    return fits if fits else bundle["laws"]


def figure_seed(bundle, out_dir):
    points = bundle["dataset"]["points"]
    laws = bundle["laws"]
    styles = law_styles(laws)
    phis = sorted({p["phi"] for p in points})
    colours = phi_colours(phis)
    flowing = [p for p in points if p["re"] > 0]
    stokes = [p for p in points if p["re"] <= 0]

    fig, (ax, ax_stokes) = plt.subplots(1, 2, figsize=(14, 6.2),
                                        gridspec_kw={"width_ratios": [1.6, 1]})
    # Left: y = (beta d^2/mu) eps/((1-eps) Re) = 18 eps^2 F/Re against x = Re/(1-eps) = Re/phi.
    for phi in phis:
        eps = 1.0 - phi
        sel = [p for p in flowing if p["phi"] == phi]
        if sel:
            ax.errorbar([p["re"] / phi for p in sel],
                        [18.0 * eps * eps * p["F"] / p["re"] for p in sel],
                        yerr=[18.0 * eps * eps * p["F_uncertainty"] / p["re"] for p in sel],
                        fmt="o", ms=5, color=colours[phi], capsize=2, zorder=5,
                        label="data, phi = %.3g" % phi)
    for law in laws:
        width = 2.0 if law.get("role") == "fit" else 1.2
        for curve in law.get("curves", []):
            phi = curve["phi"]
            eps = 1.0 - phi
            xs = [re / phi for re in curve["re"]]
            ys = [18.0 * eps * eps * f / re if finite(f) else None
                  for f, re in zip(curve["F"], curve["re"])]
            plot_law_line(ax, xs, ys, curve.get("outside_validity"),
                          colours.get(phi, "black"), styles[law["reference"]], None, width)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("Re / (1 - eps) = Re / phi      (Re = rho eps d u / mu, superficial)")
    ax.set_ylabel("(beta d^2/mu) eps / ((1 - eps) Re) = 18 eps^2 F / Re")
    ax.set_title("Seed Fig. 3: data (symbols) and laws (lines, colour = phi)")
    ax.grid(True, which="both", alpha=0.25)
    if not flowing:
        ax.text(0.5, 0.5, "no data at Re > 0", transform=ax.transAxes, ha="center")
    # Legends: symbols and colours give phi, line styles give the law.
    from matplotlib.lines import Line2D
    law_handles = [Line2D([], [], color="black", linestyle=styles[law["reference"]],
                          lw=2.0 if law.get("role") == "fit" else 1.2, label=law["label"])
                   for law in laws]
    first = ax.legend(handles=law_handles, loc="upper right", fontsize=8, title="laws")
    ax.add_artist(first)
    if flowing:
        ax.legend(loc="lower right", fontsize=8)

    # Right: Stokes limit F(phi, Re = 0), not representable on the left (y ~ 1/Re).
    law_colours = plt.get_cmap("tab10")
    for i, law in enumerate(laws):
        sc = law.get("stokes_curve")
        if sc:
            plot_law_line(ax_stokes, sc["phi"], sc["F"], sc.get("outside_validity"),
                          "black" if law.get("role") == "fit" else law_colours(i % 10),
                          styles[law["reference"]], law["label"],
                          2.0 if law.get("role") == "fit" else 1.2)
    for phi in phis:
        sel = [p for p in stokes if p["phi"] == phi]
        if sel:
            ax_stokes.errorbar([p["phi"] for p in sel], [p["F"] for p in sel],
                               yerr=[p["F_uncertainty"] for p in sel], fmt="o", ms=5,
                               color=colours[phi], capsize=2, zorder=5)
    ax_stokes.set_yscale("log")
    ax_stokes.set_xlabel("phi = 1 - eps")
    ax_stokes.set_ylabel("F(phi, Re = 0)  (drag only, F = F_d / (3 pi mu d eps u))")
    ax_stokes.set_title("Stokes flow: data and the laws' Stokes limits")
    ax_stokes.grid(True, which="both", alpha=0.25)
    ax_stokes.legend(fontsize=8)
    if not stokes:
        ax_stokes.text(0.5, 0.9, "no Re = 0 data in this dataset", transform=ax_stokes.transAxes,
                       ha="center")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fig3_seed.png"), dpi=100)
    plt.close(fig)


def figure_parity(bundle, out_dir):
    points = bundle["dataset"]["points"]
    laws = primary_laws(bundle)
    fig, ax = plt.subplots(figsize=(7, 6.5))
    f_data = [p["F"] for p in points]
    lo, hi = min(f_data), max(f_data)
    for i, law in enumerate(laws):
        f_law = law["at_points"]["F"]
        sel = [k for k, f in enumerate(f_law) if finite(f)]
        lo = min([lo] + [f_law[k] for k in sel])
        hi = max([hi] + [f_law[k] for k in sel])
        ax.errorbar([f_data[k] for k in sel], [f_law[k] for k in sel],
                    xerr=[points[k]["F_uncertainty"] for k in sel], fmt=MARKERS[i % len(MARKERS)],
                    ms=5, capsize=2, label=law["label"])
    lo, hi = lo / 1.3, hi * 1.3
    ax.plot([lo, hi], [lo, hi], "k-", lw=1, label="1:1")
    ax.fill_between([lo, hi], [0.95 * lo, 0.95 * hi], [1.05 * lo, 1.05 * hi], color="grey",
                    alpha=0.2, label="+-5 %")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.set_xlabel("F data (with 1-sigma uncertainty)")
    ax.set_ylabel("F law")
    fitted = any(law.get("role") == "fit" for law in bundle["laws"])
    ax.set_title("Parity: %s against data" % ("fit" if fitted else "laws (no fitted law given)"))
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "parity.png"), dpi=100)
    plt.close(fig)


def figure_residuals(bundle, out_dir):
    points = bundle["dataset"]["points"]
    laws = primary_laws(bundle)
    fig, (ax_phi, ax_re) = plt.subplots(1, 2, figsize=(13, 5.5), sharey=True)
    positive_re = [p["re"] for p in points if p["re"] > 0]
    for i, law in enumerate(laws):
        f_law = law["at_points"]["F"]
        sel = [k for k, f in enumerate(f_law) if finite(f)]
        ratio = [f_law[k] / points[k]["F"] for k in sel]
        resid = [r - 1.0 for r in ratio]
        # Relative uncertainty of the residual from the data: (F_fit/F_data) sigma_F/F_data.
        err = [r * points[k]["F_uncertainty"] / points[k]["F"] for r, k in zip(ratio, sel)]
        marker = MARKERS[i % len(MARKERS)]
        ax_phi.errorbar([points[k]["phi"] for k in sel], resid, yerr=err, fmt=marker, ms=5,
                        capsize=2, label=law["label"])
        ax_re.errorbar([points[k]["re"] for k in sel], resid, yerr=err, fmt=marker, ms=5,
                       capsize=2, label=law["label"])
    for ax in (ax_phi, ax_re):
        ax.axhline(0.0, color="black", lw=1)
        ax.axhspan(-0.05, 0.05, color="grey", alpha=0.15)
        ax.grid(True, alpha=0.25)
    ax_phi.set_xlabel("phi")
    ax_phi.set_ylabel("F_law / F_data - 1")
    ax_phi.set_title("Relative residuals against phi")
    # Re = 0 (Stokes) points must stay visible: linear near 0, logarithmic above.
    linthresh = min(positive_re) if positive_re else 1.0
    ax_re.set_xscale("symlog", linthresh=linthresh)
    ax_re.set_xlim(left=-0.3 * linthresh)  # keep the Re = 0 markers off the frame
    ax_re.set_xlabel("Re (superficial; symlog axis, Stokes points at 0)")
    ax_re.set_title("Relative residuals against Re")
    ax_re.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "residuals.png"), dpi=100)
    plt.close(fig)


def figure_work_precision(bundle, out_dir):
    """Draws error estimate against wall time of the finished units; returns a note for report.md."""
    units = bundle.get("units") or []
    done = [u for u in units if u.get("status") == "done" and finite(u.get("wall_s"))
            and finite(u.get("error_estimate")) and u["wall_s"] > 0 and u["error_estimate"] > 0]
    if not done:
        # Drawn anyway, saying why it is empty, so that the report's set of figures is fixed.
        note = ("no finished campaign units with a positive error estimate and wall time "
                "(imported dataset, or a campaign this database does not hold)")
        fig, ax = plt.subplots(figsize=(7.5, 6))
        ax.text(0.5, 0.5, "no campaign units:\n" + note.replace(" (", "\n("), ha="center",
                va="center", transform=ax.transAxes, wrap=True)
        ax.set_axis_off()
        ax.set_title("Work-precision of the campaign's units")
        fig.savefig(os.path.join(out_dir, "work_precision.png"), dpi=100)
        plt.close(fig)
        return note + ": the figure is empty"
    resolutions = sorted({u["resolution"] for u in done})
    cmap = plt.get_cmap("plasma")
    fig, ax = plt.subplots(figsize=(7.5, 6))
    for i, d in enumerate(resolutions):
        sel = [u for u in done if u["resolution"] == d]
        ax.scatter([u["wall_s"] for u in sel], [u["error_estimate"] for u in sel], s=28,
                   color=cmap(0.85 * i / max(len(resolutions) - 1, 1)),
                   label="d = %.3g (%d units)" % (d, len(sel)))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("unit wall time (s)")
    ax.set_ylabel("unit error estimate (relative, engine's estimate)")
    ax.set_title("Work-precision of the campaign's units (colour = resolution d)")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "work_precision.png"), dpi=100)
    plt.close(fig)
    failed = sum(1 for u in units if u.get("status") == "failed")
    return "%d finished unit(s) plotted%s" % (
        len(done), "; %d failed unit(s) not shown" % failed if failed else "")


def fmt(x, digits=4):
    return "%.*g" % (digits, x) if finite(x) else "-"


def pct(x):
    return "%.2f %%" % (100 * x) if finite(x) else "-"


def coefficient_table(law):
    lines = ["| parameter | value | 95 % interval | unit |", "|---|---|---|---|"]
    ci = law.get("ci95")
    free = law.get("fitter", {}).get("free_parameters")
    for i, p in enumerate(law["parameters"]):
        interval = "-"
        if free is not None and p["name"] not in free:
            interval = "fixed"
        elif ci and ci[i] is not None:
            lo, hi = ci[i]
            interval = "fixed" if lo == hi else "[%s, %s]" % (fmt(lo, 5), fmt(hi, 5))
        lines.append("| %s | %s | %s | %s |" % (p["name"], fmt(p["value"], 6), interval,
                                               p.get("unit", "1")))
    return lines


def write_markdown(bundle, out_dir, drawn, work_note):
    ds = bundle["dataset"]
    points = ds["points"]
    md = ["# Drag report: dataset %s" % (ds.get("id") or ds.get("name") or "?"), ""]
    md.append("Dataset `%s` (%s), %d points, phi %s-%s, Re %s-%s; %s." % (
        ds.get("id", ""), ds.get("name", ""), len(points), fmt(min(p["phi"] for p in points)),
        fmt(max(p["phi"] for p in points)), fmt(min(p["re"] for p in points)),
        fmt(max(p["re"] for p in points)),
        ("campaign %s" % ds["campaign_id"]) if ds.get("campaign_id") else "no campaign"))
    if ds.get("hash"):
        md.append("Data hash `%s`." % ds["hash"])
    md.append("Generated by draglab %s at %s." % (bundle.get("code_version", "?"),
                                                  bundle.get("generated_at", "?")))
    md += ["", "## Figures", ""]
    captions = {
        "fig3_seed.png": "Seed Fig. 3: (beta d^2/mu) eps/((1-eps) Re) against Re/(1-eps), "
                         "data and laws; Stokes panel F(phi, Re = 0)",
        "parity.png": "Parity: law F against data F (1:1 line, +-5 % band)",
        "residuals.png": "Relative residuals F_law/F_data - 1 against phi and Re",
        "work_precision.png": "Campaign units: error estimate against wall time",
    }
    for name in FIGURES:
        if name in drawn:
            md += ["- [%s](%s)" % (captions[name], name), "", "  ![%s](%s)" % (name, name), ""]
    md.append("Work-precision: %s." % work_note)
    md += ["", "## Fitted coefficients", ""]
    fits = [law for law in bundle["laws"] if law.get("role") == "fit"]
    if not fits:
        md.append("No fitted law was given (`--law NAME@V`).")
    for law in fits:
        md += ["### %s (form `%s`, %s)" % (law["reference"], law.get("form", "?"),
                                           law.get("status", "?")), ""]
        md += coefficient_table(law)
        md.append("")
        stats = law.get("fitter", {}).get("statistics")
        if stats:
            md.append("Fit statistics (from the fitter's record): %s points, dof %s, "
                      "chi^2/dof %s, RMS relative error %s, max %s, k-fold CV RMS %s." % (
                          stats.get("num_points", "-"), stats.get("dof", "-"),
                          fmt(stats.get("chi2_per_dof")), fmt(stats.get("rms_rel_err")),
                          fmt(stats.get("max_rel_err")), fmt(stats.get("cv_rms_rel_err"))))
            md.append("")
        if not law.get("ci95"):
            md.append("No covariance stored with this version: no intervals.")
        elif law.get("ci95_method") == "student_t":
            md.append("95 % intervals: the fitter's own (Student t with the fit's degrees of "
                      "freedom, covariance scaled by chi^2/dof when above 1); 'fixed' = not "
                      "fitted.")
        else:
            md.append("95 % intervals: value +- 1.96 sqrt(covariance diagonal) (normal "
                      "quantile); 'fixed' = not fitted, '-' = no covariance stored.")
        md.append("")
    md += ["## Laws against the data", "",
           "Relative difference |F_law/F_data - 1| over the %d data points." % len(points), "",
           "| law | role | max rel. diff. | RMS rel. diff. | points evaluated | outside validity |",
           "|---|---|---|---|---|---|"]
    for law in bundle["laws"]:
        s = law.get("stats", {})
        md.append("| %s | %s | %s | %s | %s | %s |" % (
            law["label"], law.get("role", ""), fmt(s.get("max_rel_diff")),
            fmt(s.get("rms_rel_diff")), s.get("n_evaluated", "-"), s.get("n_outside_validity", "-")))
    for missing in bundle.get("missing_laws", []):
        md.append("| %s | reference | not in the database: %s | | | |" % (
            missing["reference"], missing.get("reason", "")))
    md += ["", "Points outside a law's validity box are evaluated by extrapolating its formula "
           "(range policy `extrapolate`); the figures draw those parts of the curves thin.", ""]
    rows = bundle.get("form_comparison") or []
    if rows:
        md += ["## Forms compared", "",
               "Each form refitted to these points (free parameters chosen by the subset "
               "selection: the largest set the data determine, ties by AICc) beside the laws as "
               "published. CV = 5-fold cross-validation RMS relative error (for a law as "
               "published nothing was fitted, so it equals its RMS error).", "",
               "| law | fitted parameters | RMS rel. error | max rel. error | CV RMS | AICc |",
               "|---|---|---|---|---|---|"]
        for r in rows:
            if r.get("error"):
                md.append("| %s | refit failed: %s | | | | |" % (r["label"], r["error"]))
                continue
            md.append("| %s | %s | %s | %s | %s | %s |" % (
                r["label"], ", ".join(r.get("free") or []) or "none (as published)",
                pct(r.get("rms_rel_err")), pct(r.get("max_rel_err")),
                pct(r.get("cv_rms_rel_err")), fmt(r.get("aicc"))))
        md.append("")
    md += ["## Conventions", ""]
    for key, text in bundle.get("conventions", {}).items():
        md.append("- %s: %s" % (key, text))
    md += ["", "Re-render: `/usr/bin/python3 draglab_report.py report_bundle.json DIR` "
           "(see docs/report.md).", ""]
    with open(os.path.join(out_dir, "report.md.partial"), "w") as f:
        f.write("\n".join(md))
    os.replace(os.path.join(out_dir, "report.md.partial"), os.path.join(out_dir, "report.md"))


def main(argv):
    args = [a for a in argv[1:] if a != "--quiet"]
    quiet = "--quiet" in argv[1:]
    if len(args) != 2:
        sys.stderr.write("usage: draglab_report.py BUNDLE.json OUT_DIR [--quiet]\n")
        return 2
    bundle_path, out_dir = args
    with open(bundle_path) as f:
        bundle = json.load(f)
    if bundle.get("format") != BUNDLE_FORMAT:
        sys.stderr.write("error: %s is not a draglab report bundle (format '%s')\n" %
                         (bundle_path, bundle.get("format")))
        return 2
    if not bundle["dataset"]["points"]:
        sys.stderr.write("error: the bundle's dataset has no points\n")
        return 2
    os.makedirs(out_dir, exist_ok=True)
    for name in FIGURES + ("report.md",):  # an earlier report's files must not pass for ours
        if os.path.exists(os.path.join(out_dir, name)):
            os.remove(os.path.join(out_dir, name))
    figure_seed(bundle, out_dir)
    figure_parity(bundle, out_dir)
    figure_residuals(bundle, out_dir)
    work_note = figure_work_precision(bundle, out_dir)
    drawn = [name for name in FIGURES if os.path.exists(os.path.join(out_dir, name))]
    write_markdown(bundle, out_dir, drawn, work_note)
    log(quiet, "report: wrote %s and %s" % (", ".join(drawn), "report.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
