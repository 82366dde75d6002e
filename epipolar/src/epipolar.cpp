// The epipolar fallback layout (crep/epipolar/epipolar.h): Klehm et al. 2014 Sec. 4.1 (angles to the
// light, per-slice bounds of the angle and of the distance along the reference ray), slices through the
// screen border in the order of Yusov 2012 (Sec. 6.1 exit points, Sec. 6.6 sectors).
#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/epipolar/epipolar.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace crep {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Floor of sin(psi) in distances: a ray along the light axis gets a huge finite step (a valid profile).
constexpr double kMinSinPsi = 1e-12;

std::string vecString(const glm::dvec3& v) {
  return "(" + detail::formatValue(v.x) + ", " + detail::formatValue(v.y) + ", " + detail::formatValue(v.z) +
         ")";
}

/// Intersects [lo, hi] (within [0, pi]) with {psi : A cos psi + B sin psi <= 0}, a closed half-circle
/// centred at atan2(B, A) + pi.
void clipHalfCircle(double A, double B, double& lo, double& hi) {
  if (A == 0.0 && B == 0.0) return;
  const double mid = 0.5 * (lo + hi);
  double centre = std::atan2(B, A) + kPi;
  centre -= 2.0 * kPi * std::round((centre - mid) / (2.0 * kPi));
  lo = std::max(lo, centre - 0.5 * kPi);
  hi = std::min(hi, centre + 0.5 * kPi);
}

} // namespace

void validate(const EpipolarOptions& o) {
  if (o.slices < 0 || o.slices > kMaxEpipolarSlices)
    throw InvalidArgument("EpipolarOptions.slices", detail::formatValue(o.slices),
                          "must be 0 (automatic) or in [1, " + std::to_string(kMaxEpipolarSlices) + "]");
  requirePositive("EpipolarOptions.slicesPerBorderPixel", o.slicesPerBorderPixel);
  if (o.regions < 1 || o.regions > RectifyOptions::kMaxSplits)
    throw InvalidArgument("EpipolarOptions.regions", detail::formatValue(o.regions),
                          "must be in [1, " + std::to_string(RectifyOptions::kMaxSplits) + "]");
  if (o.regionScheme == SplitScheme::Blend)
    throw InvalidArgument("EpipolarOptions.regionScheme", "Blend", "must be Uniform or Logarithmic");
  requireNonNegative("EpipolarOptions.epipoleBlockRadius", o.epipoleBlockRadius);
  if (o.maxBlockPixels < 0)
    throw InvalidArgument("EpipolarOptions.maxBlockPixels", std::to_string(o.maxBlockPixels), "must be >= 0");
  requireNonNegative("EpipolarOptions.depthWarp", o.depthWarp);
}

// Sec. 4.1 (Baran-style epipolar coordinates) with Yusov Sec. 6.1: epipole, exit sides, border arc, slice
// count.
EpipolarLayout::EpipolarLayout(const Camera& camera, const DirectionalLight& light, int screenWidth,
                               int screenHeight, const EpipolarOptions& options)
    : camera_(camera), l_(light.direction()), m_(-light.direction()), width_(screenWidth),
      height_(screenHeight), options_(options) {
  init();
}

// Sec. 3.2 "Local Lights" on the Sec. 4.1 layout: the axis through the camera and the light.
EpipolarLayout::EpipolarLayout(const Camera& camera, const glm::dvec3& lightPosition, int screenWidth,
                               int screenHeight, const EpipolarOptions& options)
    : camera_(camera), width_(screenWidth), height_(screenHeight), options_(options) {
  const glm::dvec3 toLight = lightPosition - camera.position();
  const double D = glm::length(toLight);
  if (!std::isfinite(D) || !(D > 1e-9))
    throw InvalidArgument("EpipolarLayout.lightPosition", vecString(lightPosition),
                          "must be finite and differ from the camera position");
  if (options.regions < 2)
    throw InvalidArgument("EpipolarOptions.regions", detail::formatValue(options.regions),
                          "must be >= 2 for a local light (no region may span more than pi / 2)");
  lightDistance_ = D;
  m_ = toLight / D;
  l_ = -m_;
  init();
}

