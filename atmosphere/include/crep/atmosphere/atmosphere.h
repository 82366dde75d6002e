// Earth's atmosphere: precomputed single and multiple scattering tables (Bruneton and Neyret 2008, with
// the parameterisation and look-ups of Yusov's Outdoor Light Scattering demo, 2013), the sky, aerial
// perspective and light shafts in the atmosphere. This header is the CPU reference in double precision;
// AtmosphereTablesPass and AtmospherePass (crep/atmosphere/gpu_tables.h) compute the same tables and
// images on the GPU in float, with the look-ups of glsl/crep/atmosphere.glsl (a public include).
//
// ---------------------------------------------------------------------------------------------------
// Units and frames. Tables are in metres, around a planet centred at the origin with the table's point
// at (0, R + h, 0). A scene is placed on the planet by AtmospherePlacement: world +Y is the zenith at the
// world origin, world y = 0 is at `originAltitude` metres above sea level, one world unit is
// `metersPerUnit` metres; so the planet centre is at (0, -(R + originAltitude) / metersPerUnit, 0) in world
// units. Radiances are per unit extraterrestrial sun irradiance (the DirectionalLight's irradiance scales
// them); the sun direction is the direction the light travels (as DirectionalLight::direction()), l = -it.
//
// Media (Yusov 2012, Sec. 2; Bruneton and Neyret 2008, Sec. 2): Rayleigh scattering beta_R e^(-h/H_R)
// with the Rayleigh phase, Mie scattering beta_M e^(-h/H_M) with the Henyey-Greenstein phase of g and
// Mie extinction (beta_M + mieAbsorption) e^(-h/H_M). h is the altitude above sea level.
//
// The 4D table (Yusov 2013, "Look-up table parameterization"): a quantity of a point at altitude h looking
// along v with the sun towards l, parameterised by u_h (Eq. 4), u_alpha (Eq. 5, c_alpha = v . zenith),
// u_phi (Eq. 6, c_phi = l . zenith; Bruneton's form atan(max(c_phi, -0.1975) tan(1.26 * 1.1)) / 1.1) and
// u_theta (Eq. 7, c_theta = v . l). Texel centres: for h, phi and theta, texel i of N sits at u = i / (N -
// 1); for alpha, texels [0, N/2) are the rays below the horizon (texel 0 at the horizon, N/2 - 1 straight
// down) and [N/2, N) the rays above it (N/2 at the horizon, N - 1 the zenith), each half with
// u = k / (N/2 - 1) in Eq. 5's power-0.2 law. A ray of the lower half ends on the ground, a ray of the upper
// half at the top of the atmosphere, decided by the half and never by a ray-sphere test (so the two horizon
// texels are the limits from below and above, and a look-up that stays on one side is continuous).
// Packing (Listing 1): a 3D texture of width N_h, height N_alpha and depth N_phi * N_theta; slice
// z = q * N_phi + k holds u_theta texel q and u_phi texel k. Each texel is RGBA float, RGB the quantity
// (A unused, 0, except in the single scattering table).
//
// Single scattering is stored without its phase functions (Bruneton and Neyret 2008, Sec. 4; Bruneton's
// 2017 implementation): `single` holds the Rayleigh part S_R = integral of beta_R d_R T(C->P) T(P->sun) in
// RGB and the red channel of the Mie part S_M (the same with beta_M d_M) in A; `singleMie` holds S_M in RGB
// (empty with AtmospherePrecomputeOptions::combinedMie, which rebuilds S_M from `single` alone by Bruneton
// 2017's rule, combinedMieScattering). L1 of a look-up is S_R p_R(c) + S_M p_HG(c), c = v . l, the phase
// functions evaluated per look-up: 16 sun-view texels cannot hold the Mie peak (g = 0.76), a phase-free
// integrand varies slowly with c.
//
// Look-ups (Listing 1 and 2): texture coordinates in [0, 1] (texel i's centre at (i + 0.5) / N); GL linear
// filtering with clamp to edge in the three packed dimensions, clamped to the phi slice's texel centres,
// and a manual linear interpolation between the two theta slices. u_alpha keeps the side of the horizon of
// the previous look-up of the same ray (Listing 2), so every look-up of a view ray is on one side.
//
// Precomputation (Yusov 2013, "Multiple Scattering", steps 1-3), every table at texel centres:
//   optical depth to the top of the atmosphere (Yusov's net density table): for altitude u = sqrt(h/H_Atm)
//     and c = cos(zenith angle) in [-1, 1], the integrals of e^(-h/H_R) and e^(-h/H_M) along the ray to the
//     top (metres), or kOccludedDensity when the ray hits the ground;
//   L1 (single scattering, Listing 3): trapezoid rule with `singleSteps` steps from the point to the ground
//     or the top, of beta_R(h) e^(-T(C->P)) e^(-T(P->sun)) (S_R) and beta_M(h) e^(-T(C->P)) e^(-T(P->sun))
//     (S_M), without the phase functions (above);
//   AtmosphereMultipleScattering::Lut instead of the orders below: Psi_ms (Hillaire 2020, Sec. 5.5; see the
//     enum) and L_H of each texel integrated from it in the single scattering march;
//   Orders, for n = 2..N: J_n (Eq. 1, `sphereSamples` directions of a Fibonacci sphere, each a look-up into
//     L_(n-1), for n = 2 L1 with its phase functions at w . l plus, for a direction that hits the ground at
//     g, the ground's first bounce T(C->g) (groundAlbedo / pi) T_sun(g) max(0, n_g . l), Bruneton 2017's
//     ground term for the direct sunlight), then L_n (Eq. 2, Listing 5, trapezoid rule
//     with `orderSteps` steps, look-ups into J_n);
//   higher orders L_H = sum of L_n (n = 2..N); multiple scattering L_M = L1 + L_H is formed per look-up
//     (lookUpMultipleScattering), not stored;
//   ambient sky light E_sky(c_phi) (Eq. 3, Listing 6) at 20 m above the ground: the upper hemisphere of
//     kAmbientSampleFactor * sphereSamples Fibonacci directions (lower ones mirrored) times cos, from L_M
//     (L1's Mie lobe, ~14 degrees wide for g = 0.76, needs more directions than J_n's smooth orders; 64
//     texels make them cheap); 1D, texel i at c_phi = 2 i / (N - 1) - 1.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// Earth and its air (defaults: Yusov 2012, Sec. 2 and Yusov 2013; Bruneton and Neyret 2008).
struct AtmosphereParameters {
  double earthRadius = 6360.0e3;    ///< R, metres
  double atmosphereHeight = 80.0e3; ///< H_Atm, metres: the top of the atmosphere above sea level
  glm::dvec3 rayleighScattering{5.8e-6, 13.5e-6, 33.1e-6}; ///< beta_R at sea level, 1/m
  double rayleighScaleHeight = 7994.0;                     ///< H_R, metres
  glm::dvec3 mieScattering{2.0e-5};                        ///< beta_M at sea level, 1/m
  glm::dvec3 mieAbsorption{2.0e-5 / 9.0}; ///< Mie extinction = scattering / 0.9 (Bruneton and Neyret 2008)
  double mieScaleHeight = 1200.0;         ///< H_M, metres
  double mieG = 0.76;                     ///< Henyey-Greenstein g of the aerosols, |g| < 1
  /// Lambertian albedo of the ground in [0, 1]: the sunlit ground's bounce into multiple scattering (Orders:
  /// its first bounce, in J_2; Lut: in Psi_ms) and what sky rays that end on the ground see. 0.1: Hillaire
  /// 2020's Earth.
  double groundAlbedo = 0.1;
};
/// Throws InvalidArgument naming the field ("AtmosphereParameters.earthRadius", ...): radii and scale
/// heights must be finite and > 0, coefficients finite and >= 0 with some Rayleigh or Mie scattering,
/// |mieG| < 1, groundAlbedo in [0, 1].
void validate(const AtmosphereParameters& p);

