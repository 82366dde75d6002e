// crepuscular: the binding point of every resource of the library's shaders, named once for GLSL and
// C++ (this file is valid in both: only #define lines and comments). The passes include it
// ("crep/bindings.h") and declare `layout(binding = NAME)`; the host code that runs them includes it and
// binds with the same NAME. An engine that runs the passes with its own host code includes it too.
// Suffixes: _BINDING a buffer binding point (uniform or storage block), _UNIT a texture unit (sampler),
// _IMAGE an image unit. Names are CREP_<PASS>_<RESOURCE>_<SUFFIX>; one pass's resources of different
// kinds may share a number (GL has separate binding spaces per kind).
#ifndef CREP_BINDINGS_H
#define CREP_BINDINGS_H
// Vulkan, and the HLSL and MSL made from its SPIR-V (share/crepuscular/shaders, docs/PORTABLE_SHADERS.md):
// one descriptor set (0); a resource's binding is its number below plus the base of its kind, so GL's
// separate binding spaces stay apart. The numbers below stay under the next base.
#define CREP_VULKAN_UNIT_BASE     0  // combined image samplers (GL texture units)
#define CREP_VULKAN_IMAGE_BASE    16 // storage images (GL image units)
#define CREP_VULKAN_UNIFORM_BASE  24 // uniform blocks
#define CREP_VULKAN_STORAGE_BASE  32 // storage blocks

// crep/layout.glsl: the layout block and the epipolar slice table, unless a pass sets CREP_LAYOUT_BINDING /
// CREP_SLICES_BINDING (crep::LayoutBuffers::bind takes the same two numbers)
#define CREP_LAYOUT_DEFAULT_BINDING  1 // CrepProjectiveLayoutBlock or CrepEpipolarLayoutBlock (uniform)
#define CREP_SLICES_DEFAULT_BINDING  1 // the epipolar slice table (storage)
// crep/sample_list.glsl: the work list, unless a pass sets CREP_SAMPLE_LIST_BINDING
#define CREP_SAMPLE_LIST_DEFAULT_BINDING  2 // CrepSampleListBlock (storage)

// crep/scattering.glsl, crep/airlight.glsl, passes/prefilter/evaluate.comp, scattering_prefix.comp: the
// bindings of the evaluation, unless a pass sets the name without _DEFAULT (CREP_SCATTERING_BINDING, ...)
#define CREP_SCATTERING_DEFAULT_BINDING          0 // CrepScatteringBlock (uniform)
#define CREP_FILTERED_BASIS_DEFAULT_UNIT         0 // crep_filteredBasis
#define CREP_REGION_WEIGHTS_DEFAULT_BINDING      1 // CrepRegionWeightsBlock (storage; near-plane correction)
#define CREP_MEAN_COLOR_DEFAULT_UNIT             2 // crep_meanColor (light textures)
#define CREP_LOCAL_LIGHT_DEFAULT_BINDING         3 // CrepLocalLightBlock (uniform)
#define CREP_LOCAL_LIGHT_STORAGE_DEFAULT_BINDING 4 // CrepLocalLightBlock on Vulkan (storage)
#define CREP_AIRLIGHT_DEFAULT_UNIT               4 // crep_airlightTable
#define CREP_LOCAL_SECTION_DEFAULT_UNIT          5 // crep_localSections
#define CREP_VISIBILITY_TABLE_DEFAULT_UNIT       6 // crep_visibilityTable
#define CREP_SCATTERING_PREFIX_DEFAULT_UNIT      7 // crep_scatteringPrefix
#define CREP_EVALUATE_DEFAULT_BINDING            1 // CrepEvaluateBlock (uniform; evaluate.comp)
#define CREP_CAMERA_DEPTH_DEFAULT_UNIT           1 // cameraDepth (evaluate.comp)
#define CREP_TABLE_COEFFICIENTS_DEFAULT_BINDING  0 // CrepTableCoefficients (storage; scattering_prefix.comp)
// crep::EvaluatePass's layouts and work lists (the defaults above take 1 of both kinds): set as
// CREP_LAYOUT_BINDING, CREP_SLICES_BINDING and CREP_SAMPLE_LIST_BINDING
#define CREP_EVALUATE_LAYOUT_BINDING       2 // CrepProjectiveLayoutBlock or CrepEpipolarLayoutBlock (uniform)
#define CREP_EVALUATE_SLICES_BINDING       2 // the epipolar slice table (storage)
#define CREP_EVALUATE_SAMPLE_LIST_BINDING  3 // CrepSampleListBlock (storage)
// passes/pipeline/accumulate.comp
#define CREP_ACCUMULATE_ACCUMULATED_IMAGE  0 // crep_accumulated
#define CREP_ACCUMULATE_ADDEND_IMAGE       1 // crep_addend
// passes/pipeline/reverse_depth.comp
#define CREP_REVERSE_DEPTH_MAP_UNIT        0 // crep_reversedMap
#define CREP_REVERSE_DEPTH_OUT_IMAGE       0 // crep_depthOut

