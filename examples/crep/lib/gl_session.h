// The tool's GL context and the GL helpers of its commands (upload, readback, composite). The library
// itself never owns a context: this is the application side.
#pragma once

#include "timings.h"

#include <crep/core/image.h>
#include <crep/gpu/gl.h>

#include <cstdint>
#include <initializer_list>
#include <string>

namespace crep::tool {

struct FrameInputs;

/// The process-wide GL context of the tool (created on first call; never destroyed: destroying the last
/// context unloads Mesa's driver, after which LeakSanitizer cannot attribute the driver's own
/// allocations). `debug`: a debug context whose GL errors are recorded and reported by checkGlErrors().
/// Prints the renderer on stderr under `command`.
void ensureGlContext(const std::string& command, bool debug, StageTimings& timings);
/// GL_RENDERER of the tool's context ("" before ensureGlContext).
std::string glRenderer();
/// Throws GlError when the debug context reported an error since the last call.
void checkGlErrors(const char* what);

/// A GL_R32F texture holding channel 0 of `image` (nearest, clamp to edge); `parameter` names the
/// input in size errors.
gl::Handle uploadR32F(const Image& image, const char* parameter);
/// Reads an RGBA texture back (row 0 = bottom).
Image readRgba(std::uint32_t texture, int width, int height);
/// Runs a compositing compute program of the tool (8 x 8 groups, its uniforms already set) over a new
/// width x height RGBA32F texture at image unit 0, with `textures` bound at units 0, 1, ... (unbound after);
/// glFinish, then a GL error check naming `what`.
gl::Handle runImageProgram(std::uint32_t program, int width, int height,
                           std::initializer_list<std::uint32_t> textures, const char* what);
/// surface * exp(-sigma_t s) + in-scattering (glsl/passes/composite.comp), a new RGBA32F texture.
gl::Handle compositeImage(const FrameInputs& frame, std::uint32_t surfaceColor, std::uint32_t scattering);

/// sum.rgb += addend.rgb, sum.a kept (glsl/passes/add_scattering.comp): the lights of a frame add. Both
/// RGBA32F textures of the frame's size.
void addScattering(const FrameInputs& frame, std::uint32_t sum, std::uint32_t addend);

/// Throws crep::Error when `image` holds NaN or infinity (refuse to write a silently wrong image).
void requireFinite(const Image& image, const std::string& what);

} // namespace crep::tool
