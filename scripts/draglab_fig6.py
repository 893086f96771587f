#!/usr/bin/python3
"""Draw the discrete bubble model's figures (the seed paper's Fig. 6 and more) from its data.

Usage: /usr/bin/python3 draglab_fig6.py FILE.json [FILE.json ...] --out DIR [--quiet]

Each FILE.json is the figure-data file of one DBM run (solver = "dbm" with [outputs]
fields = true; consumers/src/bed/dbm_bed_model.cc writes OUT/<scene>_<law>_dbm.json): the run's
scene, law, u0, coalescence switch, column size, cells [nx, ny, nz] (x width, y depth, z
height), the time-averaged emulsion velocity and bubble fraction on the vertical mid-plane
y = depth/2, hold-up and mean bubble size against height, per-row bubble size histograms and
the bubbles at the end of the run. Writes into DIR (created if needed):
  - fig6_<scene>_<law>.png per file, the seed's Fig. 6: (a) the bubbles at the end of the run
    projected on the x-z plane, each a circle of its true diameter, in the column outline;
    (b) the time-averaged emulsion velocity on the mid-plane as arrows (reference arrow at the
    bottom) over the time-averaged bubble fraction in colour; both to scale (equal aspect);
  - dbm_profiles_<name>.png for all files together: (a) the time-averaged hold-up against
    height, one line per file; (b) the mean bubble diameter against height (rows with bubbles
    only) with, dashed, the Darton et al. (1977) correlation
    d_b = 0.54 (u0 - umf)^0.4 (h + 4 sqrt(A0))^0.8 g^-0.2 for each file that holds umf_m_s and
    area_per_orifice_m2 (gravity_m_s2 if present, else 9.81). <name> is the scene when all
    files share it, else the scenes' common prefix up to a "_" (e.g. dbm_reactor_u0.1 for
    dbm_reactor_u0.1_cfalse and dbm_reactor_u0.1_ctrue), else "combined";
  - dbm_sizes_<scene>_<law>.png per file with coalescence on: the bubble size distribution
    against height (each row's histogram normalised to 1, the last bin holding every larger
    bubble) with the row's mean diameter over it.
<law> is the law's name without its version, with _v<version> added when two files would
otherwise write the same name. Every PNG (150 dpi) is written to a temporary name and renamed.
One line "wrote PATH" per figure goes to stdout unless --quiet. A missing or unreadable file,
invalid JSON, a missing key or inconsistent sizes stop the script before it draws anything:
exit 2 with one line on stderr naming the file and the key. It only draws; it needs Debian's
python3-matplotlib (run it with /usr/bin/python3) and nothing else.
"""
import json
import math
import os
import re
import sys
import tempfile
import textwrap

try:
    import matplotlib

    matplotlib.use("Agg")  # no display on build machines
    import matplotlib.pyplot as plt
    from matplotlib.collections import EllipseCollection
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Rectangle
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    import numpy as np
except ImportError as exc:  # for direct use without Debian's interpreter
    sys.stderr.write(
        "error: matplotlib is not importable by %s (%s); install the Debian package "
        "python3-matplotlib and run this script with /usr/bin/python3\n" % (sys.executable, exc)
    )
    sys.exit(1)

DPI = 150
BUBBLE_COLOUR = "#1d3557"
DARTON_GRAVITY_M_S2 = 9.81  # when the file has no gravity_m_s2

# Keys every figure-data file must hold (dbm_bed_model.cc, "Figure data").
REQUIRED = ("scene", "law", "superficial_velocity_m_s", "coalescence", "width_m", "depth_m",
            "height_m", "cells", "t_s", "average_from_s", "midplane_u_x", "midplane_u_z",
            "midplane_bubble_fraction", "holdup_profile", "size_profile", "size_bin_m",
            "size_histogram_by_row", "bubbles")
BUBBLE_KEYS = ("x_m", "y_m", "z_m", "diameter_m")


class InputError(Exception):
    """A figure-data file that cannot be drawn: one line, naming the file."""


def log(quiet, message):
    if not quiet:
        sys.stdout.write(message + "\n")
        sys.stdout.flush()


def save_figure(fig, out_dir, name, quiet):
    """Lays out, writes OUT_DIR/NAME at 150 dpi through a temporary file renamed into place (no
    half-written PNG), closes the figure and says so."""
    fig.tight_layout()
    path = os.path.join(out_dir, name)
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix="." + name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            fig.savefig(f, dpi=DPI, format="png")
        umask = os.umask(0)  # mkstemp makes the file 0600: give it the usual permissions
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    finally:
        plt.close(fig)
    log(quiet, "wrote " + path)
    return path


