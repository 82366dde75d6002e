#include "contact_sheet.h"

#include <crep/core/error.h>
#include <crep/support/png.h>

#include <stb_easy_font.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace crep::tool {

namespace {

/// Heat ramp stops in sRGB (black, purple, orange-red, yellow, pale yellow), like "inferno".
const std::array<glm::vec3, 5> kRamp = {glm::vec3(0.0f, 0.0f, 0.02f), glm::vec3(0.34f, 0.06f, 0.43f),
                                        glm::vec3(0.85f, 0.26f, 0.19f), glm::vec3(0.99f, 0.75f, 0.15f),
                                        glm::vec3(0.99f, 1.0f, 0.75f)};

/// The ramp at t in [0, 1] (clamped; NaN -> 0).
glm::vec3 ramp(double t) {
  t = (t > 0.0 ? std::min(t, 1.0) : 0.0) * double(kRamp.size() - 1);
  const int i = std::clamp(static_cast<int>(t), 0, static_cast<int>(kRamp.size()) - 2);
  const float f = static_cast<float>(t - i);
  const glm::vec3 srgb =
      kRamp[static_cast<std::size_t>(i)] * (1.0f - f) + kRamp[static_cast<std::size_t>(i) + 1] * f;
  return {srgbToLinear(srgb.x), srgbToLinear(srgb.y), srgbToLinear(srgb.z)};
}

void setTopDown(Image& image, int x, int y, const glm::vec3& rgb) {
  if (x < 0 || y < 0 || x >= image.width() || y >= image.height()) return;
  const int row = image.height() - 1 - y;
  for (int c = 0; c < 3; ++c)
    image.at(x, row, c) = rgb[c];
}

/// Copies `tile` (RGB(A), row 0 bottom) with its top-left corner at (x0, y0) from the top, with values
/// multiplied by exposure and clamped to [0, 1] (non-finite -> magenta).
void blit(Image& sheet, const Image& tile, int x0, int y0, double exposure) {
  for (int y = 0; y < tile.height(); ++y)
    for (int x = 0; x < tile.width(); ++x) {
      glm::vec3 v;
      bool finite = true;
      for (int c = 0; c < 3; ++c) {
        const float s = tile.at(x, y, std::min(c, tile.channels() - 1));
        finite = finite && std::isfinite(s);
        v[c] = static_cast<float>(std::clamp(double(s) * exposure, 0.0, 1.0));
      }
      setTopDown(sheet, x0 + x, y0 + (tile.height() - 1 - y), finite ? v : glm::vec3(1, 0, 1));
    }
}

} // namespace

Image heatMap(const Image& actual, const Image& reference, double peak, double amplification) {
  Image out(actual.width(), actual.height(), 3);
  const double scale = amplification / (peak > 0.0 ? peak : 1.0);
  for (int y = 0; y < actual.height(); ++y)
    for (int x = 0; x < actual.width(); ++x) {
      double e = 0.0;
      bool finite = true;
      for (int c = 0; c < 3; ++c) {
        const double a = actual.at(x, y, c), r = reference.at(x, y, c);
        finite = finite && std::isfinite(a) && std::isfinite(r);
        e = std::max(e, std::abs(a - r));
      }
      const glm::vec3 v = finite ? ramp(e * scale) : glm::vec3(1, 0, 1);
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = v[c];
    }
  return out;
}

Image resizeImage(const Image& image, int width, int height) {
  if (width == image.width() && height == image.height()) return image;
  Image out(width, height, image.channels());
  const double sx = double(image.width()) / width, sy = double(image.height()) / height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // Box filter over the source footprint (at least the nearest source pixel).
      const int x0 = static_cast<int>(std::floor(x * sx)), y0 = static_cast<int>(std::floor(y * sy));
      const int x1 = std::max(x0 + 1, static_cast<int>(std::ceil((x + 1) * sx)));
      const int y1 = std::max(y0 + 1, static_cast<int>(std::ceil((y + 1) * sy)));
      for (int c = 0; c < image.channels(); ++c) {
        double sum = 0.0;
        int n = 0;
        for (int v = y0; v < std::min(y1, image.height()); ++v)
          for (int u = x0; u < std::min(x1, image.width()); ++u, ++n)
            sum += image.at(u, v, c);
        out.at(x, y, c) = static_cast<float>(n ? sum / n : 0.0);
      }
    }
  return out;
}

