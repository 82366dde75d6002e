// The shadow-pass plan's conventions and JSON (crep/pipeline/shadow_pass_plan.h); Scattering::plan fills it.
#include <crep/pipeline/shadow_pass_plan.h>

#include <cmath>
#include <cstdio>

namespace crep {

const char* conventionToken(ClipConvention convention) {
  switch (convention) {
  case ClipConvention::OpenGL:
    return "opengl";
  case ClipConvention::OpenGLZeroToOne:
    return "opengl-zero-to-one";
  case ClipConvention::Vulkan:
    return "vulkan";
  case ClipConvention::Direct3D12:
    return "d3d12";
  case ClipConvention::Metal:
    return "metal";
  }
  return "opengl";
}

// Rows of a column-major matrix: M[column][row]. Each convention is a row operation on the OpenGL matrix, so
// OpenGL without reversed-Z returns M itself (the GL path's matrices, bit for bit).
glm::dmat4 toClipConvention(const glm::dmat4& gl, const ShadowPassPlanOptions& options) {
  glm::dmat4 m = gl;
  const bool zeroToOne = options.convention != ClipConvention::OpenGL;
  for (int c = 0; c < 4; ++c) {
    if (zeroToOne) m[c][2] = 0.5 * gl[c][2] + 0.5 * gl[c][3]; // z in [0, w]: depth = 0.5 z_ndc + 0.5
    if (options.reversedZ) m[c][2] = zeroToOne ? gl[c][3] - m[c][2] : -gl[c][2]; // stores 1 - depth
    // D3D12 and Metal put NDC y = +1 at the first row; negating y keeps OpenGL's row order in memory.
    if (options.convention == ClipConvention::Direct3D12 || options.convention == ClipConvention::Metal)
      m[c][1] = -gl[c][1];
  }
  return m;
}

int ShadowPassPlan::mapCount() const noexcept {
  int n = 0;
  for (const ShadowPass& p : passes)
    n += p.needsMap() ? 1 : 0;
  return n;
}

namespace {

void appendNumber(std::string& out, double v) {
  if (!std::isfinite(v)) v = 0.0; // finite by construction; the output stays valid JSON
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out += buf;
}

void appendMatrix(std::string& out, const glm::dmat4& m) {
  out += "[";
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      if (col || row) out += ", ";
      appendNumber(out, m[col][row]);
    }
  out += "]";
}

void appendRect(std::string& out, const ShadowPass::Rect& r) {
  out += "[" + std::to_string(r.x) + ", " + std::to_string(r.y) + ", " + std::to_string(r.width) + ", " +
         std::to_string(r.height) + "]";
}

void appendString(std::string& out, std::string_view s) {
  out += '"';
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  out += '"';
}

const char* lightToken(ShadowPass::Light light) {
  switch (light) {
  case ShadowPass::Light::Sun:
    return "sun";
  case ShadowPass::Light::Spot:
    return "spot";
  case ShadowPass::Light::PointFace:
    return "point-face";
  }
  return "sun";
}

const char* kindToken(ShadowPass::Kind kind) {
  switch (kind) {
  case ShadowPass::Kind::None:
    return "none";
  case ShadowPass::Kind::Rectified:
    return "rectified";
  case ShadowPass::Kind::Standard:
    return "standard";
  }
  return "none";
}

} // namespace

std::string toJson(const ShadowPassPlan& plan) {
  std::string out = "{\"frame\": " + std::to_string(plan.frame) + ", \"convention\": \"" +
                    conventionToken(plan.options.convention) +
                    "\", \"reversedZ\": " + (plan.options.reversedZ ? "true" : "false") + ", \"passes\": [";
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    const ShadowPass& p = plan.passes[i];
    out += i ? ", " : "";
    out += std::string("{\"light\": \"") + lightToken(p.light) + "\", \"index\": " + std::to_string(p.index) +
           ", \"face\": " + std::to_string(p.face) + ", \"kind\": \"" + kindToken(p.kind) +
           "\", \"status\": \"" + statusToken(p.status) + "\", \"reason\": \"" + reasonToken(p.reason) +
           "\", \"message\": ";
    appendString(out, p.message);
    out += std::string(", \"served\": ") + (p.served ? "true" : "false") +
           ", \"width\": " + std::to_string(p.width) + ", \"height\": " + std::to_string(p.height) +
           ", \"format\": \"depth32f\", \"clearDepth\": ";
    appendNumber(out, p.clearDepth);
    out += std::string(", \"compare\": \"") + (p.compare == DepthCompare::Less ? "less" : "greater") +
           "\", \"depthClamp\": " + (p.depthClamp ? "true" : "false") +
           ", \"cullFaces\": " + (p.cullFaces ? "true" : "false") + ", \"glClipFromWorld\": ";
    appendMatrix(out, p.glClipFromWorld);
    out += ", \"splits\": [";
    for (std::size_t k = 0; k < p.splits.size(); ++k) {
      out += k ? ", " : "";
      out += "{\"clipFromWorld\": ";
      appendMatrix(out, p.splits[k].clipFromWorld);
      out += ", \"viewport\": ";
      appendRect(out, p.splits[k].viewport);
      out += ", \"scissor\": ";
      appendRect(out, p.splits[k].scissor);
      out += "}";
    }
    out += "]}";
  }
  out += "]}";
  return out;
}

} // namespace crep