/// The 4D table's size. The default 32 x 32 x 32 x 8 holds the higher orders L_H, which vary slowly, for
/// the per-frame view tables' single scattering (AtmosphereSingleScattering::ViewTables); Yusov 2013's
/// 32 x 128 x 64 x 16 (16x the texels) is the reference, and what AtmosphereSingleScattering::
/// Table4D's look-ups of L1 need (the README's atmosphere section has both images' difference).
struct AtmosphereTableSize {
  int height = 32;     ///< N_h
  int viewZenith = 32; ///< N_alpha, even (two halves)
  int sunZenith = 32;  ///< N_phi
  int sunView = 8;     ///< N_theta
};

/// How the tables hold the scattering orders n >= 2 (L_H).
enum class AtmosphereMultipleScattering {
  /// Hillaire 2020, Sec. 5.5: a 2D table Psi_ms(h, c_phi) of every order >= 2 at a point, as an isotropic
  /// source (the second order from sphereSamples rays of multipleScatteringSteps steps each, with the
  /// ground's bounce, times the geometric series 1 / (1 - f_ms) of its transfer f_ms); L_H of a texel is
  /// the integral of T(C->P) sigma_s(P) Psi_ms(P) along its ray, in the single scattering pass. Tables in
  /// seconds instead of minutes, but the isotropic second scattering leaves the image darker than Orders
  /// (the README's atmosphere section has the figures): an option, not the default.
  Lut,
  /// Bruneton and Neyret 2008, Yusov 2013 (default): orders 2..`orders` by the sphere integral J_n and the
  /// ray integral L_n; J_2 with the ground's first bounce of the sunlight (groundAlbedo).
  Orders,
};

