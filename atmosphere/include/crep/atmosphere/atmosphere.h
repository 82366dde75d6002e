// Earth's atmosphere, CPU reference in double (Bruneton and Neyret 2008; Yusov 2013's parameterisation and
// look-ups; Hillaire 2020's view tables): tables, sky, aerial perspective and light shafts; gpu_tables.h and
// gpu_pass.h do the same in float. Units, frames, the 4D table's parameterisation, packing, precomputation:
// atmosphere/README.md, "atmosphere.h".
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
  double groundAlbedo = 0.1;              ///< Lambertian ground albedo in [0, 1] (Hillaire 2020's Earth)
};
/// Throws InvalidArgument naming the field ("AtmosphereParameters.earthRadius", ...): radii, scale heights
/// > 0, coefficients >= 0 with some scattering, |mieG| < 1, groundAlbedo in [0, 1], all finite.
void validate(const AtmosphereParameters& p);

/// The 4D table's size; Yusov 2013's 32 x 128 x 64 x 16 is the reference (what Table4D's L1 needs).
struct AtmosphereTableSize {
  int height = 32;     ///< N_h
  int viewZenith = 32; ///< N_alpha, even (two halves)
  int sunZenith = 32;  ///< N_phi
  int sunView = 8;     ///< N_theta
};

/// How the tables hold the scattering orders n >= 2 (L_H).
enum class AtmosphereMultipleScattering {
  Lut,    ///< Hillaire 2020, Sec. 5.5: a 2D table Psi_ms(h, c_phi) of all orders >= 2 (faster, darker)
  Orders, ///< Bruneton and Neyret 2008, Yusov 2013: orders 2..N by J_n and L_n (default)
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
  /// Single Mie scattering only as `single`'s alpha (Bruneton 2017, combinedMieScattering): one 4D table
  /// less; needs rayleighScattering > 0 in every channel and mieScattering.r > 0.
  bool combinedMie = false;
};
/// Whether tables of `o` hold Psi_ms (AtmosphereTables::multipleScatteringLut): Lut with orders > 1.
inline bool usesMultipleScatteringLut(const AtmospherePrecomputeOptions& o) {
  return o.multipleScattering == AtmosphereMultipleScattering::Lut && o.orders > 1;
}
/// InvalidArgument naming the field: sizes in [2, 2048] (viewZenith even, >= 4; sunZenith * sunView <=
/// 2048), orders in [1, 16], steps and samples in [1, 4096].
void validate(const AtmospherePrecomputeOptions& o);
/// Both of the above, and combinedMie's needs ("AtmospherePrecomputeOptions.combinedMie").
void validate(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o);

/// The optical depth of a ray that hits the ground (metres): every transmittance is 0 in float.
inline constexpr double kOccludedDensity = 1.0e9;

/// E_sky's directions per sphereSamples.
inline constexpr int kAmbientSampleFactor = 16;

/// A packed 4D table: N_h N_alpha N_phi N_theta RGBA floats, texel (ih, ia, ip, it) at index ((it * N_phi +
/// ip) * N_alpha + ia) * N_h + ih (the 3D texture's order).
struct AtmosphereTable4D {
  AtmosphereTableSize size;
  std::vector<float> rgba;
  std::size_t texels() const;
  glm::vec4 at(int ih, int ia, int ip, int it) const;
  glm::vec4& at(int ih, int ia, int ip, int it);
};

/// Every table of one atmosphere (precomputeAtmosphere, AtmosphereTablesPass::download, a cache file).
struct AtmosphereTables {
  AtmosphereParameters parameters;
  AtmospherePrecomputeOptions options;
  Image opticalDepth;       ///< opticalDepthHeight x opticalDepthZenith: Rayleigh, Mie density integrals (m)
  AtmosphereTable4D single; ///< L1 without phase: RGB S_R, A the red channel of S_M
  AtmosphereTable4D singleMie;    ///< RGB S_M (A 0); empty (no texels) with options.combinedMie
  AtmosphereTable4D higherOrders; ///< L_H = L2 + ... + LN (phase functions inside)
  Image ambient;                  ///< ambientSize x 1, 3 channels: E_sky per unit sun irradiance
  /// Lut: Psi_ms per unit sun irradiance, n x n, texel (i, j) at h = H_Atm (i / (n - 1))^2, c_phi linear.
  Image multipleScatteringLut;
  /// L1 (with its phase functions), L2, ..., LN when options.keepOrders, else empty.
  std::vector<AtmosphereTable4D> orders;
};

