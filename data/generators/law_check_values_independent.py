#!/usr/bin/env python3
"""Independent check values for the drag-law library (no draglab code involved).

Written from the published formulas as collected in the project's drag-law dossier
(Schiller-Naumann, Ergun, Wen-Yu, Gidaspow, Gidaspow blend, Syamlal-O'Brien, Di Felice,
Rong et al. 2013, Hill-Koch-Ladd as in MFiX, van der Hoef 2005, Beetstra 2007 polydisperse,
Tenneti-Garg-Subramaniam 2011). Deliberately structured differently from the C++ library:
friction-coefficient laws are evaluated dimensionally (beta per unit solids fraction, "DgA" of
MFiX, with made-up gas properties) and only then turned into the canonical F, so that the
library's convention conversions are checked too.

Canonical output convention (the project's one convention):
  phi = solids fraction, eps = 1 - phi, u = interstitial slip, Re = rho eps d u / mu,
  F = F_d / (3 pi mu d eps u)  (drag only), i.e. F = beta d^2 / (18 mu phi eps).

Usage: python3 law_check_values_independent.py > ../law_check_values_independent.csv
Only the Python standard library is used.
"""
import math
import sys

# Arbitrary gas / particle properties: F is dimensionless and must not depend on them.
MU = 1.8e-5  # Pa s
RHO = 1.2  # kg/m^3
DIAM = 5.0e-4  # m


def slip_from_re(phi, re):
    """Interstitial slip u [m/s] for the canonical (superficial) Reynolds number."""
    return re * MU / (RHO * (1.0 - phi) * DIAM)


def f_from_dga(phi, dga):
    """Canonical F from MFiX's DgA = beta / phi (kg m^-3 s^-1): beta = 18 mu phi eps F / d^2."""
    return dga * DIAM * DIAM / (18.0 * MU * (1.0 - phi))


def cd_schiller_naumann_times_re(re_p):
    """C_d * Re for an isolated sphere: 24 (1 + 0.15 Re^0.687) up to Re = 1000, 0.44 Re above."""
    if re_p <= 1000.0:
        return 24.0 * (1.0 + 0.15 * re_p ** 0.687)
    return 0.44 * re_p


def cd_dalla_valle_times_re(re):
    """C_d * Re of Dalla Valle (1948): (0.63 sqrt(Re) + 4.8)^2."""
    return (0.63 * math.sqrt(re) + 4.8) ** 2


# ---------------------------------------------------------------------------------------------
# Laws


def schiller_naumann(phi, re):
    # Isolated-sphere law used without voidage correction: F_d = 3 pi mu d u (C_d Re_p / 24),
    # Re_p = rho d u / mu (interstitial slip), so F = (C_d Re_p / 24) / eps.
    eps = 1.0 - phi
    re_p = RHO * DIAM * slip_from_re(phi, re) / MU
    return cd_schiller_naumann_times_re(re_p) / 24.0 / eps


def ergun_dga(phi, re):
    eps = 1.0 - phi
    u = slip_from_re(phi, re)
    return 150.0 * phi * MU / (eps * DIAM ** 2) + 1.75 * RHO * u / DIAM


def wen_yu_dga(phi, re):
    eps = 1.0 - phi
    u = slip_from_re(phi, re)
    re_sup = eps * RHO * DIAM * u / MU
    # C_d (24/Re)(1 + 0.15 Re^0.687) written as C_d*Re / Re to allow Re = 0:
    # 0.75 C_d u rho eps eps^-2.65 / d = 0.75 (C_d Re) mu eps^-2.65 / d^2.
    return 0.75 * cd_schiller_naumann_times_re(re_sup) * MU * eps ** (-2.65) / DIAM ** 2


def ergun(phi, re):
    return f_from_dga(phi, ergun_dga(phi, re))


def wen_yu(phi, re):
    return f_from_dga(phi, wen_yu_dga(phi, re))


def gidaspow(phi, re):
    eps = 1.0 - phi
    dga = ergun_dga(phi, re) if eps <= 0.8 else wen_yu_dga(phi, re)
    return f_from_dga(phi, dga)


