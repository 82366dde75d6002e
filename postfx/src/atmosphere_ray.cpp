// Per-frame use of the atmosphere tables on the CPU (crep/postfx/atmosphere.h, "Per-frame use"): one view
// ray's in-scattering and transmittance (the sky and aerial perspective, Yusov 2013, Eq. 8), light shafts
// in the three ways of AtmosphereShafts, and the per-pixel image of a camera.
//
// ---------------------------------------------------------------------------------------------------
// Rule of atmosphereRay (every distance below in metres unless it says "world"):
// - C = atmospherePosition(origin); v = the unit world direction (the frames differ by a translation and a
//   scale only); l = -sun.direction(); s_m = surface * metersPerUnit; R, R_top = R + H_Atm.
// - A camera above the top of the atmosphere is moved along v to where the ray enters the atmosphere (Yusov's
//   restrained camera position): C = C + v t_enter, and every distance (s_m, the lit sections, D_start)
//   then counts from there (t -> t metersPerUnit - t_enter). A ray that misses the atmosphere: in-scattering
//   0, transmittance 1.
// - The ray's end X: the ground hit if the ray hits the ground (|C + t v| = R, nearest t > 0), else the exit
//   of the top (far root of |C + t v| = R_top), at distance t_X. A surface pixel ends at E = C + v s_E,
//   s_E = min(s_m, t_top) (clamped to the exit of the atmosphere). A sky pixel's shadowed part ends at the
//   far plane F = C + v s_F, s_F = min(s_m, t_X); the ray continues unshadowed to X.
// - Look-ups of one ray (Yusov 2013, Listing 2): the first 4D look-up (at C) chooses the side of the horizon;
//   every later look-up of the ray, in any 4D table, gets the first one's coordinates as `previous`.
//   T(C->P) is atmosphereTransmittance (1 for P = C) inside (a)'s integrand and for the sky's own
//   transmittance T(C->X); in Eq. 8 (every T(C->E), T(C->F), T(C->P1), T(C->P2) below) and for a surface
//   pixel's transmittance it is the segment's: exp(-beta_e . densityIntegral(C, P, 16)) (the optical depth
//   table's difference of two large values steps by several percent near the horizon). T_sun(P) is
//   sunTransmittance.
// - Near the horizon (|c_alpha(C) - c_h(C)| < w, w = horizonBlendWidth(h_C)) every term but (a)'s integrated
//   single scattering is the blend (1 - f) X(v_-) + f X(v_+), f = (c_alpha - c_h + w) / (2 w), of the same
//   terms for the directions v_-, v_+ in the vertical plane of v with zenith cosines c_h - w and c_h + w
//   (Bruneton and Neyret 2008's implementation): Eq. 8's two look-ups are large and nearly equal there.
// - None (Eq. 8 with L_M): surface L = L_M(C) - T(C->E) L_M(E); sky L = L_M(C) (nothing beyond the end).
// - Shafts (a), (b), (c): single + H, the higher orders unoccluded: surface H = L_H(C) - T(C->E) L_H(E),
//   sky H = L_H(C).
//   (a) single = sum over the lit sections [ta, tb] (clipped to [0, s_E], sky [0, s_F]) of the trapezoid rule
//       with max(1, ceil(integrationSteps (tb - ta) / s_m)) steps of
//       (beta_R d_R(h) p_R(c) + beta_M d_M(h) p_HG(c)) T(C->P) T_sun(P), c = v . l, d = exp(-h / H) with
//       h = max(0, |P| - R); sky: plus [s_F, t_X] unshadowed with skySteps trapezoid steps in u of the
//       substitution t = s_F + (t_X - s_F) u^3 (short steps in the dense air where the ray starts, long ones
//       towards the top: 16 uniform steps left a grazing ray's ~1000 km 6% off). T(C->P) there is
//       exp(-beta_e . D) with D the densities integrated along the ray: densityIntegral(C, C + v ta, 16) to
//       the section's start, then the trapezoid rule on the section's own steps.
//   L1 of a look-up is the single table's phase-free parts with the ray's own phase functions (c = v . l;
//   sampleSingleScattering), L_M = L1 + L_H at the same coordinates.
//   (b) P1 = C + v D_start, P2 = C + v min(D_start + D_lit, end) with D_start clamped to [0, end] (end = s_E,
//       sky s_F); single = max(0, T(C->P1) L1(P1) - T(C->P2) L1(P2)) per channel (Eq. 8 on the lit part),
//       0 without lit length; sky: plus T(C->F) L1(F) (unshadowed beyond the far plane).
//   (c) surface single = visibility (L1(C) - T(C->E) L1(E)); sky single = visibility (L1(C) - T(C->F) L1(F))
//       + T(C->F) L1(F).
// - A sky pixel whose ray hits the ground (beyond the scene's geometry: nothing else draws there) adds the
//   ground's Lambertian reflection seen through the air: T(C->X) (the segment's, below) (groundAlbedo / pi)
//   (T_sun(X) max(0, n . l) + E_sky(n . l)), n the ground's normal at X (no shadows; nothing with
//   groundAlbedo = 0).
// - In-scattering = sun.irradiance() (single + H + ground), None: sun.irradiance() (L + ground).
//   Transmittance: surface T(C->E); sky 0 when the ray hits the ground (opaque), else T(C->X).
// atmosphereImage: pixelRay(camera, depth, x, y) per pixel (no near-plane correction), sky iff the depth
// value >= 1, origin camera.position(); RGBA = (in-scattering, mean of the RGB transmittance).
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/postfx/atmosphere.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace crep {

namespace {

/// Roots t0 <= t1 of |o + t v| = r (v unit); false when the line misses the sphere.
bool sphereRoots(const glm::dvec3& o, const glm::dvec3& v, double r, double& t0, double& t1) {
  const double b = glm::dot(o, v);
  const double len = glm::length(o);
  const double c = (len - r) * (len + r); // |o|^2 - r^2 without cancellation
  const double disc = b * b - c;
  if (!(disc >= 0.0)) return false;
  const double q = std::sqrt(disc);
  t0 = -b - q;
  t1 = -b + q;
  return true;
}

void requireFiniteVector(const char* name, const glm::dvec3& x) {
  if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z)))
    throw InvalidArgument(name,
                          "(" + detail::formatValue(x.x) + ", " + detail::formatValue(x.y) + ", " +
                              detail::formatValue(x.z) + ")",
                          "must be finite");
}

