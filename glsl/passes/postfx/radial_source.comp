#version 450 core
// The occlusion pre-pass of the radial blur (crep::radialBlurSource, crep/postfx/radial_blur.h; Mitchell
// 2007, Sec. 13.5.1 with the sky's unshadowed in-scattering of Eq. 1 as the bright value, box-downsampled
// by sourceScale k as in Sec. 13.3.1). One invocation per source texel: the mean over the camera pixels of
// its k x k block inside the image of (sky: C times the transmittance integral of the pixel ray to the far
// plane, the closed form of crep::unshadowedScattering; geometry: 0), A = the sky fraction.
// Resources: CrepMarchBlock (binding 0: camera, light, medium; sizes.xy = camera image), CrepRadialBlurBlock
// (binding 1), camera depth (texture unit 0, texelFetch), source output RGBA32F (image unit 0).
#include "crep/bindings.h"
#include "crep/radial_blur.glsl"

#ifndef CREP_RADIAL_GROUP
#define CREP_RADIAL_GROUP 8
#endif
layout(local_size_x = CREP_RADIAL_GROUP, local_size_y = CREP_RADIAL_GROUP) in;

layout(std140, binding = CREP_RADIAL_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(std140, binding = CREP_RADIAL_BLUR_BINDING) uniform CrepRadialBlurBlock { CrepRadialBlurParams crep_radial; };
layout(binding = CREP_RADIAL_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_RADIAL_SOURCE_OUT_IMAGE, rgba32f) uniform writeonly image2D sourceOut;

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, crep_radial.info.zw))) return;
  int k = crep_radial.info.y;
  ivec2 first = texel * k, last = min(first + k, crep_march.sizes.xy);
  vec4 sum = vec4(0.0);
  for (int y = first.y; y < last.y; ++y)
    for (int x = first.x; x < last.x; ++x) {
      float depth = texelFetch(cameraDepth, ivec2(x, y), 0).r;
      if (!crep_radialIsSky(depth, crep_march.cameraDepth)) continue;
      sum += vec4(crep_radialUnshadowed(crep_march, crep_pixelRay(crep_march, ivec2(x, y), depth)), 1.0);
    }
  ivec2 count = last - first;
  imageStore(sourceOut, texel, sum / float(count.x * count.y));
}