def gidaspow_blend(phi, re):
    eps = 1.0 - phi
    psi = math.atan(150.0 * 1.75 * (eps - 0.8)) / math.pi + 0.5
    return f_from_dga(phi, (1.0 - psi) * ergun_dga(phi, re) + psi * wen_yu_dga(phi, re))


def syamlal_obrien(phi, re, c1=0.8, d1=2.65):
    eps = 1.0 - phi
    u = slip_from_re(phi, re)
    re_p = DIAM * u * RHO / MU  # interstitial, no eps
    a = eps ** 4.14
    b = c1 * eps ** 1.28 if eps <= 0.85 else eps ** d1
    v_r = 0.5 * (a - 0.06 * re_p + math.sqrt((0.06 * re_p) ** 2 + 0.12 * re_p * (2.0 * b - a) + a * a))
    dga = 0.75 * MU * eps * cd_dalla_valle_times_re(re_p / v_r) / (v_r * DIAM ** 2)
    return f_from_dga(phi, dga)


def _felice_like(phi, re, chi_of):
    eps = 1.0 - phi
    return cd_dalla_valle_times_re(re) / 24.0 * eps ** (-chi_of(eps, re))


def di_felice(phi, re):
    def chi(eps, re):
        if re == 0.0:
            return 3.7  # exp(-(1.5 - log10 Re)^2 / 2) -> 0 as Re -> 0
        return 3.7 - 0.65 * math.exp(-((1.5 - math.log10(re)) ** 2) / 2.0)

    return _felice_like(phi, re, chi)


def rong2013(phi, re):
    def chi(eps, re):
        bump = 0.0 if re == 0.0 else math.exp(-((1.5 - math.log10(re)) ** 2) / 2.0)
        return 2.65 * (eps + 1.0) - (5.3 - 3.5 * eps) * eps ** 2 * bump

    return _felice_like(phi, re, chi)


def hkl_total(phi, re_a):
    """Hill-Koch-Ladd total-force K(phi, Re_a) as written in MFiX DRAG_KOCH_HILL (17.14)."""
    w = math.exp(-10.0 * (0.4 - phi) / phi) if phi > 0.0 else 0.0
    ck = 10.0 * phi / (1.0 - phi) ** 3
    plogp = phi * math.log(phi) if phi > 0.0 else 0.0
    root = 3.0 * math.sqrt(phi / 2.0)
    if phi < 0.4:
        f0 = (1.0 - w) * (1.0 + root + 135.0 / 64.0 * plogp + 17.14 * phi) / (
            1.0 + 0.681 * phi - 8.48 * phi ** 2 + 8.16 * phi ** 3) + w * ck
        f2 = (1.0 - w) * (1.0 + root + 135.0 / 64.0 * plogp + 17.89 * phi) / (
            1.0 + 0.681 * phi - 11.03 * phi ** 2 + 15.41 * phi ** 3) + w * ck
    else:
        f0 = ck
        f2 = ck
    if phi <= 0.1:
        f1 = math.sqrt(2.0 / phi) / 40.0 if phi > 0.01 else float("nan")
    else:
        f1 = 0.11 + 5.1e-4 * math.exp(11.6 * phi)
    if phi < 0.0953:
        f3 = 0.9351 * phi + 0.03667
    else:
        f3 = 0.0673 + 0.212 * phi + 0.0232 / (1.0 - phi) ** 5
    if phi <= 0.01:
        re_t1 = (f2 - 1.0) / (3.0 / 8.0 - f3)
        return 1.0 + 3.0 / 8.0 * re_a if re_a <= re_t1 else f2 + f3 * re_a
    re_t2 = (f3 + math.sqrt(f3 * f3 - 4.0 * f1 * (f0 - f2))) / (2.0 * f1)
    return f0 + f1 * re_a * re_a if re_a <= re_t2 else f2 + f3 * re_a


def hill_koch_ladd(phi, re):
    # beta = 18 mu phi eps^2 K / d^2 (MFiX F_STOKES = 18 mu eps^2/d^2), Re_a = Re_d / 2.
    eps = 1.0 - phi
    dga = 18.0 * MU * eps * eps * hkl_total(phi, re / 2.0) / DIAM ** 2
    return f_from_dga(phi, dga)


