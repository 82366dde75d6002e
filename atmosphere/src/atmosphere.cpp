// CPU reference of the Earth atmosphere tables (crep/atmosphere/atmosphere.h): validation, the 4D table's
// parameterisation and look-ups (Yusov 2013, Eq. 4-7, Listings 1-2), the optical depth table, and the
// precomputation of single and multiple scattering and the ambient sky light (Yusov 2013, "Multiple
// Scattering" steps 1-3, Eq. 1-3, Listings 3-6; Bruneton and Neyret 2008). Everything is computed in double
// and stored as float; the look-ups during the precomputation read those float tables back, as the GPU
// passes do.
//
// Conventions shared with the GPU passes (they must agree texel for texel):
//  - a table texel's view ray ends on the ground for the lower alpha half and at the top of the atmosphere
//    for the upper half (never decided by a ray-sphere test);
//  - L_n's first sample (at the texel's own point C) reads J_n at the texel's own coordinates, and every
//    later look-up along the ray gets those coordinates as `previous` (so the ray stays on its side);
//  - J_n's and E_sky's look-ups into the previous order start fresh (previous = -1).
#include <crep/atmosphere/atmosphere.h>

#include <crep/core/error.h>
#include <crep/core/parallel.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace crep {

namespace {

constexpr double kPi = std::numbers::pi;
// Bruneton's sun zenith law (Yusov 2013, Eq. 6).
constexpr double kPhiClamp = -0.1975;
constexpr double kPhiScale = 1.1;
constexpr double kPhiRange = 1.26;
constexpr double kPhiOffset = 1.0 - 0.26;
// Eq. 5's power law.
constexpr double kAlphaPower = 0.2;

std::string field(const char* owner, const char* name) {
  return std::string(owner) + "." + name;
}

void requirePositiveField(const char* owner, const char* name, double v) {
  requirePositive(field(owner, name), v);
}

void requireCoefficient(const char* name, const glm::dvec3& c) {
  static const char* const kChannel[3] = {"r", "g", "b"};
  for (int i = 0; i < 3; ++i)
    if (!(std::isfinite(c[i]) && c[i] >= 0.0))
      throw InvalidArgument(std::string("AtmosphereParameters.") + name + "." + kChannel[i],
                            detail::formatValue(c[i]), "must be finite and >= 0 (1/m)");
}

void requireRange(const char* name, int v, int lo, int hi) {
  if (v < lo || v > hi)
    throw InvalidArgument(std::string("AtmospherePrecomputeOptions.") + name, detail::formatValue(v),
                          "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

double tanPhiRange() {
  return std::tan(kPhiRange * kPhiScale);
}

/// Texture coordinate of texel space u in [0, 1] for a dimension of n texels (texel i at u = i / (n - 1)).
double texCoord(double u, int n) {
  return (0.5 + u * (n - 1)) / n;
}

/// Yusov 2013, Eq. 6 (Bruneton's form): u_phi of c_phi.
double phiParam(double c) {
  const double u = 0.5 * (std::atan(std::max(c, kPhiClamp) * tanPhiRange()) / kPhiScale + kPhiOffset);
  return std::clamp(u, 0.0, 1.0);
}

/// Inverse of Eq. 6: c_phi of u_phi.
double phiFromParam(double u) {
  return std::tan((2.0 * u - kPhiOffset) * kPhiScale) / tanPhiRange();
}

/// Yusov 2013, Eq. 7: u_theta of c_theta, gamma = acos(c_theta) / pi.
double thetaParam(double c) {
  const double gamma = std::acos(std::clamp(c, -1.0, 1.0)) / kPi;
  const double u = gamma >= 0.5 ? 0.5 + 0.5 * std::pow(2.0 * (gamma - 0.5), 1.5)
                                : 0.5 - 0.5 * std::pow(2.0 * (0.5 - gamma), 1.5);
  return std::clamp(u, 0.0, 1.0);
}

/// Inverse of Eq. 7: c_theta of u_theta.
double thetaFromParam(double u) {
  const double gamma = u >= 0.5 ? 0.5 + 0.5 * std::pow(2.0 * (u - 0.5), 2.0 / 3.0)
                                : 0.5 - 0.5 * std::pow(2.0 * (0.5 - u), 2.0 / 3.0);
  return std::cos(kPi * gamma);
}

/// Yusov 2013, Eq. 5 with Listing 2: u_alpha's texture coordinate (h already clamped, c_alpha in [-1, 1]),
/// the side of the horizon from the previous look-up's u_alpha (negative: the first look-up).
double alphaCoord(const AtmosphereParameters& p, int n, double h, double ca, double previous) {
  const double ch = -std::sqrt(h * (2.0 * p.earthRadius + h)) / (p.earthRadius + h);
  const bool prevAbove = previous >= 0.5;
  const bool prevBelow = previous >= 0.0 && previous < 0.5;
  if (prevAbove || (!prevBelow && ca > ch)) {
    const double t = std::pow(std::clamp((ca - ch) / (1.0 - ch), 0.0, 1.0), kAlphaPower);
    return (n / 2 + 0.5 + t * (n / 2 - 1)) / n;
  }
  const double t = std::pow(std::clamp((ch - ca) / (ch + 1.0), 0.0, 1.0), kAlphaPower);
  return (0.5 + t * (n / 2 - 1)) / n;
}

/// Sea-level-relative densities (d_R, d_M) at distance r from the planet centre (Yusov 2012, Sec. 2).
glm::dvec2 densities(const AtmosphereParameters& p, double r) {
  const double h = std::max(r - p.earthRadius, 0.0);
  return {std::exp(-h / p.rayleighScaleHeight), std::exp(-h / p.mieScaleHeight)};
}

glm::dvec3 mieExtinction(const AtmosphereParameters& p) {
  return p.mieScattering + p.mieAbsorption;
}

/// exp(-(beta_R D.x + beta_Me D.y)) (Yusov 2013, Listing 5's extinction from density integrals).
glm::dvec3 transmittanceOf(const AtmosphereParameters& p, const glm::dvec2& d) {
  const glm::dvec3 tau = p.rayleighScattering * d.x + mieExtinction(p) * d.y;
  return glm::exp(-tau);
}

/// Far root of |C + t v| = radius for C = (0, r0, 0) and unit v with v.y = c (C inside the sphere).
double farRoot(double r0, double c, double radius) {
  const double disc = r0 * r0 * (c * c - 1.0) + radius * radius;
  return std::max(-r0 * c + std::sqrt(std::max(disc, 0.0)), 0.0);
}

/// Nearest non-negative root of |C + t v| = R (the ground) for C = (0, r0, 0); the tangent point when the
/// discriminant is negative through rounding.
double groundRoot(double r0, double c, double radius) {
  const double disc = r0 * r0 * (c * c - 1.0) + radius * radius;
  if (disc < 0.0) return std::max(-r0 * c, 0.0);
  return std::max(-r0 * c - std::sqrt(disc), 0.0);
}

/// GL linear filtering along one dimension of n texels at texture coordinate s (clamp to edge).
struct Lerp1 {
  int i0, i1;
  double f;
};
Lerp1 glLerp(double s, int n) {
  const double x = s * n - 0.5;
  const double fl = std::floor(x);
  const double f = x - fl;
  const int i = static_cast<int>(fl);
  return {std::clamp(i, 0, n - 1), std::clamp(i + 1, 0, n - 1), f};
}

glm::dvec4 texel4(const AtmosphereTable4D& t, int ih, int ia, int slice) {
  const std::size_t idx = ((static_cast<std::size_t>(slice) * static_cast<std::size_t>(t.size.viewZenith) +
                            static_cast<std::size_t>(ia)) *
                               static_cast<std::size_t>(t.size.height) +
                           static_cast<std::size_t>(ih)) *
                          4;
  return {t.rgba[idx], t.rgba[idx + 1], t.rgba[idx + 2], t.rgba[idx + 3]};
}

/// One GL trilinear fetch of the packed 3D texture (clamp to edge).
glm::dvec4 fetchTrilinear(const AtmosphereTable4D& t, double s, double tc, double r) {
  const int depth = t.size.sunZenith * t.size.sunView;
  const Lerp1 x = glLerp(s, t.size.height);
  const Lerp1 y = glLerp(tc, t.size.viewZenith);
  const Lerp1 z = glLerp(r, depth);
  const auto row = [&](int iy, int iz) {
    return glm::mix(texel4(t, x.i0, iy, iz), texel4(t, x.i1, iy, iz), x.f);
  };
  const auto plane = [&](int iz) { return glm::mix(row(y.i0, iz), row(y.i1, iz), y.f); };
  return glm::mix(plane(z.i0), plane(z.i1), z.f);
}

/// GL bilinear filtering (clamp to edge) of a 2D table of altitudes (u = sqrt(h / H_Atm), across) by cosines
/// (linear in [-1, 1], down): the optical depth table's and Psi_ms's rule. Its first min(3, channels).
glm::dvec3 sampleHeightCosine(const Image& img, double atmosphereHeight, double h, double cosZenith) {
  const int w = img.width(), hgt = img.height(), channels = std::min(3, img.channels());
  const double uh = std::sqrt(std::clamp(h / atmosphereHeight, 0.0, 1.0));
  const double uc = (std::clamp(cosZenith, -1.0, 1.0) + 1.0) * 0.5;
  const Lerp1 x = glLerp(texCoord(uh, w), w);
  const Lerp1 y = glLerp(texCoord(uc, hgt), hgt);
  const auto at = [&](int i, int j) {
    glm::dvec3 v(0.0);
    for (int c = 0; c < channels; ++c)
      v[c] = img.at(i, j, c);
    return v;
  };
  return glm::mix(glm::mix(at(x.i0, y.i0), at(x.i1, y.i0), x.f),
                  glm::mix(at(x.i0, y.i1), at(x.i1, y.i1), x.f), y.f);
}

void store(AtmosphereTable4D& t, int ih, int ia, int ip, int it, const glm::dvec3& v) {
  t.at(ih, ia, ip, it) = glm::vec4(glm::vec3(v), 0.0f);
}

AtmosphereTable4D emptyTable(const AtmosphereTableSize& size) {
  AtmosphereTable4D t;
  t.size = size;
  t.rgba.assign(t.texels() * 4, 0.0f);
  return t;
}

/// The texel's point C, view v and sun l in the table frame, and its own texture coordinates.
struct TexelRay {
  double h, cosView;
  glm::dvec3 c, v, l;
  glm::dvec4 coords;
  double length; ///< to the ground (lower half) or the top (upper half)
};

TexelRay texelRay(const AtmosphereParameters& p, const AtmosphereTableSize& size, int ih, int ia, int ip,
                  int it) {
  const glm::dvec4 w = atmosphereTexelParams(p, size, ih, ia, ip, it);
  TexelRay r;
  r.h = w.x;
  r.cosView = w.y;
  r.c = glm::dvec3(0.0, p.earthRadius + w.x, 0.0);
  atmosphereDirections(w.y, w.z, w.w, r.v, r.l);
  r.coords = glm::dvec4((ih + 0.5) / size.height, (ia + 0.5) / size.viewZenith, (ip + 0.5) / size.sunZenith,
                        (it + 0.5) / size.sunView);
  const double r0 = p.earthRadius + w.x;
  r.length = ia < size.viewZenith / 2 ? groundRoot(r0, w.y, p.earthRadius)
                                      : farRoot(r0, w.y, p.earthRadius + p.atmosphereHeight);
  return r;
}

/// Runs body(ih, ia, ip, it) for every texel of a 4D table, the (ia, ip, it) rows in parallel.
template <class Body>
void forEachTexel(const AtmosphereTableSize& size, int threads, const Body& body) {
  const int rows = size.viewZenith * size.sunZenith * size.sunView;
  parallelRows(rows, threads, [&](int row) {
    const int ia = row % size.viewZenith;
    const int ip = (row / size.viewZenith) % size.sunZenith;
    const int it = row / (size.viewZenith * size.sunZenith);
    for (int ih = 0; ih < size.height; ++ih)
      body(ih, ia, ip, it);
  });
}

/// Single scattering without the phase functions: S_R and S_M of the top of the header; with the Lut
/// method's table also L_H.
struct SingleParts {
  glm::dvec3 rayleigh{0.0}, mie{0.0}, higher{0.0};
};

/// Yusov 2013, Listing 3 without the phase functions (Bruneton and Neyret 2008, Sec. 4): S_R and S_M of
/// one texel by the trapezoid rule, T_sun from the table; `lut`: also L_H = the integral of T(C->P)
/// sigma_s(P) Psi_ms(P) (Hillaire 2020, Sec. 5.5).
SingleParts singleScattering(const AtmosphereTables& tables, const TexelRay& r, int steps, bool lut) {
  const AtmosphereParameters& p = tables.parameters;
  const double ds = r.length / steps;
  glm::dvec2 camDensity(0.0);
  glm::dvec2 prevD(0.0);
  SingleParts prevF, sum;
  for (int k = 0; k <= steps; ++k) {
    const glm::dvec3 pk = r.c + r.v * (r.length * k / steps);
    const double rk = glm::length(pk);
    const glm::dvec2 d = densities(p, rk);
    if (k > 0) camDensity += (prevD + d) * (0.5 * ds);
    const glm::dvec3 tCam = transmittanceOf(p, camDensity);
    const glm::dvec3 tt = tCam * sunTransmittance(tables, pk, r.l);
    SingleParts f{p.rayleighScattering * d.x * tt, p.mieScattering * d.y * tt, glm::dvec3(0.0)};
    if (lut) {
      const glm::dvec3 sigmaS = p.rayleighScattering * d.x + p.mieScattering * d.y;
      f.higher =
          tCam * sigmaS * lookUpMultipleScatteringLut(tables, rk - p.earthRadius, glm::dot(pk / rk, r.l));
    }
    if (k > 0) {
      sum.rayleigh += (prevF.rayleigh + f.rayleigh) * (0.5 * ds);
      sum.mie += (prevF.mie + f.mie) * (0.5 * ds);
      sum.higher += (prevF.higher + f.higher) * (0.5 * ds);
    }
    prevD = d;
    prevF = f;
  }
  return sum;
}

/// Hillaire 2020, Sec. 5.5: Psi_ms at altitude h for sun zenith cosine mu. From the point x, `samples`
/// Fibonacci directions w, each marched to the ground or the top with `steps` midpoint steps: the second
/// order L2 = mean over w of L'(w) = the integral of T(x, y) (beta_R d_R p_R + beta_M d_M p_HG)(w . l)
/// T_sun(y) (the first scattering with its true phase functions; Hillaire takes the isotropic 1 / (4 pi),
/// measured 5% darker in red on the Earth's table) plus, where w ends on the ground, T(x, ground)
/// T_sun(ground) max(0, n . l) albedo / pi; and the transfer f_ms = mean
/// over w of the integral of T(x, y) sigma_s(y) (the isotropic phase at x makes both means over the
/// sphere). Psi_ms = L2 / (1 - f_ms): every order >= 2, a geometric series.
glm::dvec3 multipleScatteringAt(const AtmosphereTables& tables, double h, double mu, int samples, int steps) {
  const AtmosphereParameters& p = tables.parameters;
  const double R = p.earthRadius, top = R + p.atmosphereHeight;
  const glm::dvec3 x(0.0, R + h, 0.0);
  const glm::dvec3 l(std::sqrt(std::max(0.0, 1.0 - mu * mu)), mu, 0.0);
  const double r0 = R + h;
  glm::dvec3 second(0.0), transfer(0.0);
  for (int i = 0; i < samples; ++i) {
    const glm::dvec3 w = fibonacciSphereDirection(i, samples);
    const double c = w.y;
    const bool ground = c < 0.0 && r0 * r0 * (c * c - 1.0) + R * R >= 0.0;
    const double length = ground ? groundRoot(r0, c, R) : farRoot(r0, c, top);
    const double dt = length / steps;
    const double wl = glm::dot(w, l);
    const double phaseR = rayleighPhase(wl), phaseM = henyeyGreenstein(p.mieG, wl);
    glm::dvec2 optical(0.0);
    glm::dvec3 lum(0.0), fms(0.0);
    for (int k = 0; k < steps; ++k) {
      const glm::dvec3 y = x + w * ((k + 0.5) * dt);
      const double ry = glm::length(y);
      const glm::dvec2 d = densities(p, ry);
      // The transmittance to the step's middle: the half step's densities added first (midpoint rule).
      const glm::dvec3 t = transmittanceOf(p, optical + d * (0.5 * dt));
      optical += d * dt;
      const glm::dvec3 sigmaS = p.rayleighScattering * d.x + p.mieScattering * d.y;
      const glm::dvec3 phased = p.rayleighScattering * (d.x * phaseR) + p.mieScattering * (d.y * phaseM);
      lum += t * phased * sunTransmittance(tables, y, l) * dt;
      fms += t * sigmaS * dt;
    }
    if (ground) {
      const glm::dvec3 g = x + w * length;
      const double cosSun = glm::dot(g / glm::length(g), l);
      if (cosSun > 0.0)
        lum += transmittanceOf(p, optical) * sunTransmittance(tables, g, l) * (cosSun * p.groundAlbedo / kPi);
    }
    second += lum;
    transfer += fms;
  }
  // Isotropic phase 1 / (4 pi) at x times the sphere's 4 pi / samples: the means.
  second /= samples;
  transfer /= samples;
  return second / (glm::dvec3(1.0) - transfer);
}

/// S_R p_R(c) + S_M p_HG(c): L1 of phase-free parts.
glm::dvec3 withPhase(const AtmosphereParameters& p, const glm::dvec3& rayleigh, const glm::dvec3& mie,
                     double c) {
  return rayleigh * rayleighPhase(c) + mie * henyeyGreenstein(p.mieG, c);
}

/// The Fibonacci directions of Eq. 1 and 3 and, per table altitude, their u_alpha coordinates for a
/// fresh look-up at the texel's point (the same numbers lookUpAtmosphere computes there: the point is on
/// the +y axis, so c_alpha = w.y exactly).
struct SphereSamples {
  std::vector<glm::dvec3> dirs;
  std::vector<double> alpha;  ///< [ih * samples + i]
  std::vector<double> height; ///< [ih]: u_h's texture coordinate
};

SphereSamples sphereSamples(const AtmosphereParameters& p, const AtmosphereTableSize& size, int samples) {
  SphereSamples s;
  s.dirs.resize(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i)
    s.dirs[static_cast<std::size_t>(i)] = fibonacciSphereDirection(i, samples);
  for (int ih = 0; ih < size.height; ++ih) {
    const glm::dvec4 w = atmosphereTexelParams(p, size, ih, 0, 0, 0);
    const double r = glm::length(glm::dvec3(0.0, p.earthRadius + w.x, 0.0));
    const double h = std::clamp(r - p.earthRadius, 0.0, p.atmosphereHeight);
    s.height.push_back(texCoord(std::sqrt(h / p.atmosphereHeight), size.height));
    for (const glm::dvec3& d : s.dirs)
      s.alpha.push_back(alphaCoord(p, size.viewZenith, h, std::clamp(d.y, -1.0, 1.0), -1.0));
  }
  return s;
}

/// The ground's first bounce seen from the texel's point along w (Bruneton 2017's ground term of the
/// orders, the direct sunlight only): a direction that hits the ground at g brings T(C->g) (groundAlbedo /
/// pi) T_sun(g) max(0, n_g . l), T(C->g) from the optical depth table (atmosphereTransmittance's rule for a
/// ray that hits the ground); 0 for the other directions. GLSL twin in passes/atmosphere_scattered.comp.
glm::dvec3 groundBounce(const AtmosphereTables& tables, const TexelRay& r, const glm::dvec3& w) {
  const AtmosphereParameters& p = tables.parameters;
  if (!(p.groundAlbedo > 0.0) || !(w.y < 0.0)) return glm::dvec3(0.0);
  const double R = p.earthRadius, r0 = R + r.h, hh = r.h * (2.0 * R + r.h), b = r0 * w.y;
  const double disc = b * b - hh;
  if (disc < 0.0) return glm::dvec3(0.0);
  const double t = hh / (std::sqrt(disc) - b); // the near root, without cancellation
  const double mu = (b + t) / R, cosSun = (r0 * r.l.y + t * glm::dot(w, r.l)) / R;
  if (!(cosSun > 0.0)) return glm::dvec3(0.0);
  const glm::dvec2 D =
      glm::max(lookUpDensityToTop(tables, 0.0, -mu) - lookUpDensityToTop(tables, r.h, -w.y), glm::dvec2(0.0));
  return transmittanceOf(p, D) * transmittanceOf(p, lookUpDensityToTop(tables, 0.0, cosSun)) *
         (cosSun * p.groundAlbedo / kPi);
}

/// Yusov 2013, Eq. 1 / Listing 4: J_n of one texel from L_(n-1) over the Fibonacci sphere (each a fresh
/// Listing 1 look-up at C; u_h, u_alpha and u_phi do not depend on the texel's view). `prev` null: L1 of
/// `tables` (n = 2), its phase functions at w . l, plus the ground's first bounce (groundBounce).
glm::dvec3 scatteredRadiance(const AtmosphereTables& tables, const AtmosphereTable4D* prev, const TexelRay& r,
                             int ih, const SphereSamples& sphere) {
  const AtmosphereParameters& p = tables.parameters;
  const AtmosphereTableSize& size = tables.options.size;
  const glm::dvec2 d = densities(p, glm::length(r.c));
  const glm::dvec3 betaR = p.rayleighScattering * d.x;
  const glm::dvec3 betaM = p.mieScattering * d.y;
  const double uPhi = texCoord(phiParam(std::clamp(r.l.y, -1.0, 1.0)), size.sunZenith);
  const int samples = static_cast<int>(sphere.dirs.size());
  const double* alpha = sphere.alpha.data() + static_cast<std::size_t>(ih) * sphere.dirs.size();
  glm::dvec3 sum(0.0);
  for (int i = 0; i < samples; ++i) {
    const glm::dvec3& w = sphere.dirs[static_cast<std::size_t>(i)];
    const double wl = std::clamp(glm::dot(w, r.l), -1.0, 1.0);
    const glm::dvec4 coords(sphere.height[static_cast<std::size_t>(ih)], alpha[i], uPhi,
                            texCoord(thetaParam(wl), size.sunView));
    glm::dvec3 l = prev ? sampleAtmosphereTable(*prev, coords) : sampleSingleScattering(tables, coords, wl);
    if (!prev) l += groundBounce(tables, r, w);
    const double c = glm::dot(w, r.v);
    sum += (betaR * rayleighPhase(c) + betaM * henyeyGreenstein(p.mieG, c)) * l;
  }
  return sum * (4.0 * kPi / samples);
}

/// Yusov 2013, Eq. 2 / Listing 5: L_n of one texel, the trapezoid rule over J_n along the texel's ray.
glm::dvec3 scatteringOrder(const AtmosphereTables& tables, const AtmosphereTable4D& j, const TexelRay& r,
                           int steps) {
  const AtmosphereParameters& p = tables.parameters;
  const double ds = r.length / steps;
  glm::dvec2 camDensity(0.0);
  glm::dvec2 prevD = densities(p, glm::length(r.c));
  glm::dvec3 prevF = sampleAtmosphereTable(j, r.coords);
  glm::dvec3 sum(0.0);
  for (int k = 1; k <= steps; ++k) {
    const glm::dvec3 pk = r.c + r.v * (r.length * k / steps);
    const glm::dvec2 d = densities(p, glm::length(pk));
    camDensity += (prevD + d) * (0.5 * ds);
    glm::dvec4 coords = r.coords;
    const glm::dvec3 f = transmittanceOf(p, camDensity) * lookUpAtmosphere(tables, j, pk, r.v, r.l, coords);
    sum += (prevF + f) * (0.5 * ds);
    prevD = d;
    prevF = f;
  }
  return sum;
}

} // namespace

// --- Validation -------------------------------------------------------------------------------------------

void validate(const AtmosphereParameters& p) {
  const char* o = "AtmosphereParameters";
  requirePositiveField(o, "earthRadius", p.earthRadius);
  requirePositiveField(o, "atmosphereHeight", p.atmosphereHeight);
  requirePositiveField(o, "rayleighScaleHeight", p.rayleighScaleHeight);
  requirePositiveField(o, "mieScaleHeight", p.mieScaleHeight);
  requireCoefficient("rayleighScattering", p.rayleighScattering);
  requireCoefficient("mieScattering", p.mieScattering);
  requireCoefficient("mieAbsorption", p.mieAbsorption);
  const glm::dvec3 s = p.rayleighScattering + p.mieScattering;
  if (!(std::max({s.x, s.y, s.z}) > 0.0))
    throw InvalidArgument("AtmosphereParameters.rayleighScattering", "0",
                          "some Rayleigh or Mie scattering is needed (mieScattering is 0 too)");
  if (!(std::isfinite(p.mieG) && std::abs(p.mieG) < 1.0))
    throw InvalidArgument("AtmosphereParameters.mieG", detail::formatValue(p.mieG), "must satisfy |g| < 1");
  if (!(p.groundAlbedo >= 0.0 && p.groundAlbedo <= 1.0))
    throw InvalidArgument("AtmosphereParameters.groundAlbedo", detail::formatValue(p.groundAlbedo),
                          "must be in [0, 1]");
}

void validate(const AtmospherePrecomputeOptions& o) {
  constexpr int kMaxSize = 2048;
  constexpr int kMaxSteps = 4096;
  requireRange("size.height", o.size.height, 2, kMaxSize);
  requireRange("size.viewZenith", o.size.viewZenith, 4, kMaxSize);
  if (o.size.viewZenith % 2 != 0)
    throw InvalidArgument("AtmospherePrecomputeOptions.size.viewZenith",
                          detail::formatValue(o.size.viewZenith), "must be even (two halves of the horizon)");
  requireRange("size.sunZenith", o.size.sunZenith, 2, kMaxSize);
  requireRange("size.sunView", o.size.sunView, 2, kMaxSize);
  if (o.size.sunZenith * o.size.sunView > kMaxSize)
    throw InvalidArgument("AtmospherePrecomputeOptions.size.sunView",
                          detail::formatValue(o.size.sunZenith * o.size.sunView),
                          "the packed depth sunZenith * sunView must be <= 2048");
  if (o.multipleScattering != AtmosphereMultipleScattering::Lut &&
      o.multipleScattering != AtmosphereMultipleScattering::Orders)
    throw InvalidArgument("AtmospherePrecomputeOptions.multipleScattering",
                          detail::formatValue(static_cast<int>(o.multipleScattering)),
                          "must be one of AtmosphereMultipleScattering");
  requireRange("multipleScatteringSize", o.multipleScatteringSize, 2, kMaxSize);
  requireRange("multipleScatteringSteps", o.multipleScatteringSteps, 1, kMaxSteps);
  requireRange("orders", o.orders, 1, 16);
  requireRange("singleSteps", o.singleSteps, 1, kMaxSteps);
  requireRange("orderSteps", o.orderSteps, 1, kMaxSteps);
  requireRange("sphereSamples", o.sphereSamples, 1, kMaxSteps);
  requireRange("opticalDepthHeight", o.opticalDepthHeight, 2, kMaxSize);
  requireRange("opticalDepthZenith", o.opticalDepthZenith, 2, kMaxSize);
  requireRange("opticalDepthSteps", o.opticalDepthSteps, 1, kMaxSteps);
  requireRange("ambientSize", o.ambientSize, 2, kMaxSize);
}

void validate(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o) {
  validate(p);
  validate(o);
  const glm::dvec3& r = p.rayleighScattering;
  if (o.combinedMie && !(r.x > 0.0 && r.y > 0.0 && r.z > 0.0 && p.mieScattering.x > 0.0))
    throw InvalidArgument("AtmospherePrecomputeOptions.combinedMie", "true",
                          "needs AtmosphereParameters.rayleighScattering > 0 in every channel and "
                          "mieScattering.r > 0 (the combined form divides by them)");
}

void validate(const AtmospherePlacement& placement, const AtmosphereParameters& p) {
  requirePositiveField("AtmospherePlacement", "metersPerUnit", placement.metersPerUnit);
  if (!(std::isfinite(placement.originAltitude) && placement.originAltitude >= 0.0 &&
        placement.originAltitude < p.atmosphereHeight))
    throw InvalidArgument("AtmospherePlacement.originAltitude", detail::formatValue(placement.originAltitude),
                          "metres, must be in [0, AtmosphereParameters.atmosphereHeight)");
}

// --- AtmosphereTable4D ------------------------------------------------------------------------------------

std::size_t AtmosphereTable4D::texels() const {
  if (size.height <= 0 || size.viewZenith <= 0 || size.sunZenith <= 0 || size.sunView <= 0) return 0;
  return static_cast<std::size_t>(size.height) * static_cast<std::size_t>(size.viewZenith) *
         static_cast<std::size_t>(size.sunZenith) * static_cast<std::size_t>(size.sunView);
}

namespace {
std::size_t packedIndex(const AtmosphereTableSize& s, int ih, int ia, int ip, int it) {
  return ((static_cast<std::size_t>(it) * static_cast<std::size_t>(s.sunZenith) +
           static_cast<std::size_t>(ip)) *
              static_cast<std::size_t>(s.viewZenith) +
          static_cast<std::size_t>(ia)) *
             static_cast<std::size_t>(s.height) +
         static_cast<std::size_t>(ih);
}
} // namespace

glm::vec4 AtmosphereTable4D::at(int ih, int ia, int ip, int it) const {
  const std::size_t i = packedIndex(size, ih, ia, ip, it) * 4;
  return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
}

glm::vec4& AtmosphereTable4D::at(int ih, int ia, int ip, int it) {
  return *reinterpret_cast<glm::vec4*>(rgba.data() + packedIndex(size, ih, ia, ip, it) * 4);
}

// --- Parameterisation -------------------------------------------------------------------------------------

// Yusov 2013, Eq. 5's c_h: the cosine of the horizon's zenith angle at altitude h.
double cosHorizon(const AtmosphereParameters& p, double h) {
  const double hh = std::max(h, 0.0);
  return -std::sqrt(hh * (2.0 * p.earthRadius + hh)) / (p.earthRadius + hh);
}

// Bruneton and Neyret 2008's horizon blend, its width from the table's altitude texels around h.
double horizonBlendWidth(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h) {
  const int N = size.height;
  const double H = p.atmosphereHeight;
  const double u = std::sqrt(std::clamp(h / H, 0.0, 1.0)) * (N - 1);
  const int i0 = std::clamp(static_cast<int>(std::floor(u)), 0, N - 2);
  const double a = double(i0) / (N - 1), b = double(i0 + 1) / (N - 1);
  return 2.0 * std::abs(cosHorizon(p, H * b * b) - cosHorizon(p, H * a * a)) + 0.004;
}

// Yusov 2013, Eq. 4-7 with Listing 2's side choice and texel-centre mapping of u_alpha.
glm::dvec4 atmosphereTableCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h,
                                 double cosViewZenith, double cosSunZenith, double cosSunView,
                                 const glm::dvec4& previous) {
  const double hc = std::clamp(h, 0.0, p.atmosphereHeight);
  const double ca = std::clamp(cosViewZenith, -1.0, 1.0);
  const double cp = std::clamp(cosSunZenith, -1.0, 1.0);
  const double ct = std::clamp(cosSunView, -1.0, 1.0);

  const double uh = std::sqrt(hc / p.atmosphereHeight); // Eq. 4

  return {texCoord(uh, size.height), alphaCoord(p, size.viewZenith, hc, ca, previous.y),
          texCoord(phiParam(cp), size.sunZenith), texCoord(thetaParam(ct), size.sunView)};
}

// The inverse of Eq. 4-7 at the texel centres (the top of crep/atmosphere/atmosphere.h).
glm::dvec4 atmosphereTexelParams(const AtmosphereParameters& p, const AtmosphereTableSize& size, int ih,
                                 int ia, int ip, int it) {
  const double uh = static_cast<double>(ih) / (size.height - 1);
  const double h = p.atmosphereHeight * uh * uh;
  const double ch = cosHorizon(p, h);
  const int half = size.viewZenith / 2;
  double ca;
  if (ia < half) {
    const double t = static_cast<double>(ia) / (half - 1);
    ca = ch - std::pow(t, 5.0) * (ch + 1.0);
  } else {
    const double t = static_cast<double>(ia - half) / (half - 1);
    ca = ch + std::pow(t, 5.0) * (1.0 - ch);
  }
  const double cp = phiFromParam(static_cast<double>(ip) / (size.sunZenith - 1));
  const double ct = thetaFromParam(static_cast<double>(it) / (size.sunView - 1));
  return {h, ca, cp, ct};
}

// Listing 3's ComputeViewDir / ComputeLightDir: v in the x-y plane, l from c_phi and c_theta.
void atmosphereDirections(double cosViewZenith, double cosSunZenith, double cosSunView, glm::dvec3& view,
                          glm::dvec3& sun) {
  const double ca = std::clamp(cosViewZenith, -1.0, 1.0);
  const double sa = std::sqrt(std::max(0.0, 1.0 - ca * ca));
  view = glm::dvec3(sa, ca, 0.0);
  const double ly = cosSunZenith;
  const double lx = sa < 1e-6 ? 0.0 : (cosSunView - ca * cosSunZenith) / sa;
  const double lz = std::sqrt(std::max(0.0, 1.0 - lx * lx - ly * ly));
  sun = glm::normalize(glm::dvec3(lx, ly, lz));
}

glm::dvec3 sampleAtmosphereTable(const AtmosphereTable4D& table, const glm::dvec4& coords) {
  return glm::dvec3(sampleAtmosphereTableRgba(table, coords));
}

// Yusov 2013, Listing 1: trilinear in the packed 3D texture, linear between the two theta slices.
glm::dvec4 sampleAtmosphereTableRgba(const AtmosphereTable4D& table, const glm::dvec4& coords) {
  const int nTheta = table.size.sunView;
  const int depth = table.size.sunZenith * nTheta;
  const double q = coords.w * nTheta - 0.5;
  const double q0 = std::clamp(std::floor(q), 0.0, static_cast<double>(nTheta - 1));
  const double weight = std::clamp(q - q0, 0.0, 1.0);
  const double q1 = std::min(q0 + 1.0, static_cast<double>(nTheta - 1));
  const double zMin = q0 / nTheta + 0.5 / depth;
  const double zMax = (q0 + 1.0) / nTheta - 0.5 / depth;
  const double z0 = std::clamp((q0 + coords.z) / nTheta, zMin, zMax);
  const double z1 = z0 + (q1 - q0) / nTheta;
  const glm::dvec4 a = fetchTrilinear(table, coords.x, coords.y, z0);
  const glm::dvec4 b = fetchTrilinear(table, coords.x, coords.y, z1);
  return glm::mix(a, b, weight);
}

// Bruneton's 2017 implementation, GetExtrapolatedSingleMieScattering.
glm::dvec3 combinedMieScattering(const AtmosphereParameters& p, const glm::dvec4& single) {
  if (!(single.x > 0.0) || !(p.mieScattering.x > 0.0)) return glm::dvec3(0.0);
  const glm::dvec3 ratio = p.mieScattering / p.rayleighScattering; // > 0 by validate(p, o)
  return glm::dvec3(single) * (single.w / single.x) * (p.rayleighScattering.x / p.mieScattering.x) * ratio;
}

// L1 = S_R p_R + S_M p_HG (the top of the header).
glm::dvec3 sampleSingleScattering(const AtmosphereTables& tables, const glm::dvec4& coords,
                                  double cosSunView) {
  const glm::dvec4 s = sampleAtmosphereTableRgba(tables.single, coords);
  const glm::dvec3 mie = tables.options.combinedMie ? combinedMieScattering(tables.parameters, s)
                                                    : sampleAtmosphereTable(tables.singleMie, coords);
  return withPhase(tables.parameters, glm::dvec3(s), mie, std::clamp(cosSunView, -1.0, 1.0));
}

glm::dvec3 lookUpSingleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                  const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords) {
  coords = atmosphereLookUpCoords(tables.parameters, tables.single.size, position, view, toSun, coords);
  return sampleSingleScattering(tables, coords, glm::dot(view, toSun));
}

