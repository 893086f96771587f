#!/usr/bin/python3
"""Draw the figures of `draglab sensitivity` from its JSON data.

Usage: /usr/bin/python3 draglab_fig4.py DATA.json OUT_DIR [--beside OTHER.json] [--quiet]

DATA.json is either
  - sensitivity.json (format "draglab_sensitivity" version 1): writes OUT_DIR/fig4.png, the seed
    paper's Fig. 4: one panel per drag law side by side, the bed (x width, y height, equal
    aspect) at t_ref after injection, particles drawn to their diameter and coloured by their
    initial layer in alternating contrasting colours (as the experiment's coloured layers, so
    mixing shows), the eps = threshold contour of the bubble over them, and the title
    "law@v  D = x.x +- y.y cm"; and OUT_DIR/bubble_series.png, D and the bubble's centroid
    height against time per law and run, t_ref marked;
    A continuum model's snapshot (the two-fluid model: no particles) is drawn as the solids
    fraction 1 - eps in grey scale (white empty, black at the packing limit), as the seed's
    Fig. 5. With --beside OTHER.json (another sensitivity.json, typically the DPM's of the same
    laws) it also writes OUT_DIR/fig5.png, the seed's Fig. 5: OTHER's panels above DATA's, every
    panel as solids fraction in grey scale, matched by law, each titled with its model, time and
    D +- uncertainty;
  - work_precision.json (format "draglab_work_precision" version 1): writes
    OUT_DIR/work_precision.png, the bubble diameter and its error against wall time.
Both are described in docs/scenes.md ("Sensitivity and work-precision"). This script only
draws; it needs Debian's python3-matplotlib (run it with /usr/bin/python3) and nothing else.
"""
import json
import math
import os
import sys
import textwrap

try:
    import matplotlib

    matplotlib.use("Agg")  # no display on build machines
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    from matplotlib.collections import EllipseCollection
    import numpy as np
except ImportError as exc:  # the C++ side checks first; this is for direct use
    sys.stderr.write(
        "error: matplotlib is not importable by %s (%s); install the Debian package "
        "python3-matplotlib and run this script with /usr/bin/python3\n" % (sys.executable, exc)
    )
    sys.exit(1)

# Alternating layer colours: dark blue and amber contrast in colour and in grey scale.
LAYER_COLOURS = ("#1d3557", "#f4a300")
CONTOUR_COLOUR = "#d62828"


def log(quiet, message):
    if not quiet:
        sys.stderr.write(message + "\n")


def save_figure(fig, out_dir, name, quiet):
    """Lays out, writes OUT_DIR/NAME at 130 dpi, closes the figure and says so."""
    fig.tight_layout()
    path = os.path.join(out_dir, name)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    log(quiet, "wrote " + path)


def finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def bubble_only_field(field, bubble, threshold):
    """The void fraction with every above-threshold region except the bubble pulled just below the
    threshold, so that the threshold contour outlines the bubble only (not the freeboard or other
    voids). The bubble is the 4-connected region above the threshold, below the bed surface, whose
    centroid is nearest the reported one (draglab's bubble.h finds it from the jet; its cells are
    not in the data, its centroid and area are)."""
    nx, ny = field["nx"], field["ny"]
    eps = np.array(field["values"], dtype=float).reshape(ny, nx)  # row j from the bottom
    dx, dy = field["width_m"] / nx, field["height_m"] / ny
    below = np.nextafter(threshold, 0.0)
    if not bubble or not bubble.get("found"):
        return np.minimum(eps, below)
    surface = bubble.get("bed_height_m", field["height_m"])
    label = -np.ones((ny, nx), dtype=int)
    regions = []
    for j0 in range(ny):
        for i0 in range(nx):
            if label[j0, i0] >= 0 or eps[j0, i0] <= threshold or (j0 + 0.5) * dy >= surface:
                continue
            k = len(regions)
            stack, cells = [(j0, i0)], []
            label[j0, i0] = k
            while stack:
                j, i = stack.pop()
                cells.append((j, i))
                for jj, ii in ((j + 1, i), (j - 1, i), (j, i + 1), (j, i - 1)):
                    if 0 <= jj < ny and 0 <= ii < nx and label[jj, ii] < 0 \
                            and eps[jj, ii] > threshold and (jj + 0.5) * dy < surface:
                        label[jj, ii] = k
                        stack.append((jj, ii))
            cx = sum((i + 0.5) * dx for _, i in cells) / len(cells)
            cy = sum((j + 0.5) * dy for j, _ in cells) / len(cells)
            regions.append((cx, cy, len(cells)))
    if not regions:
        return np.minimum(eps, below)
    bx, by = bubble["centroid_x_m"], bubble["centroid_y_m"]
    best = min(range(len(regions)), key=lambda k: (
        (regions[k][0] - bx) ** 2 + (regions[k][1] - by) ** 2, -regions[k][2]))
    out = np.minimum(eps, below)
    out[label == best] = eps[label == best]
    return out


