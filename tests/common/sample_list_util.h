// GPU work lists (crep/scatter/gpu_sample_list.h) filled from the CPU for the tests of their consumers
// (tests/epipolar/MarchListGLTest.cpp, tests/prefilter/EvaluateListGLTest.cpp): coordinates uploaded, the
// buffer's header and entries written, the output cleared to NaN (an unwritten texel stays NaN); and the
// comparisons of a list's output against the per-pixel pass's, bit for bit. GL tests only (needs a context).
#pragma once

#include "common/analytic_reference.h"

#include <crep/core/image.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/gpu_sample_list.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

namespace crep::test {

/// A work list and the textures it names (owned here).
struct TestList {
  gl::Handle buffer, coordinates, output;
  gpu::SampleList list;
};

/// A work list whose coordinates texture is width x height (x, y, d, z per texel, `coordinates`) and whose
/// entries are `texels`, written from the CPU: header (ceil(count / 64), 1, 1, count), then x | y << 16
/// per entry; the output starts as NaN.
inline TestList makeTestList(int width, int height, const std::vector<float>& coordinates,
                             const std::vector<glm::ivec2>& texels) {
  TestList t;
  t.buffer = gpu::createSampleListBuffer(width * height);
  t.coordinates = gl::createTexture2D(GL_RGBA32F, width, height);
  glTextureSubImage2D(t.coordinates.get(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, coordinates.data());
  t.output = gl::createTexture2D(GL_RGBA32F, width, height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float fill[4] = {nan, nan, nan, nan};
  glClearTexImage(t.output.get(), 0, GL_RGBA, GL_FLOAT, fill);
  const auto count = static_cast<std::uint32_t>(texels.size());
  std::vector<std::uint32_t> data{(count + 63) / 64, 1, 1, count};
  for (const glm::ivec2& p : texels)
    data.push_back(static_cast<std::uint32_t>(p.x) | (static_cast<std::uint32_t>(p.y) << 16));
  glNamedBufferSubData(t.buffer.get(), 0, static_cast<GLsizeiptr>(data.size() * 4), data.data());
  t.list = {t.buffer.get(), t.coordinates.get(), t.output.get(), width, height, width * height};
  return t;
}

/// The coordinates of every pixel centre of a camera depth image (z: not read by the passes, 0 here).
inline std::vector<float> pixelCoordinates(const Image& depth) {
  std::vector<float> c;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      c.insert(c.end(), {x + 0.5f, y + 0.5f, depth.at(x, y), 0.0f});
  return c;
}

/// A work list over the pixel centres of a camera depth image (its size, pixelCoordinates) with entries
/// `texels`.
inline TestList makePixelList(const Image& depth, const std::vector<glm::ivec2>& texels) {
  return makeTestList(depth.width(), depth.height(), pixelCoordinates(depth), texels);
}

/// The texels (x, y) of a width x height image for which `keep` holds (row by row; all by default).
inline std::vector<glm::ivec2> texelsWhere(int width, int height,
                                           const std::function<bool(int, int)>& keep = {}) {
  std::vector<glm::ivec2> texels;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (!keep || keep(x, y)) texels.push_back({x, y});
  return texels;
}

inline bool sameBits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

/// Values whose bits differ between two images of the same size.
inline int bitDifferences(const Image& a, const Image& b) {
  REQUIRE(a.data().size() == b.data().size());
  int differ = 0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    if (!sameBits(a.data()[i], b.data()[i])) ++differ;
  return differ;
}

/// A pass's list variant against its per-pixel output on every pixel of a camera depth image: `run(list)`
/// runs the pass into `output` (RGBA, the depth's size) for list = nullptr, else into the list's output.
/// The two agree bit for bit, and the image is not black.
inline void checkListEqualsPerPixel(const Image& depth, std::uint32_t output,
                                    const std::function<void(const gpu::SampleList*)>& run) {
  run(nullptr);
  const TestList list = makePixelList(depth, texelsWhere(depth.width(), depth.height()));
  run(&list.list);
  const Image perPixel = gl::readTexture(output, depth.width(), depth.height(), gl::TexelData::Rgba);
  const Image listed = gl::readTexture(list.output.get(), depth.width(), depth.height(), gl::TexelData::Rgba);
  CHECK(bitDifferences(listed, perPixel) == 0);
  CHECK(rgbMetrics(perPixel, perPixel).peak > 0.0);
}

/// What a list wrote, against the per-pixel output: values left NaN at entries, values written elsewhere,
/// entry values whose bits differ from the per-pixel ones.
struct ListWrites {
  int nanAtEntries = 0, writtenElsewhere = 0, differ = 0;
};

/// ListWrites of `listed` (RGBA, the list's output) with `entry(x, y)` telling the entries.
inline ListWrites listWrites(const Image& listed, const Image& perPixel,
                             const std::function<bool(int, int)>& entry) {
  ListWrites w;
  for (int y = 0; y < listed.height(); ++y)
    for (int x = 0; x < listed.width(); ++x) {
      const bool isEntry = entry(x, y);
      for (int c = 0; c < 4; ++c) {
        const float v = listed.at(x, y, c);
        if (isEntry && std::isnan(v)) ++w.nanAtEntries;
        if (!isEntry && !std::isnan(v)) ++w.writtenElsewhere;
        if (isEntry && !sameBits(v, perPixel.at(x, y, c))) ++w.differ;
      }
    }
  return w;
}

} // namespace crep::test
