// crepuscular: light textures, an RGB texture projected from the light that multiplies the light's colour
// per light ray (crep/scatter/light_texture.h has the rule; Klehm et al. 2014, Sec. 3.2 coloured light
// textures). Float twin of crep::lightTextureColor.
//
// Public include (conventions in crep/common.glsl). What it provides:
//   struct CrepLightTextureParams     the std140 block of gpu::LightTextureParams
//   vec3 crep_lightTexel(sampler2D tex, ivec2 texel)   one texel, non-finite / negative channels as 0
//   vec3 crep_lightTextureColor(sampler2D tex, CrepLightTextureParams p, vec3 world)
//        the texture's colour at a world point: 0 behind the projector (clip w <= 0), else GL_LINEAR with
//        clamp to edge at the point's NDC, computed from four texelFetch as c0 + f (c1 - c0) (so a constant
//        texture gives its value exactly, as on the CPU).
// GPU: the four texelFetch instead of one GL_LINEAR fetch keep the interpolation weights in float (the
// hardware's are 8-bit fixed point on many GPUs and on llvmpipe), so the colour map matches the CPU
// reference to float rounding; the cost is once per map texel (the colour map pass) or per lit section
// (the world march), not per pixel and region.
#ifndef CREP_LIGHT_TEXTURE_GLSL
#define CREP_LIGHT_TEXTURE_GLSL

// gpu::LightTextureParams (std140).
struct CrepLightTextureParams {
  mat4 textureClipFromWorld; // world -> the texture's clip space (NDC x, y in [-1, 1] cover it)
  ivec4 size;                // xy texture size (texels); zw the colour map's size (colour map pass)
  vec4 lightPosition;        // colour map pass: xyz the local light's position, w 1 = local light, 0 = sun
};

// One texel as the GPU reads it: non-finite or negative channels count as 0 (no light), so one bad texel
// cannot turn a frame into NaN. The CPU reference refuses such textures (crep::validateLightColors), so the
// two agree on every texture it accepts.
vec3 crep_lightTexel(sampler2D tex, ivec2 texel) {
  vec3 c = texelFetch(tex, texel, 0).rgb;
  for (int k = 0; k < 3; ++k)
    if (isnan(c[k]) || isinf(c[k]) || !(c[k] > 0.0)) c[k] = 0.0;
  return c;
}

vec3 crep_lightTextureColor(sampler2D tex, CrepLightTextureParams p, vec3 world) {
  vec4 q = p.textureClipFromWorld * vec4(world, 1.0);
  if (!(q.w > 0.0)) return vec3(0.0);
  ivec2 size = p.size.xy;
  vec2 xy = (0.5 * q.xy / q.w + 0.5) * vec2(size) - 0.5;
  if (any(isnan(xy)) || any(isinf(xy))) return vec3(0.0);
  xy = clamp(xy, vec2(-1.0), vec2(size)); // far outside, every index clamps to the edge
  vec2 f0 = floor(xy), f = xy - f0;
  ivec2 i0 = ivec2(f0);
  ivec2 lo = clamp(i0, ivec2(0), size - 1), hi = clamp(i0 + 1, ivec2(0), size - 1);
  vec3 c00 = crep_lightTexel(tex, ivec2(lo.x, lo.y)), c10 = crep_lightTexel(tex, ivec2(hi.x, lo.y));
  vec3 c01 = crep_lightTexel(tex, ivec2(lo.x, hi.y)), c11 = crep_lightTexel(tex, ivec2(hi.x, hi.y));
  vec3 bottom = c00 + f.x * (c10 - c00), top = c01 + f.x * (c11 - c01);
  return bottom + f.y * (top - bottom);
}

#endif // CREP_LIGHT_TEXTURE_GLSL