/// Yusov 2013, "Multiple Scattering" steps 1-3 and Eq. 3 in double (stored as float), validated, rows on
/// `threads` workers (0 = all). One-time; minutes at the default size: for tests and small tables.
AtmosphereTables precomputeAtmosphere(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                      int threads = 0);

// --- Parameterisation (Yusov 2013, Eq. 4-7) -------------------------------------------------------------

/// cos of the horizon's zenith angle at altitude h: -sqrt(h (2R + h)) / (R + h).
double cosHorizon(const AtmosphereParameters& p, double h);

/// Half-width (cos zenith) of the horizon band where Eq. 8's segments are blended from rays below and above
/// it: the spread of cosHorizon between the altitude texels around h, plus 0.004.
double horizonBlendWidth(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h);

/// (h, c_alpha, c_phi, c_theta) -> the 4D table's texture coordinates in [0, 1]; `previous`: the ray's last
/// look-up's, or negative (Listing 2: it decides the side of the horizon).
glm::dvec4 atmosphereTableCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size, double h,
                                 double cosViewZenith, double cosSunZenith, double cosSunView,
                                 const glm::dvec4& previous = glm::dvec4(-1.0));

/// (h, c_alpha, c_phi, c_theta) at the centre of texel (ih, ia, ip, it): Eq. 4-7 inverted.
glm::dvec4 atmosphereTexelParams(const AtmosphereParameters& p, const AtmosphereTableSize& size, int ih,
                                 int ia, int ip, int it);

/// The view and sun directions at (0, R + h, 0) for (c_alpha, c_phi, c_theta); v in the x-y plane, l
/// renormalized when the cosines are incompatible.
void atmosphereDirections(double cosViewZenith, double cosSunZenith, double cosSunView, glm::dvec3& view,
                          glm::dvec3& sun);

/// Listing 1: the 4D table at `coords`, trilinear in the packed dimensions, linear between theta slices.
glm::dvec3 sampleAtmosphereTable(const AtmosphereTable4D& table, const glm::dvec4& coords);

/// Listing 1's coordinates of `position` (metres, planet at the origin) looking along `view`, sun `toSun`.
glm::dvec4 atmosphereLookUpCoords(const AtmosphereParameters& p, const AtmosphereTableSize& size,
                                  const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                                  const glm::dvec4& previous = glm::dvec4(-1.0));

/// sampleAtmosphereTable with the alpha channel (`single`'s Mie red).
glm::dvec4 sampleAtmosphereTableRgba(const AtmosphereTable4D& table, const glm::dvec4& coords);

/// Listing 1 end to end (as atmosphereLookUpCoords); `coords`: the ray's previous look-up's coordinates in
/// (negative for the first), this one's out.
glm::dvec3 lookUpAtmosphere(const AtmosphereTables& tables, const AtmosphereTable4D& table,
                            const glm::dvec3& position, const glm::dvec3& view, const glm::dvec3& toSun,
                            glm::dvec4& coords);

/// Bruneton 2017's combined form: S_M's RGB from `single` (RGB S_R, A S_M's red) = S_R (A / S_R.r)
/// (beta_R.r / beta_M.r) (beta_M / beta_R); 0 where S_R.r <= 0.
glm::dvec3 combinedMieScattering(const AtmosphereParameters& p, const glm::dvec4& single);

/// L1 at `coords` with the phase functions of c = cos(view, sun): S_R p_R(c) + S_M p_HG(g, c).
glm::dvec3 sampleSingleScattering(const AtmosphereTables& tables, const glm::dvec4& coords,
                                  double cosSunView);

