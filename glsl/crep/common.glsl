// crepuscular: constants and small helpers shared by every crepuscular shader.
//
// Public include: an engine can `#include "crep/common.glsl"` in its own shaders (the installed copy
// is under <prefix>/share/crepuscular/glsl/). No #version here: the including shader has one
// (GLSL 4.50 core is assumed). The crepuscular shader library includes each file once per shader;
// the guard below is for include mechanisms without that rule. Names start with crep_ / CREP_.
#ifndef CREP_COMMON_GLSL
#define CREP_COMMON_GLSL

#define CREP_PI 3.14159265358979323846
#define CREP_TWO_PI 6.28318530717958647693
#define CREP_FOUR_PI 12.5663706143591729539
#define CREP_INV_PI 0.31830988618379067154
#define CREP_INV_FOUR_PI 0.07957747154594766788

// View-space distance along -Z (positive, in world units) of a depth-buffer value `depth` in [0, 1]
// written with a standard OpenGL perspective projection (clip z in [-w, w], glDepthRange(0, 1)) with
// near and far planes at zNear and zFar. depth = 0 gives zNear, depth = 1 gives zFar.
float crep_linearDepth(float depth, float zNear, float zFar) {
  float ndcZ = 2.0 * depth - 1.0;
  return 2.0 * zNear * zFar / (zFar + zNear - ndcZ * (zFar - zNear));
}

// The same distance written near far / (near + (1 - depth)(far - near)): 1 - depth is exact for depth >= 1/2,
// so there is no cancellation where crep_linearDepth's (2 depth - 1) form loses digits (depth near 1).
float crep_viewDepth(float depth, float zNear, float zFar) {
  return zNear * zFar / (zNear + (1.0 - depth) * (zFar - zNear));
}

// The view-space distance of a surface in a camera depth buffer: the sky (depth >= 1, also NaN) is the far
// plane, depth < 0 the near plane (what the evaluation integrates to; crep::pixelRay's rule).
float crep_surfaceViewDepth(float depth, float zNear, float zFar) {
  return depth < 1.0 ? crep_viewDepth(max(depth, 0.0), zNear, zFar) : zFar;
}

// The same for a camera of any depth convention (crep::Camera::surfaceViewDepth): map = (near, projection
// far or 0 for an infinite far plane, integration far, 1 for reversed-Z else 0). t = 1 - depth (standard) or
// depth (reversed) is (1/Z - 1/f) / (1/n - 1/f); the cleared value (t <= 0, also NaN) is the integration
// far, t >= 1 the near plane. For GL's default convention this is crep_surfaceViewDepth exactly.
float crep_cameraViewDepth(float depth, vec4 map) {
  float t = map.w > 0.5 ? depth : 1.0 - depth;
  if (!(t > 0.0)) return map.z;
  if (t >= 1.0) return map.x;
  float Z = map.y > 0.0 ? map.x * map.y / (map.x + t * (map.y - map.x)) : map.x / t;
  return min(Z, map.z);
}

// sRGB transfer function (IEC 61966-2-1): linear [0, 1] to encoded [0, 1], per channel.
vec3 crep_srgbEncode(vec3 linearColor) {
  vec3 c = clamp(linearColor, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// Inverse of crep_srgbEncode.
vec3 crep_srgbDecode(vec3 encoded) {
  vec3 c = clamp(encoded, 0.0, 1.0);
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// Relative luminance of linear Rec. 709 / sRGB primaries.
float crep_luminance(vec3 linearColor) { return dot(linearColor, vec3(0.2126, 0.7152, 0.0722)); }

#endif // CREP_COMMON_GLSL