void EpipolarLayout::init() {
  const int screenWidth = width_, screenHeight = height_;
  const Camera& camera = camera_;
  const EpipolarOptions& options = options_;
  if (screenWidth <= 0 || screenHeight <= 0 || screenWidth > Image::kMaxDimension ||
      screenHeight > Image::kMaxDimension)
    throw InvalidArgument("EpipolarLayout.screenSize",
                          std::to_string(screenWidth) + " x " + std::to_string(screenHeight),
                          "must be in [1, " + std::to_string(Image::kMaxDimension) + "] per side");
  validate(options);
  tanY_ = std::tan(0.5 * camera.fovY());
  tanX_ = tanY_ * camera.aspect();

  // The epipole: the image of the light axis, from the side of it that is in front (V.z >= 0).
  const glm::dvec3 hm = image(m_);
  vanishing_ = hm.z >= 0.0 ? hm : -hm;
  kind_ = hm.z > 0.0 ? EpipoleKind::Epipole : hm.z < 0.0 ? EpipoleKind::AntiEpipole : EpipoleKind::AtInfinity;
  exitAtHigh_ = hm.z >= 0.0;
  if (vanishing_.z > 0.0) epipoleNdc_ = glm::dvec2(vanishing_) / vanishing_.z;

  // Exit sides: rays from the epipole leave the screen through the sides whose inner half-plane holds it.
  const glm::dvec3& V = vanishing_;
  const bool exits[4] = {V.x > -V.z, V.y > -V.z, V.x < V.z, V.y < V.z}; // left, bottom, right, top
  const double side[4] = {static_cast<double>(height_), static_cast<double>(width_),
                          static_cast<double>(height_), static_cast<double>(width_)};
  const double sideBegin[4] = {0.0, side[0], side[0] + side[1], side[0] + side[1] + side[2]};
  exitSides_ = 0;
  for (int s = 0; s < 4; ++s)
    exitSides_ |= exits[s] ? 1 << s : 0;
  if (exitSides_ == 15 || exitSides_ == 0) {
    // All four (epipole on screen), or none (only for a degenerate V): the whole border from the corner.
    arcBegin_ = 0.0;
    arcLength_ = perimeter();
    exitSides_ = 15;
  } else {
    int first = 0;
    while (!(exits[first] && !exits[(first + 3) % 4]))
      ++first;
    arcBegin_ = sideBegin[first];
    arcLength_ = 0.0;
    for (int s = first; exits[s % 4] && s < first + 4; ++s)
      arcLength_ += side[s % 4];
  }
  const int H = options.slices > 0
                    ? options.slices
                    : static_cast<int>(std::ceil(arcLength_ * options.slicesPerBorderPixel - 1e-9));
  if (H < 1 || H > kMaxEpipolarSlices)
    throw InvalidArgument(
        "EpipolarOptions.slicesPerBorderPixel", detail::formatValue(options.slicesPerBorderPixel),
        "gives " + std::to_string(H) + " slices; must give [1, " + std::to_string(kMaxEpipolarSlices) + "]");
  slices_.resize(static_cast<std::size_t>(H));
  buildSlices();
  const int K = options.regions;
  fractions_.assign(static_cast<std::size_t>(K) + 1, 1.0);
  fractions_[0] = 0.0;
  const double ratio = std::min(camera.near() / camera.far(), 0.5);
  for (int k = 1; k < K; ++k)
    fractions_[static_cast<std::size_t>(k)] = options.regionScheme == SplitScheme::Uniform
                                                  ? static_cast<double>(k) / K
                                                  : std::pow(ratio, 1.0 - static_cast<double>(k) / K);
  // A local light's regions span at most half of [0, thetaMax] <= pi / 2 (tan of the half width <= 1).
  if (localLight())
    for (int k = K - 1; k >= 1; --k)
      fractions_[static_cast<std::size_t>(k)] = std::max(fractions_[static_cast<std::size_t>(k)],
                                                         fractions_[static_cast<std::size_t>(k) + 1] - 0.5);
}