namespace {
/// Printable ASCII only (the font's range); anything else becomes '?'.
std::string printable(const std::string& text) {
  std::string s = text;
  for (char& c : s)
    if (c < 32 || c > 126) c = '?';
  return s;
}
} // namespace

int textWidth(const std::string& text, int scale) {
  std::string copy = printable(text);
  return stb_easy_font_width(copy.data()) * scale;
}

int drawText(Image& image, int x, int y, const std::string& text, int scale, const glm::vec3& rgb) {
  std::vector<char> buffer(text.size() * 400 + 1024);
  std::string copy = printable(text);
  const int quads =
      stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
  struct Vertex {
    float x, y, z;
    unsigned char color[4];
  };
  static_assert(sizeof(Vertex) == 16, "stb_easy_font vertex layout");
  std::vector<Vertex> vertices(static_cast<std::size_t>(quads) * 4);
  std::copy_n(buffer.data(), vertices.size() * sizeof(Vertex), reinterpret_cast<char*>(vertices.data()));
  for (int q = 0; q < quads; ++q) {
    float minX = 1e9f, minY = 1e9f, maxX = -1e9f, maxY = -1e9f;
    for (int k = 0; k < 4; ++k) {
      const Vertex& v = vertices[static_cast<std::size_t>(4 * q + k)];
      minX = std::min(minX, v.x);
      maxX = std::max(maxX, v.x);
      minY = std::min(minY, v.y);
      maxY = std::max(maxY, v.y);
    }
    for (int py = static_cast<int>(std::lround(minY * scale));
         py < static_cast<int>(std::lround(maxY * scale)); ++py)
      for (int px = static_cast<int>(std::lround(minX * scale));
           px < static_cast<int>(std::lround(maxX * scale)); ++px)
        setTopDown(image, x + px, y + py, rgb);
  }
  return stb_easy_font_width(copy.data()) * scale;
}

namespace {
/// Greedy word wrap of `text` into lines at most `width` pixels wide at scale 1.
std::vector<std::string> wrap(const std::string& text, int width) {
  std::vector<std::string> lines;
  std::string line, word;
  auto flush = [&] {
    if (word.empty()) return;
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && textWidth(candidate, 1) > width) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
    word.clear();
    // A word wider than the line on its own: cut it where it fills the line.
    while (textWidth(line, 1) > width && line.size() > 1) {
      std::size_t fits = 1;
      while (fits + 1 < line.size() && textWidth(line.substr(0, fits + 1), 1) <= width)
        ++fits;
      lines.push_back(line.substr(0, fits));
      line = line.substr(fits);
    }
  };
  for (char c : text) {
    if (c == ' ')
      flush();
    else
      word += c;
  }
  flush();
  if (!line.empty()) lines.push_back(line);
  return lines;
}
} // namespace

namespace {
constexpr int kMargin = 8;

/// "20", "0.5", "1e+06": the amplification as the legend shows it.
std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// A tile's title: one line at scale 2 when it fits the tile, else wrapped to the tile at scale 1.
struct Label {
  std::vector<std::string> lines;
  int scale = 2;
  int height() const { return static_cast<int>(lines.size()) * 10 * scale; }
};
Label fitLabel(const std::string& title, int width) {
  if (textWidth(title, 2) <= width) return {{title}, 2};
  return {wrap(title, width), 1};
}
void drawLabel(Image& sheet, int x, int y, const Label& label, const glm::vec3& rgb) {
  for (const std::string& line : label.lines) {
    drawText(sheet, x, y, line, label.scale, rgb);
    y += 10 * label.scale;
  }
}
} // namespace

int sheetTileHeight(int tileWidth, glm::ivec2 imageSize) {
  const double h = std::round(double(tileWidth) * imageSize.y / std::max(1, imageSize.x));
  return static_cast<int>(std::clamp(h, 1.0, 1e9));
}