struct AtmospherePrecomputeOptions {
  AtmosphereTableSize size;
  AtmosphereMultipleScattering multipleScattering = AtmosphereMultipleScattering::Orders;
  int multipleScatteringSize = 32;  ///< Lut: Psi_ms texels per side (u = sqrt(h / H_Atm), c_phi linear)
  int multipleScatteringSteps = 20; ///< Lut: midpoint steps of each of Psi_ms's rays
  int orders = 4; ///< Orders: N, orders 1..N (1: single scattering only, L_H = 0); Lut: 1 drops L_H too
  int singleSteps = 100;        ///< trapezoid steps of L1 (Listing 3)
  int orderSteps = 64;          ///< trapezoid steps of each L_n (Listing 5)
  int sphereSamples = 128;      ///< directions of J_n and E_sky (Eq. 1, 3)
  int opticalDepthHeight = 64;  ///< optical depth table: altitude texels (u = sqrt(h / H_Atm))
  int opticalDepthZenith = 256; ///< optical depth table: cos zenith texels in [-1, 1]
  int opticalDepthSteps = 256;  ///< trapezoid steps of each optical depth integral
  int ambientSize = 64;         ///< E_sky texels over c_phi in [-1, 1]
  bool keepOrders = false;      ///< keep each L_n in AtmosphereTables::orders (tests, analysis)
  /// Store single Mie scattering only as the red channel in `single`'s alpha and rebuild its RGB per
  /// look-up (Bruneton 2017's combined form, combinedMieScattering): one 4D table less, at the error the
  /// README's atmosphere section states. Needs rayleighScattering > 0 in every channel, mieScattering.r > 0.
  bool combinedMie = false;
};
/// Whether tables of `o` hold Psi_ms (AtmosphereTables::multipleScatteringLut): Lut with orders > 1.
inline bool usesMultipleScatteringLut(const AtmospherePrecomputeOptions& o) {
  return o.multipleScattering == AtmosphereMultipleScattering::Lut && o.orders > 1;
}
/// Throws InvalidArgument naming the field ("AtmospherePrecomputeOptions.size.viewZenith", ...): sizes >= 2
/// (viewZenith even and >= 4), orders in [1, 16], steps and samples in [1, 4096], a packed depth
/// sunZenith * sunView <= 2048 and every size <= 2048 (GL_MAX_3D_TEXTURE_SIZE's guaranteed minimum).
void validate(const AtmospherePrecomputeOptions& o);
/// Both of the above, and what combinedMie needs of the parameters (InvalidArgument
/// "AtmospherePrecomputeOptions.combinedMie").
void validate(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o);

/// The value a texel of the optical depth table holds for a ray that hits the ground (metres of sea-level
/// density): large enough that every channel's transmittance is 0 in float.
inline constexpr double kOccludedDensity = 1.0e9;

/// E_sky's directions per sphereSamples (the top of this header).
inline constexpr int kAmbientSampleFactor = 16;