void validateRayOptions(const AtmosphereRayOptions& o) {
  if (o.shafts != AtmosphereShafts::None && o.shafts != AtmosphereShafts::Integrated &&
      o.shafts != AtmosphereShafts::LitLengthTable && o.shafts != AtmosphereShafts::PrefilteredVisibility)
    throw InvalidArgument("AtmosphereRayOptions.shafts", detail::formatValue(static_cast<int>(o.shafts)),
                          "must be one of AtmosphereShafts");
  if (o.integrationSteps < 1 || o.integrationSteps > 1 << 20)
    throw InvalidArgument("AtmosphereRayOptions.integrationSteps", detail::formatValue(o.integrationSteps),
                          "must be in [1, 2^20]");
  if (o.skySteps < 1 || o.skySteps > 1 << 20)
    throw InvalidArgument("AtmosphereRayOptions.skySteps", detail::formatValue(o.skySteps),
                          "must be in [1, 2^20]");
}

/// Trapezoid steps of the transmittance of a segment (RayEvaluator::segmentTransmittance; GLSL twin in
/// passes/atmosphere.comp).
constexpr int kSegmentSteps = 16;
/// The power of (a)'s sky substitution t = s_F + (t_X - s_F) u^p (CREP_SKY_POWER in passes/atmosphere.comp).
constexpr int kSkyStepPower = 3;

/// The look-ups and integrands of one ray from C along v with the sun towards l.
class RayEvaluator {
public:
  RayEvaluator(const AtmosphereTables& tables, const glm::dvec3& C, const glm::dvec3& v, const glm::dvec3& l)
      : tables_(tables), p_(tables.parameters), C_(C), v_(v), l_(l) {
    cosSunView_ = glm::dot(v, l);
    phaseR_ = rayleighPhase(cosSunView_);
    phaseM_ = henyeyGreenstein(p_.mieG, cosSunView_);
  }