// passes/atmosphere/atmosphere.comp
#define CREP_ATMOSPHERE_MARCH_BINDING              0 // CrepMarchBlock
#define CREP_ATMOSPHERE_PARAMS_BINDING             2 // CrepAtmosphereBlock
#define CREP_ATMOSPHERE_CAMERA_DEPTH_UNIT          0 // cameraDepth
#define CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT   2 // opticalDepthTable
#define CREP_ATMOSPHERE_SINGLE_TABLE_UNIT          3 // singleTable
#define CREP_ATMOSPHERE_HIGHER_ORDERS_TABLE_UNIT   4 // higherOrdersTable
#define CREP_ATMOSPHERE_SINGLE_MIE_TABLE_UNIT      5 // singleMieTable
#define CREP_ATMOSPHERE_AMBIENT_TABLE_UNIT         7 // ambientTable
#define CREP_ATMOSPHERE_RECTIFIED_DEPTH_UNIT       1 // rectifiedDepth
#define CREP_ATMOSPHERE_MIN_MAX_BINDING            0 // CrepMinMaxBlock
#define CREP_ATMOSPHERE_PREFILTERED_UNIT           6 // prefiltered
#define CREP_ATMOSPHERE_VOLUME_RAYLEIGH_OUT_IMAGE  0 // volumeRayleighOut
#define CREP_ATMOSPHERE_VOLUME_MIE_OUT_IMAGE       1 // volumeMieOut
#define CREP_ATMOSPHERE_SKY_RAYLEIGH_OUT_IMAGE     0 // skyRayleighOut
#define CREP_ATMOSPHERE_SKY_MIE_OUT_IMAGE          1 // skyMieOut
#define CREP_ATMOSPHERE_INSCATTERING_OUT_IMAGE     0 // inscatteringOut
#define CREP_ATMOSPHERE_TRANSMITTANCE_OUT_IMAGE    1 // transmittanceOut
#define CREP_ATMOSPHERE_VOLUME_RAYLEIGH_UNIT       8 // volumeRayleigh
#define CREP_ATMOSPHERE_VOLUME_MIE_UNIT            9 // volumeMie
#define CREP_ATMOSPHERE_SKY_RAYLEIGH_UNIT         10 // skyRayleigh
#define CREP_ATMOSPHERE_SKY_MIE_UNIT              11 // skyMie

