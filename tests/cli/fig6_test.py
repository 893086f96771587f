#!/usr/bin/python3
"""Test of scripts/draglab_fig6.py (the DBM figures) on synthetic figure-data files.

Usage: /usr/bin/python3 tests/cli/fig6_test.py [path/to/draglab_fig6.py]

Set-up: two small figure-data files written here in the layout of
consumers/src/bed/dbm_bed_model.cc ("Figure data"): a 0.2 x 0.1 x 0.6 m column on 4 x 2 x 6
cells, scenes syn_u0.2_ctrue (coalescence on, with umf_m_s and area_per_orifice_m2 for the
Darton line, 30 bubbles) and syn_u0.2_cfalse (coalescence off, without them, no bubbles left at
the end, one null (NaN) value in the mid-plane field), both law gidaspow@1.
Checks:
  a. Both files together into a directory that does not exist yet: exit 0; exactly
     fig6_<scene>_gidaspow.png for each, dbm_profiles_syn_u0.2.png (the scenes' common prefix)
     and dbm_sizes_syn_u0.2_ctrue_gidaspow.png (coalescence on only); each a PNG (signature,
     IHDR of 300-6000 px each way, over 5 kB); one "wrote PATH" line per figure on stdout; no
     temporary file left behind.
  b. --quiet: the same figures, nothing on stdout.
  c. Bad input exits 2 with one line on stderr naming the file (and the key), before drawing
     anything (the output directory stays absent): a missing top-level key, a missing key under
     bubbles, a profile row without its z_m, a mid-plane field of the wrong size, invalid JSON, a
     missing file, the same scene and law twice; and a usage error (no --out) exits 2.
Without matplotlib in this interpreter the script must fail with a clear message naming
python3-matplotlib (exit 1); that is checked instead. Reads nothing outside its temp directory.
"""
import copy
import json
import os
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    HERE, os.pardir, os.pardir, "scripts", "draglab_fig6.py")
failures = []


def check(name, condition, detail=""):
    print(("ok   " if condition else "FAIL ") + name + ("" if condition else ": " + detail))
    if not condition:
        failures.append(name)