def solids_grid(field):
    """Cell faces [cm] and the solids fraction 1 - eps (row j from the bottom) of a snapshot."""
    nx, ny = field["nx"], field["ny"]
    phi = 1.0 - np.array(field["values"], dtype=float).reshape(ny, nx)
    xf = np.linspace(0.0, field["width_m"], nx + 1) * 100
    yf = np.linspace(0.0, field["height_m"], ny + 1) * 100
    return xf, yf, phi


def draw_solids(ax, snap, threshold):
    """Grey-scale solids fraction of a snapshot with the bubble's threshold contour."""
    field = snap["void_fraction"]
    xf, yf, phi = solids_grid(field)
    ax.pcolormesh(xf, yf, phi, cmap="Greys", vmin=0.0, vmax=0.64, shading="flat")
    eps = bubble_only_field(field, snap.get("bubble"), threshold)
    nx, ny = field["nx"], field["ny"]
    if nx >= 2 and ny >= 2 and eps.max() > threshold:
        xc = (np.arange(nx) + 0.5) * field["width_m"] / nx * 100
        yc = (np.arange(ny) + 0.5) * field["height_m"] / ny * 100
        ax.contour(xc, yc, eps, levels=[threshold], colors=CONTOUR_COLOUR, linewidths=1.5)


def shown_height(laws, width, height):
    """The bed, not the freeboard: up to the highest particle top or the bed surface, + 15 %
    of the width."""
    top = 0.0
    for law in laws:
        snap = law.get("snapshot")
        if not snap:
            continue
        if snap["y"]:
            top = max(top, max(y + 0.5 * d for y, d in zip(snap["y"], snap["diameter"])))
        elif snap.get("bubble"):
            top = max(top, snap["bubble"].get("bed_height_m", 0.0))
    return min(height, top + 0.15 * width) if top > 0 else height


def draw_fig4(data, out_dir, quiet):
    laws = data["laws"]
    if not laws:
        raise SystemExit("error: the data hold no laws")
    width = data["geometry"]["width_m"]
    height = data["geometry"]["height_m"]
    threshold = data["eps_threshold"]
    shown = shown_height(laws, width, height)
    continuum = any(law.get("snapshot") and not law["snapshot"]["x"] for law in laws)
    panel_w = 2.6
    panel_h = min(8.0, max(2.0, panel_w * shown / width))
    fig_w = max(6.0, panel_w * len(laws) + 0.6)
    fig, axes = plt.subplots(1, len(laws), figsize=(fig_w, panel_h + 1.5), squeeze=False)
    for ax, law in zip(axes[0], laws):
        snap = law.get("snapshot")
        d_est, d_unc = law["d_estimate_m"], law["uncertainty_m"]
        if law.get("bubble_found"):
            size = "D = %.1f \u00b1 %.1f cm" % (100 * d_est, 100 * d_unc)
        else:
            size = "D = %.1f \u00b1 %.1f cm (no bubble in %d of %d runs)" % (
                100 * d_est, 100 * d_unc, len(law["runs"]) - law["bubbles_found"],
                len(law["runs"]))
        ax.set_title("%s  %s" % (law["law"], size), fontsize=9)
        ax.set_xlim(0, 100 * width)
        ax.set_ylim(0, 100 * shown)
        ax.set_aspect("equal")
        ax.set_xlabel("x [cm]")
        if not snap:
            ax.text(0.5, 0.5, "no snapshot\n(run ended before t_ref)", transform=ax.transAxes,
                    ha="center", va="center")
            continue
        if not snap["x"]:
            draw_solids(ax, snap, threshold)
            continue
        xy = np.column_stack([np.array(snap["x"]) * 100, np.array(snap["y"]) * 100])
        diam = np.array(snap["diameter"]) * 100
        colours = [LAYER_COLOURS[layer % 2] for layer in snap["layer"]]
        ax.add_collection(EllipseCollection(diam, diam, np.zeros_like(diam), units="xy",
                                            offsets=xy, offset_transform=ax.transData,
                                            facecolors=colours, edgecolors="none"))
        field = snap["void_fraction"]
        nx, ny = field["nx"], field["ny"]
        if nx >= 2 and ny >= 2:
            eps = bubble_only_field(field, snap.get("bubble"), threshold)
            # Cell centres plus the walls and the plate (edge values copied there), so that the
            # contour of a bubble on the plate or at a wall reaches it.
            eps = np.pad(eps, 1, mode="edge")
            xc = np.concatenate(([0.0], (np.arange(nx) + 0.5) * field["width_m"] / nx,
                                 [field["width_m"]])) * 100
            yc = np.concatenate(([0.0], (np.arange(ny) + 0.5) * field["height_m"] / ny,
                                 [field["height_m"]])) * 100
            if eps.max() > threshold:
                ax.contour(xc, yc, eps, levels=[threshold], colors=CONTOUR_COLOUR, linewidths=1.8)
    axes[0][0].set_ylabel("y [cm]")
    caption = ("%s: bubble %.3g s after injection; %s; red: "
               "\u03b5 = %.2f contour of the bubble; \u00b1 from %s (sensitivity.json)" % (
                   data["scene"], data["t_ref_s"],
                   "solids fraction in grey (black: 0.64)" if continuum
                   else "particles coloured by initial layer", threshold,
                   data["uncertainty"]["method"]))
    fig.suptitle(textwrap.fill(caption, width=int(16 * fig_w)), fontsize=9)
    save_figure(fig, out_dir, "fig4.png", quiet)


