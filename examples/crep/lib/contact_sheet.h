// The contact sheet of `crep compare`: one column per method, its image on top, an amplified error
// heat map against the reference below, its metrics and stage timings printed underneath (text drawn
// with stb_easy_font's quads, rasterized here). Composed in linear RGB so that writePng (sRGB) shows
// the intended colours.
#pragma once

#include <crep/core/image.h>
#include <crep/support/image_compare.h>

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace crep::tool {

/// One column of the sheet.
struct SheetColumn {
  std::string title; ///< e.g. "prefilter"
  Image image;       ///< RGB(A) linear, what the method rendered (tone-mapped: clamp(v * exposure))
  Image heat;        ///< RGB linear heat map (heatMap()), or empty for the reference column
  std::vector<std::string> lines; ///< metrics and timings, one per line
};

/// |actual - reference| per pixel (max over RGB), divided by `peak` and multiplied by `amplification`,
/// through a black-purple-orange-yellow-white ramp (values >= 1 saturate). RGB linear, same size.
Image heatMap(const Image& actual, const Image& reference, double peak, double amplification);

/// Area-average downsampling (or nearest upsampling) to width x height.
Image resizeImage(const Image& image, int width, int height);

/// Draws `text` (ASCII) with stb_easy_font at pixel (x, y) from the top-left corner of `image` (3 or 4
/// channels, row 0 at the bottom as everywhere), `scale` pixels per font unit, colour `rgb` (linear).
/// Returns the width drawn in pixels.
int drawText(Image& image, int x, int y, const std::string& text, int scale, const glm::vec3& rgb);

/// Width in pixels of `text` drawn at `scale`.
int textWidth(const std::string& text, int scale);

/// Tile widths a sheet accepts (`crep compare --tile-width`).
constexpr int kMinTileWidth = 16, kMaxTileWidth = 4096;

/// Height of the image tiles of a sheet whose tiles are tileWidth wide, for images of imageSize (aspect
/// ratio kept, at least 1).
int sheetTileHeight(int tileWidth, glm::ivec2 imageSize);

/// The width of a sheet of `columns` columns of tiles tileWidth wide, and an upper bound of its height
/// (two tiles per column plus the text rows; the text is bounded by kSheetTextBound pixels for the
/// header, legend and a column's lines of `crep compare`).
glm::ivec2 sheetSizeBound(int tileWidth, glm::ivec2 imageSize, int columns);
constexpr int kSheetTextBound = 2048;

/// The sheet: a header line on top, then the columns (each tileWidth wide, images resized keeping the
/// aspect ratio), the heat map legend in the reference column's heat slot. RGB linear. Throws
/// InvalidArgument for no columns or tileWidth < 1 (any tileWidth >= 1 works; the tool asks for at
/// least kMinTileWidth so that the text fits).
Image composeSheet(const std::string& header, const std::vector<SheetColumn>& columns, int tileWidth,
                   double exposure, double amplification);

/// One labelled image of a grid sheet (composeGridSheet).
struct SheetTile {
  std::string title; ///< drawn under the image
  Image image;       ///< RGB(A) linear display values, clamped to [0, 1] (non-finite -> magenta)
};

/// A grid sheet (`crep render --tonemap all`): a header on top, then the tiles, `columns` per row, each
/// resized to tileWidth wide keeping the first tile's aspect ratio, its title underneath. RGB linear.
/// Throws InvalidArgument for no tiles, tileWidth < 1 or columns < 1.
Image composeGridSheet(const std::string& header, const std::vector<SheetTile>& tiles, int tileWidth,
                       int columns);

} // namespace crep::tool