/// lookUpAtmosphere for L1 (sampleSingleScattering) and for L_M = L1 + L_H (the same coordinates).
glm::dvec3 lookUpSingleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                  const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords);
glm::dvec3 lookUpMultipleScattering(const AtmosphereTables& tables, const glm::dvec3& position,
                                    const glm::dvec3& view, const glm::dvec3& toSun, glm::dvec4& coords);

/// The optical depth table, bilinear: (Rayleigh, Mie) density integrals from altitude h to the top.
glm::dvec2 lookUpDensityToTop(const AtmosphereTables& tables, double h, double cosZenith);

/// Transmittance from `position` to the sun (unit `toSun`) through the optical depth table.
glm::dvec3 sunTransmittance(const AtmosphereTables& tables, const glm::dvec3& position,
                            const glm::dvec3& toSun);

/// RGB transmittance between points a and b (metres, planet at the origin) through the optical depth table
/// (the ground rule: README).
glm::dvec3 atmosphereTransmittance(const AtmosphereTables& tables, const glm::dvec3& a, const glm::dvec3& b);

/// Psi_ms at altitude h and sun zenith cosine c (bilinear in the Lut method's table; 0 without it).
glm::dvec3 lookUpMultipleScatteringLut(const AtmosphereTables& tables, double h, double cosSunZenith);

/// E_sky at the cosine of the sun's zenith angle (linear in the 1D table).
glm::dvec3 lookUpAmbientSkyLight(const AtmosphereTables& tables, double cosSunZenith);

/// Direction i of the n-direction Fibonacci sphere of Eq. 1 and 3 (zenith +y; y = 1 - (2 i + 1) / n).
glm::dvec3 fibonacciSphereDirection(int i, int n);

// --- Exact integrals (no tables), the references of the tests --------------------------------------------

/// (Rayleigh, Mie) density integrals along a -> b (metres, planet at the origin), `steps` trapezoid steps.
glm::dvec2 densityIntegral(const AtmosphereParameters& p, const glm::dvec3& a, const glm::dvec3& b,
                           int steps);

// --- Per-frame use ----------------------------------------------------------------------------------------

/// Where a scene sits on the planet: world +Y is the zenith at the world origin.
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
  None,                  ///< no shadows: Eq. 8 with L_M from the camera to the surface (or the sky)
  Integrated,            ///< (a) L1 integrated over the ray's lit sections, plus unoccluded L_H
  LitLengthTable,        ///< (b) Eq. 8 with L1 over [D_start, D_start + D_lit], plus unoccluded L_H
  PrefilteredVisibility, ///< (c) the prefiltered visibility fraction times L1, plus unoccluded L_H
};

/// One view ray's in-scattered radiance (the sun's irradiance applied) and RGB transmittance (0 for the sky).
struct AtmosphereRay {
  glm::dvec3 inscattering{0.0};
  glm::dvec3 transmittance{1.0};
};

/// What the shadow map says about one ray (world distances from the camera, within [0, surface]).
struct AtmosphereShadowing {
  std::vector<glm::dvec2> litSections; ///< (a): lit [ta, tb], ascending, within [0, surface]
  double litLength = 0.0;              ///< (b): D_lit
  double firstLit = 0.0;               ///< (b): D_start
  double visibility = 1.0;             ///< (c): the visible fraction
};

