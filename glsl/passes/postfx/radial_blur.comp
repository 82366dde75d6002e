#version 450 core
// The radial blur (crep::radialBlur, crep/postfx/radial_blur.h; Mitchell 2007, Eq. 4 averaged over its
// n + 1 terms, Sec. 13.4): per camera pixel, n + 1 bilinear reads of the source image along the screen
// segment toward the sun, weighted decay^i, times fade exposure weight / (n + 1); A = exp(-sbar s) of the
// pixel ray (crep/scatter/ray.h's output convention).
// CREP_RADIAL_FRACTION 1 (RadialBlurMode::OcclusionFraction, Mitchell 2007, Eq. 2): the sum reads the
// source's A (sky fraction) and is multiplied by the pixel's own unshadowed in-scattering.
// Resources: CrepMarchBlock (binding 0: camera, medium; sizes.xy = camera image), CrepRadialBlurBlock
// (binding 1), camera depth (texture unit 0, texelFetch), source (texture unit 1, bilinear, clamp to edge),
// output RGBA32F (image unit 0).
#include "crep/bindings.h"
#include "crep/radial_blur.glsl"

#ifndef CREP_RADIAL_GROUP
#define CREP_RADIAL_GROUP 8
#endif
#ifndef CREP_RADIAL_FRACTION
#define CREP_RADIAL_FRACTION 0
#endif
layout(local_size_x = CREP_RADIAL_GROUP, local_size_y = CREP_RADIAL_GROUP) in;

layout(std140, binding = CREP_RADIAL_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(std140, binding = CREP_RADIAL_BLUR_BINDING) uniform CrepRadialBlurBlock { CrepRadialBlurParams crep_radial; };
layout(binding = CREP_RADIAL_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_RADIAL_SOURCE_UNIT) uniform sampler2D radialSource;
layout(binding = CREP_RADIAL_SCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D scatteringOut;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_march.sizes.xy;
  if (any(greaterThanEqual(pixel, size))) return;
  vec3 L = vec3(0.0);
  if (crep_radial.light.z > 0.0) {
    int n = crep_radial.info.x;
    vec2 p = (vec2(pixel) + 0.5) / vec2(size);
    vec2 delta = (p - crep_radial.light.xy) * crep_radial.shape.y;
    // Full-image texture coordinates to the source's: the source texel j covers pixels [j k, (j + 1) k).
    vec2 toSource = vec2(size) / (float(crep_radial.info.y) * vec2(crep_radial.info.zw));
    float decay = 1.0;
    // The hardware bilinear filter (Mitchell 2007, Sec. 13.3.1): one fetch per sample; on GPUs its weights
    // have about 8 fractional bits, which the averaging over n + 1 samples hides.
    for (int i = 0; i <= n; ++i) {
      vec4 v = textureLod(radialSource, (p - float(i) * delta) * toSource, 0.0);
#if CREP_RADIAL_FRACTION
      L += vec3(decay * v.a);
#else
      L += decay * v.rgb;
#endif
      decay *= crep_radial.shape.x;
    }
    L *= crep_radial.light.z * crep_radial.light.w;
  }
  vec4 ray = crep_pixelRay(crep_march, pixel, texelFetch(cameraDepth, pixel, 0).r);
#if CREP_RADIAL_FRACTION
  L *= crep_radialUnshadowed(crep_march, ray);
#endif
  imageStore(scatteringOut, pixel, vec4(L, exp(-crep_march.extinction.w * ray.w)));
}