glm::dvec3 lookUpMultipleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                    const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords) {
  const glm::dvec3 single = lookUpSingleScattering(tables, position, view, toSun, coords);
  return single + sampleAtmosphereTable(tables.higherOrders, coords);
}

// Yusov 2013, Listing 1 end to end.
glm::dvec3 lookUpAtmosphere(const AtmosphereTables& tables, const AtmosphereTable4D& table,
                            const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                            glm::dvec4& coords) {
  coords = atmosphereLookUpCoords(tables.parameters, table.size, position, view, toSun, coords);
  return sampleAtmosphereTable(table, coords);
}

// Listing 1's coordinates of a world point and its directions.
glm::dvec4 atmosphereLookUpCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size,
                                  const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                                  const glm::dvec4& previous) {
  const double r = glm::length(position);
  const glm::dvec3 up = position / r;
  return atmosphereTableCoords(p, size, r - p.earthRadius, glm::dot(up, view), glm::dot(up, toSun),
                               glm::dot(view, toSun), previous);
}

// Yusov 2013, the net density table look-up (bilinear, clamp to edge).
glm::dvec2 lookUpDensityToTop(const AtmosphereTables& tables, double h, double cosZenith) {
  return glm::dvec2(
      sampleHeightCosine(tables.opticalDepth, tables.parameters.atmosphereHeight, h, cosZenith));
}

