// tiles.hpp — a heightmap cut into tiles for game engines and GIS: each tile a
// 16-bit PNG, a .r16 or a .r32, neighbouring tiles sharing their edge row or
// column (the same samples, bit for bit, as Unreal's World Partition and
// Unity's terrain tiles expect: a seam is then impossible), one height scale
// for all of them, a JSON index, and a GDAL VRT that mosaics them back into
// one raster.
//
// Tiles are tile_size samples a side (Unreal's landscape sizes: 127, 253, 505,
// 1009, 2017, 4033; Unity's 2^n + 1) and start every tile_size − 1 samples,
// so a W-sample row holds ceil((W − 1) / (tile_size − 1)) tiles; the last tile
// of a row or column is smaller when W − 1 is not a multiple of tile_size − 1.
#pragma once

#include <orogen/formats/raw.hpp>

#include <orogen/grid.hpp>

#include <string>
#include <vector>

namespace orogen::tiles_export {

/// glb: the chunked level-of-detail pyramid of lod.hpp, with a 3D Tiles tileset as the index.
enum class Format { png16, r16, r32, glb };
Format format_named(const std::string& name);  ///< "png16", "r16", "r32", "glb"; throws orogen::BadInput
const char* extension(Format format);  ///< ".png", ".r16", ".r32", ".glb"

/// A double as JSON, exactly (%.17g), and a string as a JSON string.
std::string number(double v);
std::string json_string(const std::string& s);

/// One tile: its samples (x0, y0) .. (x0 + width − 1, y0 + height − 1) of the whole grid.
struct Tile {
    int column = 0, row = 0;
    int x0 = 0, y0 = 0, width = 0, height = 0;
    std::string file;  ///< name, relative to the index's folder
};

/// The tiles of a width × height grid, row by row from the north-west; files named <stem>_x<column>_y<row><ext>.
std::vector<Tile> layout(int width, int height, int tile_size, const std::string& stem, Format format);

/// The samples of one tile, row-major.
std::vector<float> cut(ConstGridView grid, const Tile& tile);

struct Index {
    Format format = Format::png16;
    int width = 0, height = 0, tile_size = 0;
    double cell = 1.0;  ///< m
    formats::raw::Range range;  ///< png16 / r16: the heights of 0 and 65535, m (the same for every tile)
    std::vector<Tile> tiles;
};

/// The index (JSON): sizes, cell, height scale, the engines' scale settings, every tile's file and place.
std::string index_json(const Index& index);

/// A GDAL VRT mosaicking the tiles into one width × height raster (band 1; png16 and r16 with offset and scale
/// so GDAL's unscaled values are metres). RAW tiles are referenced through `raw_tile_vrt` files beside them.
std::string mosaic_vrt(const Index& index);
/// A VRT that lets GDAL read one headerless RAW tile (VRTRawRasterBand, little-endian).
std::string raw_tile_vrt(const Index& index, const Tile& tile);

}  // namespace orogen::tiles_export