/// A 4D table packed as described at the top: texels() = N_h * N_alpha * N_phi * N_theta RGBA floats,
/// texel (ih, ia, ip, it) at index ((it * N_phi + ip) * N_alpha + ia) * N_h + ih (the 3D texture's order).
struct AtmosphereTable4D {
  AtmosphereTableSize size;
  std::vector<float> rgba;
  std::size_t texels() const;
  glm::vec4 at(int ih, int ia, int ip, int it) const;
  glm::vec4& at(int ih, int ia, int ip, int it);
};

/// Every table of one atmosphere (the result of precomputeAtmosphere, AtmosphereTablesPass::download and
/// loadAtmosphereTables).
struct AtmosphereTables {
  AtmosphereParameters parameters;
  AtmospherePrecomputeOptions options;
  /// opticalDepthHeight x opticalDepthZenith, 2 channels: Rayleigh and Mie density integrals, metres.
  Image opticalDepth;
  AtmosphereTable4D single;       ///< L1 without phase: RGB S_R, A the red channel of S_M (see the top)
  AtmosphereTable4D singleMie;    ///< RGB S_M (A 0); empty (no texels) with options.combinedMie
  AtmosphereTable4D higherOrders; ///< L_H = L2 + ... + LN (phase functions inside)
  Image ambient;                  ///< ambientSize x 1, 3 channels: E_sky per unit sun irradiance
  /// Lut: multipleScatteringSize^2, 3 channels: Psi_ms per unit sun irradiance, texel (i, j) at
  /// h = H_Atm (i / (n - 1))^2, c_phi = 2 j / (n - 1) - 1; empty with Orders.
  Image multipleScatteringLut;
  /// L1, L2, ..., LN when options.keepOrders, else empty; L1 there with its phase functions at each
  /// texel's own c_theta (for analysis: the sum of the orders at a texel).
  std::vector<AtmosphereTable4D> orders;
};

/// Yusov 2013, "Multiple Scattering" steps 1-3 and Eq. 3 on the CPU, in double (stored as float), rows in
/// parallel on `threads` workers (0 = hardware concurrency). For tests and small tables: the default size
/// takes minutes. Validates both arguments.
AtmosphereTables precomputeAtmosphere(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                      int threads = 0);

// --- Parameterisation (Yusov 2013, Eq. 4-7) -------------------------------------------------------------

/// cos of the horizon's zenith angle at altitude h: -sqrt(h (2R + h)) / (R + h).
double cosHorizon(const AtmosphereParameters& p, double h);

/// Half-width, in cos zenith, of the band around the horizon where the segment values of Eq. 8 (the
/// difference of two look-ups) are blended from one ray just below and one just above the horizon (the fix
/// of Bruneton and Neyret 2008's implementation, there with a fixed 0.004): near the horizon the two look-ups
/// are large and nearly equal, and the altitude texels around h have horizons that differ by this spread,
/// so their difference is noise. The spread of cosHorizon between the two altitude texels around h, plus
/// 0.004.
double horizonBlendWidth(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h);

/// World parameters (h, c_alpha, c_phi, c_theta) -> texture coordinates (u_h, u_alpha, u_phi, u_theta) of
/// the 4D table, each in [0, 1] with texel i's centre at (i + 0.5) / N. `previous` is the previous look-up's
/// coordinates of the same view ray, or negative for the first (Listing 2: its u_alpha decides the side of
/// the horizon). h is clamped to [0, H_Atm], the cosines to [-1, 1].
glm::dvec4 atmosphereTableCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h,
                                 double cosViewZenith, double cosSunZenith, double cosSunView,
                                 const glm::dvec4& previous = glm::dvec4(-1.0));

/// The world parameters at the centre of texel (ih, ia, ip, it): (h, c_alpha, c_phi, c_theta) (the inverse
/// of Eq. 4-7 at the texel centres of the top of this header).
glm::dvec4 atmosphereTexelParams(const AtmosphereParameters& p, const AtmosphereTableSize& size, int ih,
                                 int ia, int ip, int it);