// Yusov 2013, "Terrain shaders": the sun's extinction from the net density to the top.
glm::dvec3 sunTransmittance(const AtmosphereTables& tables, const glm::dvec3& position,
                            const glm::dvec3& toSun) {
  const double r = glm::length(position);
  const glm::dvec2 d =
      lookUpDensityToTop(tables, r - tables.parameters.earthRadius, glm::dot(position / r, toSun));
  return transmittanceOf(tables.parameters, d);
}

// Transmittance between two points as the difference of two net densities to the top (header comment).
glm::dvec3 atmosphereTransmittance(const AtmosphereTables& tables, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 ab = b - a;
  const double len = glm::length(ab);
  if (!(len > 0.0)) return glm::dvec3(1.0);
  const glm::dvec3 v = ab / len;
  const double R = tables.parameters.earthRadius;
  const double ra = glm::length(a);
  const double rb = glm::length(b);
  const double ca = glm::dot(a / ra, v);
  const bool hitsGround = ca < 0.0 && ra * ra * (ca * ca - 1.0) + R * R >= 0.0;
  glm::dvec2 d;
  if (!hitsGround) {
    d = lookUpDensityToTop(tables, ra - R, ca) - lookUpDensityToTop(tables, rb - R, glm::dot(b / rb, v));
  } else {
    d = lookUpDensityToTop(tables, rb - R, -glm::dot(b / rb, v)) - lookUpDensityToTop(tables, ra - R, -ca);
  }
  return transmittanceOf(tables.parameters, glm::max(d, glm::dvec2(0.0)));
}

