#pragma once
// An image cut into square tiles, numbered row by row; the tiles of the last column and row are
// cut by the image's edges. The raster draws tile by tile, the ray route traces region by
// region and the comparison compares tile by tile on such grids: a check that does all three
// for one tile at a time (Checker, keepPixels = false) relies on their tiles being the same
// rectangles, and this is the one place that says which pixels a tile holds.
//
//   const zcheck::TileGrid grid(width, height, 64);
//   for (int tile = 0; tile < grid.count(); ++tile) {
//       const zcheck::PixelRect r = grid.rect(tile);       // pixels [col0, col1) × [row0, row1)
//       double* first = image + grid.firstPixel(tile);     // row-major, width entries per row
//   }
#include <cstddef>

namespace zcheck {

// The pixels [col0, col1) × [row0, row1).
struct PixelRect {
    int col0, row0, col1, row1;

    int width() const { return col1 - col0; }
    int height() const { return row1 - row0; }
};

class TileGrid {
public:
    // width, height ≥ 1 pixels; side ≥ 1 pixels per tile side.
    TileGrid(int width, int height, int side)
        : width_(width), height_(height), side_(side), tilesX_((width + side - 1) / side), tilesY_((height + side - 1) / side)
    {
    }

    int tilesX() const { return tilesX_; }
    int tilesY() const { return tilesY_; }
    int count() const { return tilesX_ * tilesY_; }

    // The tile's pixels, cut by the image's edges.
    PixelRect rect(int tile) const
    {
        const int col0 = (tile % tilesX_) * side_, row0 = (tile / tilesX_) * side_;
        return {col0, row0, col0 + side_ < width_ ? col0 + side_ : width_, row0 + side_ < height_ ? row0 + side_ : height_};
    }
    // The row-major index, in a width-wide image, of the tile's top-left pixel.
    std::size_t firstPixel(int tile) const
    {
        const PixelRect r = rect(tile);
        return std::size_t(r.row0) * std::size_t(width_) + std::size_t(r.col0);
    }

private:
    int width_, height_, side_, tilesX_, tilesY_;
};

}  // namespace zcheck