/// The view and sun directions of the table's point (0, R + h, 0) for (c_alpha, c_phi, c_theta): v in the
/// x-y plane (v = (sqrt(1 - c_alpha^2), c_alpha, 0)), l with l.y = c_phi and v . l = c_theta when the three
/// cosines are compatible; otherwise l's component off the plane is 0 and the result is renormalized.
void atmosphereDirections(double cosViewZenith, double cosSunZenith, double cosSunView, glm::dvec3& view,
                          glm::dvec3& sun);

/// Listing 1: the 4D table at texture coordinates `coords` (atmosphereTableCoords), trilinear in the
/// packed dimensions (GL rules, clamp to edge) and linear between theta slices.
glm::dvec3 sampleAtmosphereTable(const AtmosphereTable4D& table, const glm::dvec4& coords);

/// Listing 1's coordinates for the point `position` (metres, planet centre at the origin) looking along unit
/// `view` with the sun towards unit `toSun`: atmosphereTableCoords of its altitude and three cosines.
glm::dvec4 atmosphereLookUpCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size,
                                  const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                                  const glm::dvec4& previous = glm::dvec4(-1.0));

/// sampleAtmosphereTable with the alpha channel (`single`'s Mie red).
glm::dvec4 sampleAtmosphereTableRgba(const AtmosphereTable4D& table, const glm::dvec4& coords);

/// Listing 1 end to end: the table's value for the point `position` (metres, planet centre at the origin)
/// looking along unit `view` with the sun towards unit `toSun`. `coords` carries the previous look-up's
/// coordinates of the same ray in (negative for the first) and this look-up's out.
glm::dvec3 lookUpAtmosphere(const AtmosphereTables& tables, const AtmosphereTable4D& table,
                            const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                            glm::dvec4& coords);

/// Bruneton's 2017 combined form: S_M's RGB from a texel (or look-up) of `single` (RGB S_R, A S_M's red):
/// S_R (A / S_R.r) (beta_R.r / beta_M.r) (beta_M / beta_R), exact where S_M / S_R is the ratio of the
/// coefficients times one factor for all channels; 0 where S_R.r <= 0.
glm::dvec3 combinedMieScattering(const AtmosphereParameters& p, const glm::dvec4& single);

/// L1 at table coordinates `coords` with the phase functions of c = cos(view, sun) applied: S_R p_R(c) +
/// S_M p_HG(g, c), S_M from `singleMie` or, with options.combinedMie, combinedMieScattering.
glm::dvec3 sampleSingleScattering(const AtmosphereTables& tables, const glm::dvec4& coords,
                                  double cosSunView);

/// lookUpAtmosphere for L1 (sampleSingleScattering) and for L_M = L1 + L_H (the same coordinates for both
/// tables).
glm::dvec3 lookUpSingleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                  const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords);
glm::dvec3 lookUpMultipleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                    const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords);

/// The optical depth table, bilinear (GL rules): (Rayleigh, Mie) density integrals from altitude h along
/// a ray with cos zenith c to the top of the atmosphere.
glm::dvec2 lookUpDensityToTop(const AtmosphereTables& tables, double h, double cosZenith);

/// Transmittance from `position` to the sun (unit `toSun`) through the optical depth table.
glm::dvec3 sunTransmittance(const AtmosphereTables& tables, const glm::dvec3& position,
                            const glm::dvec3& toSun);

/// RGB transmittance between two points a and b (metres, planet at the origin; b on the ray from a) through
/// the optical depth table, D = lookUpDensityToTop, beta_e the extinctions: when the ray from a through b
/// does not hit the ground, exp(-beta_e . (D(a, v) - D(b, v))); when it does (it descends all the way from a
/// to b), exp(-beta_e . (D(b, -v) - D(a, -v))), v = normalize(b - a). Differences are clamped to >= 0.
glm::dvec3 atmosphereTransmittance(const AtmosphereTables& tables, const glm::dvec3& a, const glm::dvec3& b);

/// Psi_ms at altitude h and sun zenith cosine c (bilinear in the Lut method's table; 0 without it).
glm::dvec3 lookUpMultipleScatteringLut(const AtmosphereTables& tables, double h, double cosSunZenith);

/// E_sky at the cosine of the sun's zenith angle (linear in the 1D table).
glm::dvec3 lookUpAmbientSkyLight(const AtmosphereTables& tables, double cosSunZenith);