// Hillaire 2020, Sec. 5.5: Psi_ms bilinear (texel (i, j) at u = sqrt(h / H_Atm) = i / (n - 1), c = 2 j / (n -
// 1) - 1).
glm::dvec3 lookUpMultipleScatteringLut(const AtmosphereTables& tables, double h, double cosSunZenith) {
  const Image& img = tables.multipleScatteringLut;
  if (img.width() < 2 || img.height() < 2) return glm::dvec3(0.0);
  return sampleHeightCosine(img, tables.parameters.atmosphereHeight, h, cosSunZenith);
}

// Yusov 2013, "Terrain shaders": E_sky linear in the 1D table (texel i at c = 2 i / (N - 1) - 1).
glm::dvec3 lookUpAmbientSkyLight(const AtmosphereTables& tables, double cosSunZenith) {
  const Image& img = tables.ambient;
  const int n = img.width();
  const Lerp1 x = glLerp(texCoord((std::clamp(cosSunZenith, -1.0, 1.0) + 1.0) * 0.5, n), n);
  const auto at = [&](int i) { return glm::dvec3(img.at(i, 0, 0), img.at(i, 0, 1), img.at(i, 0, 2)); };
  return glm::mix(at(x.i0), at(x.i1), x.f);
}

// The Fibonacci sphere of Eq. 1 and 3 (the header's formula).
glm::dvec3 fibonacciSphereDirection(int i, int n) {
  const double y = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
  const double angle = i * kPi * (3.0 - std::sqrt(5.0));
  return {r * std::cos(angle), y, r * std::sin(angle)};
}