def vdh2005(phi, re):
    del re  # Stokes-limit law
    return 10.0 * phi / (1.0 - phi) ** 2 + (1.0 - phi) ** 2 * (1.0 + 1.5 * math.sqrt(phi))


def bvk2007_mono(phi, re):
    eps = 1.0 - phi
    f = vdh2005(phi, 0.0)
    if re > 0.0:
        f += 0.413 * re / (24.0 * eps ** 2) * (1.0 / eps + 3.0 * phi * eps + 8.4 * re ** (-0.343)) / (
            1.0 + 10.0 ** (3.0 * phi) * re ** (-(1.0 + 4.0 * phi) / 2.0))
    return f


def bvk2007_poly(phi, re, y):
    eps = 1.0 - phi
    return bvk2007_mono(phi, re) * (eps * y + phi * y * y + 0.064 * eps * y ** 3)


def vdh2005_poly(phi, re, y):
    return vdh2005(phi, re) * ((1.0 - phi) * y + phi * y * y)


def hys2010(phi, re, y):
    # MFiX DRAG_HYS: F_YS = 1/EPg + (F_D_BVK - 1/EPg)(a_YS Y_i + (1 - a_YS) Y_i^2), with the
    # Stokes part at zero slip (MFiX sets F_D_BVK = 0 there) and no lubrication cross term.
    eps = 1.0 - phi
    a = 1.0 - 2.66 * phi + 9.096 * phi ** 2 - 11.338 * phi ** 3
    return 1.0 / eps + (bvk2007_mono(phi, re) - 1.0 / eps) * (a * y + (1.0 - a) * y * y)


def tenneti2011(phi, re):
    # Total-force TGS form; drag-only F = (1 - phi) F_TGS (waLBerla reading).
    eps = 1.0 - phi
    f_isol = 1.0 + 0.15 * re ** 0.687
    f_phi = 5.81 * phi / eps ** 3 + 0.48 * phi ** (1.0 / 3.0) / eps ** 4
    f_phi_re = phi ** 3 * re * (0.95 + 0.61 * phi ** 3 / eps ** 2)
    return eps * (f_isol / eps ** 3 + f_phi + f_phi_re)


# ---------------------------------------------------------------------------------------------
# Grids: avoid points within 1e-6 (relative) of a regime switch, where the two codes' switch
# inclusivity (<= vs <) could legitimately differ.

PHIS_GENERIC = [0.0, 0.05, 0.1, 0.14, 0.16, 0.2, 0.3, 0.4, 0.5, 0.6]
RES_GENERIC = [0.0, 0.01, 0.1, 1.0, 10.0, 31.6227766, 100.0, 500.0, 1000.0, 2000.0]