def draw_bubble_series(data, out_dir, quiet):
    """OUT_DIR/bubble_series.png: D and the bubble's centroid height against time after
    injection, one colour per law, one line style per packing realization (or grid), t_ref
    marked. Shows whether the snapshot falls while the bubble grows, holds or rains out. Data
    without time series (older files) draw nothing."""
    laws = data["laws"]
    if not laws or not all(r.get("series") for law in laws for r in law["runs"]):
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4.2))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ("-", "--", ":", "-.")
    for i, law in enumerate(laws):
        for k, run in enumerate(law["runs"]):
            series = run["series"]
            t = np.asarray(series["t_s"], dtype=float)
            keep = t >= 0.0
            label = "%s (seed %d, %dx%d)" % (law["law"], run["seed"], run["cells_x"], run["cells_y"])
            style = dict(color=colours[i % len(colours)], ls=styles[k % len(styles)], lw=1.4)
            left.plot(t[keep], 100 * np.asarray(series["bubble_diameter_m"])[keep], label=label,
                      **style)
            centroid = 100 * np.asarray(series["bubble_centroid_m"], dtype=float)[keep]
            right.plot(t[keep], np.where(centroid > 0, centroid, np.nan), **style)
    for ax in (left, right):
        ax.axvline(data["t_ref_s"], color="0.4", ls="--", lw=1)
        ax.set_xlabel("time after injection [s]")
        ax.grid(alpha=0.3)
    left.set_ylabel("bubble diameter D [cm]")
    right.set_ylabel("bubble centroid height [cm]")
    left.legend(fontsize=7, loc="lower center")
    fig.suptitle("%s: the bubble against time (dashed: t_ref = %g s)" % (
        data["scene"], data["t_ref_s"]), fontsize=10)
    save_figure(fig, out_dir, "bubble_series.png", quiet)


def draw_fig5(above, below, out_dir, quiet):
    """OUT_DIR/fig5.png: the seed's Fig. 5, one column per law present in both data sets,
    `above`'s snapshot over `below`'s, each as solids fraction in grey scale with the bubble
    contour, titled with the scene, the time after injection and D +- uncertainty."""
    laws_above = {law["law"]: law for law in above["laws"]}
    names = [law["law"] for law in below["laws"] if law["law"] in laws_above]
    if not names:
        raise SystemExit("error: --beside: the two data sets share no law")
    width = below["geometry"]["width_m"]
    rows = (above, below)
    shown = max(shown_height(d["laws"], width, d["geometry"]["height_m"]) for d in rows)
    panel_w = 2.4
    panel_h = min(6.0, max(2.0, panel_w * shown / width))
    fig, axes = plt.subplots(2, len(names), figsize=(max(6.0, panel_w * len(names) + 0.6),
                                                     2 * panel_h + 1.6), squeeze=False)
    for r, data in enumerate(rows):
        by_law = {law["law"]: law for law in data["laws"]}
        for c, name in enumerate(names):
            ax, law = axes[r][c], by_law[name]
            snap = law.get("snapshot")
            ax.set_xlim(0, 100 * width)
            ax.set_ylim(0, 100 * shown)
            ax.set_aspect("equal")
            t = snap["t_s"] if snap else data["t_ref_s"]
            ax.set_title("%s %s\nt = %.2f s  D = %.1f \u00b1 %.1f cm" % (
                data["scene"], name, t, 100 * law["d_estimate_m"], 100 * law["uncertainty_m"]),
                fontsize=8)
            if snap:
                draw_solids(ax, snap, data["eps_threshold"])
            else:
                ax.text(0.5, 0.5, "no snapshot", transform=ax.transAxes, ha="center")
        axes[r][0].set_ylabel("y [cm]")
    if abs(above["t_ref_s"] - below["t_ref_s"]) > 1e-9:
        note = " (NOT the same time after injection: %g s above, %g s below)" % (
            above["t_ref_s"], below["t_ref_s"])
    else:
        note = ""
    fig.suptitle(textwrap.fill("Bubble per law, %s above %s: solids fraction in grey (black: "
                               "0.64), red: bubble contour%s" % (above["scene"], below["scene"],
                                                                 note), width=110), fontsize=9)
    save_figure(fig, out_dir, "fig5.png", quiet)