// Trapezoid rule of (d_R, d_M) along a segment (Yusov 2013, Listing 5's net density).
glm::dvec2 densityIntegral(const AtmosphereParameters& p, const glm::dvec3& a, const glm::dvec3& b,
                           int steps) {
  const int n = std::max(steps, 1);
  const double ds = glm::length(b - a) / n;
  glm::dvec2 sum(0.0);
  glm::dvec2 prev = densities(p, glm::length(a));
  for (int k = 1; k <= n; ++k) {
    const glm::dvec2 d = densities(p, glm::length(glm::mix(a, b, static_cast<double>(k) / n)));
    sum += (prev + d) * (0.5 * ds);
    prev = d;
  }
  return sum;
}

// World point -> metres around the planet centre (the header's placement rule).
glm::dvec3 atmospherePosition(const AtmospherePlacement& placement, const AtmosphereParameters& p,
                              const glm::dvec3& world) {
  return world * placement.metersPerUnit + glm::dvec3(0.0, p.earthRadius + placement.originAltitude, 0.0);
}

// --- Precomputation ---------------------------------------------------------------------------------------

namespace {

/// The optical depth table: net (Rayleigh, Mie) density from each height and zenith cosine to the top of
/// the atmosphere (occluded rays: kOccludedDensity).
Image opticalDepthTable(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o, int threads) {
  const double R = p.earthRadius;
  const double top = R + p.atmosphereHeight;
  const int w = o.opticalDepthHeight;
  const int hgt = o.opticalDepthZenith;
  Image table(w, hgt, 2);
  parallelRows(hgt, threads, [&](int j) {
    const double c = -1.0 + 2.0 * j / (hgt - 1);
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    for (int i = 0; i < w; ++i) {
      const double u = static_cast<double>(i) / (w - 1);
      const double r0 = R + p.atmosphereHeight * u * u;
      glm::dvec2 d(kOccludedDensity);
      if (!(c < 0.0 && r0 * r0 * (c * c - 1.0) + R * R >= 0.0)) {
        const glm::dvec3 a(0.0, r0, 0.0);
        const glm::dvec3 b = a + glm::dvec3(s, c, 0.0) * farRoot(r0, c, top);
        d = densityIntegral(p, a, b, o.opticalDepthSteps);
      }
      table.at(i, j, 0) = static_cast<float>(d.x);
      table.at(i, j, 1) = static_cast<float>(d.y);
    }
  });
  return table;
}

/// Hillaire 2020's multiple scattering table Psi_ms (the Lut method) from the optical depth of `t`.
Image multipleScatteringTable(const AtmosphereTables& t, int threads) {
  const AtmosphereParameters& p = t.parameters;
  const AtmospherePrecomputeOptions& o = t.options;
  const int m = o.multipleScatteringSize;
  Image table(m, m, 3);
  parallelRows(m, threads, [&](int j) {
    const double mu = -1.0 + 2.0 * j / (m - 1);
    for (int i = 0; i < m; ++i) {
      const double u = static_cast<double>(i) / (m - 1);
      const glm::dvec3 psi =
          multipleScatteringAt(t, p.atmosphereHeight * u * u, mu, o.sphereSamples, o.multipleScatteringSteps);
      for (int ch = 0; ch < 3; ++ch)
        table.at(i, j, ch) = static_cast<float>(psi[ch]);
    }
  });
  return table;
}

/// Eq. 3 / Listing 6: ambient sky light at 20 m from L_M of `t`, per sun zenith cosine.
Image ambientTable(const AtmosphereTables& t, int threads) {
  const AtmospherePrecomputeOptions& o = t.options;
  const int na = o.ambientSize;
  Image table(na, 1, 3);
  const glm::dvec3 c(0.0, t.parameters.earthRadius + 20.0, 0.0);
  parallelRows(na, threads, [&](int i) {
    const double cp = -1.0 + 2.0 * i / (na - 1);
    const glm::dvec3 l(std::sqrt(std::max(0.0, 1.0 - cp * cp)), cp, 0.0);
    glm::dvec3 sum(0.0);
    const int samples = kAmbientSampleFactor * o.sphereSamples;
    for (int k = 0; k < samples; ++k) {
      glm::dvec3 w = fibonacciSphereDirection(k, samples);
      w.y = std::abs(w.y);
      glm::dvec4 coords(-1.0);
      sum += lookUpMultipleScattering(t, c, w, l, coords) * w.y;
    }
    sum *= 2.0 * kPi / samples;
    for (int ch = 0; ch < 3; ++ch)
      table.at(i, 0, ch) = static_cast<float>(sum[ch]);
  });
  return table;
}

} // namespace