def rows():
    out = []

    def add(law, phi, re, y, value):
        out.append((law, phi, re, y, value))

    for phi in [0.0, 0.1, 0.3]:
        for re in [0.0, 0.1, 1.0, 10.0, 100.0, 500.0, 990.0, 1010.0, 2000.0, 1.0e4]:
            if abs(re / (1.0 - phi) - 1000.0) < 1e-3:
                continue
            add("schiller_naumann", phi, re, None, schiller_naumann(phi, re))
    for phi in [0.0, 0.05, 0.1, 0.15, 0.19, 0.21, 0.3, 0.4, 0.5, 0.6]:
        for re in [0.0, 0.01, 0.1, 1.0, 10.0, 100.0, 500.0, 990.0, 1010.0, 2000.0]:
            add("gidaspow", phi, re, None, gidaspow(phi, re))
            add("gidaspow_blend", phi, re, None, gidaspow_blend(phi, re))
    for re in [0.0, 1.0, 10.0]:
        add("wen_yu", 0.0, re, None, wen_yu(0.0, re))
        add("wen_yu", 0.3, re, None, wen_yu(0.3, re))
    for phi in PHIS_GENERIC:
        for re in RES_GENERIC:
            add("syamlal_obrien", phi, re, None, syamlal_obrien(phi, re))
            add("di_felice", phi, re, None, di_felice(phi, re))
            add("rong2013", phi, re, None, rong2013(phi, re))
    for phi in [0.005, 0.02, 0.05, 0.08, 0.12, 0.2, 0.3, 0.35, 0.45, 0.5, 0.6]:
        for re in [0.0, 0.1, 1.0, 5.0, 20.0, 50.0, 100.0, 200.0, 400.0]:
            add("hill_koch_ladd", phi, re, None, hill_koch_ladd(phi, re))
    for phi in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]:
        add("vdh2005", phi, 0.0, None, vdh2005(phi, 0.0))
    for phi in [0.1, 0.3, 0.5]:
        for re in [0.0, 10.0, 100.0, 1000.0]:
            for y in [0.25, 0.5, 1.0, 2.0, 4.0]:
                add("bvk2007_poly", phi, re, y, bvk2007_poly(phi, re, y))
                add("hys2010", phi, re, y, hys2010(phi, re, y))
    for phi in [0.1, 0.3, 0.5, 0.6]:
        for y in [0.25, 0.5, 1.0, 2.0, 4.0]:
            add("vdh2005_poly", phi, 0.0, y, vdh2005_poly(phi, 0.0, y))
    for phi in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]:
        for re in [0.0, 1.0, 10.0, 100.0, 300.0]:
            add("tenneti2011", phi, re, None, tenneti2011(phi, re))
    return out


def main():
    w = sys.stdout.write
    w("# Drag-law check values computed by data/generators/law_check_values_independent.py\n")
    w("# (Python standard library, written from the published formulas, NOT from draglab's C++).\n")
    w("# Convention: canonical drag-only F = F_d/(3 pi mu d eps u), Re = rho eps d u/mu (u interstitial\n")
    w("# slip), phi = 1 - eps. beta-form laws are evaluated dimensionally (beta/phi with mu = 1.8e-5 Pa s,\n")
    w("# rho = 1.2 kg/m^3, d = 0.5 mm) and converted by beta = 18 mu phi eps F / d^2; total-force laws\n")
    w("# (hill_koch_ladd with Re_a = Re/2, tenneti2011) by F = (1 - phi) K. y = d_i/<d> (Sauter) for\n")
    w("# the polydisperse laws, with Re based on <d>; empty for monodisperse laws. Values: 12 significant digits.\n")
    w("# Formula sources: Schiller-Naumann 1933 (Re_p <= 1000: 24(1+0.15 Re^0.687), else 0.44 Re);\n")
    w("# Ergun 1952; Wen-Yu 1966 (eps^-2.65 in beta); Ding-Gidaspow 1990 (Ergun for eps <= 0.8);\n")
    w("# Lathouwers-Bellan arctan blend (MFiX DRAG_GIDASPOW_BLEND); Syamlal-O'Brien 1988 (C1 = 0.8,\n")
    w("# D1 = 2.65, interstitial Re); Di Felice 1994 and Rong-Dong-Yu 2013 (Dalla Valle C_d);\n")
    w("# Hill-Koch-Ladd 2001 as in MFiX DRAG_KOCH_HILL (17.14); van der Hoef et al. 2005 (Stokes);\n")
    w("# Beetstra et al. 2007 polydisperse factor (1-phi)y + phi y^2 + 0.064 (1-phi) y^3; van der Hoef\n")
    w("# et al. 2005's (1-phi)y + phi y^2; Yin-Sundaresan as in MFiX DRAG_HYS (1/eps + (F_BVK - 1/eps)\n")
    w("# (a y + (1-a) y^2), a = 1 - 2.66 phi + 9.096 phi^2 - 11.338 phi^3, no lubrication term);\n")
    w("# Tenneti-Garg-Subramaniam 2011 (phi^3 in the last bracket, drag-only F = (1-phi) F_TGS).\n")
    w("law,phi,Re,y,F\n")
    for law, phi, re, y, value in rows():
        ytxt = "" if y is None else "%.12g" % y
        w("%s,%.12g,%.12g,%s,%.12g\n" % (law, phi, re, ytxt, value))


if __name__ == "__main__":
    main()