/// Direction i of the n-direction Fibonacci sphere used by Eq. 1 and 3 (zenith +y):
/// y = 1 - (2 i + 1) / n, r = sqrt(1 - y^2), angle = i pi (3 - sqrt(5)), (r cos(angle), y, r sin(angle)).
glm::dvec3 fibonacciSphereDirection(int i, int n);

// --- Exact integrals (no tables), the references of the tests --------------------------------------------

/// (Rayleigh, Mie) density integrals along the segment a -> b (metres, planet at the origin) with
/// `steps` trapezoid steps.
glm::dvec2 densityIntegral(const AtmosphereParameters& p, const glm::dvec3& a, const glm::dvec3& b,
                           int steps);

// --- Per-frame use ----------------------------------------------------------------------------------------

/// Where a scene sits on the planet (see the top of this header).
struct AtmospherePlacement {
  double metersPerUnit = 1.0;  ///< > 0
  double originAltitude = 0.0; ///< metres above sea level of world y = 0, in [0, H_Atm)
};
/// Throws InvalidArgument ("AtmospherePlacement.metersPerUnit", ...).
void validate(const AtmospherePlacement& placement, const AtmosphereParameters& p);

/// World point -> metres around the planet centre.
glm::dvec3 atmospherePosition(const AtmospherePlacement& placement, const AtmosphereParameters& p,
                              const glm::dvec3& world);

/// How light shafts (volumetric shadows of the scene's shadow map) enter the atmosphere's in-scattering.
enum class AtmosphereShafts {
  None,       ///< no shadows: Eq. 8 with L_M from the camera to the surface (or the sky)
  Integrated, ///< (a) single scattering integrated along the ray over its lit sections, plus
              ///<     unoccluded higher orders (Eq. 8 with L_H): the demo's integration mode with unoccluded
              ///<     higher orders
  LitLengthTable, ///< (b) lit length D_lit and first lit distance D_start, Eq. 8 with L1 over
                  ///<     [D_start, D_start + D_lit], plus unoccluded higher orders: the demo's table mode
  PrefilteredVisibility, ///< (c) the pixel's prefiltered visibility fraction times Eq. 8 with L1, plus
                         ///<     unoccluded higher orders (not in the seeds)
};

/// One view ray's result: in-scattered radiance (per unit sun irradiance times the light's irradiance)
/// and the RGB transmittance from the camera to the ray's end (0 for the sky: nothing behind it).
struct AtmosphereRay {
  glm::dvec3 inscattering{0.0};
  glm::dvec3 transmittance{1.0};
};

/// What the shadow map says about one ray (world distances from the camera along the ray; `surface` is
/// the distance to the visible surface or the far plane).
struct AtmosphereShadowing {
  std::vector<glm::dvec2> litSections; ///< (a): lit [ta, tb], ascending, within [0, surface]
  double litLength = 0.0;              ///< (b): D_lit
  double firstLit = 0.0;               ///< (b): D_start
  double visibility = 1.0;             ///< (c): the visible fraction
};

/// Where None, (b) and (c) take single scattering from.
enum class AtmosphereSingleScattering {
  /// Hillaire 2020, Sec. 5.2-5.3 (default): the camera's AtmosphereViewTables, integrated from the camera
  /// once per frame: the aerial perspective volume in front of the far plane, the sky-view table beyond it.
  ViewTables,
  /// Yusov 2013, Eq. 8 on the 4D table: L1(C) - T(C->P) L1(P); 8-16% off on short segments, where the two
  /// look-ups are large and nearly equal, and several percent in the horizon's blend band.
  Table4D,
};

struct AtmosphereRayOptions {
  AtmosphereShafts shafts = AtmosphereShafts::None;
  int integrationSteps = 64; ///< (a): trapezoid steps over [0, surface] (lit sections get their share)
  int skySteps = 16; ///< (a): steps beyond the far plane to the end of a sky ray (t = s_F + (t_X - s_F) u^3)
  /// None, (b), (c); (a) integrates its own. atmosphereRay takes the view tables as an argument.
  AtmosphereSingleScattering single = AtmosphereSingleScattering::ViewTables;
  glm::ivec3 volumeSize{64, 64, 32}; ///< ViewTables: volume froxels across, up, depth slices; [2, 1024]
  int volumeSteps = 4;               ///< ViewTables: trapezoid steps per depth slice, in [1, 64]
  glm::ivec2 skyViewSize{192, 108};  ///< ViewTables: sky-view azimuths, elevations (even); [2, 4096]
  int skyViewSteps = 32;             ///< ViewTables: steps of a sky-view ray, in [1, 4096]
};