// passes/atmosphere/ambient.comp, passes/atmosphere/ms.comp, passes/atmosphere/optical_depth.comp,
//   passes/atmosphere/order.comp, passes/atmosphere/scattered.comp, passes/atmosphere/single.comp,
//   passes/atmosphere/sum.comp
#define CREP_ATMOSPHERE_TABLES_PARAMS_BINDING                 0 // CrepAtmosphereBlock
#define CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_UNIT            0 // crep_single
#define CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_MIE_UNIT        1 // crep_singleMie
#define CREP_ATMOSPHERE_TABLES_AMBIENT_HIGHER_ORDERS_UNIT     2 // crep_higherOrders
#define CREP_ATMOSPHERE_TABLES_AMBIENT_OUTPUT_IMAGE           0 // crep_ambient
#define CREP_ATMOSPHERE_TABLES_MS_OPTICAL_DEPTH_UNIT          0 // crep_opticalDepth
#define CREP_ATMOSPHERE_TABLES_MS_OUTPUT_IMAGE                0 // crep_output
#define CREP_ATMOSPHERE_TABLES_OPTICAL_DEPTH_OUTPUT_IMAGE     0 // crep_opticalDepth
#define CREP_ATMOSPHERE_TABLES_ORDER_SCATTERED_UNIT           0 // crep_scattered
#define CREP_ATMOSPHERE_TABLES_ORDER_OUTPUT_IMAGE             0 // crep_output
#define CREP_ATMOSPHERE_TABLES_SCATTERED_PREVIOUS_ORDER_UNIT  0 // crep_previousOrder
#define CREP_ATMOSPHERE_TABLES_SCATTERED_SINGLE_MIE_UNIT      1 // crep_singleMie
#define CREP_ATMOSPHERE_TABLES_SCATTERED_OPTICAL_DEPTH_UNIT   2 // crep_opticalDepth
#define CREP_ATMOSPHERE_TABLES_SCATTERED_OUTPUT_IMAGE         0 // crep_output
#define CREP_ATMOSPHERE_TABLES_SINGLE_OPTICAL_DEPTH_UNIT      0 // crep_opticalDepth
#define CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_IMAGE            0 // crep_output
#define CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_MIE_IMAGE        1 // crep_outputMie
#define CREP_ATMOSPHERE_TABLES_SINGLE_MS_LUT_UNIT             1 // crep_msLut
#define CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_HIGHER_IMAGE     2 // crep_outputHigher
#define CREP_ATMOSPHERE_TABLES_SUM_ACCUMULATOR_IMAGE          0 // crep_accumulator
#define CREP_ATMOSPHERE_TABLES_SUM_ADDEND_IMAGE               1 // crep_addend

// passes/pipeline/depth_downsample.comp
#define CREP_DEPTH_DOWNSAMPLE_FULL_DEPTH_UNIT  0 // crep_fullDepth
#define CREP_DEPTH_DOWNSAMPLE_LOW_DEPTH_IMAGE  0 // crep_lowDepth

// passes/pipeline/depth_upsample.comp
#define CREP_DEPTH_UPSAMPLE_LOW_UNIT         0 // crep_low
#define CREP_DEPTH_UPSAMPLE_LOW_DEPTH_UNIT   1 // crep_lowDepth
#define CREP_DEPTH_UPSAMPLE_FULL_DEPTH_UNIT  2 // crep_fullDepth
#define CREP_DEPTH_UPSAMPLE_OUTPUT_IMAGE     0 // crep_output