/// Where None, (b) and (c) take single scattering from.
enum class AtmosphereSingleScattering {
  ViewTables, ///< Hillaire 2020, Sec. 5.2-5.3: the camera's AtmosphereViewTables, per frame (default)
  Table4D,    ///< Yusov 2013, Eq. 8 on the 4D table: L1(C) - T(C->P) L1(P)
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

/// InvalidArgument naming `owner`.single, .volumeSize.x, ..., .skyViewSteps out of its stated range (the one
/// check of atmosphereRay, atmosphereViewTables and AtmospherePass).
void validateViewTables(const AtmosphereRayOptions& o, const std::string& owner = "AtmosphereRayOptions");

/// The per-frame tables of one camera (Hillaire 2020, Sec. 5.2-5.3), without phase functions, per unit sun
/// irradiance: the aerial perspective volume (index (k H + j) W + i) and the sky-view table (index j W + i).
/// Their rules: README "atmosphere.h". Not used when the camera is above the atmosphere (Table4D then).
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
/// Both tables of `camera` (validates placement and the view tables' fields; rows on `threads` workers, 0 =
/// all). Per frame, O(volume cells + sky texels) ray marches.
AtmosphereViewTables atmosphereViewTables(const AtmosphereTables& tables,
                                          const AtmospherePlacement& placement, const Camera& camera,
                                          const DirectionalLight& sun, const AtmosphereRayOptions& options,
                                          int threads = 0);
/// L1 per unit sun irradiance of the camera ray along `direction` to world distance `distance`: the volume,
/// trilinear, with the phases of `cosSunView`.
glm::dvec3 sampleAerialPerspective(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                                   const glm::dvec3& direction, double distance, double cosSunView);
/// L1 per unit sun irradiance of the whole camera ray along `direction`: the sky-view table, bilinear.
glm::dvec3 sampleSkyView(const AtmosphereViewTables& view, const AtmosphereParameters& p,
                         const glm::dvec3& direction, double cosSunView);

/// One view ray from world `origin` along `direction` to world distance `surface` (the far plane when `sky`:
/// then on, unshadowed). `view`: the camera's AtmosphereViewTables, or null (Table4D).
AtmosphereRay atmosphereRay(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                            const DirectionalLight& sun, const glm::dvec3& origin,
                            const glm::dvec3& direction, double surface, bool sky,
                            const AtmosphereShadowing& shadowing, const AtmosphereRayOptions& options,
                            const AtmosphereViewTables* view = nullptr);

/// (b)'s shadowing from (a)'s lit sections: D_lit their total length, D_start the first's start; keeps them.
AtmosphereShadowing shadowingFromSections(std::vector<glm::dvec2> litSections);

/// (c): a ray's visible fraction, luminance(shadowed) / luminance(unshadowed closed form) in `proxy`, clamped
/// to [0, 1] (1 where the unshadowed value is 0); `shadowed` e.g. crep::Scattering's RGB.
double prefilteredVisibility(const glm::dvec3& shadowed, const DirectionalLight& light, const Medium& proxy,
                             const glm::dvec3& direction, double surface);

/// The per-pixel outputs every atmosphere method writes (AtmospherePass too).
struct AtmosphereImage {
  Image inscattering;  ///< RGBA: RGB atmosphereRay's in-scattered radiance, A its mean RGB transmittance
  Image transmittance; ///< RGB
};

/// atmosphereRay for every pixel (crep/scatter/ray.h's pixel rays; depth 1 = sky), `shadowing` per pixel,
/// row-major (empty for None); rows on `threads` workers (0 = all).
AtmosphereImage atmosphereImage(const AtmosphereTables& tables, const AtmospherePlacement& placement,
                                const Camera& camera, const DirectionalLight& sun, const Image& cameraDepth,
                                const std::vector<AtmosphereShadowing>& shadowing,
                                const AtmosphereRayOptions& options, int threads = 0);

// --- Disk cache ------------------------------------------------------------------------------------------

/// Hex digest of every field of (p, o) that changes the tables (not threads, keepOrders).
std::string atmosphereCacheKey(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o);

/// Writes every table to `path` (checksummed binary; format: atmosphere/src/cache.cpp). Throws IoError.
void saveAtmosphereTables(const AtmosphereTables& tables, const std::filesystem::path& path);
/// Reads `path`; IoError naming the file when missing, truncated or corrupt (magic, version, checksum).
AtmosphereTables loadAtmosphereTables(const std::filesystem::path& path);

/// Loads `directory`/atmosphere-<key>.bin if valid for (p, o), else computes, saves and returns; a corrupt
/// or mismatching file goes to `warn` (naming the file and why) and is recomputed, never used.
AtmosphereTables cachedAtmosphereTables(const std::filesystem::path& directory, const AtmosphereParameters& p,
                                        const AtmospherePrecomputeOptions& o,
                                        const std::function<AtmosphereTables()>& compute,
                                        const std::function<void(const std::string&)>& warn);

} // namespace crep