glm::dvec3 EpipolarLayout::image(const glm::dvec3& w) const {
  return {glm::dot(w, camera_.right()) / tanX_, glm::dot(w, camera_.up()) / tanY_,
          glm::dot(w, camera_.forward())};
}

bool EpipolarLayout::epipoleOnScreen() const noexcept {
  return kind_ != EpipoleKind::AtInfinity && std::abs(epipoleNdc_.x) <= 1.0 && std::abs(epipoleNdc_.y) <= 1.0;
}

std::optional<glm::dvec2> EpipolarLayout::epipolePixel() const {
  if (kind_ == EpipoleKind::AtInfinity || !(vanishing_.z > 0.0)) return std::nullopt;
  glm::dvec2 ndc = epipoleNdc_; // of the symmetric frustum covering the camera's (its slices' screen)
  if (!camera_.symmetric()) {
    // The camera's own (off-centre) image: tangent X = ndc.x tanX, ndc' = (X - centre) / half-width.
    const glm::dvec4& t = camera_.tangents();
    ndc = glm::dvec2((ndc.x * tanX_ - 0.5 * (t.x + t.y)) / (0.5 * (t.y - t.x)),
                     (ndc.y * tanY_ - 0.5 * (t.z + t.w)) / (0.5 * (t.w - t.z)));
  }
  return glm::dvec2((ndc.x + 1.0) * 0.5 * width_, (ndc.y + 1.0) * 0.5 * height_);
}

long long EpipolarLayout::blockPixelCount(double radius) const {
  const auto e = epipolePixel();
  if (!e || !(radius >= 0.0) || !std::isfinite(e->x) || !std::isfinite(e->y)) return 0;
  // Per pixel row, the pixel centres x + 0.5 in [ex - dx, ex + dx], dx = sqrt(r^2 - dy^2), within [0, w).
  long long n = 0;
  const int y0 = std::max(0, static_cast<int>(std::floor(e->y - radius - 1.0)));
  const int y1 = std::min(height_ - 1, static_cast<int>(std::ceil(e->y + radius + 1.0)));
  for (int y = y0; y <= y1; ++y) {
    const double dy = y + 0.5 - e->y, h2 = radius * radius - dy * dy;
    if (h2 < 0.0) continue;
    const double dx = std::sqrt(h2);
    const int x0 = std::max(0, static_cast<int>(std::ceil(e->x - dx - 0.5)));
    const int x1 = std::min(width_ - 1, static_cast<int>(std::floor(e->x + dx - 0.5)));
    if (x1 >= x0) n += x1 - x0 + 1;
  }
  return n;
}

double EpipolarLayout::epipoleBlockRadiusPixels() const {
  const double r = options_.epipoleBlockRadius *
                   std::sqrt(static_cast<double>(width_) * width_ + static_cast<double>(height_) * height_);
  const long long cap = options_.maxBlockPixels;
  if (cap <= 0 || !(r > 0.0) || blockPixelCount(r) <= cap) return r;
  // The count grows with the radius: bisect for the largest radius that holds at most `cap` pixels.
  double lo = 0.0, hi = r;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (blockPixelCount(mid) <= cap ? lo : hi) = mid;
  }
  return lo;
}

