// JSON form of a rectification (see crep/rectify/json.h).
#include <crep/rectify/json.h>

#include <cmath>
#include <cstdio>

namespace crep {

namespace {
void appendNumber(std::string& out, double v) {
  // Finite by construction; guard anyway so the output is always valid JSON.
  if (!std::isfinite(v)) v = 0.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out += buf;
}
} // namespace

std::string toJson(const Rectification& r) {
  std::string out = "{\"status\": \"";
  out += statusToken(r.status);
  out += "\", \"reason\": \"";
  out += reasonToken(r.reason);
  out += "\", \"measure\": ";
  appendNumber(out, r.measure);
  out += ", \"threshold\": ";
  appendNumber(out, r.threshold);
  out += ", \"splits\": [";
  for (std::size_t k = 0; k < r.splits.size(); ++k) {
    const Split& s = r.splits[k];
    out += k ? ", " : "";
    out += "{\"rectClipFromWorld\": [";
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row) {
        if (col || row) out += ", ";
        appendNumber(out, s.rectClipFromWorld[col][row]);
      }
    out += "], \"range\": [";
    appendNumber(out, s.rangeBegin);
    out += ", ";
    appendNumber(out, s.rangeEnd);
    out += "]}";
  }
  out += "]}";
  return out;
}

} // namespace crep