def run(*args):
    p = subprocess.run([sys.executable, SCRIPT] + list(args), stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def figure_data(scene, coalescence, bubbles, darton_keys):
    nx, ny, nz = 4, 2, 6
    W, D, H = 0.2, 0.1, 0.6
    hz = H / nz
    ux = [[0.02 * (i - 1.5) * (1 if j < nz / 2 else -1) for i in range(nx)] for j in range(nz)]
    uz = [[0.05 if i in (1, 2) else -0.05 for i in range(nx)] for j in range(nz)]
    eb = [[0.01 * (j + 1) * (2 if i in (1, 2) else 1) for i in range(nx)] for j in range(nz)]
    bins = 100
    hist = [[0.0] * bins for _ in range(nz)]
    for j in range(nz):
        hist[j][2 + j] = 10.0 + j
        hist[j][3 + j] = 5.0
    hist[nz - 1] = [0.0] * bins  # a row without bubbles
    data = {
        "scene": scene, "law": "gidaspow@1", "superficial_velocity_m_s": 0.2,
        "coalescence": coalescence, "width_m": W, "depth_m": D, "height_m": H,
        "cells": [nx, ny, nz], "t_s": 5.0, "average_from_s": 1.0,
        "midplane_u_x": ux, "midplane_u_z": uz, "midplane_bubble_fraction": eb,
        "holdup_profile": [{"z_m": (j + 0.5) * hz, "holdup": 0.05 + 0.01 * j}
                           for j in range(nz)],
        "size_profile": [{"z_m": (j + 0.5) * hz,
                          "mean_diameter_m": 0.0 if j == nz - 1 else 0.025 + 0.01 * j,
                          "bubbles_per_sample": 0.0 if j == nz - 1 else 3.0}
                         for j in range(nz)],
        "size_bin_m": 0.01, "size_histogram_by_row": hist,
        "bubbles": {"x_m": [0.02 + 0.16 * (k % 7) / 6 for k in range(bubbles)],
                    "y_m": [0.05] * bubbles,
                    "z_m": [0.02 + 0.56 * k / max(bubbles - 1, 1) for k in range(bubbles)],
                    "diameter_m": [0.02 + 0.002 * (k % 5) for k in range(bubbles)]},
    }
    if darton_keys:
        data["umf_m_s"] = 0.05
        data["area_per_orifice_m2"] = 0.005
    return data


def write(path, data):
    with open(path, "w") as f:
        json.dump(data, f)
    return path


def png_ok(path):
    try:
        with open(path, "rb") as f:
            blob = f.read()
    except OSError as exc:
        return False, str(exc)
    if blob[:8] != b"\x89PNG\r\n\x1a\n" or blob[12:16] != b"IHDR":
        return False, "not a PNG"
    width, height = struct.unpack(">II", blob[16:24])
    if not (300 <= width <= 6000 and 300 <= height <= 6000):
        return False, "size %d x %d px" % (width, height)
    if len(blob) < 5000:
        return False, "%d bytes" % len(blob)
    return True, ""


def main():
    with tempfile.TemporaryDirectory() as work:
        on = write(os.path.join(work, "on.json"),
                   figure_data("syn_u0.2_ctrue", True, 30, darton_keys=True))
        off_data = figure_data("syn_u0.2_cfalse", False, 0, darton_keys=False)
        off_data["midplane_u_x"][2][1] = None  # NaN as nlohmann writes it
        off = write(os.path.join(work, "off.json"), off_data)

        probe = subprocess.run([sys.executable, "-c", "import matplotlib"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        if probe.returncode != 0:
            rc, _, err = run(on, "--out", os.path.join(work, "figs"))
            check("without matplotlib: exit 1", rc == 1, "exit %d" % rc)
            check("without matplotlib: names python3-matplotlib", "python3-matplotlib" in err, err)
            print("note: %s cannot import matplotlib: figures not checked" % sys.executable)
            return 1 if failures else 0

        # a. Both files, a new nested directory.
        out = os.path.join(work, "figs", "nested")
        rc, stdout, err = run(on, off, "--out", out)
        check("two files: exit 0", rc == 0, "exit %d, stderr %r" % (rc, err))
        expected = {"fig6_syn_u0.2_ctrue_gidaspow.png", "fig6_syn_u0.2_cfalse_gidaspow.png",
                    "dbm_profiles_syn_u0.2.png", "dbm_sizes_syn_u0.2_ctrue_gidaspow.png"}
        present = set(os.listdir(out)) if os.path.isdir(out) else set()
        check("exactly the expected figures", present == expected,
              "got %s" % sorted(present))
        for name in sorted(expected):
            ok, why = png_ok(os.path.join(out, name))
            check(name + " is a plausible PNG", ok, why)
        lines = stdout.splitlines()
        check("one line per figure on stdout", len(lines) == len(expected), repr(stdout))
        check("stdout names the figures",
              sorted(os.path.basename(line.split()[-1]) for line in lines if line.strip())
              == sorted(expected), repr(stdout))

        # b. --quiet.
        quiet_out = os.path.join(work, "quiet")
        rc, stdout, err = run(on, "--out", quiet_out, "--quiet")
        check("--quiet: exit 0", rc == 0, "exit %d, stderr %r" % (rc, err))
        check("--quiet: nothing on stdout", stdout == "", repr(stdout))
        check("--quiet: one file's figures",
              sorted(os.listdir(quiet_out)) == ["dbm_profiles_syn_u0.2_ctrue.png",
                                                "dbm_sizes_syn_u0.2_ctrue_gidaspow.png",
                                                "fig6_syn_u0.2_ctrue_gidaspow.png"],
              str(os.listdir(quiet_out)))

        # c. Bad input: exit 2, one line naming the file and the key, nothing drawn.
        good = figure_data("syn_u0.2_ctrue", True, 30, darton_keys=True)

        def without(mutate):
            d = copy.deepcopy(good)
            mutate(d)
            return d

        cases = [
            ("missing top-level key", without(lambda d: d.pop("midplane_u_z")), "midplane_u_z"),
            ("missing bubbles key", without(lambda d: d["bubbles"].pop("diameter_m")),
             "bubbles.diameter_m"),
            ("profile row without z_m", without(lambda d: d["holdup_profile"][3].pop("z_m")),
             "z_m"),
            ("mid-plane field of the wrong size",
             without(lambda d: d["midplane_bubble_fraction"].pop()), "midplane_bubble_fraction"),
        ]
        for k, (name, data, key) in enumerate(cases):
            path = write(os.path.join(work, "bad%d.json" % k), data)
            bad_out = os.path.join(work, "bad_out%d" % k)
            rc, stdout, err = run(on, path, "--out", bad_out)
            check(name + ": exit 2", rc == 2, "exit %d" % rc)
            check(name + ": one line naming file and key",
                  len(err.strip().splitlines()) == 1 and path in err and key in err, repr(err))
            check(name + ": nothing drawn", not os.path.exists(bad_out), bad_out)
        invalid = os.path.join(work, "invalid.json")
        with open(invalid, "w") as f:
            f.write('{"scene": "x", ')
        missing = os.path.join(work, "no_such.json")
        for name, path in (("invalid JSON", invalid), ("missing file", missing)):
            rc, _, err = run(path, "--out", os.path.join(work, "bad_out"))
            check(name + ": exit 2", rc == 2, "exit %d" % rc)
            check(name + ": one line naming the file",
                  len(err.strip().splitlines()) == 1 and path in err, repr(err))
        rc, _, err = run(on, on, "--out", os.path.join(work, "bad_out"))
        check("same scene and law twice: exit 2", rc == 2, "exit %d, %r" % (rc, err))
        check("nothing drawn on bad input", not os.path.exists(os.path.join(work, "bad_out")))
        rc, _, err = run(on)
        check("no --out: exit 2", rc == 2 and "--out" in err, "exit %d, %r" % (rc, err))
    print("%d failure(s)" % len(failures) if failures else "all passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
