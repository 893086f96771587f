// collision.h: the per-node D3Q19 collision operators with Guo forcing, written for SIMD.
//
// Populations are stored and handled SHIFTED by their weight, g_i = f_i - w_i (the rest state is
// g = 0). This keeps the deviations, which carry all the physics of a low-Mach flow, at full
// relative precision in float storage ("DDF shifting"); in double it costs nothing. Moments:
//   rho = 1 + drho, drho = sum g_i,   j = sum g_i c_i + G/2   (Guo: second-order velocity),
//   u = j / rho (full equilibrium) or u = j (Stokes mode, rho0 = 1).
// The body force G = (G_x, 0, 0) is a force density (rho0 = 1).
//
// Equilibrium, shifted, split into its parts even and odd in c:
//   full:   eq+_i = w_i (drho + 4.5 (c.j)(c.u) - 1.5 j.u),   eq-_i = 3 w_i c.j
//   Stokes: eq+_i = w_i drho,                                eq-_i = 3 w_i c.j
// (the Stokes-mode equilibrium is the linear one: it drops every u.u term, and the Guo term
// drops its u.G part, so the scheme solves the steady Stokes equations exactly linearly in G).
//
// TRT (Ginzburg): the even part relaxes with omega+ = 1/tau+, the odd part with omega- = 1/tau-;
// Guo forcing split the same way: F_i = (1 - omega-/2) 3 w_i c.G + (1 - omega+/2) w_i
// (9 (c.u)(c.G) - 3 u.G). BGK is TRT with omega+ = omega-, so one kernel does both.
//
// Regularized BGK (Latt & Chopard 2006): the non-equilibrium part is replaced by its projection
// on the second-order Hermite polynomial, w_i 4.5 Q_i : Pi_neq (Q_i = c_i c_i - I/3,
// Pi_neq = sum g c c - drho I/3 - j u), plus its exact first moment sum f_neq c = -G/2 (kept so
// that the post-collision momentum is exactly j + G/2 as with Guo's BGK):
//   f*_i = feq_i + (1 - omega) w_i (4.5 Q_i : Pi_neq - 1.5 c.G) + F_i(omega).
// Every node gains exactly G of momentum per step with every operator, which the steady
// momentum balance (sum of body forces = G times the fluid node count) relies on.
#pragma once

#include <cstdint>

#include "d3q19.h"

