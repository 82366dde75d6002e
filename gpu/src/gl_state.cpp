#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/gl_state.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace crep::gl {

namespace {

bool enabled(GLenum cap) {
  return glIsEnabled(cap) == GL_TRUE;
}
void enable(GLenum cap, bool on) {
  (on ? glEnable : glDisable)(cap);
}
GLenum getEnum(GLenum pname) {
  GLint v = 0;
  glGetIntegerv(pname, &v);
  return static_cast<GLenum>(v);
}

int clipDistanceCount() {
  GLint n = 0;
  glGetIntegerv(GL_MAX_CLIP_DISTANCES, &n);
  return std::clamp(n, 0, 32);
}

/// Extensions are a property of the implementation; looked up once per process.
bool hasDepthBounds() {
  static const bool has = epoxy_has_gl_extension("GL_EXT_depth_bounds_test");
  return has;
}
GLenum conservativeRasterCap() {
  static const GLenum cap = epoxy_has_gl_extension("GL_NV_conservative_raster")             ? 0x9346u
                            : epoxy_has_gl_extension("GL_INTEL_conservative_rasterization") ? 0x83FEu
                                                                                            : 0u;
  return cap;
}

std::string enumName(GLenum e) {
  switch (e) {
  case GL_LOWER_LEFT:
    return "GL_LOWER_LEFT";
  case GL_UPPER_LEFT:
    return "GL_UPPER_LEFT";
  case GL_NEGATIVE_ONE_TO_ONE:
    return "GL_NEGATIVE_ONE_TO_ONE";
  case GL_ZERO_TO_ONE:
    return "GL_ZERO_TO_ONE";
  case GL_NEVER:
    return "GL_NEVER";
  case GL_LESS:
    return "GL_LESS";
  case GL_EQUAL:
    return "GL_EQUAL";
  case GL_LEQUAL:
    return "GL_LEQUAL";
  case GL_GREATER:
    return "GL_GREATER";
  case GL_NOTEQUAL:
    return "GL_NOTEQUAL";
  case GL_GEQUAL:
    return "GL_GEQUAL";
  case GL_ALWAYS:
    return "GL_ALWAYS";
  case GL_FILL:
    return "GL_FILL";
  case GL_LINE:
    return "GL_LINE";
  case GL_POINT:
    return "GL_POINT";
  case GL_FRONT:
    return "GL_FRONT";
  case GL_BACK:
    return "GL_BACK";
  case GL_FRONT_AND_BACK:
    return "GL_FRONT_AND_BACK";
  case GL_CW:
    return "GL_CW";
  case GL_CCW:
    return "GL_CCW";
  default: {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", e);
    return buf;
  }
  }
}

std::string text(bool v) {
  return v ? "enabled" : "disabled";
}
template <class T>
std::string numbers(const T* v, int n) {
  std::string s = "(";
  for (int i = 0; i < n; ++i)
    s += (i ? ", " : "") + std::to_string(v[i]);
  return s + ")";
}

} // namespace

