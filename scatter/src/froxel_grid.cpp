// The froxel volume's coordinates (Wronski 2014: frustum-aligned cells, exponential depth slices).
#include <crep/scatter/froxel_grid.h>

#include <crep/core/error.h>

#include <cmath>
#include <limits>
#include <string>

namespace crep {

namespace {

std::string field(const char* owner, const char* name) {
  return std::string(owner) + ".grid." + name;
}

void requireCells(const char* owner, const char* name, int value) {
  if (value < 1 || value > 2048)
    throw InvalidArgument(field(owner, name), detail::formatValue(value), "cells, must be in [1, 2048]");
}

void requireDepth(const char* owner, const char* name, double value) {
  if (!std::isfinite(value) || value < 0.0)
    throw InvalidArgument(field(owner, name), detail::formatValue(value),
                          "world units, must be finite and >= 0 (0 = the camera's)");
}

/// Radical inverse of i in `base` (the Halton sequence's element i).
double radicalInverse(int i, int base) {
  double result = 0.0, f = 1.0 / base;
  for (; i > 0; i /= base, f /= base)
    result += f * (i % base);
  return result;
}

} // namespace

void validate(const FroxelGrid& grid, const char* owner) {
  requireCells(owner, "width", grid.width);
  requireCells(owner, "height", grid.height);
  requireCells(owner, "depth", grid.depth);
  requireDepth(owner, "nearDepth", grid.nearDepth);
  requireDepth(owner, "farDepth", grid.farDepth);
  if (grid.nearDepth > 0.0 && grid.farDepth > 0.0 && grid.farDepth <= grid.nearDepth)
    throw InvalidArgument(field(owner, "farDepth"), detail::formatValue(grid.farDepth),
                          "must be > nearDepth (" + detail::formatValue(grid.nearDepth) + ")");
}

FroxelDepthRange froxelDepthRange(const FroxelGrid& grid, const Camera& camera, const char* owner) {
  FroxelDepthRange r;
  r.near = grid.nearDepth > 0.0 ? grid.nearDepth : camera.near();
  r.far = grid.farDepth > 0.0 ? grid.farDepth : camera.far();
  if (!(r.far > r.near))
    throw InvalidArgument(field(owner, "farDepth"), detail::formatValue(r.far),
                          "must be > the volume's near depth " + detail::formatValue(r.near) +
                              " (0 = the camera's far(); nearDepth 0 = the camera's near())");
  return r;
}

// Wronski 2014, exponential depth distribution: Z = near (far / near)^w.
double froxelSliceCoord(const FroxelDepthRange& range, double viewDepth) {
  if (!(viewDepth > 0.0)) return -std::numeric_limits<double>::infinity();
  return std::log(viewDepth / range.near) / std::log(range.far / range.near);
}

double froxelViewDepth(const FroxelDepthRange& range, double sliceCoord) {
  return range.near * std::pow(range.far / range.near, sliceCoord);
}

double froxelRayDistance(const Camera& camera, const glm::dvec3& uvw, double viewDepth) {
  const glm::dvec3 ray = camera.rayDirection(2.0 * uvw.x - 1.0, 2.0 * uvw.y - 1.0);
  return viewDepth / glm::dot(ray, camera.forward());
}

glm::dvec3 froxelWorldPoint(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& uvw) {
  const glm::dvec3 ray = camera.rayDirection(2.0 * uvw.x - 1.0, 2.0 * uvw.y - 1.0);
  const double z = froxelViewDepth(range, uvw.z);
  return camera.position() + ray * (z / glm::dot(ray, camera.forward()));
}

glm::dvec3 froxelCoord(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& world) {
  const glm::dvec3 d = world - camera.position();
  const double z = glm::dot(d, camera.forward());
  if (!(z > 0.0)) return glm::dvec3(0.0, 0.0, -std::numeric_limits<double>::infinity());
  const glm::dvec4& t = camera.tangents();
  const double cx = 0.5 * (t.x + t.y), hx = 0.5 * (t.y - t.x);
  const double cy = 0.5 * (t.z + t.w), hy = 0.5 * (t.w - t.z);
  const double ndcX = (glm::dot(d, camera.right()) / z - cx) / hx;
  const double ndcY = (glm::dot(d, camera.up()) / z - cy) / hy;
  return {0.5 * (ndcX + 1.0), 0.5 * (ndcY + 1.0), froxelSliceCoord(range, z)};
}

glm::dvec3 froxelJitter(int frameIndex) {
  const int i = (frameIndex % 1024 + 1024) % 1024 + 1;
  return glm::dvec3(radicalInverse(i, 2), radicalInverse(i, 3), radicalInverse(i, 5)) - 0.5;
}

} // namespace crep
