// crepuscular: the blocks shared with C++ by the prefiltered-scattering passes, member for member the
// structs of crep/prefilter/gpu_structs.h (std140 uniform blocks, one std430 storage buffer; the GL
// test PrefilterGpuStructsGLTest checks the offsets). Units and meanings are documented there.
//
// Public include (see crep/common.glsl); crep/scattering.glsl includes it.
#ifndef CREP_SCATTERING_STRUCTS_GLSL
#define CREP_SCATTERING_STRUCTS_GLSL

// gpu::kMaxSplits
#define CREP_MAX_SPLITS 64

// crep::WeightMode values (weights.h), CrepScatteringParams.basisInfo.w / CrepPrefilterParams.basisInfo.z.
#define CREP_WEIGHTS_AVERAGE_VISIBILITY 0
#define CREP_WEIGHTS_CONSTANT_STEP 1
#define CREP_WEIGHTS_CONSTANT_RATIO 2
#define CREP_WEIGHTS_EXACT 3

// gpu::ScatteringParams (std140).
struct CrepScatteringParams {
  vec4 frameOrigin;        // xyz camera position; w 0
  vec4 frameAxisX;         // xyz projection axis; w rho
  vec4 frameAxisY;         // xyz; w 0
  vec4 frameAxisZ;         // xyz light direction at the camera; w 0
  vec4 slopes;             // row slope min, 1 / row range, depth slope min, 1 / depth range
  vec4 extinction;         // rgb sigma_t; w weight extinction s
  vec4 mieScattering;      // rgb; w Henyey-Greenstein g
  vec4 rayleighScattering; // rgb; w 0
  vec4 lightIrradiance;    // rgb; w 0
  vec4 lightDirection;     // xyz; w 0
  ivec4 mapSize;           // W, H, regions R, layout regions K
  ivec4 basisInfo;         // M, layers, regions per split P, weight mode
  vec4 depthMargin;        // x m
  vec4 splitZeta[CREP_MAX_SPLITS]; // x zetaBegin, y zetaEnd
};

// gpu::RegionWeights (std430, 16 bytes).
struct CrepRegionWeights {
  float scale;
  float c;
  float d;
  int valid;
};

// gpu::PrefilterParams (std140).
struct CrepPrefilterParams {
  ivec4 mapSize;   // W, H, regions R, texels per region n
  ivec4 basisInfo; // M, bases per invocation, weight mode, 0
  vec4 weights;    // weight extinction s, depth margin m, 0, 0
};

// gpu::LocalLightParams (std140).
struct CrepLocalLightParams {
  vec4 origin;             // xyz camera position; w grey extinction s
  vec4 position;           // xyz light position; w near plane
  vec4 axis;               // xyz spot or face axis; w point face 0-5, -1 none
  vec4 cone;               // x cos inner, y cos outer, z 1 = spot falloff, w prefilter weights (0 full, 1 angular, 2 none)
  vec4 intensity;          // rgb radiant intensity
  vec4 mieScattering;      // rgb; w Henyey-Greenstein g
  vec4 rayleighScattering; // rgb
};

// gpu::EvaluateParams (std140).
struct CrepEvaluateParams {
  vec4 cameraPosition; // xyz; w near
  vec4 cameraForward;  // xyz; w far
  vec4 cameraRight;    // xyz right * tan(fovY / 2) * aspect
  vec4 cameraUp;       // xyz up * tan(fovY / 2)
  ivec4 imageSize;     // xy
  vec4 cameraCenter;   // xyz the image centre's offset from forward (off-centre projections); w 0
  vec4 cameraDepth;    // depth convention: x near, y projection far (0 = infinite), z integration far, w reversed
};

#endif // CREP_SCATTERING_STRUCTS_GLSL
