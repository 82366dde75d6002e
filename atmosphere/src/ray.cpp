// Per-frame use of the atmosphere tables on the CPU (crep/atmosphere/atmosphere.h, "Per-frame use"): one view
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
// - With `view` (AtmosphereViewTables of the camera at `origin`, options.single ViewTables), a camera in the
//   atmosphere and shafts None, (b) or (c), L1 comes from the view tables instead of the 4D table, and the
//   table part (blended at the horizon as above) is L_H alone: V(t) = sampleAerialPerspective at distance t,
//   S = sampleSkyView of the whole ray; None single = V(s_E); (b) single = max(0, V(b) - V(a)) with a, b the
//   clamped D_start and D_start + D_lit (0 without lit length); (c) single = visibility V(s_E); a sky pixel
//   adds max(0, S - V(s_F)) (unshadowed beyond the far plane). No difference of two large look-ups remains.
// - A sky pixel whose ray hits the ground (beyond the scene's geometry: nothing else draws there) adds the
//   ground's Lambertian reflection seen through the air: T(C->X) (the segment's, below) (groundAlbedo / pi)
//   (T_sun(X) max(0, n . l) + E_sky(n . l)), n the ground's normal at X (no shadows; nothing with
//   groundAlbedo = 0).
// - In-scattering = sun.irradiance() (single + H + ground), None: sun.irradiance() (L + ground).
//   Transmittance: surface T(C->E); sky 0 when the ray hits the ground (opaque), else T(C->X).
// atmosphereImage: pixelRay(camera, depth, x, y) per pixel (no near-plane correction), sky iff the depth
// value >= 1, origin camera.position(); RGBA = (in-scattering, mean of the RGB transmittance).
#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
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
  validateViewTables(o);
}

/// (d_R, d_M) at P (metres around the planet centre): exp(-h / H) with h = max(0, |P| - R).
glm::dvec2 densityAt(const AtmosphereParameters& p, const glm::dvec3& P) {
  const double h = std::max(0.0, glm::length(P) - p.earthRadius);
  return {std::exp(-h / p.rayleighScaleHeight), std::exp(-h / p.mieScaleHeight)};
}

/// exp(-beta_e . D) of density integrals D.
glm::dvec3 extinguishedBy(const AtmosphereParameters& p, const glm::dvec2& d) {
  return glm::exp(-(p.rayleighScattering * d.x + (p.mieScattering + p.mieAbsorption) * d.y));
}

/// Trapezoid steps of the transmittance of a segment (RayEvaluator::segmentTransmittance; GLSL twin in
/// passes/atmosphere/atmosphere.comp).
constexpr int kSegmentSteps = 16;

