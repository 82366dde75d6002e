#version 450 core
// Epipolar sampling, stage 5: unwarping the samples to the target grid of (W / F) x (H / F) pixels
// (Yusov 2012, Sec. 6.6; rules and CPU reference: crep::unwarpSamples in
// crep/epipolar/epipolar_sampling.h). One thread per target pixel p: its point c = (p + 0.5) F (full
// resolution), its depth texel p F + F / 2 and view depth z_p; its continuous slice coordinate s
// (EpipolarLines::sliceOf: where the ray from the epipole through c leaves the screen, as a border
// parameter), the two nearest lines, on each the two samples around c's projection: 4 candidates, each
// with its bilinear weight times a bilateral depth test (|z_src - z_p| <= threshold z_p, valid samples
// only). Total weight <= 1e-4: the pixel is appended to the correction list and its output is not
// written (the evaluator writes it). The target coordinates (c.x, c.y, d, z_p) are written for every pixel.
//
// Real GPUs: 4 texel loads (Yusov's 2-fetch bilinear trick with a linear sampler is not needed with
// texelFetch-style loads here, and would mix the bilateral weights); float only; the exit point is found
// from c itself (not from the epipole, which may be 1e5 px away) so that it keeps float precision.
//
// Resources: MarchParams (uniform 0, camera depth map), EpipolarSamplingParams (uniform 1), line table
// (storage 0), correction list (storage 2), camera depth (texture unit 0), coordinates RGBA32F (image 0,
// read), samples RGBA32F (image 1, read), output RGBA32F (image 2, written), target coordinates RGBA32F
// (image 3, written).
#include "crep/bindings.h"
#include "crep/march.glsl"
#include "crep/sample_list.glsl"
#include "crep/epipolar_sampling.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_EPIPOLAR_SAMPLING_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, rgba32f) uniform readonly image2D coordinatesIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_SAMPLES_IN_IMAGE, rgba32f) uniform readonly image2D samplesIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, rgba32f) uniform writeonly image2D output_;
layout(binding = CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_OUT_IMAGE, rgba32f) uniform writeonly image2D targetCoordinatesOut;

// EpipolarLines::borderSigma: the border parameter of a border point X, on the side it is nearest to
// (ties: left, bottom, right, top).
float crep_borderSigma(vec2 X) {
  float W = crep_sampling.border.x, H = crep_sampling.border.y;
  vec4 dist = abs(vec4(X.x, X.y, W - X.x, H - X.y));
  float m = min(min(dist.x, dist.y), min(dist.z, dist.w));
  if (dist.x == m) return H - clamp(X.y, 0.0, H);
  if (dist.y == m) return H + clamp(X.x, 0.0, W);
  if (dist.z == m) return H + W + clamp(X.y, 0.0, H);
  return 2.0 * H + W + (W - clamp(X.x, 0.0, W));
}

// EpipolarLines::sliceOf(c) (the continuous slice coordinate, slice i at s = i); false within 1e-3 px of
// the epipole.
bool crep_sliceOf(vec2 c, out float s) {
  vec2 v = c - crep_sampling.epipole.xy;
  if (length(v) < 1e-3) return false;
  vec2 size = crep_sampling.border.xy;
  float t = 3.0e38; // from c: c lies inside the screen, so the exit is at t >= 0
  for (int a = 0; a < 2; ++a) {
    if (abs(v[a]) < 1e-12) continue;
    t = min(t, ((v[a] > 0.0 ? size[a] : 0.0) - c[a]) / v[a]);
  }
  float P = crep_sampling.border.z;
  float m = mod(crep_borderSigma(c + t * v) - crep_sampling.epipole.z, P), arc = crep_sampling.epipole.w;
  // Off screen, a point a rounding error before the arc's start belongs to the start, not the end.
  if (crep_sampling.border.w < 0.5 && m > arc && m - arc > P - m) m -= P;
  s = m / arc * float(crep_sampling.counts.x) - 0.5;
  return true;
}

vec4 sum = vec4(0.0);
float total = 0.0;

// The two candidates of line i around c, line weight lw (bilateral: valid samples within the threshold).
void crep_addLine(int i, float lw, vec2 c, float zp) {
  CrepEpipolarLine line = crep_lines[i];
  if (line.info.x < 0 || !(lw > 0.0)) return;
  int Ns = crep_sampling.counts.y;
  vec2 e0 = line.ends.xy, d = line.ends.zw - line.ends.xy;
  float u = clamp(dot(c - e0, d) / dot(d, d) * float(Ns - 1), 0.0, float(Ns - 1));
  int k0 = min(int(floor(u)), Ns - 2);
  float g = u - float(k0);
  for (int n = 0; n < 2; ++n) {
    int k = k0 + n;
    float w = lw * (n == 0 ? 1.0 - g : g);
    if (k > line.info.x) continue;
    float z = imageLoad(coordinatesIn, ivec2(k, i)).w;
    if (!(abs(z - zp) <= crep_sampling.thresholds.z * zp)) continue;
    sum += w * imageLoad(samplesIn, ivec2(k, i));
    total += w;
  }
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, crep_sampling.target.xy))) return;
  int F = crep_sampling.counts.w, N = crep_sampling.counts.x;
  vec2 c = (vec2(p) + 0.5) * float(F);
  float d = texelFetch(cameraDepth, p * F + F / 2, 0).r;
  float zp = crep_cameraViewDepth(d, crep_march.cameraDepth);
  imageStore(targetCoordinatesOut, p, vec4(c, d, zp));
  float s;
  if (crep_sliceOf(c, s)) {
    int i0, i1;
    float f;
    if (crep_sampling.border.w > 0.5) { // the epipole on screen: the lines go all around, wrap
      float fl = floor(s);
      f = s - fl;
      i0 = ((int(fl) % N) + N) % N;
      i1 = (i0 + 1) % N;
    } else if (s < 0.0) {
      i0 = i1 = 0;
      f = 0.0;
    } else if (s > float(N - 1)) {
      i0 = i1 = N - 1;
      f = 0.0;
    } else {
      float fl = floor(s);
      f = s - fl;
      i0 = int(fl);
      i1 = min(i0 + 1, N - 1);
    }
    crep_addLine(i0, 1.0 - f, c, zp);
    crep_addLine(i1, f, c, zp);
  }
  if (total <= 1e-4) {
    crep_listAppend(uvec2(p));
    return;
  }
  imageStore(output_, p, sum / total);
}