RasterState RasterState::read() {
  RasterState s;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s.drawFramebuffer);
  glGetFloati_v(GL_VIEWPORT, 0, s.viewport);
  glGetIntegeri_v(GL_SCISSOR_BOX, 0, s.scissorBox);
  s.scissorTest = glIsEnabledi(GL_SCISSOR_TEST, 0) == GL_TRUE;
  glGetDoublei_v(GL_DEPTH_RANGE, 0, s.depthRange);
  s.clipOrigin = getEnum(GL_CLIP_ORIGIN);
  s.clipDepthMode = getEnum(GL_CLIP_DEPTH_MODE);
  s.depthFunc = getEnum(GL_DEPTH_FUNC);
  GLboolean mask = GL_TRUE;
  glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
  s.depthMask = mask == GL_TRUE;
  s.depthTest = enabled(GL_DEPTH_TEST);
  s.depthClamp = enabled(GL_DEPTH_CLAMP);
  GLint modes[2] = {GL_FILL, GL_FILL};
  glGetIntegerv(GL_POLYGON_MODE, modes);
  s.polygonMode = static_cast<GLenum>(modes[0]);
  s.polygonOffsetFill = enabled(GL_POLYGON_OFFSET_FILL);
  s.polygonOffsetLine = enabled(GL_POLYGON_OFFSET_LINE);
  s.polygonOffsetPoint = enabled(GL_POLYGON_OFFSET_POINT);
  s.polygonSmooth = enabled(GL_POLYGON_SMOOTH);
  s.cullFace = enabled(GL_CULL_FACE);
  s.cullFaceMode = getEnum(GL_CULL_FACE_MODE);
  s.frontFace = getEnum(GL_FRONT_FACE);
  s.rasterizerDiscard = enabled(GL_RASTERIZER_DISCARD);
  const int clips = clipDistanceCount();
  for (int i = 0; i < clips; ++i)
    if (enabled(GL_CLIP_DISTANCE0 + static_cast<GLenum>(i))) s.clipDistances |= 1u << i;
  if (hasDepthBounds()) s.depthBoundsTest = enabled(GL_DEPTH_BOUNDS_TEST_EXT);
  if (const GLenum cap = conservativeRasterCap(); cap != 0) s.conservativeRaster = enabled(cap);
  return s;
}

void RasterState::apply() const {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFramebuffer));
  glViewportIndexedfv(0, viewport);
  glScissorIndexedv(0, scissorBox);
  (scissorTest ? glEnablei : glDisablei)(GL_SCISSOR_TEST, 0);
  glDepthRangeIndexed(0, depthRange[0], depthRange[1]);
  glClipControl(clipOrigin, clipDepthMode);
  glDepthFunc(depthFunc);
  glDepthMask(depthMask ? GL_TRUE : GL_FALSE);
  enable(GL_DEPTH_TEST, depthTest);
  enable(GL_DEPTH_CLAMP, depthClamp);
  glPolygonMode(GL_FRONT_AND_BACK, polygonMode);
  enable(GL_POLYGON_OFFSET_FILL, polygonOffsetFill);
  enable(GL_POLYGON_OFFSET_LINE, polygonOffsetLine);
  enable(GL_POLYGON_OFFSET_POINT, polygonOffsetPoint);
  enable(GL_POLYGON_SMOOTH, polygonSmooth);
  enable(GL_CULL_FACE, cullFace);
  glCullFace(cullFaceMode);
  glFrontFace(frontFace);
  enable(GL_RASTERIZER_DISCARD, rasterizerDiscard);
  const int clips = clipDistanceCount();
  for (int i = 0; i < clips; ++i)
    enable(GL_CLIP_DISTANCE0 + static_cast<GLenum>(i), (clipDistances >> i) & 1u);
  if (hasDepthBounds()) enable(GL_DEPTH_BOUNDS_TEST_EXT, depthBoundsTest);
  if (const GLenum cap = conservativeRasterCap(); cap != 0) enable(cap, conservativeRaster);
}

