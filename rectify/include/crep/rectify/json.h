// JSON form of a rectification, as printed by `crep rectify` (the interface the tool exposes).
#pragma once

#include <string>

#include <crep/rectify/rectify.h>

namespace crep {

/// One JSON object, exactly:
///   {"status": "projective" | "fallback" | "empty", "reason": "<reasonToken(reason)>",
///    "measure": <degrees>, "threshold": <degrees>,
///    "splits": [{"rectClipFromWorld": [16 numbers, column-major as in GLSL], "range": [begin, end]}, ...]}
/// "splits" is empty unless projective ("empty" only for spot / point light faces). Numbers are printed
/// with 17 significant digits (they round-trip to the same doubles); no NaN or Inf can occur.
std::string toJson(const Rectification& rectification);

} // namespace crep