/// Throws InvalidArgument naming `owner`.single, .volumeSize.x, ..., .skyViewSteps for a field of the view
/// tables out of the range its comment states (atmosphereRay, atmosphereViewTables and AtmospherePass check
/// them so).
void validateViewTables(const AtmosphereRayOptions& o, const std::string& owner = "AtmosphereRayOptions");

/// The per-frame tables of one camera (Hillaire 2020, Sec. 5.2-5.3), without phase functions. Both hold
/// integrals from the camera C along a ray of beta_R d_R T(C->P) T_sun(P) (`...Rayleigh`) and
/// beta_M d_M T(C->P) T_sun(P) (`...Mie`), per unit sun irradiance, RGB: (a)'s integrand without its phase
/// functions, T(C->P) from the densities marched from C. L1 of a ray is p_R(c) Rayleigh + p_HG(c) Mie read
/// there, c = v . l of the ray itself.
/// - The aerial perspective volume: froxel (i, j, k) of W x H x D (volumeSize) is the ray of
///   screenRay(camera, W, H, i + 0.5, j + 0.5, .) to view depth z_k = far (k / (D - 1))^2 (far =
///   camera.far()), volumeSteps trapezoid steps per slice; index (k H + j) W + i. Read by
///   sampleAerialPerspective.
/// - The sky-view table: texel (i, j) of W x H (skyViewSize) is the whole ray to the ground or the top of the
///   atmosphere along the direction of azimuth phi_i = pi i / (W - 1) from the sun's vertical plane (the
///   atmosphere is mirror-symmetric about it) and elevation e_j: rows [0, H/2) below the horizon's
///   elevation e_h (row 0 at it, from below; H/2 - 1 straight down), rows [H/2, H) above (H/2 at it, from
///   above; H - 1 the zenith), e = e_h -/+ s^2 (e_h + pi/2 or pi/2 - e_h), s = k / (H/2 - 1) within each
///   half (texels crowd at the horizon, and a look-up never mixes the two sides); skyViewSteps trapezoid
///   steps in u of t = t_end u^3 (as (a)'s sky). Index j W + i. Read by sampleSkyView.
/// Not used when the camera is above the atmosphere (Table4D then).
struct AtmosphereViewTables {
  glm::ivec3 volumeSize{0};
  glm::ivec2 skyViewSize{0};
  glm::dvec3 origin{0.0};                       ///< the camera's world position
  glm::dvec3 forward{0.0}, right{0.0}, up{0.0}; ///< the camera's unit axes
  glm::dvec4 tangents{0.0};                     ///< Camera::tangents()
  double far = 0.0;                             ///< world units: camera.far()
  glm::dvec3 zenith{0.0}, sunAzimuth{0.0};      ///< unit: the camera's zenith, the sun's horizontal direction
  double horizonElevation = 0.0;                ///< e_h, radians (<= 0)
  std::vector<glm::vec3> volumeRayleigh, volumeMie, skyRayleigh, skyMie;
};
/// Computes both tables of `camera` (validates placement and the ViewTables fields of `options`; rows in
/// parallel on `threads` workers, 0 = hardware concurrency).
AtmosphereViewTables atmosphereViewTables(const AtmosphereTables& tables,
                                          const AtmospherePlacement& placement, const Camera& camera,
                                          const DirectionalLight& sun, const AtmosphereRayOptions& options,
                                          int threads = 0);