// crep/epipolar_sampling.glsl, passes/epipolar/coordinates.comp, passes/epipolar/interpolate.comp,
//   passes/epipolar/refine.comp, passes/epipolar/unwarp.comp, passes/epipolar/upscale.comp
#define CREP_EPIPOLAR_SAMPLING_PARAMS_BINDING                1 // CrepEpipolarSamplingBlock
#define CREP_EPIPOLAR_SAMPLING_LINES_BINDING                 0 // CrepEpipolarLinesBlock
#define CREP_EPIPOLAR_SAMPLING_MARCH_BINDING                 0 // CrepMarchBlock
#define CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT             0 // cameraDepth
#define CREP_EPIPOLAR_SAMPLING_COORDINATES_OUT_IMAGE         0 // coordinatesOut
#define CREP_EPIPOLAR_SAMPLING_UNSHADOWED_OUT_IMAGE          1 // unshadowedOut
#define CREP_EPIPOLAR_SAMPLING_SOURCES_IN_IMAGE              0 // sourcesIn
#define CREP_EPIPOLAR_SAMPLING_SAMPLES_IMAGE                 1 // samples
#define CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE          0 // coordinatesIn
#define CREP_EPIPOLAR_SAMPLING_UNSHADOWED_IN_IMAGE           1 // unshadowedIn
#define CREP_EPIPOLAR_SAMPLING_SOURCES_OUT_IMAGE             2 // sourcesOut
#define CREP_EPIPOLAR_SAMPLING_SAMPLES_IN_IMAGE              1 // samplesIn
#define CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE                  2 // output_
#define CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_OUT_IMAGE  3 // targetCoordinatesOut
#define CREP_EPIPOLAR_SAMPLING_TARGET_IN_IMAGE               0 // targetIn
#define CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_IN_IMAGE   1 // targetCoordinatesIn
#define CREP_EPIPOLAR_SAMPLING_FULL_COORDINATES_OUT_IMAGE    3 // fullCoordinatesOut

// passes/postfx/esm_blur.comp, passes/postfx/esm_downsample.comp
#define CREP_ESM_FROXEL_BINDING   0 // CrepFroxelBlock
#define CREP_ESM_IN_UNIT          0 // esmIn
#define CREP_ESM_OUT_IMAGE        0 // esmOut
#define CREP_ESM_SHADOW_MAP_UNIT  0 // shadowMap

// passes/prefilter/evaluate.comp
#define CREP_EVALUATE_FROXELS_OUT_IMAGE     0 // crep_froxelsOut
#define CREP_EVALUATE_SCATTERING_OUT_IMAGE  0 // crep_scatteringOut

// passes/postfx/froxel_accumulate.comp, passes/postfx/froxel_apply.comp,
//   passes/postfx/froxel_light.comp, passes/postfx/froxel_temporal.comp
#define CREP_FROXEL_PARAMS_BINDING        0 // CrepFroxelBlock
#define CREP_FROXEL_VOLUME_IMAGE          0 // volume
#define CREP_FROXEL_CAMERA_DEPTH_UNIT     0 // cameraDepth
#define CREP_FROXEL_INTEGRATED_UNIT       1 // integrated
#define CREP_FROXEL_SCATTERING_OUT_IMAGE  0 // scatteringOut
#define CREP_FROXEL_ESM_UNIT              0 // esm
#define CREP_FROXEL_LIGHTING_OUT_IMAGE    0 // lightingOut
#define CREP_FROXEL_CURRENT_UNIT          0 // current
#define CREP_FROXEL_HISTORY_UNIT          1 // history
#define CREP_FROXEL_BLENDED_OUT_IMAGE     0 // blendedOut

// passes/scatter/light_colors.comp
#define CREP_LIGHT_COLORS_LIGHT_TEXTURE_UNIT     0 // crep_lightTexture
#define CREP_LIGHT_COLORS_COLORS_OUT_IMAGE       0 // crep_colorsOut
#define CREP_LIGHT_COLORS_LIGHT_TEXTURE_BINDING  0 // CrepLightTextureBlock

// passes/epipolar/march_rectified.comp, passes/scatter/march_reference.comp
#define CREP_MARCH_PARAMS_BINDING         0 // CrepMarchBlock
#define CREP_MARCH_CAMERA_DEPTH_UNIT      0 // cameraDepth
#define CREP_MARCH_MAP_UNIT               1 // rectifiedDepth (rectified), shadowMap (reference)
#define CREP_MARCH_MIN_MAX_BINDING        0 // CrepMinMaxBlock
#define CREP_MARCH_LIGHT_COLORS_UNIT      2 // crep_lightColors
#define CREP_MARCH_SCATTERING_OUT_IMAGE   0 // scatteringOut
#define CREP_MARCH_STEPS_OUT_IMAGE        1 // stepsOut
#define CREP_MARCH_LIGHT_TEXTURE_BINDING  1 // CrepLightTextureBlock
#define CREP_MARCH_LIGHT_TEXTURE_UNIT     2 // crep_lightTexture