def file_part(text):
    """`text` made safe for a file name."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", str(text)) or "_"


def number(path, data, key, positive=False):
    x = data[key]
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or \
            (positive and not x > 0):
        raise InputError("%s: key '%s' is %r, not a %snumber" % (
            path, key, x, "positive " if positive else ""))
    return float(x)


def grid(path, data, key, rows, cols):
    """A rows x cols list of lists as a float array (null, as nlohmann writes NaN, is NaN)."""
    value = data[key]
    if not isinstance(value, list) or len(value) != rows or \
            any(not isinstance(r, list) or len(r) != cols for r in value):
        raise InputError("%s: key '%s' is not %d rows of %d values (cells nz x nx)" % (
            path, key, rows, cols))
    try:
        return np.array(value, dtype=float).reshape(rows, cols)
    except (TypeError, ValueError):
        raise InputError("%s: key '%s' holds non-numbers" % (path, key))


def records(path, data, key, fields, rows):
    """A list of `rows` objects with `fields` as a dict of float arrays."""
    value = data[key]
    if not isinstance(value, list) or len(value) != rows:
        raise InputError("%s: key '%s' is not a list of %d rows (cells nz)" % (path, key, rows))
    out = {}
    for field in fields:
        column = []
        for k, item in enumerate(value):
            if not isinstance(item, dict) or field not in item:
                raise InputError("%s: missing key '%s[%d].%s'" % (path, key, k, field))
            column.append(item[field])
        try:
            out[field] = np.array(column, dtype=float)
        except (TypeError, ValueError):
            raise InputError("%s: key '%s[].%s' holds non-numbers" % (path, key, field))
    return out


def load(path):
    """Reads and checks one figure-data file; returns a dict of plain values and arrays."""
    try:
        with open(path) as f:
            data = json.load(f)
    except FileNotFoundError:
        raise InputError("%s: no such file" % path)
    except json.JSONDecodeError as exc:
        raise InputError("%s: invalid JSON (%s)" % (path, exc))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("%s: cannot read (%s)" % (path, exc))
    if not isinstance(data, dict):
        raise InputError("%s: not a JSON object (DBM figure data expected)" % path)
    for key in REQUIRED:
        if key not in data:
            raise InputError("%s: missing key '%s' (not DBM figure data?)" % (path, key))
    cells = data["cells"]
    if not isinstance(cells, list) or len(cells) != 3 or \
            any(isinstance(c, bool) or not isinstance(c, int) or c < 1 for c in cells):
        raise InputError("%s: key 'cells' is %r, not [nx, ny, nz] of positive integers" % (
            path, cells))
    nx, _, nz = cells
    d = {"path": path, "scene": str(data["scene"]), "law": str(data["law"]),
         "coalescence": bool(data["coalescence"]), "nx": nx, "nz": nz}
    for key in ("superficial_velocity_m_s", "t_s", "average_from_s"):
        d[key] = number(path, data, key)
    for key in ("width_m", "depth_m", "height_m", "size_bin_m"):
        d[key] = number(path, data, key, positive=True)
    for key in ("midplane_u_x", "midplane_u_z", "midplane_bubble_fraction"):
        d[key] = grid(path, data, key, nz, nx)
    d["holdup"] = records(path, data, "holdup_profile", ("z_m", "holdup"), nz)
    d["sizes"] = records(path, data, "size_profile",
                         ("z_m", "mean_diameter_m", "bubbles_per_sample"), nz)
    hist = data["size_histogram_by_row"]
    bins = len(hist[0]) if isinstance(hist, list) and hist and isinstance(hist[0], list) else 0
    if bins < 1:
        raise InputError("%s: key 'size_histogram_by_row' is not %d rows of size bins" % (
            path, nz))
    d["histogram"] = grid(path, data, "size_histogram_by_row", nz, bins)
    bubbles = data["bubbles"]
    if not isinstance(bubbles, dict):
        raise InputError("%s: key 'bubbles' is not an object of x_m, y_m, z_m, diameter_m" % path)
    for key in BUBBLE_KEYS:
        if key not in bubbles:
            raise InputError("%s: missing key 'bubbles.%s'" % (path, key))
        try:
            d["bubble_" + key] = np.array(bubbles[key], dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise InputError("%s: key 'bubbles.%s' is not a list of numbers" % (path, key))
    if len({len(d["bubble_" + key]) for key in BUBBLE_KEYS}) != 1:
        raise InputError("%s: the lists under 'bubbles' differ in length" % path)
    # Optional: what the Darton correlation needs (skipped quietly without them).
    d["umf_m_s"] = data.get("umf_m_s")
    d["area_per_orifice_m2"] = data.get("area_per_orifice_m2")
    d["gravity_m_s2"] = data.get("gravity_m_s2", DARTON_GRAVITY_M_S2)
    return d


def law_name(law):
    return law.split("@", 1)[0]


def label(d):
    return "u0 = %g m/s, %s, coalescence %s" % (
        d["superficial_velocity_m_s"], d["law"], "on" if d["coalescence"] else "off")


def nice_below(x):
    """The largest 1, 2 or 5 times a power of ten not above x > 0."""
    p = 10.0 ** math.floor(math.log10(x))
    for m in (5.0, 2.0, 1.0):
        if m * p <= x * (1 + 1e-9):
            return m * p
    return p


def draw_bubbles(ax, d):
    """Panel (a): the bubbles on the x-z plane as circles of their diameter, column outline."""
    W, H = d["width_m"], d["height_m"]
    x, z, diam = d["bubble_x_m"], d["bubble_z_m"], d["bubble_diameter_m"]
    keep = np.isfinite(x) & np.isfinite(z) & np.isfinite(diam) & (diam > 0)
    x, z, diam = x[keep], z[keep], diam[keep]
    if len(diam):
        ax.add_collection(EllipseCollection(
            diam, diam, np.zeros_like(diam), units="xy", offsets=np.column_stack([x, z]),
            offset_transform=ax.transData, facecolors=BUBBLE_COLOUR, edgecolors=BUBBLE_COLOUR,
            linewidths=0.3, alpha=0.35))
    else:
        ax.text(0.5, 0.5, "no bubbles", transform=ax.transAxes, ha="center", va="center")
    ax.add_patch(Rectangle((0, 0), W, H, fill=False, edgecolor="k", linewidth=1.2))
    pad = 0.02 * max(W, H)
    ax.set_xlim(-pad, W + pad)
    ax.set_ylim(-pad, H + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title("(a) bubbles at t = %.3g s (%d), projected on x-z" % (d["t_s"], len(diam)),
                 fontsize=9)


def draw_midplane(fig, ax, d):
    """Panel (b): time-averaged emulsion velocity (arrows) over the bubble fraction (colour)."""
    W, H, nx, nz = d["width_m"], d["height_m"], d["nx"], d["nz"]
    xf = np.linspace(0.0, W, nx + 1)
    zf = np.linspace(0.0, H, nz + 1)
    eb = np.ma.masked_invalid(d["midplane_bubble_fraction"])
    top = float(eb.max()) if eb.count() else 0.0
    mesh = ax.pcolormesh(xf, zf, eb, cmap="YlOrRd", vmin=0.0, vmax=top if top > 0 else 1.0,
                         shading="flat")
    cax = make_axes_locatable(ax).append_axes("right", size="6%", pad=0.08)
    fig.colorbar(mesh, cax=cax, label="time-averaged bubble fraction [-]")
    dx, dz = W / nx, H / nz
    sx, sz = max(1, math.ceil(nx / 24)), max(1, math.ceil(nz / 48))  # at most ~24 x 48 arrows
    xc = (np.arange(nx) + 0.5) * dx
    zc = (np.arange(nz) + 0.5) * dz
    X, Z = np.meshgrid(xc[::sx], zc[::sz])
    u = np.nan_to_num(d["midplane_u_x"][::sz, ::sx])
    w = np.nan_to_num(d["midplane_u_z"][::sz, ::sx])
    speed = float(np.max(np.hypot(u, w))) if u.size else 0.0
    if speed > 0:
        # The fastest arrow spans 1.5 (sub-sampled) cells of the narrower direction.
        scale = speed / (1.5 * min(sx * dx, sz * dz))
        q = ax.quiver(X, Z, u, w, angles="xy", scale_units="xy", scale=scale, width=0.006,
                      color="k", pivot="mid")
        ref = nice_below(speed)
        ax.quiverkey(q, 0.5, -0.09, ref, "%g m/s" % ref, labelpos="E", coordinates="axes",
                     fontproperties={"size": 8})
    else:
        ax.text(0.5, 0.5, "no emulsion motion", transform=ax.transAxes, ha="center")
    ax.add_patch(Rectangle((0, 0), W, H, fill=False, edgecolor="k", linewidth=1.2))
    ax.set_xlim(0, W)
    ax.set_ylim(0, H)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]", labelpad=14 if speed > 0 else 4)
    ax.set_title("(b) emulsion velocity and bubble fraction,\nmid-plane y = %.3g m, time-averaged"
                 % (0.5 * d["depth_m"]), fontsize=9)


def draw_fig6(d, out_dir, name, quiet):
    W, H = d["width_m"], d["height_m"]
    panel_w = 3.3
    panel_h = min(9.0, max(2.5, panel_w * H / W))
    fig, (left, right) = plt.subplots(1, 2, figsize=(2 * panel_w + 1.6, panel_h + 1.6))
    draw_bubbles(left, d)
    draw_midplane(fig, right, d)
    title = "%s: %s; averaged over %.3g-%.3g s" % (
        d["scene"], label(d), d["average_from_s"], d["t_s"])
    fig.suptitle(textwrap.fill(title, width=90), fontsize=10)
    return save_figure(fig, out_dir, name, quiet)


def darton(d, z):
    """Darton et al. (1977) at heights z [m], or None without umf_m_s and area_per_orifice_m2."""
    umf, a0, g = d["umf_m_s"], d["area_per_orifice_m2"], d["gravity_m_s2"]
    ok = all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
             for v in (umf, a0, g))
    if not ok or a0 < 0 or g <= 0 or d["superficial_velocity_m_s"] <= umf:
        return None
    excess = d["superficial_velocity_m_s"] - umf
    return 0.54 * excess ** 0.4 * (z + 4.0 * math.sqrt(a0)) ** 0.8 * g ** -0.2


def draw_profiles(datas, out_dir, name, quiet):
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 5.2), sharey=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    top = max(d["height_m"] for d in datas)
    any_darton = False
    for k, d in enumerate(datas):
        colour = colours[k % len(colours)]
        h = d["holdup"]
        left.plot(h["holdup"], h["z_m"], "-o", ms=3, color=colour, label=label(d))
        s = d["sizes"]
        has = (s["bubbles_per_sample"] > 0) & np.isfinite(s["mean_diameter_m"]) & \
            (s["mean_diameter_m"] > 0)
        right.plot(100 * s["mean_diameter_m"][has], s["z_m"][has], "-o", ms=3, color=colour,
                   label=label(d))
        z = np.linspace(0.0, d["height_m"], 200)
        db = darton(d, z)
        if db is not None:
            any_darton = True
            right.plot(100 * db, z, "--", color=colour, lw=1.2,
                       label="Darton, u0 = %g m/s" % d["superficial_velocity_m_s"])
    left.set_xlabel("time-averaged bubble hold-up [-]")
    left.set_ylabel("height z [m]")
    left.set_title("(a) hold-up against height", fontsize=9)
    right.set_xlabel("mean bubble diameter [cm]")
    right.set_title("(b) mean bubble diameter against height" +
                    ("; dashed: Darton et al. 1977" if any_darton else ""), fontsize=9)
    for ax in (left, right):
        ax.set_ylim(0, top)
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle("Discrete bubble model: %s (time-averaged profiles)" % name, fontsize=10)
    return save_figure(fig, out_dir, "dbm_profiles_%s.png" % file_part(name), quiet)


def draw_sizes(d, out_dir, name, quiet):
    hist = np.nan_to_num(d["histogram"])
    nz, bins = hist.shape
    totals = hist.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(totals > 0, hist / np.where(totals > 0, totals, 1.0), np.nan)
    share = np.ma.masked_invalid(share)
    bin_cm = 100 * d["size_bin_m"]
    used = np.nonzero(hist.sum(axis=0) > 0)[0]
    last = int(used[-1]) + 1 if len(used) else bins
    shown = min(bins, last + max(2, last // 10))
    df = np.arange(bins + 1) * bin_cm
    zf = np.linspace(0.0, d["height_m"], nz + 1)
    fig, ax = plt.subplots(figsize=(7, max(4.0, min(8.0, 2 + 1.2 * d["height_m"] / d["width_m"]))))
    # Log colours so that the few large bubbles of the tail show; empty bins stay white.
    share = np.ma.masked_less_equal(share, 0.0)
    mesh = ax.pcolormesh(df, zf, share, cmap="viridis", norm=LogNorm(vmin=1e-3, vmax=1.0),
                         shading="flat")
    fig.colorbar(mesh, ax=ax, extend="min",
                 label="fraction of the row's bubbles per %.3g cm bin" % bin_cm)
    s = d["sizes"]
    has = (s["bubbles_per_sample"] > 0) & np.isfinite(s["mean_diameter_m"]) & \
        (s["mean_diameter_m"] > 0)
    ax.plot(100 * s["mean_diameter_m"][has], s["z_m"][has], "-o", color="#d62828", ms=3,
            label="mean diameter")
    ax.set_xlim(0, shown * bin_cm)
    ax.set_ylim(0, d["height_m"])
    ax.set_xlabel("bubble diameter [cm]" + (" (last bin: all larger)" if shown == bins else ""))
    ax.set_ylabel("height z [m]")
    ax.legend(fontsize=8, loc="upper right")
    title = "%s: bubble sizes against height (white: none), %s; averaged over %.3g-%.3g s" % (
        d["scene"], label(d), d["average_from_s"], d["t_s"])
    ax.set_title(textwrap.fill(title, width=80), fontsize=9)
    return save_figure(fig, out_dir, name, quiet)


def profile_name(datas):
    """The scene, or the scenes' common prefix cut at a '_', or 'combined'."""
    scenes = [d["scene"] for d in datas]
    if len(set(scenes)) == 1:
        return scenes[0]
    prefix = os.path.commonprefix(scenes)
    if not all(s[len(prefix):len(prefix) + 1] in ("", "_") for s in scenes):
        prefix = prefix[:prefix.rfind("_") + 1] if "_" in prefix else ""
    prefix = prefix.rstrip("_")
    return prefix or "combined"