  glm::dvec3 at(double t) const { return C_ + v_ * t; }

  /// T(C -> C + v t) (atmosphereTransmittance; 1 at t <= 0).
  glm::dvec3 transmittance(double t) const {
    if (!(t > 0.0)) return glm::dvec3(1.0);
    return atmosphereTransmittance(tables_, C_, at(t));
  }

  /// T(C -> C + v t) of a segment that Eq. 8 or the output uses: the trapezoid rule with kSegmentSteps steps
  /// of the densities along it (the optical depth table's difference of two large values has steps of
  /// several percent near the horizon, where its zenith cosine is coarse); 1 at t <= 0.
  glm::dvec3 segmentTransmittance(double t) const { return extinguished(segmentDensity(t)); }

  /// Listing 1 at C + v t; the first look-up of the ray is at C (made first when the first call is
  /// elsewhere) and chooses the side of the horizon that every later look-up keeps (Listing 2). An empty
  /// table reads 0.
  glm::dvec3 lookUp(const AtmosphereTable4D& table, double t) {
    if (table.rgba.empty()) return glm::dvec3(0.0);
    return sampleAtmosphereTable(table, coords(t));
  }
  /// L1 at C + v t: the phase-free parts with this ray's phase functions (sampleSingleScattering).
  glm::dvec3 single(double t) { return sampleSingleScattering(tables_, coords(t), cosSunView_); }
  /// L_M = L1 + L_H at C + v t.
  glm::dvec3 multiple(double t) { return single(t) + lookUp(tables_.higherOrders, t); }

  /// Eq. 8 between C and C + v t of a quantity `of(t)`: L(C) - T(C -> C + v t) L(C + v t).
  template <class Of>
  glm::dvec3 eq8(const Of& of, double t) {
    const glm::dvec3 atC = of(0.0);
    return atC - segmentTransmittance(t) * of(t);
  }

  /// The trapezoid rule with n steps in u over [ta, tb] of the same integrand as trapezoid(), in the
  /// substitution t = ta + (tb - ta) u^kSkyStepPower (a sky ray's unshadowed rest).
  glm::dvec3 skyQuadrature(double ta, double tb, int n) const {
    if (!(tb > ta)) return glm::dvec3(0.0);
    const double len = tb - ta;
    glm::dvec2 optical = segmentDensity(ta);
    glm::dvec2 previous(0.0);
    double tPrevious = ta;
    glm::dvec3 sum(0.0);
    for (int k = 0; k <= n; ++k) {
      const double u = static_cast<double>(k) / n;
      const double t = ta + len * std::pow(u, kSkyStepPower);
      const glm::dvec3 P = at(t);
      const glm::dvec2 d = density(P);
      if (k > 0) optical += 0.5 * (previous + d) * (t - tPrevious);
      previous = d;
      tPrevious = t;
      const double dtdu = len * kSkyStepPower * std::pow(u, kSkyStepPower - 1);
      sum += (k == 0 || k == n ? 0.5 : 1.0) * integrand(P, d) * extinguished(optical) * dtdu;
    }
    return sum / static_cast<double>(n);
  }

  /// Trapezoid rule with n steps over [ta, tb] of the single-scattering integrand (beta_R d_R p_R + beta_M
  /// d_M p_HG) T(C->P) T_sun(P) (Listing 3's): T(C->P) from the densities marched along the ray (the
  /// segment's to ta, then the trapezoid rule of the same steps), never the optical depth table's
  /// difference, whose two large values cancel on rays that graze the ground.
  glm::dvec3 trapezoid(double ta, double tb, int n) const {
    if (!(tb > ta)) return glm::dvec3(0.0);
    const double dt = (tb - ta) / n;
    glm::dvec2 optical = segmentDensity(ta); // C -> the section
    glm::dvec2 previous(0.0);
    glm::dvec3 sum(0.0);
    for (int k = 0; k <= n; ++k) {
      const double t = ta + dt * k;
      const glm::dvec3 P = at(t);
      const glm::dvec2 d = density(P);
      if (k > 0) optical += 0.5 * (previous + d) * dt;
      previous = d;
      sum += (k == 0 || k == n ? 0.5 : 1.0) * integrand(P, d) * extinguished(optical);
    }
    return sum * dt;
  }

private:
  /// (d_R, d_M) at P: exp(-h / H) with h = max(0, |P| - R).
  glm::dvec2 density(const glm::dvec3& P) const {
    const double h = std::max(0.0, glm::length(P) - p_.earthRadius);
    return {std::exp(-h / p_.rayleighScaleHeight), std::exp(-h / p_.mieScaleHeight)};
  }
  /// (beta_R d_R p_R + beta_M d_M p_HG) T_sun(P), without T(C->P).
  glm::dvec3 integrand(const glm::dvec3& P, const glm::dvec2& d) const {
    return (p_.rayleighScattering * (d.x * phaseR_) + p_.mieScattering * (d.y * phaseM_)) *
           sunTransmittance(tables_, P, l_);
  }