namespace draglab {
namespace lbm {

enum class CollisionKernel { kTrt, kRegularized };

/// Relaxation and forcing constants in the compute type T.
template <typename T>
struct KernelParams {
  T omega_plus = 1;   ///< 1/tau+ (even moments: viscosity).
  T omega_minus = 1;  ///< 1/tau- (odd moments).
  T force_x = 0;      ///< G_x, force density.
  T force_even = 0;   ///< (1 - omega+/2) G_x.
  T force_odd = 0;    ///< (1 - omega-/2) G_x.
};

#define DRAGLAB_LBM_INLINE inline __attribute__((always_inline))

namespace detail {

/// TRT in pair form, arranged for few operations (about 170 per node, against about 230 for the
/// textbook form): with S = g_i + g_ib and D = g_i - g_ib (which also give the moments),
///   o_i = g_i + P + M,  o_ib = g_ib + P - M,
///   P = -omega+/2 S + omega+ eq+_i + F+_i,   M = -omega-/2 D + omega- eq-_i + F-_i,
/// where omega+ eq+ + F+ = C_w + cu (4.5 omega+ w c.j + 9 w (1 - omega+/2) G_x c_x), C_w =
/// w (omega+ (drho - 1.5 j.u) - 3 (1 - omega+/2) G_x u_x) per weight class, and omega- eq- + F- =
/// 3 w (omega- c.j + (1 - omega-/2) G_x c_x).
template <typename T, bool kStokes>
DRAGLAB_LBM_INLINE void collide_trt(const T (&g)[19], T (&o)[19], const KernelParams<T>& p) {
  constexpr T w0 = T(d3q19::kW0), wa = T(d3q19::kWAxis), wd = T(d3q19::kWDiag);
  const T s12 = g[1] + g[2], s34 = g[3] + g[4], s56 = g[5] + g[6], s78 = g[7] + g[8];
  const T s910 = g[9] + g[10], s1112 = g[11] + g[12], s1314 = g[13] + g[14];
  const T s1516 = g[15] + g[16], s1718 = g[17] + g[18];
  const T d12 = g[1] - g[2], d34 = g[3] - g[4], d56 = g[5] - g[6], d78 = g[7] - g[8];
  const T d910 = g[9] - g[10], d1112 = g[11] - g[12], d1314 = g[13] - g[14];
  const T d1516 = g[15] - g[16], d1718 = g[17] - g[18];
  const T drho = ((g[0] + s12) + (s34 + s56)) + ((s78 + s910) + (s1112 + s1314)) + (s1516 + s1718);
  const T jx = (d12 + d78) + (d910 + d1112) + d1314 + T(0.5) * p.force_x;
  const T jy = (d34 + d78) - d910 + (d1516 + d1718);
  const T jz = (d56 + d1112) - d1314 + (d1516 - d1718);
  const T hp = T(-0.5) * p.omega_plus, hm = T(-0.5) * p.omega_minus;
  // Odd parts: M = hm D + 3 w (omega- c.j + F-odd c_x).
  const T wm_a = T(3) * wa * p.omega_minus, wm_d = T(3) * wd * p.omega_minus;
  const T fo_a = T(3) * wa * p.force_odd, fo_d = T(3) * wd * p.force_odd;
  // Diagonal combinations of j.
  const T jxy_p = jx + jy, jxy_m = jx - jy, jxz_p = jx + jz, jxz_m = jx - jz;
  const T jyz_p = jy + jz, jyz_m = jy - jz;
  T c_a, c_d;  // C_w per weight class
  T k_a, k_d;  // 4.5 omega+ w (multiplies (c.j)(c.u))
  T f_a, f_d;  // 9 w (1 - omega+/2) G_x (multiplies c_x (c.u))
  T ux = 0, uy = 0, uz = 0;
  if (kStokes) {
    c_a = p.omega_plus * wa * drho;
    c_d = p.omega_plus * wd * drho;
    o[0] = g[0] + p.omega_plus * (w0 * drho - g[0]);
    k_a = k_d = f_a = f_d = T(0);
  } else {
    const T inv_rho = T(1) / (T(1) + drho);
    ux = jx * inv_rho;
    uy = jy * inv_rho;
    uz = jz * inv_rho;
    const T ju = jx * ux + jy * uy + jz * uz;
    const T a = p.omega_plus * (drho - T(1.5) * ju) - T(3) * p.force_even * ux;
    c_a = wa * a;
    c_d = wd * a;
    o[0] = g[0] - p.omega_plus * g[0] + w0 * a;
    k_a = T(4.5) * wa * p.omega_plus;
    k_d = T(4.5) * wd * p.omega_plus;
    f_a = T(9) * wa * p.force_even;
    f_d = T(9) * wd * p.force_even;
  }
  // One pair: cj = c.j, cu = c.u, cx = c_x (0 or +-1, compile-time), S, D.
  auto pair = [&](T gi, T gib, T & oi, T & oib, T cj, T cu, int cx, bool axis)
      __attribute__((always_inline)) {
    const T S = gi + gib, D = gi - gib;
    T q = axis ? c_a : c_d;
    if (!kStokes) {
      q += (axis ? k_a : k_d) * cj * cu;
      if (cx != 0) q += (axis ? f_a : f_d) * T(cx) * cu;
    }
    const T P = hp * S + q;
    T r = (axis ? wm_a : wm_d) * cj;
    if (cx != 0) r += (axis ? fo_a : fo_d) * T(cx);
    const T M = hm * D + r;
    oi = gi + P + M;
    oib = gib + P - M;
  };
  pair(g[1], g[2], o[1], o[2], jx, ux, 1, true);
  pair(g[3], g[4], o[3], o[4], jy, uy, 0, true);
  pair(g[5], g[6], o[5], o[6], jz, uz, 0, true);
  pair(g[7], g[8], o[7], o[8], jxy_p, ux + uy, 1, false);
  pair(g[9], g[10], o[9], o[10], jxy_m, ux - uy, 1, false);
  pair(g[11], g[12], o[11], o[12], jxz_p, ux + uz, 1, false);
  pair(g[13], g[14], o[13], o[14], jxz_m, ux - uz, 1, false);
  pair(g[15], g[16], o[15], o[16], jyz_p, uy + uz, 0, false);
  pair(g[17], g[18], o[17], o[18], jyz_m, uy - uz, 0, false);
}

/// Regularized, in the same pair form: with the node scalar A = drho - 1.5 j.u - 3 F+ u_x
/// (F+ = (1 - omega+/2) G_x) and, per weight class, n_w = 4.5 w (1 - omega+),
///   o_i = P + M,  o_ib = P - M,
///   P = w A + cu (4.5 w c.j + 9 w F+ c_x) + n_w Q_i : Pi_neq,
///   M = 3 w c.j + c_x w (3 F- - 1.5 (1 - omega+) G_x)      (F- = (1 - omega-/2) G_x).
template <typename T, bool kStokes>
DRAGLAB_LBM_INLINE void collide_regularized(const T (&g)[19], T (&o)[19],
                                            const KernelParams<T>& p) {
  constexpr T w0 = T(d3q19::kW0), wa = T(d3q19::kWAxis), wd = T(d3q19::kWDiag);
  const T s12 = g[1] + g[2], s34 = g[3] + g[4], s56 = g[5] + g[6], s78 = g[7] + g[8];
  const T s910 = g[9] + g[10], s1112 = g[11] + g[12], s1314 = g[13] + g[14];
  const T s1516 = g[15] + g[16], s1718 = g[17] + g[18];
  const T d12 = g[1] - g[2], d34 = g[3] - g[4], d56 = g[5] - g[6];
  const T d78 = g[7] - g[8], d910 = g[9] - g[10], d1112 = g[11] - g[12], d1314 = g[13] - g[14];
  const T d1516 = g[15] - g[16], d1718 = g[17] - g[18];
  const T drho = ((g[0] + s12) + (s34 + s56)) + ((s78 + s910) + (s1112 + s1314)) + (s1516 + s1718);
  const T jx = (d12 + d78) + (d910 + d1112) + d1314 + T(0.5) * p.force_x;
  const T jy = (d34 + d78) - d910 + (d1516 + d1718);
  const T jz = (d56 + d1112) - d1314 + (d1516 - d1718);
  T ux = 0, uy = 0, uz = 0, a = drho;
  if (!kStokes) {
    const T inv_rho = T(1) / (T(1) + drho);
    ux = jx * inv_rho;
    uy = jy * inv_rho;
    uz = jz * inv_rho;
    a = drho - T(1.5) * (jx * ux + jy * uy + jz * uz) - T(3) * p.force_even * ux;
  }
  // Pi_neq = sum g c c - drho I/3 - j u (Pi_eq - I/3 = drho I/3 + j u), and Q_i : Pi_neq =
  // c.Pi_neq.c - tr(Pi_neq)/3, scaled by n_w: axis x is n_a (pxx - t), diagonal xy is
  // n_d (pxx + pyy - t) +- 2 n_d pxy (t = tr/3).
  const T third_drho = drho * T(1.0 / 3.0);
  const T pxx = (s12 + s78) + (s910 + s1112) + s1314 - third_drho - (kStokes ? T(0) : jx * ux);
  const T pyy = (s34 + s78) + (s910 + s1516) + s1718 - third_drho - (kStokes ? T(0) : jy * uy);
  const T pzz = (s56 + s1112) + (s1314 + s1516) + s1718 - third_drho - (kStokes ? T(0) : jz * uz);
  const T pxy = s78 - s910 - (kStokes ? T(0) : jx * uy);
  const T pxz = s1112 - s1314 - (kStokes ? T(0) : jx * uz);
  const T pyz = s1516 - s1718 - (kStokes ? T(0) : jy * uz);
  const T t = (pxx + pyy + pzz) * T(1.0 / 3.0);
  const T one_minus_omega = T(1) - p.omega_plus;
  const T n_a = T(4.5) * wa * one_minus_omega, n_d = T(4.5) * wd * one_minus_omega;
  const T two_n_d = T(2) * n_d;
  o[0] = w0 * a - T(4.5) * w0 * one_minus_omega * t;
  const T m_a = T(3) * wa, m_d = T(3) * wd;
  const T r_x = p.force_odd * T(3) - T(1.5) * one_minus_omega * p.force_x;
  const T r_a = wa * r_x, r_d = wd * r_x;
  const T c_a = wa * a, c_d = wd * a;
  const T k_a = T(4.5) * wa, k_d = T(4.5) * wd;
  const T f_a = T(9) * wa * p.force_even, f_d = T(9) * wd * p.force_even;
  // One pair: cj = c.j, cu = c.u, cx = c_x (compile-time), nq = n_w Q_i : Pi_neq.
  auto pair = [&](T & oi, T & oib, T cj, T cu, T nq, int cx, bool axis)
      __attribute__((always_inline)) {
    T P = (axis ? c_a : c_d) + nq;
    if (!kStokes) {
      T slope = (axis ? k_a : k_d) * cj;
      if (cx != 0) slope += (axis ? f_a : f_d) * T(cx);
      P += cu * slope;
    }
    T M = (axis ? m_a : m_d) * cj;
    if (cx != 0) M += (axis ? r_a : r_d) * T(cx);
    oi = P + M;
    oib = P - M;
  };
  const T dxy = n_d * (pxx + pyy - t), dxz = n_d * (pxx + pzz - t), dyz = n_d * (pyy + pzz - t);
  const T exy = two_n_d * pxy, exz = two_n_d * pxz, eyz = two_n_d * pyz;
  pair(o[1], o[2], jx, ux, n_a * (pxx - t), 1, true);
  pair(o[3], o[4], jy, uy, n_a * (pyy - t), 0, true);
  pair(o[5], o[6], jz, uz, n_a * (pzz - t), 0, true);
  pair(o[7], o[8], jx + jy, ux + uy, dxy + exy, 1, false);
  pair(o[9], o[10], jx - jy, ux - uy, dxy - exy, 1, false);
  pair(o[11], o[12], jx + jz, ux + uz, dxz + exz, 1, false);
  pair(o[13], o[14], jx - jz, ux - uz, dxz - exz, 1, false);
  pair(o[15], o[16], jy + jz, uy + uz, dyz + eyz, 0, false);
  pair(o[17], o[18], jy - jz, uy - uz, dyz - eyz, 0, false);
}

}  // namespace detail

/// Collides one node: g[0..18] in (shifted, pre-collision), o[0..18] out (shifted,
/// post-collision, o[i] is the population leaving along c_i).
template <typename T, CollisionKernel K, bool kStokes>
DRAGLAB_LBM_INLINE void collide_node(const T (&g)[19], T (&o)[19], const KernelParams<T>& p) {
  if constexpr (K == CollisionKernel::kTrt) {
    detail::collide_trt<T, kStokes>(g, o, p);
  } else {
    detail::collide_regularized<T, kStokes>(g, o, p);
  }
}

}  // namespace lbm
}  // namespace draglab