def output_names(datas):
    """fig6 / sizes name part per file: <scene>_<law name>, with the version when needed."""
    short = [file_part(d["scene"]) + "_" + file_part(law_name(d["law"])) for d in datas]
    names = []
    for d, s in zip(datas, short):
        if short.count(s) > 1:
            s = file_part(d["scene"]) + "_" + file_part(d["law"].replace("@", "_v"))
        names.append(s)
    for i in range(len(names)):
        for j in range(i):
            if names[i] == names[j]:
                raise InputError("%s and %s hold the same scene and law (%s, %s): their figures "
                                 "would overwrite each other" % (datas[j]["path"],
                                                                 datas[i]["path"],
                                                                 datas[i]["scene"],
                                                                 datas[i]["law"]))
    return names


def usage_error(message):
    sys.stderr.write("error: %s\nusage: /usr/bin/python3 draglab_fig6.py FILE.json "
                     "[FILE.json ...] --out DIR [--quiet]\n" % message)
    return 2


def main(argv):
    files, out_dir, quiet = [], None, False
    args = argv[1:]
    k = 0
    while k < len(args):
        a = args[k]
        if a in ("-h", "--help"):
            sys.stdout.write(__doc__)
            return 0
        if a == "--quiet":
            quiet = True
        elif a == "--out" or a.startswith("--out="):
            if a == "--out":
                if k + 1 >= len(args):
                    return usage_error("--out needs a directory")
                k += 1
                out_dir = args[k]
            else:
                out_dir = a[len("--out="):]
        elif a.startswith("--"):
            return usage_error("unknown option %s" % a)
        else:
            files.append(a)
        k += 1
    if out_dir is None or out_dir == "":
        return usage_error("--out DIR is required")
    if not files:
        return usage_error("no figure-data file given")
    try:
        datas = [load(path) for path in files]
        names = output_names(datas)
    except InputError as exc:
        sys.stderr.write("error: %s\n" % exc)
        return 2
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as exc:
        sys.stderr.write("error: cannot create the output directory %s (%s)\n" % (out_dir, exc))
        return 2
    for d, name in zip(datas, names):
        draw_fig6(d, out_dir, "fig6_%s.png" % name, quiet)
    draw_profiles(datas, out_dir, profile_name(datas), quiet)
    for d, name in zip(datas, names):
        if d["coalescence"]:
            draw_sizes(d, out_dir, "dbm_sizes_%s.png" % name, quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