  /// The (Rayleigh, Mie) density integrals of the segment to C + v t (kSegmentSteps trapezoid steps; 0 at
  /// t <= 0).
  glm::dvec2 segmentDensity(double t) const {
    return t > 0.0 ? densityIntegral(p_, C_, at(t), kSegmentSteps) : glm::dvec2(0.0);
  }
  /// exp(-beta_e . D) of density integrals D.
  glm::dvec3 extinguished(const glm::dvec2& d) const {
    return glm::exp(-(p_.rayleighScattering * d.x + (p_.mieScattering + p_.mieAbsorption) * d.y));
  }

  /// The table coordinates of C + v t; the first look-up of the ray is at C (made first when the first
  /// call is elsewhere) and chooses the side of the horizon that every later one keeps (Listing 2).
  glm::dvec4 coords(double t) {
    if (!haveFirst_ && t != 0.0) coords(0.0);
    const glm::dvec4 c = atmosphereLookUpCoords(p_, tables_.options.size, at(t), v_, l_,
                                                haveFirst_ ? first_ : glm::dvec4(-1.0));
    if (!haveFirst_) {
      first_ = c;
      haveFirst_ = true;
    }
    return c;
  }

  const AtmosphereTables& tables_;
  const AtmosphereParameters& p_;
  glm::dvec3 C_, v_, l_;
  double cosSunView_ = 0.0, phaseR_ = 0.0, phaseM_ = 0.0;
  glm::dvec4 first_{-1.0};
  bool haveFirst_ = false;
};

double luminance(const glm::dvec3& c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

} // namespace

