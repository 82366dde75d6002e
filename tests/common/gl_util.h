// GL helpers of the tests (GL tests only: they need a context): images uploaded as textures, textures and
// froxel volumes read back, and the properties of a linked program's resources (the std140 / std430 twins'
// offsets).
#pragma once

#include <crep/core/image.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/froxel_grid.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace crep::test {

/// A GL_TEXTURE_2D of `format` (GL enum) with nearest filtering, clamp to edge.
inline gl::Handle createTexture2D(std::uint32_t format, int width, int height) {
  return gl::createTexture2D(format, width, height);
}

/// A GL_R32F texture holding channel 0 of a 1-channel image (camera depth, rectified or shadow map).
inline gl::Handle uploadR32F(const Image& image) {
  REQUIRE(image.channels() == 1);
  gl::Handle t = gl::createTexture2D(GL_R32F, image.width(), image.height());
  glTextureSubImage2D(t.get(), 0, 0, 0, image.width(), image.height(), GL_RED, GL_FLOAT, image.data().data());
  return t;
}

/// An RGBA image as a 2D texture of `format` (GL enum).
inline gl::Handle uploadRgba(const Image& image, std::uint32_t format = GL_RGBA32F) {
  gl::Handle t = gl::createTexture2D(format, image.width(), image.height());
  glTextureSubImage2D(t.get(), 0, 0, 0, image.width(), image.height(), GL_RGBA, GL_FLOAT,
                      image.data().data());
  return t;
}

/// An RGB image (a light texture) as a GL_RGBA32F texture (A = 1).
inline gl::Handle uploadRgb(const Image& image) {
  Image rgba(image.width(), image.height(), 4, 1.0f);
  for (int j = 0; j < image.height(); ++j)
    for (int i = 0; i < image.width(); ++i)
      for (int k = 0; k < 3; ++k)
        rgba.at(i, j, k) = image.at(i, j, k);
  return uploadRgba(rgba);
}

/// A 4-channel image of an RGBA 2D texture.
inline Image readRgbaTexture(std::uint32_t texture, int width, int height) {
  return gl::readTexture(texture, width, height, gl::TexelData::Rgba);
}

/// Every texel of a texture array (layers * height * width * 4 floats, layer-major: the order of
/// FilteredBasis::texels).
inline std::vector<float> readTextureArray(std::uint32_t texture, int width, int height, int layers) {
  std::vector<float> out(static_cast<std::size_t>(layers) * static_cast<std::size_t>(height) *
                         static_cast<std::size_t>(width) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(out.size() * sizeof(float)),
                    out.data());
  return out;
}

/// A GL_TEXTURE_3D volume of the grid's size.
inline gl::Handle createVolume(const FroxelGrid& grid, std::uint32_t format = GL_RGBA32F) {
  gl::Handle v = gl::createTexture(GL_TEXTURE_3D);
  glTextureStorage3D(v.get(), 1, format, grid.width, grid.height, grid.depth);
  return v;
}

/// The volume read back as evaluateFroxels lays it out: width x (height depth), slice z at rows z height.
inline Image readVolume(std::uint32_t volume, const FroxelGrid& grid) {
  Image out(grid.width, grid.height * grid.depth, 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(volume, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(out.byteSize()), out.data().data());
  return out;
}

/// One property of a program resource; -1 when the resource is not active.
inline GLint resourceProperty(GLuint program, GLenum interface, const std::string& name, GLenum property) {
  const GLuint index = glGetProgramResourceIndex(program, interface, name.c_str());
  if (index == GL_INVALID_INDEX) return -1;
  GLint value = -1;
  glGetProgramResourceiv(program, interface, index, 1, &property, 1, nullptr, &value);
  return value;
}

} // namespace crep::test