// Yusov 2013, "Multiple Scattering" steps 1-3 and Eq. 3.
AtmosphereTables precomputeAtmosphere(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                      int threads) {
  validate(p, o);
  AtmosphereTables t;
  t.parameters = p;
  t.options = o;

  // Net density to the top of the atmosphere (occluded rays: kOccludedDensity).
  t.opticalDepth = opticalDepthTable(p, o, threads);

  // Hillaire 2020's multiple scattering table (the Lut method; L_H from it below).
  const bool lut = usesMultipleScatteringLut(o);
  if (lut) t.multipleScatteringLut = multipleScatteringTable(t, threads);

  const AtmosphereTableSize& size = o.size;
  const std::size_t n = emptyTable(size).texels();
  std::vector<glm::dvec3> higher(n, glm::dvec3(0.0));

  // Step 1: single scattering without its phase functions (S_R, S_M); Lut: L_H in the same march.
  t.single = emptyTable(size);
  if (!o.combinedMie) t.singleMie = emptyTable(size);
  const bool orders = o.multipleScattering == AtmosphereMultipleScattering::Orders;
  const bool keep = o.keepOrders && orders;
  AtmosphereTable4D first; // L1 with its phase functions at each texel's c_theta (keepOrders)
  if (keep) first = emptyTable(size);
  forEachTexel(size, threads, [&](int ih, int ia, int ip, int it) {
    const TexelRay r = texelRay(p, size, ih, ia, ip, it);
    const SingleParts v = singleScattering(t, r, o.singleSteps, lut);
    if (lut) higher[packedIndex(size, ih, ia, ip, it)] = v.higher;
    t.single.at(ih, ia, ip, it) = glm::vec4(glm::vec3(v.rayleigh), static_cast<float>(v.mie.x));
    if (!o.combinedMie) store(t.singleMie, ih, ia, ip, it, v.mie);
    if (keep) store(first, ih, ia, ip, it, withPhase(p, v.rayleigh, v.mie, glm::dot(r.v, r.l)));
  });
  if (keep) t.orders.push_back(std::move(first));

  // Step 2: J_n from L_(n-1) (n = 2: L1 with its phase functions), then L_n from J_n; L_H accumulates.
  const SphereSamples sphere = sphereSamples(p, size, o.sphereSamples);
  AtmosphereTable4D previous;
  for (int order = 2; orders && order <= o.orders; ++order) {
    AtmosphereTable4D j = emptyTable(size);
    forEachTexel(size, threads, [&](int ih, int ia, int ip, int it) {
      const TexelRay r = texelRay(p, size, ih, ia, ip, it);
      store(j, ih, ia, ip, it, scatteredRadiance(t, order == 2 ? nullptr : &previous, r, ih, sphere));
    });
    AtmosphereTable4D ln = emptyTable(size);
    forEachTexel(size, threads, [&](int ih, int ia, int ip, int it) {
      const TexelRay r = texelRay(p, size, ih, ia, ip, it);
      const glm::dvec3 v = scatteringOrder(t, j, r, o.orderSteps);
      higher[packedIndex(size, ih, ia, ip, it)] += v;
      store(ln, ih, ia, ip, it, v);
    });
    previous = std::move(ln);
    if (keep) t.orders.push_back(previous);
  }

  // Step 3: L_H.
  t.higherOrders = emptyTable(size);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec4 b(glm::vec3(higher[i]), 0.0f);
    std::copy(&b.x, &b.x + 4, t.higherOrders.rgba.begin() + static_cast<std::ptrdiff_t>(4 * i));
  }

  // Eq. 3 / Listing 6: ambient sky light at 20 m from L_M.
  t.ambient = ambientTable(t, threads);
  return t;
}

} // namespace crep
