// The unshadowed in-scattering of a local light along a view-ray section in closed form: Sun, Ramamoorthi,
// Narasimhan and Nayar 2005 ("A practical analytic single scattering model for real time rendering",
// Sec. 3, Eq. 5-10), extended to what crep::RayScattering integrates (crep/scatter/ray_scattering.h): the
// Henyey-Greenstein and Rayleigh phase functions, per-channel extinction, the light path's own extinction
// exp(-sigma d) (in Sun et al. too), a spot's angular falloff and a point face's sector.
//
// The substitution (Sun et al. 2005, Eq. 7-9): for the ray x(t) = o + t v (v unit), t0 and h the nearest
// point of its line to the light and its distance, write t - t0 = h tan(phi), d = h / cos(phi), and
// xi = pi / 4 + phi / 2 in (0, pi / 2). Then t + d = t0 + h tan(xi), dt / d^2 = 2 dxi / h and the
// scattering angle has cos(theta) = cos(2 xi), so outside the light's near ball (d >= nearPlane) and where
// the light's intensity I toward x is constant (a point face inside its sector, a spot inside its inner
// cone):
//
//   S(ta, tb) = I (2 / h) sum_phase sigma_s,phase [ E(ta) - E(tb) ],    per RGB channel, with
//   E(t)      = exp(-sigma (t + d(t))) T_phase(sigma h, xi(t)),
//   T_p(u, xi) = exp(u tan xi) integral_xi^(pi/2) exp(-u tan xi') p(cos 2 xi') dxi'.
//
// T is Sun et al.'s F(u, v) turned into a tail normalized by its integrand at xi: every exponential is
// <= 1 and E(t) never overflows where exp(-sigma t0) would (a light far behind the camera). T depends on u
// and xi alone for Rayleigh and for a given g for Henyey-Greenstein, so one 2D table per medium g serves
// every ray, light and extinction: the table stores N = T / K with K(u, eta) = s G(u / s), s = sin(eta) =
// cos(xi), eta = pi / 2 - xi, G(r) = (1 + a r) / (1 + (1 + 2a) r + a r^2), a = 0.9135: the form of T for a
// constant phase (T ~ eta for u -> 0, ~ cos^2(xi) / u for u -> infinity, and near the horizon xi -> pi / 2
// eta G(u / eta) with G(r) = 1 - r e^r E1(r), which the rational G follows within 6%), so N stays a
// smooth, bounded average of the phase function that bilinear filtering reproduces.
//
// Pieces the closed form does not cover (the breakpoints are RayScattering's) keep RayScattering's
// quadrature: a spot's falloff band (the angle to the axis between the inner and the outer cone, where the
// intensity varies along the ray), and the whole ray when it passes through the light's near ball (h <=
// nearPlane). Closed-form variants of the band were measured (its mean falloff from 3 Gauss-Legendre nodes
// per part of at most 0.1 rad in xi: 0.25% worst error of a ray's sum, 1.7% at 0.2 rad) and cost more than
// the quadrature they replace (a table end per part on top of the nodes).
//
// Accuracy of the table rule (64 x 512 table, bilinear; tests/scatter/AirlightTest.cpp, 644 random rays of
// spots and point faces, g in [0, 0.9], extinction 0.003-0.3, 16 regions per ray): worst relative error of a
// ray's sum 0.23%, RMS 0.018% (64 x 256: 1.0% / 0.05%, the horizon corner).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/medium.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// The tabulated tails N(u, xi) = T(u, xi) / K(u, xi) of one Henyey-Greenstein g and of the Rayleigh
/// phase (see the top), on a grid: column j <-> xi = (pi / 2) j / (xiSamples - 1), row i <-> y = i /
/// (uSamples - 1) with u = kAirlightUScale y / (1 - y) (the last row is the limit u -> infinity, N =
/// p(cos 2 xi)). Sampled like a GL_LINEAR texture with clamp to edge whose texel centres are the grid
/// points (AirlightTable::lookup; glsl/crep/airlight.glsl reads the same texture).
struct AirlightTable {
  static constexpr int kDefaultUSamples = 64;   ///< rows
  static constexpr int kDefaultXiSamples = 512; ///< columns
  int uSamples = 0, xiSamples = 0;
  double g = 0.0; ///< Henyey-Greenstein g the first channel was made for
  /// Row-major (row i, column j) pairs (Henyey-Greenstein N, Rayleigh N): the RG32F texels, 1/sr.
  std::vector<float> values;

  /// Bilinear N of both phase functions at (u >= 0, xi in [0, pi / 2]), as GL_LINEAR samples the texture.
  glm::dvec2 lookup(double u, double xi) const;
};

/// The table's coordinates: row y in [0, 1] <-> u = kAirlightUScale y^2 / (1 - y) (finer toward u = 0),
/// column x in [0, 1] <-> x = sqrt(sin xi) / (sqrt(sin xi) + sqrt(cos xi)) (xi = atan((x / (1 - x))^2);
/// finer toward both ends: the phase peak at xi = 0 and the horizon xi = pi / 2, where N depends on u / eta;
/// a GPU gets sin xi and cos xi from the ray's geometry with square roots, no transcendental function).
inline constexpr double kAirlightUScale = 1.0;
double airlightRowU(double y);
double airlightURow(double u);
double airlightColumnXi(double x);
double airlightXiColumn(double eta);

/// The table for Henyey-Greenstein `g` in (-1, 1) (InvalidArgument naming "g"), sizes >= 2
/// ("uSamples", "xiSamples"); each T by an adaptive-free Gauss-Legendre rule in double, exact to 1e-12.
AirlightTable makeAirlightTable(double g, int uSamples = AirlightTable::kDefaultUSamples,
                                int xiSamples = AirlightTable::kDefaultXiSamples);

/// T_p(u, xi) of the top in double without a table (the table's source and the tests' truth): p is
/// Henyey-Greenstein(g) when rayleigh is false, else the Rayleigh phase.
double airlightTail(double g, bool rayleigh, double u, double xi);

/// K(u, eta) of the top: T = N K (eta in [0, pi / 2]).
double airlightScale(double u, double eta);

/// S(ta, tb) of one view ray for a local light by the closed form (see the top): the CPU reference of the
/// GPU evaluation's section integral (crep_airlightSegment, glsl/crep/airlight.glsl) in double on the same
/// table. Differs from RayScattering::segment (exact) by the table's interpolation.
class AirlightScattering {
public:
  /// `table` must be made for medium.hgG() and outlive this object.
  AirlightScattering(const LocalLight& light, const Medium& medium, const AirlightTable& table,
                     const glm::dvec3& origin, const glm::dvec3& direction);

  /// S(ta, tb) per channel; 0 when tb <= ta.
  glm::dvec3 segment(double ta, double tb) const;

private:
  /// exp(-sigma (t + d)) sum_p sigma_s,p N_p K per channel at t (outside the near ball).
  glm::dvec3 endTerm(double t) const;

  RayScattering exact_;
  const AirlightTable* table_;
  LocalLight light_;
  glm::dvec3 origin_, direction_, sigma_, mie_, rayleigh_;
  double g_;
  glm::dvec3 perp_; ///< nearest point of the line minus the light position
  double t0_ = 0.0, h_ = 0.0;
};

} // namespace crep