glm::ivec2 sheetSizeBound(int tileWidth, glm::ivec2 imageSize, int columns) {
  const long long width = kMargin + static_cast<long long>(columns) * (tileWidth + kMargin);
  const long long height = 2LL * sheetTileHeight(tileWidth, imageSize) + kSheetTextBound;
  return {static_cast<int>(std::min(width, 1LL << 30)), static_cast<int>(std::min(height, 1LL << 30))};
}

Image composeSheet(const std::string& header, const std::vector<SheetColumn>& columns, int tileWidth,
                   double exposure, double amplification) {
  if (columns.empty()) throw InvalidArgument("composeSheet.columns", "none", "must not be empty");
  if (tileWidth < 1)
    throw InvalidArgument("composeSheet.tileWidth", std::to_string(tileWidth), "must be >= 1");
  const int margin = kMargin, lineHeight = 10;
  const Image& first = columns.front().image;
  const int tileHeight = sheetTileHeight(tileWidth, {first.width(), first.height()});
  // Every title and text line fits its tile: titles shrink and wrap, lines wrap.
  std::vector<Label> titles;
  std::vector<std::vector<std::string>> texts;
  int titleHeight = 20;
  std::size_t maxLines = 0;
  for (const SheetColumn& c : columns) {
    titles.push_back(fitLabel(c.title, tileWidth));
    titleHeight = std::max(titleHeight, titles.back().height());
    std::vector<std::string> lines;
    for (const std::string& line : c.lines)
      for (std::string& part : wrap(line, tileWidth))
        lines.push_back(std::move(part));
    maxLines = std::max(maxLines, lines.size());
    texts.push_back(std::move(lines));
  }
  const int columnsCount = static_cast<int>(columns.size());
  const int width = margin + columnsCount * (tileWidth + margin);
  const std::vector<std::string> headerLines = wrap(header, width - 2 * margin);
  const std::vector<std::string> legendLines =
      wrap("top: composited image (exposure " + shortNumber(exposure) +
               "); middle: |error| of the in-scattering against the reference (max over RGB) / its peak x " +
               shortNumber(amplification) +
               "; bottom: metrics of the in-scattering, milliseconds per stage (wall clock, glFinish)",
           width - 2 * margin);
  const int headerHeight =
      2 * margin + static_cast<int>(headerLines.size() + legendLines.size()) * lineHeight;
  const int textHeight = titleHeight + static_cast<int>(maxLines) * lineHeight + margin;
  const int height = headerHeight + 2 * tileHeight + margin + textHeight + margin;
  Image sheet(width, height, 3, srgbToLinear(0.12f));
  const glm::vec3 white(1.0f), grey(srgbToLinear(0.7f));
  int headerY = margin;
  for (const std::string& line : headerLines) {
    drawText(sheet, margin, headerY, line, 1, white);
    headerY += lineHeight;
  }
  for (const std::string& line : legendLines) {
    drawText(sheet, margin, headerY, line, 1, grey);
    headerY += lineHeight;
  }
  for (int i = 0; i < columnsCount; ++i) {
    const SheetColumn& col = columns[static_cast<std::size_t>(i)];
    const int x0 = margin + i * (tileWidth + margin);
    int y = headerHeight;
    blit(sheet, resizeImage(col.image, tileWidth, tileHeight), x0, y, exposure);
    y += tileHeight + margin / 2;
    if (!col.heat.empty()) {
      blit(sheet, resizeImage(col.heat, tileWidth, tileHeight), x0, y, 1.0);
    } else {
      // Legend: the ramp from 0 to a peak / amplification.
      const int barTop = y + tileHeight / 2 - 8;
      for (int x = 0; x < tileWidth; ++x) {
        const glm::vec3 v = ramp(tileWidth > 1 ? double(x) / (tileWidth - 1) : 0.0);
        for (int dy = 0; dy < 16; ++dy)
          setTopDown(sheet, x0 + x, barTop + dy, v);
      }
      // Its caption above the bar and its ends below, each within the tile (narrow tiles: shorter
      // caption, the right end on a line of its own).
      std::vector<std::string> caption = wrap("error scale (reference: no error)", tileWidth);
      const int captionLines = std::max(1, (barTop - 4 - y) / lineHeight);
      if (static_cast<int>(caption.size()) > captionLines) caption = wrap("error scale", tileWidth);
      if (static_cast<int>(caption.size()) > captionLines)
        caption.resize(static_cast<std::size_t>(captionLines));
      int captionY = barTop - 4 - static_cast<int>(caption.size()) * lineHeight;
      for (const std::string& line : caption) {
        drawText(sheet, x0, captionY, line, 1, white);
        captionY += lineHeight;
      }
      drawText(sheet, x0, barTop + 20, "0", 1, white);
      std::string right = ">= peak / " + shortNumber(amplification);
      if (textWidth("0 ", 1) + textWidth(right, 1) > tileWidth)
        right = ">=peak/" + shortNumber(amplification);
      if (textWidth("0 ", 1) + textWidth(right, 1) <= tileWidth) {
        drawText(sheet, x0 + tileWidth - textWidth(right, 1), barTop + 20, right, 1, white);
      } else {
        int rightY = barTop + 20 + lineHeight;
        for (const std::string& line : wrap(right, tileWidth)) {
          drawText(sheet, x0, rightY, line, 1, white);
          rightY += lineHeight;
        }
      }
    }
    y += tileHeight + margin / 2;
    drawLabel(sheet, x0, y + 2, titles[static_cast<std::size_t>(i)], white);
    y += titleHeight;
    for (const std::string& line : texts[static_cast<std::size_t>(i)]) {
      drawText(sheet, x0, y, line, 1, grey);
      y += lineHeight;
    }
  }
  return sheet;
}

