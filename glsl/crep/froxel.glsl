// crepuscular: the froxel volume's coordinates (crep/scatter/froxel_grid.h; Wronski 2014, frustum-aligned
// cells with exponential depth slices). Public include.
//
// uvw in [0, 1]^3: (u, v) = ((ndc.x + 1) / 2, (ndc.y + 1) / 2) of the camera image, w = log(Z / near) /
// log(far / near) of view depth Z. `range` = (near, far) of the volume (FroxelDepthRange).
#ifndef CREP_FROXEL_GLSL
#define CREP_FROXEL_GLSL

// Slice coordinate w of view depth Z > 0.
float crep_froxelSliceCoord(vec2 range, float viewDepth) {
  return log(viewDepth / range.x) / log(range.y / range.x);
}

// View depth Z of slice coordinate w.
float crep_froxelViewDepth(vec2 range, float sliceCoord) {
  return range.x * exp2(sliceCoord * log2(range.y / range.x));
}

// The camera of a froxel pass (gpu::FroxelCamera, the vectors of gpu::GpuCamera): the ray through NDC (x, y)
// is normalize(forward + center + x right + y up), right and up scaled by the image's half extents.
struct CrepFroxelCamera {
  vec4 position; // xyz world; w near
  vec4 forward;  // xyz unit view direction; w integration far
  vec4 right;    // xyz right * half width at unit distance; w 0
  vec4 up;       // xyz up * half height at unit distance; w 0
  vec4 center;   // xyz the image centre's offset from forward (off-centre projections); w 0
};

// gpu::FroxelParams (std140, crep/postfx/gpu_froxel_fog.h): the frame block of the froxel fog passes.
struct CrepFroxelParams {
  CrepFroxelCamera camera;   // this frame's camera
  CrepFroxelCamera previous; // last frame's camera (temporal reprojection)
  vec4 cameraDepth;          // the depth convention (crep_cameraViewDepth): near, projection far, far, reversed
  vec4 range;                // x near, y far of the volume; z near, w far of last frame's volume
  ivec4 grid;                // xyz volume size (cells); w 1 = the history volume is valid
  vec4 jitter;               // xyz sample offset (cells); w history weight
  vec4 lightDirection;       // xyz direction the light travels; w 0
  vec4 lightIrradiance;      // rgb; w 0
  vec4 mieScattering;        // rgb sigma_s (Henyey-Greenstein part); w g
  vec4 rayleighScattering;   // rgb; w 0
  vec4 extinction;           // rgb sigma_t; w grey extinction sbar
  vec4 ambient;              // rgb isotropic ambient radiance; w 0
  vec4 density;              // x height base, y height falloff (0 = off), z noise amplitude, w noise frequency
  vec4 noiseOffset;          // xyz world units; w 0
  vec4 esm;                  // x exponent c, y bias, z 1 = shadowed by the ESM (else lit), w 0
  ivec4 sizes;               // xy shadow map or camera image, zw ESM
  ivec4 info;                // x ESM downsample factor, y blur radius, zw 0
  mat4 lightClipFromWorld;   // the standard shadow map's matrix
};

// Unit ray through volume coordinates (u, v) (NDC 2u - 1, 2v - 1).
vec3 crep_froxelRay(CrepFroxelCamera c, vec2 uv) {
  vec2 ndc = 2.0 * uv - 1.0;
  return normalize(c.forward.xyz + c.center.xyz + ndc.x * c.right.xyz + ndc.y * c.up.xyz);
}

// crep::froxelWorldPoint: the point at view depth Z(w) on the ray through (u, v).
vec3 crep_froxelWorldPoint(CrepFroxelCamera c, vec2 range, vec3 uvw) {
  vec3 ray = crep_froxelRay(c, uvw.xy);
  return c.position.xyz + ray * (crep_froxelViewDepth(range, uvw.z) / dot(ray, c.forward.xyz));
}

// crep::froxelCoord: uvw of world point p in camera c's volume; z = -1e30 behind the camera.
vec3 crep_froxelCoord(CrepFroxelCamera c, vec2 range, vec3 p) {
  vec3 d = p - c.position.xyz;
  float z = dot(d, c.forward.xyz);
  if (!(z > 0.0)) return vec3(0.0, 0.0, -1e30);
  vec3 q = d / z - c.forward.xyz - c.center.xyz; // = ndc.x right + ndc.y up
  vec2 ndc = vec2(dot(q, c.right.xyz) / dot(c.right.xyz, c.right.xyz), dot(q, c.up.xyz) / dot(c.up.xyz, c.up.xyz));
  return vec3(0.5 * (ndc + 1.0), crep_froxelSliceCoord(range, z));
}

// lowbias32 (C. Wellons' 32-bit integer finalizer), as crep::froxelValueNoise.
uint crep_lowbias32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

float crep_froxelLattice(ivec3 i) {
  uint h = (uint(i.x) * 73856093u) ^ (uint(i.y) * 19349663u) ^ (uint(i.z) * 83492791u);
  return float(crep_lowbias32(h)) * (1.0 / 4294967296.0);
}

// crep::froxelValueNoise: value noise in [0, 1] at p (lattice units), smoothstep-weighted corners.
float crep_froxelValueNoise(vec3 p) {
  vec3 f = floor(p);
  vec3 t = p - f;
  vec3 s = t * t * (3.0 - 2.0 * t);
  ivec3 i = ivec3(f);
  float v000 = crep_froxelLattice(i), v100 = crep_froxelLattice(i + ivec3(1, 0, 0));
  float v010 = crep_froxelLattice(i + ivec3(0, 1, 0)), v110 = crep_froxelLattice(i + ivec3(1, 1, 0));
  float v001 = crep_froxelLattice(i + ivec3(0, 0, 1)), v101 = crep_froxelLattice(i + ivec3(1, 0, 1));
  float v011 = crep_froxelLattice(i + ivec3(0, 1, 1)), v111 = crep_froxelLattice(i + ivec3(1, 1, 1));
  float y0 = mix(mix(v000, v100, s.x), mix(v010, v110, s.x), s.y);
  float y1 = mix(mix(v001, v101, s.x), mix(v011, v111, s.x), s.y);
  return mix(y0, y1, s.z);
}

#endif
