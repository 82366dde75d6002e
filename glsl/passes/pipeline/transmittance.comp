#version 450 core
// The output of a frame without a directional light (crep::Scattering, FrameAttribs::light null: a night
// frame of local lights only): RGB 0, A the grey transmittance exp(-sigma_t s) to the surface (the factor of
// the surface radiance in Klehm et al. 2014, Eq. 1), as the marches and the evaluation store it; the local
// lights' radiance is then added (passes/pipeline/accumulate.comp). One invocation per pixel.
//
// Resources: params block (binding 0: the camera members, sizes.xy the camera image, extinction.w the grey
// extinction), camera depth (unit 0, texelFetch), output: RGBA32F (image 0).
#include "crep/bindings.h"
#include "crep/march.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_MARCH_PARAMS_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_MARCH_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_MARCH_SCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D scatteringOut;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, crep_march.sizes.xy))) return;
  vec4 ray = crep_pixelRay(crep_march, pixel, texelFetch(cameraDepth, pixel, 0).r);
  imageStore(scatteringOut, pixel, vec4(0.0, 0.0, 0.0, exp(-crep_march.extinction.w * ray.w)));
}