/// L1 per unit sun irradiance of the camera ray along unit world `direction` to world distance `distance`:
/// the volume trilinear (GL rules: texel centres, clamp to edge) at the direction's screen position and
/// sqrt(z / far) (D - 1) of its depth z = distance (direction . forward), phases of `cosSunView`.
glm::dvec3 sampleAerialPerspective(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                                   const glm::dvec3& direction, double distance, double cosSunView);
/// L1 per unit sun irradiance of the whole camera ray along unit world `direction`: the sky-view table
/// bilinear (GL rules within the direction's half), phases of `cosSunView`.
glm::dvec3 sampleSkyView(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                         const glm::dvec3& direction, double cosSunView);

/// One view ray of a camera: from world point `origin` along unit world `direction` to world distance
/// `surface` (the far plane for sky pixels: `sky` true, then the ray continues unshadowed to the ground or
/// the top of the atmosphere and its transmittance is 0 where it hits the ground, else the sky's own).
/// `view`: the AtmosphereViewTables of the camera at `origin` that None, (b) and (c) read (null: Table4D,
/// whatever options.single says).
AtmosphereRay atmosphereRay(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                            const DirectionalLight& sun, const glm::dvec3& origin,
                            const glm::dvec3& direction, double surface, bool sky,
                            const AtmosphereShadowing& shadowing, const AtmosphereRayOptions& options,
                            const AtmosphereViewTables* view = nullptr);

/// The shadowing of (b) from the lit sections of (a): D_lit = the sum of their lengths, D_start = the first
/// section's start (0 and 0 without sections). Keeps the sections.
AtmosphereShadowing shadowingFromSections(std::vector<glm::dvec2> litSections);

/// (c): the visible fraction of a pixel's ray from a prefiltered (or any shadowed) homogeneous-medium
/// result `shadowed` (RGB radiance of crep::Scattering / EvaluatePass for `light` in the proxy medium
/// `proxy`): luminance(shadowed) / luminance(unshadowed closed form of the same ray, length `surface`
/// world units), clamped to [0, 1]; 1 where the unshadowed value is 0.
double prefilteredVisibility(const glm::dvec3& shadowed, const DirectionalLight& light, const Medium& proxy,
                             const glm::dvec3& direction, double surface);

/// The per-pixel image of a camera: RGBA, RGB the in-scattered radiance of atmosphereRay, A the mean of its
/// RGB transmittance; `transmittance` RGB. The outputs every atmosphere method writes (AtmospherePass too).
struct AtmosphereImage {
  Image inscattering;  ///< RGBA
  Image transmittance; ///< RGB
};

/// atmosphereRay for every pixel of `camera` (pixel rays and sky test of crep/scatter/ray.h: depth-buffer
/// value 1 is the sky) with `shadowing` per pixel in row-major order (width * height entries; may be empty
/// for AtmosphereShafts::None). Rows in parallel on `threads` workers (0 = hardware concurrency). With
/// options.single ViewTables (and shafts other than (a)) the camera's AtmosphereViewTables first.
AtmosphereImage atmosphereImage(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                                const Camera& camera, const DirectionalLight& sun, const Image& cameraDepth,
                                const std::vector<AtmosphereShadowing>& shadowing,
                                const AtmosphereRayOptions& options, int threads = 0);

// --- Disk cache
// ---------------------------------------------------------------------------------------------

/// The cache key of (parameters, options): a hex digest of every field that changes the tables (threads
/// and keepOrders excluded).
std::string atmosphereCacheKey(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o);

/// Writes every table to `path` (a documented binary, see the .cpp's top: magic, version, key, sizes,
/// data, checksum). Throws IoError.
void saveAtmosphereTables(const AtmosphereTables& tables, const std::filesystem::path& path);
/// Reads `path`; throws IoError naming the file for a missing, truncated or corrupt file (bad magic,
/// version, sizes or checksum).
AtmosphereTables loadAtmosphereTables(const std::filesystem::path& path);

/// The cache: loads `directory`/atmosphere-<key>.bin if it is valid for (p, o); else computes with
/// `compute`, saves, and returns the result. A corrupt or mismatching file is reported through `warn`
/// (a message naming the file and why) and recomputed, never used.
AtmosphereTables cachedAtmosphereTables(const std::filesystem::path& directory, const AtmosphereParameters& p,
                                        const AtmospherePrecomputeOptions& o,
                                        const std::function<AtmosphereTables()>& compute,
                                        const std::function<void(const std::string&)>& warn);

} // namespace crep