std::string RasterState::firstDifference(const RasterState& a) const {
  auto is = [](const std::string& name, const std::string& actual, const std::string& expected) {
    return name + " = " + actual + " (expected " + expected + ")";
  };
  if (a.drawFramebuffer != drawFramebuffer)
    return is("GL_DRAW_FRAMEBUFFER_BINDING", std::to_string(a.drawFramebuffer),
              std::to_string(drawFramebuffer));
  if (!std::equal(viewport, viewport + 4, a.viewport))
    return is("GL_VIEWPORT[0]", numbers(a.viewport, 4), numbers(viewport, 4));
  if (!std::equal(scissorBox, scissorBox + 4, a.scissorBox))
    return is("GL_SCISSOR_BOX[0]", numbers(a.scissorBox, 4), numbers(scissorBox, 4));
  if (a.scissorTest != scissorTest) return is("GL_SCISSOR_TEST[0]", text(a.scissorTest), text(scissorTest));
  if (!std::equal(depthRange, depthRange + 2, a.depthRange))
    return is("GL_DEPTH_RANGE[0]", numbers(a.depthRange, 2), numbers(depthRange, 2));
  if (a.clipOrigin != clipOrigin) return is("GL_CLIP_ORIGIN", enumName(a.clipOrigin), enumName(clipOrigin));
  if (a.clipDepthMode != clipDepthMode)
    return is("GL_CLIP_DEPTH_MODE", enumName(a.clipDepthMode), enumName(clipDepthMode));
  if (a.depthFunc != depthFunc) return is("GL_DEPTH_FUNC", enumName(a.depthFunc), enumName(depthFunc));
  if (a.depthMask != depthMask)
    return is("GL_DEPTH_WRITEMASK", a.depthMask ? "GL_TRUE" : "GL_FALSE", depthMask ? "GL_TRUE" : "GL_FALSE");
  if (a.depthTest != depthTest) return is("GL_DEPTH_TEST", text(a.depthTest), text(depthTest));
  if (a.depthClamp != depthClamp) return is("GL_DEPTH_CLAMP", text(a.depthClamp), text(depthClamp));
  if (a.polygonMode != polygonMode)
    return is("GL_POLYGON_MODE", enumName(a.polygonMode), enumName(polygonMode));
  if (a.polygonOffsetFill != polygonOffsetFill)
    return is("GL_POLYGON_OFFSET_FILL", text(a.polygonOffsetFill), text(polygonOffsetFill));
  if (a.polygonOffsetLine != polygonOffsetLine)
    return is("GL_POLYGON_OFFSET_LINE", text(a.polygonOffsetLine), text(polygonOffsetLine));
  if (a.polygonOffsetPoint != polygonOffsetPoint)
    return is("GL_POLYGON_OFFSET_POINT", text(a.polygonOffsetPoint), text(polygonOffsetPoint));
  if (a.polygonSmooth != polygonSmooth)
    return is("GL_POLYGON_SMOOTH", text(a.polygonSmooth), text(polygonSmooth));
  if (a.cullFace != cullFace) return is("GL_CULL_FACE", text(a.cullFace), text(cullFace));
  if (a.cullFaceMode != cullFaceMode)
    return is("GL_CULL_FACE_MODE", enumName(a.cullFaceMode), enumName(cullFaceMode));
  if (a.frontFace != frontFace) return is("GL_FRONT_FACE", enumName(a.frontFace), enumName(frontFace));
  if (a.rasterizerDiscard != rasterizerDiscard)
    return is("GL_RASTERIZER_DISCARD", text(a.rasterizerDiscard), text(rasterizerDiscard));
  for (int i = 0; i < 32; ++i)
    if (((a.clipDistances ^ clipDistances) >> i) & 1u)
      return is("GL_CLIP_DISTANCE" + std::to_string(i), text((a.clipDistances >> i) & 1u),
                text((clipDistances >> i) & 1u));
  if (a.depthBoundsTest != depthBoundsTest)
    return is("GL_DEPTH_BOUNDS_TEST_EXT", text(a.depthBoundsTest), text(depthBoundsTest));
  if (a.conservativeRaster != conservativeRaster)
    return is("GL_CONSERVATIVE_RASTERIZATION", text(a.conservativeRaster), text(conservativeRaster));
  return {};
}

DepthPassScope::DepthPassScope(std::uint32_t framebuffer, int width, int height,
                               const DepthPassState& state) {
  requireNoActiveTransformFeedback("a depth pass of the library");
  saved_ = RasterState::read();
  set_.drawFramebuffer = static_cast<int>(framebuffer);
  set_.viewport[2] = static_cast<float>(width);
  set_.viewport[3] = static_cast<float>(height);
  set_.scissorBox[2] = width;
  set_.scissorBox[3] = height;
  set_.scissorTest = true;
  set_.depthRange[0] = 0.0;
  set_.depthRange[1] = 1.0;
  set_.clipOrigin = GL_LOWER_LEFT;
  set_.clipDepthMode = GL_NEGATIVE_ONE_TO_ONE;
  set_.depthFunc = GL_LESS;
  set_.depthMask = true;
  set_.depthTest = true;
  set_.depthClamp = state.depthClamp;
  set_.polygonMode = GL_FILL;
  set_.cullFace = state.cullBackFaces;
  set_.cullFaceMode = GL_BACK;
  set_.frontFace = GL_CCW;
  set_.apply();
}