def draw_work_precision(data, out_dir, quiet):
    rows = data["rows"]
    if not rows:
        raise SystemExit("error: the data hold no configurations")
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4.2))
    # The model's time resolution (DPM: contact steps; TFM: CFL) joins the label when it varies.
    step_name = data.get("time_resolution_name", "contact_steps")
    steps = [r.get("time_resolution", r.get(step_name)) for r in rows]
    varied = len(set(steps)) > 1
    for r, step in zip(rows, steps):
        label = ("%dx%d/%g" % (r["cells_x"], r["cells_y"], step) if varied
                 else "%dx%d" % (r["cells_x"], r["cells_y"]))
        wall = max(r["wall_s"], 1e-3)
        d_cm = 100 * r["bubble_diameter_m"]
        left.errorbar([wall], [d_cm], yerr=[100 * r["cell_size_m"]], fmt="o", capsize=3,
                      color="k" if r.get("is_reference") else "C0")
        left.annotate(label, (wall, d_cm), textcoords="offset points", xytext=(4, 4), fontsize=7)
        if finite(r.get("error_m")) and r["error_m"] > 0:
            right.loglog([wall], [100 * r["error_m"]], "o", color="C0")
            right.annotate(label, (wall, 100 * r["error_m"]), textcoords="offset points",
                           xytext=(4, 4), fontsize=7)
        right.loglog([wall], [100 * r["cell_size_m"]], "s", mfc="none", color="C1")
    zero = sum(1 for r in rows if finite(r.get("error_m")) and r["error_m"] == 0)
    left.axhline(100 * data["reference_diameter_m"], color="0.5", ls="--", lw=1)
    left.set_xscale("log")
    left.set_xlabel("wall time [s]")
    left.set_ylabel("D at t_ref [cm]  (bar: one cell)")
    left.set_title("bubble diameter; dashed: reference (%s)" % data["reference_method"],
                   fontsize=9)
    right.set_xlabel("wall time [s]")
    right.set_ylabel("error [cm]")
    right.set_title("circles: |D - D_ref|; squares: cell bound h" +
                    ("; %d zero error(s) not shown" % zero if zero else ""), fontsize=9)
    for ax in (left, right):  # plain wall-time labels (runs often span less than a decade)
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.tick_params(axis="x", which="minor", labelsize=7)
    right.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    right.yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    right.tick_params(axis="y", which="minor", labelsize=7)
    fig.suptitle("work-precision of %s on %s (%s per point%s)" % (
        data["law"], data["scene"], "grid/" + step_name if varied else "grid",
        "" if varied else ", %s %g" % (step_name, steps[0])), fontsize=10)
    save_figure(fig, out_dir, "work_precision.png", quiet)


def load(path):
    with open(path) as f:
        data = json.load(f)
    kind = data.get("format")
    if data.get("version") != 1 or kind not in ("draglab_sensitivity", "draglab_work_precision"):
        sys.stderr.write("error: %s is not draglab sensitivity data (format %r, version %r)\n" % (
            path, kind, data.get("version")))
        sys.exit(2)
    return data


def main(argv):
    args = [a for a in argv[1:] if a != "--quiet"]
    quiet = "--quiet" in argv[1:]
    beside = None
    if "--beside" in args:
        k = args.index("--beside")
        if k + 1 >= len(args):
            sys.stderr.write(__doc__)
            return 2
        beside = args[k + 1]
        del args[k:k + 2]
    if len(args) != 2:
        sys.stderr.write(__doc__)
        return 2
    data = load(args[0])
    kind = data["format"]
    os.makedirs(args[1], exist_ok=True)
    if kind == "draglab_sensitivity":
        draw_fig4(data, args[1], quiet)
        draw_bubble_series(data, args[1], quiet)
        if beside:
            other = load(beside)
            if other["format"] != "draglab_sensitivity":
                sys.stderr.write("error: --beside %s is not sensitivity data\n" % beside)
                return 2
            draw_fig5(other, data, args[1], quiet)
    else:
        draw_work_precision(data, args[1], quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