/// The trapezoid rule of the phase-free integrands (beta_R d_R, beta_M d_M) T(C->P) T_sun(P) along C + v t
/// from t0, T(C->P) the densities marched from C (`optical0` those of [0, t0]): step(t, ...) moves to t,
/// adding to `rayleigh` and `mie`. The aerial perspective volume's slices, the sky-view table's rays and
/// (a)'s sky (RayEvaluator::skyQuadrature); GLSL twin viewStep in passes/atmosphere.comp.
class ViewMarch {
public:
  ViewMarch(const AtmosphereTables& tables, const glm::dvec3& C, const glm::dvec3& v, const glm::dvec3& l,
            double t0 = 0.0, const glm::dvec2& optical0 = glm::dvec2(0.0))
      : tables_(tables), p_(tables.parameters), C_(C), v_(v), l_(l), optical_(optical0), t_(t0) {
    const glm::dvec3 P = C + v * t0;
    d_ = densityAt(p_, P);
    integrand(P, d_, fR_, fM_);
  }
  /// One trapezoid step to t: rayleigh += (wPrevious f(t_prev) + w f(t)) / 2, the weights dt (uniform
  /// steps) or du dt/du at each end (a substitution t(u)); the optical depth takes the step's dt.
  void step(double t, double wPrevious, double w) {
    const glm::dvec3 P = C_ + v_ * t;
    const glm::dvec2 d = densityAt(p_, P);
    optical_ += 0.5 * (d_ + d) * (t - t_);
    glm::dvec3 gR, gM;
    integrand(P, d, gR, gM);
    rayleigh += 0.5 * (wPrevious * fR_ + w * gR);
    mie += 0.5 * (wPrevious * fM_ + w * gM);
    t_ = t;
    d_ = d;
    fR_ = gR;
    fM_ = gM;
  }
  /// `n` trapezoid steps in u from the current t to tb in the substitution t = ta + (tb - ta) u^3 (short
  /// steps in the dense air where a ray starts, long ones towards the top of the atmosphere).
  void cubic(double tb, int n) {
    const double ta = t_, len = tb - ta, du = 1.0 / n;
    const auto weight = [&](double u) { return du * 3.0 * len * u * u; }; // du dt/du
    for (int k = 1; k <= n; ++k) {
      const double u = static_cast<double>(k) / n;
      step(ta + len * u * u * u, weight(u - du), weight(u));
    }
  }
  glm::dvec3 rayleigh{0.0}, mie{0.0};

private:
  void integrand(const glm::dvec3& P, const glm::dvec2& d, glm::dvec3& fR, glm::dvec3& fM) const {
    const glm::dvec3 w = extinguishedBy(p_, optical_) * sunTransmittance(tables_, P, l_);
    fR = p_.rayleighScattering * d.x * w;
    fM = p_.mieScattering * d.y * w;
  }
  const AtmosphereTables& tables_;
  const AtmosphereParameters& p_;
  glm::dvec3 C_, v_, l_;
  glm::dvec2 d_{0.0}, optical_{0.0};
  glm::dvec3 fR_{0.0}, fM_{0.0};
  double t_ = 0.0;
};

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

  /// The integrand of trapezoid() over [ta, tb] with n steps of ViewMarch::cubic (a sky ray's unshadowed
  /// rest), T(C->P) the segment's densities to ta, then marched.
  glm::dvec3 skyQuadrature(double ta, double tb, int n) const {
    if (!(tb > ta)) return glm::dvec3(0.0);
    ViewMarch march(tables_, C_, v_, l_, ta, segmentDensity(ta));
    march.cubic(tb, n);
    return march.rayleigh * phaseR_ + march.mie * phaseM_;
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
  glm::dvec2 density(const glm::dvec3& P) const { return densityAt(p_, P); }
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
  glm::dvec3 extinguished(const glm::dvec2& d) const { return extinguishedBy(p_, d); }

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

/// Where a ray of atmosphereRay runs, in meters along it from C: Yusov's restrained camera (a camera above
/// the atmosphere starts where its ray enters it), the ends of Eq. 8.
struct RayGeometry {
  glm::dvec3 C{0.0};           ///< the ray's start in the planet frame (meters)
  double enter = 0.0;          ///< meters from the camera to C
  double tX = 0.0, tTop = 0.0; ///< the end of the atmosphere or the ground (t_X); the top of the atmosphere
  double sm = 0.0;             ///< the surface
  double sEnd = 0.0;           ///< s_F (sky) or s_E
  bool hitsGround = false;
};

/// The geometry of the ray from `C` along `v`, or nothing when it misses the atmosphere.
std::optional<RayGeometry> rayGeometry(const AtmosphereParameters& p, glm::dvec3 C, const glm::dvec3& v,
                                       double surfaceMeters, bool sky) {
  const double R = p.earthRadius, top = R + p.atmosphereHeight;
  RayGeometry g;
  double t0 = 0.0, t1 = 0.0;
  if (glm::length(C) > top) {
    if (!sphereRoots(C, v, top, t0, t1) || !(t1 > 0.0)) return std::nullopt; // misses the atmosphere
    g.enter = std::max(0.0, t0);
    C += v * g.enter;
  }
  g.C = C;
  if (sphereRoots(C, v, top, t0, t1)) g.tTop = std::max(0.0, t1);
  g.tX = g.tTop;
  if (sphereRoots(C, v, R, t0, t1) && t0 > 0.0) {
    g.hitsGround = true;
    g.tX = std::min(t0, g.tTop);
  }
  g.sm = std::max(0.0, surfaceMeters - g.enter);
  g.sEnd = sky ? std::min(g.sm, g.tX) : std::min(g.sm, g.tTop); // s_F or s_E
  return g;
}

/// The terms of one ray's radiance (Yusov 2013, Eq. 8 and "Light shafts"), each added in the order of the
/// rule at the top of this file.
struct RayTerms {
  const AtmosphereTables& tables;
  const AtmosphereShadowing& shadowing;
  const AtmosphereRayOptions& options;
  const RayGeometry& g;
  double mpu = 1.0;
  bool sky = false;
  bool fromView = false; ///< the view tables: None, (b), (c) with a camera in the atmosphere

  /// The table-based part of the radiance (all but (a)'s integrated single scattering and the view tables'
  /// part) of the ray of `r`.
  glm::dvec3 tablePart(RayEvaluator& r) const {
    const double sEnd = g.sEnd;
    const auto multiple = [&](double t) { return r.multiple(t); };
    const auto higher = [&](double t) { return r.lookUp(tables.higherOrders, t); };
    if (fromView) return sky ? r.lookUp(tables.higherOrders, 0.0) : r.eq8(higher, sEnd); // L_H only
    if (options.shafts == AtmosphereShafts::None) return sky ? r.multiple(0.0) : r.eq8(multiple, sEnd);
    // Unoccluded higher orders (MS-UnO).
    glm::dvec3 part = sky ? r.lookUp(tables.higherOrders, 0.0) : r.eq8(higher, sEnd);
    if (options.shafts == AtmosphereShafts::LitLengthTable) {
      // SS-LUT: Eq. 8 with L1 between the first lit point and the end of the lit length.
      const double litLength = std::max(0.0, shadowing.litLength) * mpu;
      if (litLength > 0.0) {
        const double first = shadowing.firstLit * mpu - g.enter;
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
  }

  /// tablePart() of `ray`; near the horizon the blend of a ray just below and one just above it
  /// (horizonBlendWidth).
  glm::dvec3 blendedTablePart(RayEvaluator& ray, const glm::dvec3& v, const glm::dvec3& l) const {
    const AtmosphereParameters& p = tables.parameters;
    const double R = p.earthRadius;
    const double r = glm::length(g.C), c = glm::dot(g.C, v) / r;
    const double ch = cosHorizon(p, r - R), eps = horizonBlendWidth(p, tables.options.size, r - R);
    const glm::dvec3 n = g.C / r, across = v - c * n;
    if (std::abs(c - ch) < eps && glm::length(across) > 1e-9) {
      const glm::dvec3 u = glm::normalize(across);
      const auto tilted = [&](double cz) { return cz * n + std::sqrt(std::max(0.0, 1.0 - cz * cz)) * u; };
      RayEvaluator below(tables, g.C, tilted(ch - eps), l), above(tables, g.C, tilted(ch + eps), l);
      const double w = (c - ch + eps) / (2.0 * eps);
      return (1.0 - w) * tablePart(below) + w * tablePart(above);
    }
    return tablePart(ray);
  }

  /// L1 from the view tables: the volume in front of the far plane, the sky-view table's whole ray beyond it.
  void addViewTables(glm::dvec3& radiance, const AtmosphereViewTables& view, const glm::dvec3& v,
                     const glm::dvec3& l) const {
    const AtmosphereParameters& p = tables.parameters;
    const double sEnd = g.sEnd;
    const double cosSunView = glm::dot(v, l);
    const auto L1 = [&](double t) {
      return t > 0.0 ? sampleAerialPerspective(view, p, v, t / mpu, cosSunView) : glm::dvec3(0.0);
    };
    const glm::dvec3 toEnd = L1(sEnd);
    if (options.shafts == AtmosphereShafts::None) {
      radiance += toEnd;
    } else if (options.shafts == AtmosphereShafts::LitLengthTable) {
      const double litLength = std::max(0.0, shadowing.litLength) * mpu;
      if (litLength > 0.0) {
        const double a = std::clamp(shadowing.firstLit * mpu, 0.0, sEnd);
        const double b = std::clamp(shadowing.firstLit * mpu + litLength, a, sEnd);
        radiance += glm::max(L1(b) - L1(a), glm::dvec3(0.0));
      }
    } else {
      radiance += shadowing.visibility * toEnd;
    }
    if (sky) radiance += glm::max(sampleSkyView(view, p, v, cosSunView) - toEnd, glm::dvec3(0.0));
  }

  /// SS-Int: the lit sections, then (sky) the unshadowed rest to the end of the ray.
  glm::dvec3 integratedSingle(RayEvaluator& ray) const {
    glm::dvec3 single(0.0);
    for (const glm::dvec2& section : shadowing.litSections) {
      const double ta = std::clamp(section.x * mpu - g.enter, 0.0, g.sEnd);
      const double tb = std::clamp(section.y * mpu - g.enter, 0.0, g.sEnd);
      if (!(tb > ta)) continue;
      const double share = std::ceil(options.integrationSteps * (tb - ta) / g.sm);
      const int steps =
          static_cast<int>(std::clamp(share, 1.0, static_cast<double>(options.integrationSteps)));
      single += ray.trapezoid(ta, tb, steps);
    }
    if (sky && g.tX > g.sEnd) single += ray.skyQuadrature(g.sEnd, g.tX, options.skySteps);
    return single;
  }
};

} // namespace

// The view tables' fields (atmosphere.h), named after `owner`.
void validateViewTables(const AtmosphereRayOptions& o, const std::string& owner) {
  const auto fail = [&](const std::string& field, int value, const char* why) {
    throw InvalidArgument(owner + "." + field, detail::formatValue(value), why);
  };
  if (o.single != AtmosphereSingleScattering::ViewTables && o.single != AtmosphereSingleScattering::Table4D)
    fail("single", static_cast<int>(o.single), "must be one of AtmosphereSingleScattering");
  const char* axes[] = {"volumeSize.x", "volumeSize.y", "volumeSize.z"};
  for (int i = 0; i < 3; ++i)
    if (o.volumeSize[i] < 2 || o.volumeSize[i] > 1024) fail(axes[i], o.volumeSize[i], "must be in [2, 1024]");
  if (o.volumeSteps < 1 || o.volumeSteps > 64) fail("volumeSteps", o.volumeSteps, "must be in [1, 64]");
  if (o.skyViewSize.x < 2 || o.skyViewSize.x > 4096)
    fail("skyViewSize.x", o.skyViewSize.x, "must be in [2, 4096]");
  if (o.skyViewSize.y < 4 || o.skyViewSize.y > 4096 || o.skyViewSize.y % 2 != 0)
    fail("skyViewSize.y", o.skyViewSize.y, "must be even and in [4, 4096]");
  if (o.skyViewSteps < 1 || o.skyViewSteps > 4096)
    fail("skyViewSteps", o.skyViewSteps, "must be in [1, 4096]");
}

// Yusov 2013, Eq. 8 and "Light shafts" (SS-Int, SS-LUT, MS-UnO); rule at the top of this file.
AtmosphereRay atmosphereRay(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                            const DirectionalLight& sun, const glm::dvec3& origin,
                            const glm::dvec3& direction, double surface, bool sky,
                            const AtmosphereShadowing& shadowing, const AtmosphereRayOptions& options,
                            const AtmosphereViewTables* view) {
  validate(placement, tables.parameters);
  validateRayOptions(options);
  requireFinite("origin", origin);
  requireFinite("direction", direction);
  const double dirLength = glm::length(direction);
  if (!(dirLength > 0.0)) throw InvalidArgument("direction", "zero length", "must be a non-zero direction");
  requireNonNegative("surface", surface);

  const AtmosphereParameters& p = tables.parameters;
  const double mpu = placement.metersPerUnit;
  const glm::dvec3 v = direction / dirLength;
  const glm::dvec3 l = -sun.direction();
  AtmosphereRay out;
  const std::optional<RayGeometry> geometry =
      rayGeometry(p, atmospherePosition(placement, p, origin), v, surface * mpu, sky);
  if (!geometry) return out; // misses the atmosphere
  const RayGeometry& g = *geometry;
  RayEvaluator ray(tables, g.C, v, l);
  const RayTerms terms{tables,
                       shadowing,
                       options,
                       g,
                       mpu,
                       sky,
                       view && options.shafts != AtmosphereShafts::Integrated && g.enter == 0.0};
  glm::dvec3 radiance = terms.blendedTablePart(ray, v, l);
  if (terms.fromView) terms.addViewTables(radiance, *view, v, l);
  if (options.shafts == AtmosphereShafts::Integrated) radiance += terms.integratedSingle(ray);
  // A sky pixel whose ray ends on the ground beyond the scene: the ground's reflected light.
  if (sky && g.hitsGround && p.groundAlbedo > 0.0) {
    const glm::dvec3 X = ray.at(g.tX);
    const double cosSun = glm::dot(X / glm::length(X), l);
    const glm::dvec3 direct = cosSun > 0.0 ? sunTransmittance(tables, X, l) * cosSun : glm::dvec3(0.0);
    radiance += ray.segmentTransmittance(g.tX) * (p.groundAlbedo / std::numbers::pi) *
                (direct + lookUpAmbientSkyLight(tables, cosSun));
  }
  out.inscattering = sun.irradiance() * radiance;
  if (sky)
    out.transmittance = g.hitsGround ? glm::dvec3(0.0) : ray.transmittance(g.tX);
  else
    out.transmittance = ray.segmentTransmittance(g.sEnd);
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

namespace {

/// The direction of sky-view texel (i, j) (atmosphere.h's rule); its elevation in `elevation`.
glm::dvec3 skyViewDirection(const AtmosphereViewTables& view, int i, int j, double* elevation) {
  const int W = view.skyViewSize.x, half = view.skyViewSize.y / 2;
  const double eh = view.horizonElevation, pi = std::numbers::pi;
  const double phi = pi * i / (W - 1);
  const bool above = j >= half;
  const double s = static_cast<double>(above ? j - half : j) / (half - 1);
  const double e = above ? eh + s * s * (0.5 * pi - eh) : eh - s * s * (eh + 0.5 * pi);
  *elevation = e;
  const glm::dvec3 side = glm::cross(view.zenith, view.sunAzimuth);
  return std::cos(e) * (std::cos(phi) * view.sunAzimuth + std::sin(phi) * side) + std::sin(e) * view.zenith;
}

} // namespace

// Hillaire 2020, Sec. 5.2-5.3: the sky-view table and the aerial perspective volume (atmosphere.h's rule).
AtmosphereViewTables atmosphereViewTables(const AtmosphereTables& tables,
                                          const AtmospherePlacement& placement, const Camera& camera,
                                          const DirectionalLight& sun, const AtmosphereRayOptions& options,
                                          int threads) {
  validate(placement, tables.parameters);
  validateRayOptions(options);
  if (threads < 0) throw InvalidArgument("threads", detail::formatValue(threads), "must be >= 0");
  const AtmosphereParameters& p = tables.parameters;
  AtmosphereViewTables view;
  view.volumeSize = options.volumeSize;
  view.skyViewSize = options.skyViewSize;
  view.origin = camera.position();
  view.forward = camera.forward();
  view.right = camera.right();
  view.up = camera.up();
  view.tangents = camera.tangents();
  view.far = camera.far();
  const glm::dvec3 C = atmospherePosition(placement, p, camera.position()), l = -sun.direction();
  const double mpu = placement.metersPerUnit, R = p.earthRadius;
  view.zenith = glm::normalize(C);
  const glm::dvec3 across = l - glm::dot(l, view.zenith) * view.zenith;
  view.sunAzimuth = glm::length(across) > 1e-9
                        ? glm::normalize(across)
                        : glm::normalize(glm::cross(view.zenith, std::abs(view.zenith.x) < 0.9
                                                                     ? glm::dvec3(1.0, 0.0, 0.0)
                                                                     : glm::dvec3(0.0, 0.0, 1.0)));
  const double hC = std::max(0.0, glm::length(C) - R);
  view.horizonElevation = std::asin(std::clamp(cosHorizon(p, hC), -1.0, 1.0));

  // The aerial perspective volume: one column per froxel, slice k at view depth far (k / (D - 1))^2.
  const int W = view.volumeSize.x, H = view.volumeSize.y, D = view.volumeSize.z, steps = options.volumeSteps;
  const std::size_t count = static_cast<std::size_t>(W) * static_cast<std::size_t>(H) * D;
  view.volumeRayleigh.assign(count, glm::vec3(0.0f));
  view.volumeMie.assign(count, glm::vec3(0.0f));
  parallelRows(H, threads, [&](int j) {
    for (int i = 0; i < W; ++i) {
      const glm::dvec3 v = camera.rayDirection(2.0 * (i + 0.5) / W - 1.0, 2.0 * (j + 0.5) / H - 1.0);
      const double end = view.far / glm::dot(v, view.forward) * mpu; // metres to the far plane
      ViewMarch march(tables, C, v, l);
      double t = 0.0;
      for (int k = 1; k < D; ++k) {
        const double u = static_cast<double>(k) / (D - 1);
        const double tb = end * u * u, dt = (tb - t) / steps;
        for (int s = 1; s <= steps; ++s)
          march.step(t + dt * s, dt, dt);
        t = tb;
        const std::size_t index = (static_cast<std::size_t>(k) * H + j) * W + i;
        view.volumeRayleigh[index] = glm::vec3(march.rayleigh);
        view.volumeMie[index] = glm::vec3(march.mie);
      }
    }
  });

  // The sky-view table: each texel's whole ray, t = t_end u^3; a ray of the lower half ends on the ground
  // (the tangent point at the horizon row), of the upper half at the top, decided by the half.
  const int SW = view.skyViewSize.x, SH = view.skyViewSize.y, n = options.skyViewSteps;
  view.skyRayleigh.assign(static_cast<std::size_t>(SW) * SH, glm::vec3(0.0f));
  view.skyMie.assign(static_cast<std::size_t>(SW) * SH, glm::vec3(0.0f));
  const double rr = hC * (2.0 * R + hC), top = R + p.atmosphereHeight, rc = glm::length(C);
  parallelRows(SH, threads, [&](int j) {
    for (int i = 0; i < SW; ++i) {
      double e = 0.0;
      const glm::dvec3 v = skyViewDirection(view, i, j, &e);
      const double b = glm::dot(C, v);
      double end = 0.0;
      if (j < SH / 2) { // b^2 - c = (R - r cos e)(R + r cos e), R - r cos e = r (cos e_h - cos e)
        const double eh = view.horizonElevation;
        const double disc = std::max(0.0, -2.0 * rc * std::sin(0.5 * (eh + e)) * std::sin(0.5 * (eh - e)) *
                                              (R + rc * std::cos(e)));
        end = rr / (std::sqrt(disc) - b);
      } else {
        end = -b + std::sqrt(std::max(0.0, b * b - (rc - top) * (rc + top)));
      }
      ViewMarch march(tables, C, v, l);
      march.cubic(end, n);
      const std::size_t index = static_cast<std::size_t>(j) * SW + i;
      view.skyRayleigh[index] = glm::vec3(march.rayleigh);
      view.skyMie[index] = glm::vec3(march.mie);
    }
  });
  return view;
}

// The volume's trilinear look-up at a ray's screen position and depth (GL rules; atmosphere.h).
glm::dvec3 sampleAerialPerspective(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                                   const glm::dvec3& direction, double distance, double cosSunView) {
  const glm::dvec4& tg = view.tangents;
  const double f = glm::dot(direction, view.forward);
  if (!(f > 0.0) || view.volumeRayleigh.empty()) return glm::dvec3(0.0);
  const double a = glm::dot(direction, view.right) / f, b = glm::dot(direction, view.up) / f;
  const double ndcX = (a - 0.5 * (tg.x + tg.y)) / (0.5 * (tg.y - tg.x));
  const double ndcY = (b - 0.5 * (tg.z + tg.w)) / (0.5 * (tg.w - tg.z));
  const int W = view.volumeSize.x, H = view.volumeSize.y, D = view.volumeSize.z;
  // Texel-space coordinates (texel i's centre at i); the depth slice at sqrt(z / far) (D - 1).
  const double x = std::clamp(0.5 * (ndcX + 1.0) * W - 0.5, 0.0, W - 1.0);
  const double y = std::clamp(0.5 * (ndcY + 1.0) * H - 0.5, 0.0, H - 1.0);
  const double z = std::sqrt(std::clamp(distance * f / view.far, 0.0, 1.0)) * (D - 1);
  const int x0 = std::min(static_cast<int>(x), W - 2), y0 = std::min(static_cast<int>(y), H - 2),
            z0 = std::min(static_cast<int>(z), D - 2);
  const double fx = x - x0, fy = y - y0, fz = z - z0;
  glm::dvec3 rayleigh(0.0), mie(0.0);
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const double weight = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy) * (dz ? fz : 1.0 - fz);
    const std::size_t index = (static_cast<std::size_t>(z0 + dz) * H + (y0 + dy)) * W + (x0 + dx);
    rayleigh += weight * glm::dvec3(view.volumeRayleigh[index]);
    mie += weight * glm::dvec3(view.volumeMie[index]);
  }
  return rayleigh * rayleighPhase(cosSunView) + mie * henyeyGreenstein(p.mieG, cosSunView);
}

// The sky-view table's bilinear look-up within the direction's half (atmosphere.h's rule).
glm::dvec3 sampleSkyView(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                         const glm::dvec3& direction, double cosSunView) {
  if (view.skyRayleigh.empty()) return glm::dvec3(0.0);
  const int W = view.skyViewSize.x, H = view.skyViewSize.y, half = H / 2;
  const double pi = std::numbers::pi, eh = view.horizonElevation;
  // atan2 for both angles (the GLSL twin's float needs it; atmosphere.comp).
  const glm::dvec3 v = glm::normalize(direction);
  const double cz = glm::dot(v, view.zenith);
  const glm::dvec3 level = v - cz * view.zenith;
  const double e = std::atan2(cz, glm::length(level));
  const double across = glm::dot(level, glm::cross(view.zenith, view.sunAzimuth)),
               along = glm::dot(level, view.sunAzimuth);
  const double phi = across != 0.0 || along != 0.0 ? std::abs(std::atan2(across, along)) : 0.0;
  const double x = std::clamp(phi / pi, 0.0, 1.0) * (W - 1);
  double y = 0.0;
  int y0 = 0;
  if (e >= eh) {
    y = half + std::sqrt(std::clamp((e - eh) / (0.5 * pi - eh), 0.0, 1.0)) * (half - 1);
    y0 = std::min(static_cast<int>(y), H - 2);
  } else {
    y = std::sqrt(std::clamp((eh - e) / (eh + 0.5 * pi), 0.0, 1.0)) * (half - 1);
    y0 = std::min(static_cast<int>(y), half - 2);
  }
  const int x0 = std::min(static_cast<int>(x), W - 2);
  const double fx = x - x0, fy = y - y0;
  glm::dvec3 rayleigh(0.0), mie(0.0);
  for (int c = 0; c < 4; ++c) {
    const int dx = c & 1, dy = c >> 1;
    const double weight = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
    const std::size_t index = static_cast<std::size_t>(y0 + dy) * W + (x0 + dx);
    rayleigh += weight * glm::dvec3(view.skyRayleigh[index]);
    mie += weight * glm::dvec3(view.skyMie[index]);
  }
  return rayleigh * rayleighPhase(cosSunView) + mie * henyeyGreenstein(p.mieG, cosSunView);
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
  std::optional<AtmosphereViewTables> view;
  if (options.single == AtmosphereSingleScattering::ViewTables &&
      options.shafts != AtmosphereShafts::Integrated)
    view = atmosphereViewTables(tables, placement, camera, sun, options, threads);
  parallelRows(h, threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t index =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const PixelRay pr = pixelRay(camera, cameraDepth, x, y);
      const bool sky = cameraDepth.at(x, y) >= 1.0f;
      const AtmosphereRay r =
          atmosphereRay(tables, placement, sun, origin, pr.direction, pr.surface, sky,
                        shadowing.empty() ? unshadowed : shadowing[index], options, view ? &*view : nullptr);
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