std::vector<int> EpipolarLayout::epipoleBlockPixels() const {
  std::vector<int> out;
  const auto e = epipolePixel();
  const double r = epipoleBlockRadiusPixels();
  if (!e || !(r > 0.0) || !std::isfinite(e->x) || !std::isfinite(e->y)) return out;
  const int y0 = std::max(0, static_cast<int>(std::floor(e->y - r - 1.0)));
  const int y1 = std::min(height_ - 1, static_cast<int>(std::ceil(e->y + r + 1.0)));
  const int x0 = std::max(0, static_cast<int>(std::floor(e->x - r - 1.0)));
  const int x1 = std::min(width_ - 1, static_cast<int>(std::ceil(e->x + r + 1.0)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (glm::length(glm::dvec2(x + 0.5, y + 0.5) - *e) <= r) out.push_back(y * width_ + x);
  return out;
}

// ---------------------------------------------------------------------------------------------------
// Border parameterization (Yusov's order, in pixels)

glm::dvec2 EpipolarLayout::borderPoint(double sigma) const {
  const double P = perimeter(), w = width_, h = height_;
  double s = std::fmod(sigma, P);
  if (s < 0.0) s += P;
  if (s < h) return {-1.0, 1.0 - 2.0 * s / h};
  s -= h;
  if (s < w) return {-1.0 + 2.0 * s / w, -1.0};
  s -= w;
  if (s < h) return {1.0, -1.0 + 2.0 * s / h};
  s -= h;
  return {1.0 - 2.0 * std::min(s, w) / w, 1.0};
}

double EpipolarLayout::borderSigma(const glm::dvec2& ndc) const {
  const double w = width_, h = height_;
  const double x = std::clamp(ndc.x, -1.0, 1.0), y = std::clamp(ndc.y, -1.0, 1.0);
  if (std::abs(x) >= std::abs(y)) {
    if (x < 0.0) return 0.5 * (1.0 - y) * h; // left, top to bottom
    return h + w + 0.5 * (y + 1.0) * h;      // right, bottom to top
  }
  if (y < 0.0) return h + 0.5 * (x + 1.0) * w; // bottom, left to right
  return 2.0 * h + w + 0.5 * (1.0 - x) * w;    // top, right to left
}

double EpipolarLayout::rowSigma(double row) const {
  return arcBegin_ + row * arcLength_;
}

double EpipolarLayout::rowOfSigma(double sigma) const {
  const double P = perimeter();
  double d = sigma - arcBegin_;
  if (arcLength_ >= P) {
    d = std::fmod(d, P);
    if (d < 0.0) d += P;
    return d / P;
  }
  // Outside the arc (rounding next to its ends): the nearer end.
  const double gap = P - arcLength_;
  d = std::fmod(d + 0.5 * gap, P);
  if (d < 0.0) d += P;
  return std::clamp((d - 0.5 * gap) / arcLength_, 0.0, 1.0);
}

glm::dvec3 EpipolarLayout::borderDirection(double sigma) const {
  const glm::dvec2 p = borderPoint(sigma);
  return glm::normalize(camera_.forward() + p.x * tanX_ * camera_.right() + p.y * tanY_ * camera_.up());
}

int EpipolarLayout::sliceIndex(double row) const {
  const int H = sliceCount();
  if (!(row == row)) return 0;
  return std::clamp(static_cast<int>(std::floor(std::clamp(row, -1.0, 2.0) * H)), 0, H - 1);
}

glm::dvec3 EpipolarLayout::sliceDirection(double row) const {
  const glm::dvec3 w = borderDirection(rowSigma(row));
  const glm::dvec3 q = w - glm::dot(w, m_) * m_;
  const double len = glm::length(q);
  return len > 0.0 ? q / len : anyOrthogonal(m_);
}

double EpipolarLayout::columnFraction(double column) const {
  const int K = regionCount();
  const int k = std::clamp(static_cast<int>(std::floor(column * K)), 0, K - 1);
  const double f0 = fractions_[static_cast<std::size_t>(k)], f1 = fractions_[static_cast<std::size_t>(k) + 1];
  return f0 + (column * K - k) * (f1 - f0);
}

double EpipolarLayout::fractionColumn(double fraction) const {
  const int K = regionCount();
  int k = 0;
  while (k < K - 1 && fraction >= fractions_[static_cast<std::size_t>(k) + 1])
    ++k;
  const double f0 = fractions_[static_cast<std::size_t>(k)], f1 = fractions_[static_cast<std::size_t>(k) + 1];
  return (k + (fraction - f0) / (f1 - f0)) / K;
}

double EpipolarLayout::warp(double psi) const {
  const double e = options_.depthWarp;
  return e > 0.0 ? std::log((psi + e) / (kPi - psi + e)) : psi;
}

double EpipolarLayout::unwarp(double g) const {
  const double e = options_.depthWarp;
  if (!(e > 0.0)) return g;
  const double r = std::exp(g);
  return std::clamp((r * (kPi + e) - e) / (1.0 + r), 0.0, kPi);
}

double EpipolarLayout::psi(int slice, double depth) const {
  const Slice& s = slices_[static_cast<std::size_t>(std::clamp(slice, 0, sliceCount() - 1))];
  const double g0 = warp(s.psiMin), g1 = warp(s.psiMax);
  return unwarp(g0 + depth * (g1 - g0));
}

double EpipolarLayout::depthOfPsi(int slice, double psiValue) const {
  const Slice& s = slices_[static_cast<std::size_t>(std::clamp(slice, 0, sliceCount() - 1))];
  const double g0 = warp(s.psiMin), g1 = warp(s.psiMax);
  return (warp(psiValue) - g0) / (g1 - g0);
}

// ---------------------------------------------------------------------------------------------------
// Half-planes

// Yusov Sec. 6.1 / 6.6: the entry and exit points of an epipolar line, here as the visible psi interval of
// the slice's half-plane (exact in 3D, also for an epipole behind the camera or at infinity).
std::optional<EpipolarLayout::HalfPlaneView> EpipolarLayout::viewOfHalfPlane(const glm::dvec3& n) const {
  // Directions of the half-plane: w(psi) = cos(psi) m + sin(psi) n, psi in [0, pi]; its image point is
  // H(psi) = cos(psi) hm + sin(psi) hn. On screen: |H.x| <= H.z, |H.y| <= H.z (which implies H.z >= 0).
  const glm::dvec3 hm = image(m_), hn = image(n);
  double lo = 0.0, hi = kPi;
  clipHalfCircle(hm.x - hm.z, hn.x - hn.z, lo, hi);   // x <= 1
  clipHalfCircle(-hm.x - hm.z, -hn.x - hn.z, lo, hi); // x >= -1
  clipHalfCircle(hm.y - hm.z, hn.y - hn.z, lo, hi);   // y <= 1
  clipHalfCircle(-hm.y - hm.z, -hn.y - hn.z, lo, hi); // y >= -1
  if (!(lo <= hi)) return std::nullopt;
  const double psiExit = exitAtHigh_ ? hi : lo;
  const glm::dvec3 H = std::cos(psiExit) * hm + std::sin(psiExit) * hn;
  if (!(H.z > 0.0)) return std::nullopt;
  return HalfPlaneView{lo, hi, borderSigma(glm::dvec2(H) / H.z)};
}

// Sec. 4.1 bounds: z (psi) from the limiting view rays of each slice row, x (b) from the far-plane points of
// its limiting rays (and the screen corners inside it).
void EpipolarLayout::buildSlices() {
  const int H = sliceCount();
  const double far = camera_.far();
  const glm::dvec3 F = camera_.forward();
  for (auto& s : slices_) {
    s.bMax = 0.0;
    s.psiMin = kInf;
    s.psiMax = -kInf;
  }
  // Includes the view ray of angle psi in the half-plane n into slice j's bounds.
  // The far-plane point of the view ray of angle psi in the half-plane n: b (directional) or theta (local).
  const auto includeFar = [&](Slice& s, const glm::dvec3& n, double psiValue) {
    const glm::dvec3 w = std::cos(psiValue) * m_ + std::sin(psiValue) * n;
    const double cosF = glm::dot(w, F);
    if (!(cosF > 0.0)) return;
    const double t = far / cosF;
    if (localLight())
      s.thetaMax = std::max(s.thetaMax, thetaOf(t * w));
    else
      s.bMax = std::max(s.bMax, t * std::sin(psiValue));
  };
  const auto include = [&](int j, const glm::dvec3& n, double psiValue) {
    Slice& s = slices_[static_cast<std::size_t>(j)];
    s.psiMin = std::min(s.psiMin, psiValue);
    s.psiMax = std::max(s.psiMax, psiValue);
    includeFar(s, n, psiValue);
  };
  const auto includeSlice = [&](int j, double row) {
    const glm::dvec3 n = sliceDirection(row);
    if (const auto view = viewOfHalfPlane(n)) {
      include(j, n, view->psiLo);
      include(j, n, view->psiHi);
      // theta is not convex on the far plane: its largest value on the sector can lie inside an edge.
      if (localLight())
        for (int i = 1; i < 16; ++i)
          includeFar(slices_[static_cast<std::size_t>(j)], n,
                     view->psiLo + (view->psiHi - view->psiLo) * i / 16.0);
    }
  };
  for (int j = 0; j < H; ++j) {
    includeSlice(j, static_cast<double>(j) / H);
    includeSlice(j, (j + 0.5) / H);
    includeSlice(j, static_cast<double>(j + 1) / H);
    slices_[static_cast<std::size_t>(j)].direction = sliceDirection((j + 0.5) / H);
  }
  // Screen corners inside a slice row's sector are vertices of it too.
  for (const glm::dvec2 corner :
       {glm::dvec2(-1, -1), glm::dvec2(1, -1), glm::dvec2(1, 1), glm::dvec2(-1, 1)}) {
    const glm::dvec3 w =
        glm::normalize(F + corner.x * tanX_ * camera_.right() + corner.y * tanY_ * camera_.up());
    const glm::dvec3 q = w - glm::dot(w, m_) * m_;
    const double b = glm::length(q);
    if (!(b > 1e-12)) continue;
    const glm::dvec3 n = q / b;
    if (const auto view = viewOfHalfPlane(n))
      include(sliceIndex(rowOfSigma(view->exitSigma)), n, std::atan2(b, glm::dot(w, m_)));
  }
  for (auto& s : slices_) {
    if (!(s.psiMin <=
          s.psiMax)) { // no visible ray (cannot happen for a row of the exit arc): a harmless default
      s.psiMin = 0.0;
      s.psiMax = kPi;
    }
    // Degenerate ranges would make the depth undefined; keep a tiny one.
    const double minRange = 1e-9;
    if (s.psiMax - s.psiMin < minRange) {
      const double c = 0.5 * (s.psiMin + s.psiMax);
      s.psiMin = std::max(0.0, c - minRange);
      s.psiMax = std::min(kPi, s.psiMin + 2.0 * minRange);
    }
    s.bMax = s.bMax > 0.0 ? s.bMax * (1.0 + 1e-12) : far * 1e-9;
    // Local light: a margin for the sector between the sampled rays, at most pi (the axis beyond L).
    if (localLight()) s.thetaMax = s.thetaMax > 0.0 ? std::min(kPi, s.thetaMax * 1.01) : 1e-6;
  }
}

// ---------------------------------------------------------------------------------------------------
// Local lights (see the header, "Local lights")

double EpipolarLayout::thetaOf(const glm::dvec3& q) const {
  const double a = glm::dot(q, m_);
  return std::atan2(glm::length(q - a * m_), lightDistance_ - a);
}

glm::dvec2 EpipolarLayout::regionAngles(int slice, int region) const {
  const double thetaMax = slices_[static_cast<std::size_t>(std::clamp(slice, 0, sliceCount() - 1))].thetaMax;
  const double t0 = fractions_[static_cast<std::size_t>(region)] * thetaMax,
               t1 = fractions_[static_cast<std::size_t>(region) + 1] * thetaMax;
  return {0.5 * (t0 + t1), std::tan(0.5 * (t1 - t0))};
}

double EpipolarLayout::columnTheta(int slice, double column) const {
  const int K = regionCount();
  const int k = std::clamp(static_cast<int>(std::floor(column * K)), 0, K - 1);
  const glm::dvec2 angles = regionAngles(slice, k);
  return angles.x + std::atan((2.0 * (column * K - k) - 1.0) * angles.y);
}

double EpipolarLayout::thetaColumn(int slice, double theta, int& region, double& u) const {
  const double thetaMax = slices_[static_cast<std::size_t>(std::clamp(slice, 0, sliceCount() - 1))].thetaMax;
  const double fraction = theta / thetaMax;
  const int K = regionCount();
  int k = 0;
  while (k < K - 1 && fraction >= fractions_[static_cast<std::size_t>(k) + 1])
    ++k;
  const glm::dvec2 angles = regionAngles(slice, k);
  region = k;
  u = 0.5 * (std::tan(theta - angles.x) / angles.y + 1.0);
  return (k + u) / K;
}

// ---------------------------------------------------------------------------------------------------
// RectifiedLayout

// Sec. 4.1 mapping: y = slice (by its exit point), x = distance along the reference ray (b), z = angle to the
// light.
RectPoint EpipolarLayout::toRectified(const glm::dvec3& world) const {
  const glm::dvec3 q = world - camera_.position();
  const double a = glm::dot(q, m_);
  const glm::dvec3 perp = q - a * m_;
  const double b = glm::length(perp);
  if (!std::isfinite(a) || !std::isfinite(b))
    throw InvalidArgument("EpipolarLayout.toRectified.world", vecString(world), "must be finite");
  if (!(b > 0.0))
    throw InvalidArgument("EpipolarLayout.toRectified.world", vecString(world),
                          "lies on the light axis through the camera (no slice)");
  const glm::dvec3 n = perp / b;
  const auto view = viewOfHalfPlane(n);
  if (!view)
    throw InvalidArgument("EpipolarLayout.toRectified.world", vecString(world),
                          "its epipolar half-plane is not on screen (no slice)");
  RectPoint p;
  p.row = rowOfSigma(view->exitSigma);
  p.depth = depthOfPsi(sliceIndex(p.row), std::atan2(b, a));
  if (localLight()) {
    p.column = thetaColumn(sliceIndex(p.row), std::atan2(b, lightDistance_ - a), p.split, p.splitColumn);
    return p;
  }
  const double fraction = b / slices_[static_cast<std::size_t>(sliceIndex(p.row))].bMax;
  const int K = regionCount();
  int k = 0;
  while (k < K - 1 && fraction >= fractions_[static_cast<std::size_t>(k) + 1])
    ++k;
  const double f0 = fractions_[static_cast<std::size_t>(k)], f1 = fractions_[static_cast<std::size_t>(k) + 1];
  p.split = k;
  p.splitColumn = (fraction - f0) / (f1 - f0);
  p.column = (k + p.splitColumn) / K;
  return p;
}

LightRay EpipolarLayout::lightRay(double column, double row) const {
  if (!std::isfinite(column) || !std::isfinite(row))
    throw InvalidArgument("EpipolarLayout.lightRay",
                          "column " + detail::formatValue(column) + ", row " + detail::formatValue(row),
                          "must be finite");
  const Slice& s = slices_[static_cast<std::size_t>(sliceIndex(row))];
  if (localLight()) {
    const double theta = columnTheta(sliceIndex(row), column);
    return {lightPosition(), -std::cos(theta) * m_ + std::sin(theta) * sliceDirection(row)};
  }
  return {camera_.position() + columnFraction(column) * s.bMax * sliceDirection(row), l_};
}

glm::dvec3 EpipolarLayout::viewRayDirection(double row, double depth) const {
  const double angle = psi(sliceIndex(row), depth);
  return std::cos(angle) * m_ + std::sin(angle) * sliceDirection(row);
}

double EpipolarLayout::rayDistance(double row, double depth, double column) const {
  const int j = sliceIndex(row);
  if (localLight()) {
    // The law of sines in the triangle (camera, light, point).
    const double theta = columnTheta(j, column), s = std::sin(psi(j, depth) + theta);
    return s > 0.0 ? lightDistance_ * std::sin(theta) / s : kInf;
  }
  // A ray along the light axis (sin(psi) = 0) never leaves column 0: the same huge finite step as
  // rayProfile() keeps the two consistent.
  const double sinPsi = std::max(std::sin(psi(j, depth)), kMinSinPsi);
  return columnFraction(column) * slices_[static_cast<std::size_t>(j)].bMax / sinPsi;
}

// Sec. 3.2: the row's reference ray (bisectrix, or the optimal k_ref = sqrt(k_min k_max)).
double EpipolarLayout::referenceDepth(double row) const {
  const Slice& s = slices_[static_cast<std::size_t>(sliceIndex(row))];
  // k = sin(psi) (Sec. 3.2: the cosine to the slice's direction orthogonal to the light); the ray's world
  // step per column is proportional to 1 / k. psiA: largest k (smallest step), psiB: smallest k.
  const double halfPi = 0.5 * kPi;
  const double psiA = std::clamp(halfPi, s.psiMin, s.psiMax);
  const double psiB = std::abs(s.psiMin - halfPi) > std::abs(s.psiMax - halfPi) ? s.psiMin : s.psiMax;
  double psiRef = 0.5 * (psiA + psiB);
  if (options_.referenceRay == ReferenceRay::Optimal) {
    const double kMin = std::sin(psiB), kMax = std::sin(psiA);
    if (kMin > 0.0) {
      const double k = std::sqrt(kMin * kMax);
      // The ray between psiA and psiB with sin(psi) = k.
      psiRef = psiB < halfPi ? std::asin(std::min(1.0, k)) : kPi - std::asin(std::min(1.0, k));
    }
  }
  return depthOfPsi(sliceIndex(row), psiRef);
}

double EpipolarLayout::referenceDistance(double row, double column) const {
  return rayDistance(row, referenceDepth(row), column);
}

// Sec. 3.2 / Eq. 11: distances along a ray are linear in the column inside a region (constant step).
DistanceProfile EpipolarLayout::rayProfile(double row, double depth, int region) const {
  const int K = regionCount();
  if (region < 0 || region >= K)
    throw InvalidArgument("EpipolarLayout.region", detail::formatValue(region),
                          "must be in [0, " + std::to_string(K) + ")");
  if (!std::isfinite(row) || !std::isfinite(depth))
    throw InvalidArgument("EpipolarLayout.rayProfile",
                          "row " + detail::formatValue(row) + ", depth " + detail::formatValue(depth),
                          "must be finite");
  const int j = sliceIndex(row);
  if (localLight()) {
    // t = D (sin mu + cos mu tau) / (sin(psi + mu) + cos(psi + mu) tau), tau = (2 u - 1) tan h.
    const glm::dvec2 angles = regionAngles(j, region);
    const double mu = angles.x, T = angles.y, D = lightDistance_, pm = psi(j, depth) + mu;
    return {D * (std::sin(mu) - T * std::cos(mu)), 2.0 * D * T * std::cos(mu),
            std::sin(pm) - T * std::cos(pm), 2.0 * T * std::cos(pm)};
  }
  const double sinPsi = std::max(std::sin(psi(j, depth)), kMinSinPsi);
  const double scale = slices_[static_cast<std::size_t>(j)].bMax / sinPsi;
  const double f0 = fractions_[static_cast<std::size_t>(region)],
               f1 = fractions_[static_cast<std::size_t>(region) + 1];
  return {f0 * scale, (f1 - f0) * scale, 1.0, 0.0};
}

DistanceProfile EpipolarLayout::referenceProfile(double row, int region) const {
  return rayProfile(row, regionReferenceDepth(row, region), region);
}

double EpipolarLayout::regionReferenceDepth(double row, int region) const {
  const double reference = referenceDepth(row);
  if (!localLight()) return reference;
  const int j = sliceIndex(row);
  const Slice& s = slices_[static_cast<std::size_t>(j)];
  const double end = fractions_[static_cast<std::size_t>(std::clamp(region, 0, regionCount() - 1)) + 1] *
                     s.thetaMax,
               psiRef = psi(j, reference);
  if (psiRef <= 0.75 * (kPi - end)) return reference;
  const double chosen = std::clamp(0.5 * (kPi - end), std::max(s.psiMin, std::min(1e-3, s.psiMax)), s.psiMax);
  return depthOfPsi(j, chosen);
}

} // namespace crep