// Yusov 2013, Eq. 8 and "Light shafts" (SS-Int, SS-LUT, MS-UnO); rule at the top of this file.
AtmosphereRay atmosphereRay(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                            const DirectionalLight& sun, const glm::dvec3& origin,
                            const glm::dvec3& direction, double surface, bool sky,
                            const AtmosphereShadowing& shadowing, const AtmosphereRayOptions& options) {
  validate(placement, tables.parameters);
  validateRayOptions(options);
  requireFiniteVector("origin", origin);
  requireFiniteVector("direction", direction);
  const double dirLength = glm::length(direction);
  if (!(dirLength > 0.0)) throw InvalidArgument("direction", "zero length", "must be a non-zero direction");
  if (!(surface >= 0.0) || !std::isfinite(surface))
    throw InvalidArgument("surface", detail::formatValue(surface), "must be finite and >= 0");

  const AtmosphereParameters& p = tables.parameters;
  const double R = p.earthRadius, top = R + p.atmosphereHeight, mpu = placement.metersPerUnit;
  const glm::dvec3 v = direction / dirLength;
  const glm::dvec3 l = -sun.direction();
  glm::dvec3 C = atmospherePosition(placement, p, origin);

  AtmosphereRay out;
  // Yusov's restrained camera: a camera above the atmosphere starts where its ray enters it.
  double enter = 0.0;
  double t0 = 0.0, t1 = 0.0;
  if (glm::length(C) > top) {
    if (!sphereRoots(C, v, top, t0, t1) || !(t1 > 0.0)) return out; // misses the atmosphere
    enter = std::max(0.0, t0);
    C += v * enter;
  }
  double tTop = 0.0;
  if (sphereRoots(C, v, top, t0, t1)) tTop = std::max(0.0, t1);
  bool hitsGround = false;
  double tX = tTop;
  if (sphereRoots(C, v, R, t0, t1) && t0 > 0.0) {
    hitsGround = true;
    tX = std::min(t0, tTop);
  }
  const double sm = std::max(0.0, surface * mpu - enter);
  const double sEnd = sky ? std::min(sm, tX) : std::min(sm, tTop); // s_F or s_E

  RayEvaluator ray(tables, C, v, l);
  // The table-based part of the radiance (all but (a)'s integrated single scattering) of the ray of `r`.
  const auto tablePart = [&](RayEvaluator& r) {
    const auto multiple = [&](double t) { return r.multiple(t); };
    const auto higher = [&](double t) { return r.lookUp(tables.higherOrders, t); };
    if (options.shafts == AtmosphereShafts::None) return sky ? r.multiple(0.0) : r.eq8(multiple, sEnd);
    // Unoccluded higher orders (MS-UnO).
    glm::dvec3 part = sky ? r.lookUp(tables.higherOrders, 0.0) : r.eq8(higher, sEnd);
    if (options.shafts == AtmosphereShafts::LitLengthTable) {
      // SS-LUT: Eq. 8 with L1 between the first lit point and the end of the lit length.
      const double litLength = std::max(0.0, shadowing.litLength) * mpu;
      if (litLength > 0.0) {
        const double first = shadowing.firstLit * mpu - enter;
        const double a = std::clamp(first, 0.0, sEnd);
        const double b = std::clamp(first + litLength, a, sEnd);
        const glm::dvec3 l1C = r.single(0.0); // the first look-up is at C
        const glm::dvec3 l1a = a > 0.0 ? r.single(a) : l1C;
        const glm::dvec3 lit = r.segmentTransmittance(a) * l1a - r.segmentTransmittance(b) * r.single(b);
        part += glm::max(lit, glm::dvec3(0.0));
      }
      if (sky) part += r.segmentTransmittance(sEnd) * r.single(sEnd);
    } else if (options.shafts == AtmosphereShafts::PrefilteredVisibility) {
      const glm::dvec3 l1C = r.single(0.0);
      const glm::dvec3 beyond = r.segmentTransmittance(sEnd) * r.single(sEnd);
      part += shadowing.visibility * (l1C - beyond);
      if (sky) part += beyond;
    }
    return part;
  };
  // Near the horizon: the blend of a ray just below and one just above it (horizonBlendWidth).
  glm::dvec3 radiance(0.0);
  {
    const double r = glm::length(C), c = glm::dot(C, v) / r;
    const double ch = cosHorizon(p, r - R), eps = horizonBlendWidth(p, tables.options.size, r - R);
    const glm::dvec3 n = C / r, across = v - c * n;
    if (std::abs(c - ch) < eps && glm::length(across) > 1e-9) {
      const glm::dvec3 u = glm::normalize(across);
      const auto tilted = [&](double cz) { return cz * n + std::sqrt(std::max(0.0, 1.0 - cz * cz)) * u; };
      RayEvaluator below(tables, C, tilted(ch - eps), l), above(tables, C, tilted(ch + eps), l);
      const double w = (c - ch + eps) / (2.0 * eps);
      radiance = (1.0 - w) * tablePart(below) + w * tablePart(above);
    } else {
      radiance = tablePart(ray);
    }
  }
  if (options.shafts == AtmosphereShafts::Integrated) {
    // SS-Int: the lit sections, then (sky) the unshadowed rest to the end of the ray.
    glm::dvec3 single(0.0);
    for (const glm::dvec2& section : shadowing.litSections) {
      const double ta = std::clamp(section.x * mpu - enter, 0.0, sEnd);
      const double tb = std::clamp(section.y * mpu - enter, 0.0, sEnd);
      if (!(tb > ta)) continue;
      const double share = std::ceil(options.integrationSteps * (tb - ta) / sm);
      const int steps =
          static_cast<int>(std::clamp(share, 1.0, static_cast<double>(options.integrationSteps)));
      single += ray.trapezoid(ta, tb, steps);
    }
    if (sky && tX > sEnd) single += ray.skyQuadrature(sEnd, tX, options.skySteps);
    radiance += single;
  }
  // A sky pixel whose ray ends on the ground beyond the scene: the ground's reflected light.
  if (sky && hitsGround && p.groundAlbedo > 0.0) {
    const glm::dvec3 X = ray.at(tX);
    const double cosSun = glm::dot(X / glm::length(X), l);
    const glm::dvec3 direct = cosSun > 0.0 ? sunTransmittance(tables, X, l) * cosSun : glm::dvec3(0.0);
    radiance += ray.segmentTransmittance(tX) * (p.groundAlbedo / std::numbers::pi) *
                (direct + lookUpAmbientSkyLight(tables, cosSun));
  }
  out.inscattering = sun.irradiance() * radiance;
  if (sky)
    out.transmittance = hitsGround ? glm::dvec3(0.0) : ray.transmittance(tX);
  else
    out.transmittance = ray.segmentTransmittance(sEnd);
  return out;
}