// passes/epipolar/minmax_build.comp
#define CREP_MIN_MAX_TREE_RECTIFIED_DEPTH_UNIT  0 // rectifiedDepth
#define CREP_MIN_MAX_TREE_MIN_MAX_BINDING       0 // CrepMinMaxBlock

// passes/prefilter/prefilter.comp
#define CREP_PREFILTER_RECTIFIED_DEPTH_UNIT      0 // crep_rectifiedDepth
#define CREP_PREFILTER_FILTERED_BASIS_OUT_IMAGE  0 // crep_filteredBasisOut
#define CREP_PREFILTER_PARAMS_BINDING            0 // CrepPrefilterBlock
#define CREP_PREFILTER_REGION_WEIGHTS_BINDING    0 // CrepRegionWeightsBlock
#define CREP_PREFILTER_LIGHT_COLORS_UNIT         1 // crep_lightColors
#define CREP_PREFILTER_MEAN_COLOR_OUT_IMAGE      1 // crep_meanColorOut
#define CREP_PREFILTER_LOCAL_LIGHT_BINDING       1 // CrepLocalLightBlock
#define CREP_PREFILTER_REGION_RAYS_BINDING       1 // CrepRegionRaysBlock

// passes/postfx/radial_blur.comp, passes/postfx/radial_source.comp
#define CREP_RADIAL_MARCH_BINDING         0 // CrepMarchBlock
#define CREP_RADIAL_BLUR_BINDING          1 // CrepRadialBlurBlock
#define CREP_RADIAL_CAMERA_DEPTH_UNIT     0 // cameraDepth
#define CREP_RADIAL_SOURCE_UNIT           1 // radialSource
#define CREP_RADIAL_SCATTERING_OUT_IMAGE  0 // scatteringOut
#define CREP_RADIAL_SOURCE_OUT_IMAGE      0 // sourceOut

// passes/epipolar/resample.comp
#define CREP_RESAMPLE_MIN_MAX_BINDING      0 // CrepMinMaxBlock
#define CREP_RESAMPLE_MARCH_BINDING        0 // CrepMarchBlock
#define CREP_RESAMPLE_SHADOW_MAP_UNIT      0 // shadowMap
#define CREP_RESAMPLE_RECTIFIED_OUT_IMAGE  0 // rectifiedOut

// passes/prefilter/scattering_prefix.comp
#define CREP_SCATTERING_PREFIX_PREFIX_OUT_IMAGE   0 // crep_prefixOut
#define CREP_SCATTERING_PREFIX_SECTION_OUT_IMAGE  1 // crep_sectionOut

// passes/postfx/luminance_adapt.comp, passes/postfx/luminance_reduce.comp, passes/postfx/tone_map.comp
#define CREP_TONE_MAP_PARAMS_BINDING              0 // CrepToneMapBlock
#define CREP_TONE_MAP_LUMINANCE_PARTIALS_BINDING  0 // CrepLuminancePartials
#define CREP_TONE_MAP_STATE_BINDING               1 // CrepToneMapStateBlock
#define CREP_TONE_MAP_HDR_UNIT                    0 // crep_hdr
#define CREP_TONE_MAP_DISPLAY_IMAGE               0 // crep_display

// passes/prefilter/visibility_table.comp
#define CREP_VISIBILITY_TABLE_BASIS_UNIT                  0 // crep_basis
#define CREP_VISIBILITY_TABLE_TABLE_OUT_IMAGE             0 // crep_tableOut
#define CREP_VISIBILITY_TABLE_TABLE_COEFFICIENTS_BINDING  0 // CrepTableCoefficients

#endif // CREP_BINDINGS_H