Image composeGridSheet(const std::string& header, const std::vector<SheetTile>& tiles, int tileWidth,
                       int columns) {
  if (tiles.empty()) throw InvalidArgument("composeGridSheet.tiles", "none", "must not be empty");
  if (tileWidth < 1)
    throw InvalidArgument("composeGridSheet.tileWidth", std::to_string(tileWidth), "must be >= 1");
  if (columns < 1) throw InvalidArgument("composeGridSheet.columns", std::to_string(columns), "must be >= 1");
  const int margin = kMargin, lineHeight = 10;
  const Image& first = tiles.front().image;
  const int tileHeight = sheetTileHeight(tileWidth, {first.width(), first.height()});
  const int count = static_cast<int>(tiles.size());
  columns = std::min(columns, count);
  const int rows = (count + columns - 1) / columns;
  const int width = margin + columns * (tileWidth + margin);
  const std::vector<std::string> headerLines = wrap(header, width - 2 * margin);
  const int headerHeight = 2 * margin + static_cast<int>(headerLines.size()) * lineHeight;
  std::vector<Label> titles;
  int titleHeight = 20;
  for (const SheetTile& tile : tiles) {
    titles.push_back(fitLabel(tile.title, tileWidth));
    titleHeight = std::max(titleHeight, titles.back().height());
  }
  const int cellHeight = tileHeight + margin / 2 + titleHeight + margin;
  Image sheet(width, headerHeight + rows * cellHeight, 3, srgbToLinear(0.12f));
  int y = margin;
  for (const std::string& line : headerLines) {
    drawText(sheet, margin, y, line, 1, glm::vec3(1.0f));
    y += lineHeight;
  }
  for (int i = 0; i < count; ++i) {
    const SheetTile& tile = tiles[static_cast<std::size_t>(i)];
    const int x0 = margin + (i % columns) * (tileWidth + margin),
              y0 = headerHeight + (i / columns) * cellHeight;
    blit(sheet, resizeImage(tile.image, tileWidth, tileHeight), x0, y0, 1.0);
    drawLabel(sheet, x0, y0 + tileHeight + margin / 2 + 2, titles[static_cast<std::size_t>(i)],
              glm::vec3(1.0f));
  }
  return sheet;
}

} // namespace crep::tool