DepthPassScope::~DepthPassScope() {
  saved_.apply();
}

void DepthPassScope::setViewport(int x, int y, int width, int height) {
  const float v[4] = {static_cast<float>(x), static_cast<float>(y), static_cast<float>(width),
                      static_cast<float>(height)};
  std::copy(v, v + 4, set_.viewport);
  set_.scissorBox[0] = x;
  set_.scissorBox[1] = y;
  set_.scissorBox[2] = width;
  set_.scissorBox[3] = height;
  glViewportIndexedfv(0, set_.viewport);
  glScissorIndexedv(0, set_.scissorBox);
}

void DepthPassScope::requireUnchanged(const char* callback) const {
  const std::string difference = set_.firstDifference(RasterState::read());
  if (!difference.empty())
    throw InvalidArgument(callback, "left " + difference,
                          "must draw with the pass's raster state and leave it as it was given "
                          "(docs/GL_STATE.md)");
}

namespace {
constexpr GLenum kPackNames[8] = {GL_PACK_ALIGNMENT,  GL_PACK_ROW_LENGTH,   GL_PACK_SKIP_PIXELS,
                                  GL_PACK_SKIP_ROWS,  GL_PACK_IMAGE_HEIGHT, GL_PACK_SKIP_IMAGES,
                                  GL_PACK_SWAP_BYTES, GL_PACK_LSB_FIRST};
constexpr GLenum kUnpackNames[8] = {GL_UNPACK_ALIGNMENT,  GL_UNPACK_ROW_LENGTH,   GL_UNPACK_SKIP_PIXELS,
                                    GL_UNPACK_SKIP_ROWS,  GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_IMAGES,
                                    GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST};
} // namespace

PixelStoreScope::PixelStoreScope() {
  for (int i = 0; i < 8; ++i) {
    glGetIntegerv(kPackNames[i], &pack_[i]);
    glGetIntegerv(kUnpackNames[i], &unpack_[i]);
    const GLint value = i == 0 ? 1 : 0; // alignment 1, every other parameter GL's default
    glPixelStorei(kPackNames[i], value);
    glPixelStorei(kUnpackNames[i], value);
  }
  glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer_);
  glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &unpackBuffer_);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

PixelStoreScope::~PixelStoreScope() {
  for (int i = 0; i < 8; ++i) {
    glPixelStorei(kPackNames[i], pack_[i]);
    glPixelStorei(kUnpackNames[i], unpack_[i]);
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(packBuffer_));
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, static_cast<GLuint>(unpackBuffer_));
}

void requireNoActiveTransformFeedback(const char* owner) {
  GLboolean active = GL_FALSE, paused = GL_FALSE;
  glGetBooleanv(GL_TRANSFORM_FEEDBACK_ACTIVE, &active);
  glGetBooleanv(GL_TRANSFORM_FEEDBACK_PAUSED, &paused);
  if (active == GL_TRUE && paused != GL_TRUE)
    throw GlError(std::string("crep: ") + owner +
                  ": a transform feedback is active (GL_TRANSFORM_FEEDBACK_ACTIVE) and not paused; it would "
                  "capture the library's draws and rejects its programs: pause or end it before the call");
}

void requireNoPendingError(const char* owner) {
  const std::string errors = gl::drainErrors();
  if (!errors.empty())
    throw GlError(std::string("crep: ") + owner + ": GL errors were pending before the call (" + errors +
                  "), raised by earlier GL calls of the caller; check glGetError() after your own passes");
}

void requireNoActiveTimerQuery(const char* owner) {
  GLint query = 0;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &query);
  if (query != 0)
    throw GlError(std::string("crep: ") + owner + ": the caller's GL_TIME_ELAPSED query " +
                  std::to_string(query) +
                  " is active and such queries do not nest; end it before the call, or turn the stage "
                  "timings off");
}

} // namespace crep::gl
