// The unshadowed in-scattering of a local light along a view-ray section in closed form (Sun, Ramamoorthi,
// Narasimhan and Nayar 2005, Sec. 3, Eq. 5-10), on a 2D table per medium g. The substitution, the table's
// normalization and coordinates, what stays quadrature: scatter/README.md, "crep/scatter/airlight.h".
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/medium.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// The tabulated tails N = T / K of one Henyey-Greenstein g and of the Rayleigh phase, sampled like a
/// GL_LINEAR, clamp-to-edge texture (README). One-time per medium g: 64 x 512 x 8 bytes by default.
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

/// The table's coordinates: row y <-> u = kAirlightUScale y^2 / (1 - y), column x <-> xi (README).
inline constexpr double kAirlightUScale = 1.0;
double airlightRowU(double y);
double airlightURow(double u);
double airlightColumnXi(double x);
double airlightXiColumn(double eta);

/// The table for Henyey-Greenstein `g` in (-1, 1) (InvalidArgument "g"), sizes >= 2 ("uSamples",
/// "xiSamples"). One-time, O(uSamples x xiSamples) quadratures.
AirlightTable makeAirlightTable(double g, int uSamples = AirlightTable::kDefaultUSamples,
                                int xiSamples = AirlightTable::kDefaultXiSamples);

/// T_p(u, xi) in double without a table: p is Henyey-Greenstein(g), or Rayleigh when `rayleigh`.
double airlightTail(double g, bool rayleigh, double u, double xi);

/// K(u, eta): T = N K (eta in [0, pi / 2]).
double airlightScale(double u, double eta);

/// S(ta, tb) of one view ray for a local light by the closed form: the CPU reference of
/// crep_airlightSegment (glsl/crep/airlight.glsl), on the same table.
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