// (b)'s D_lit and D_start from (a)'s sections (Yusov 2013, "Light shafts").
AtmosphereShadowing shadowingFromSections(std::vector<glm::dvec2> litSections) {
  AtmosphereShadowing s;
  for (const glm::dvec2& section : litSections)
    s.litLength += std::max(0.0, section.y - section.x);
  if (!litSections.empty()) s.firstLit = litSections.front().x;
  s.litSections = std::move(litSections);
  return s;
}

// (c): Rec. 709 luminance of the shadowed result over the unshadowed closed form (Klehm et al. 2014, Eq. 3).
double prefilteredVisibility(const glm::dvec3& shadowed, const DirectionalLight& light, const Medium& proxy,
                             const glm::dvec3& direction, double surface) {
  const glm::dvec3 unshadowed =
      scatteringConstant(light, proxy, direction) * transmittanceIntegral(proxy.extinction(), 0.0, surface);
  const double denominator = luminance(unshadowed);
  if (!(denominator > 0.0)) return 1.0;
  const double visibility = luminance(shadowed) / denominator;
  if (std::isnan(visibility)) return 1.0;
  return std::clamp(visibility, 0.0, 1.0);
}

// atmosphereRay per pixel (rays of crep/scatter/ray.h), rows in parallel.
AtmosphereImage atmosphereImage(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                                const Camera& camera, const DirectionalLight& sun, const Image& cameraDepth,
                                const std::vector<AtmosphereShadowing>& shadowing,
                                const AtmosphereRayOptions& options, int threads) {
  validate(placement, tables.parameters);
  validateRayOptions(options);
  validateCameraDepth(cameraDepth);
  if (cameraDepth.channels() != 1)
    throw InvalidArgument("cameraDepth", std::to_string(cameraDepth.channels()) + " channels",
                          "must have 1 channel");
  if (threads < 0) throw InvalidArgument("threads", detail::formatValue(threads), "must be >= 0");
  const int w = cameraDepth.width(), h = cameraDepth.height();
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const bool none = options.shafts == AtmosphereShafts::None;
  if (!(shadowing.size() == pixels || (none && shadowing.empty())))
    throw InvalidArgument("atmosphereImage.shadowing", std::to_string(shadowing.size()) + " entries",
                          "must have width * height = " + std::to_string(pixels) +
                              " entries (may be empty for AtmosphereShafts::None)");
  AtmosphereImage out{Image(w, h, 4), Image(w, h, 3)};
  const AtmosphereShadowing unshadowed;
  const glm::dvec3 origin = camera.position();
  parallelRows(h, threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t index =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const PixelRay pr = pixelRay(camera, cameraDepth, x, y);
      const bool sky = cameraDepth.at(x, y) >= 1.0f;
      const AtmosphereRay r = atmosphereRay(tables, placement, sun, origin, pr.direction, pr.surface, sky,
                                            shadowing.empty() ? unshadowed : shadowing[index], options);
      for (int c = 0; c < 3; ++c) {
        out.inscattering.at(x, y, c) = static_cast<float>(r.inscattering[c]);
        out.transmittance.at(x, y, c) = static_cast<float>(r.transmittance[c]);
      }
      out.inscattering.at(x, y, 3) =
          static_cast<float>((r.transmittance.x + r.transmittance.y + r.transmittance.z) / 3.0);
    }
  });
  return out;
}

} // namespace crep
