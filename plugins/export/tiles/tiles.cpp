// The tile layout, the index and the VRTs (tiles.hpp).
#include "tiles.hpp"

#include <orogen/error.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace orogen::tiles_export {

std::string number(double v) {
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    return buffer;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

namespace {

std::string xml_text(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '&') out += "&amp;";
        else if (c == '<') out += "&lt;";
        else if (c == '>') out += "&gt;";
        else if (c == '"') out += "&quot;";
        else out += c;
    }
    return out;
}

const char* format_name(Format f) {
    return f == Format::png16 ? "png16" : f == Format::r16 ? "r16" : f == Format::r32 ? "r32" : "glb";
}

}  // namespace

Format format_named(const std::string& name) {
    if (name == "png16") return Format::png16;
    if (name == "r16") return Format::r16;
    if (name == "r32") return Format::r32;
    if (name == "glb") return Format::glb;
    throw BadInput("export:tiles: format must be png16, r16, r32 or glb, got \"" + name + "\"");
}

const char* extension(Format format) {
    return format == Format::png16 ? ".png" : format == Format::r16 ? ".r16" : format == Format::r32 ? ".r32" : ".glb";
}

std::vector<Tile> layout(int width, int height, int tile_size, const std::string& stem, Format format) {
    if (tile_size < 2) throw BadInput("export:tiles: tile_size must be 2 or more, got " + std::to_string(tile_size));
    if (width < 2 || height < 2) throw BadInput("export:tiles: the terrain needs at least 2 × 2 samples");
    const int step = tile_size - 1;  // neighbours share one row or column
    const int columns = (width - 2) / step + 1, rows = (height - 2) / step + 1;
    std::vector<Tile> tiles;
    tiles.reserve(std::size_t(columns) * std::size_t(rows));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < columns; ++c) {
            Tile t;
            t.column = c;
            t.row = r;
            t.x0 = c * step;
            t.y0 = r * step;
            t.width = std::min(tile_size, width - t.x0);
            t.height = std::min(tile_size, height - t.y0);
            t.file = stem + "_x" + std::to_string(c) + "_y" + std::to_string(r) + extension(format);
            tiles.push_back(std::move(t));
        }
    return tiles;
}

std::vector<float> cut(ConstGridView grid, const Tile& tile) {
    std::vector<float> out(std::size_t(tile.width) * std::size_t(tile.height));
    for (int y = 0; y < tile.height; ++y)
        std::copy(grid.row(tile.y0 + y) + tile.x0, grid.row(tile.y0 + y) + tile.x0 + tile.width,
                  out.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(tile.width)));
    return out;
}

std::string index_json(const Index& ix) {
    const bool quantised = ix.format != Format::r32;
    const double span = ix.range.high - ix.range.low;
    int columns = 0, rows = 0;
    for (const Tile& t : ix.tiles) {
        columns = std::max(columns, t.column + 1);
        rows = std::max(rows, t.row + 1);
    }
    std::ostringstream o;
    o << "{\n"
      << "  \"format\": " << json_string(format_name(ix.format)) << ",\n"
      << "  \"byte_order\": \"little-endian\",\n"
      << "  \"rows_run\": \"north to south\",\n"
      << "  \"width\": " << ix.width << ",\n"
      << "  \"height\": " << ix.height << ",\n"
      << "  \"cell_m\": " << number(ix.cell) << ",\n"
      << "  \"tile_size\": " << ix.tile_size << ",\n"
      << "  \"shared_edge_samples\": 1,\n"
      << "  \"columns\": " << columns << ",\n"
      << "  \"rows\": " << rows << ",\n";
    if (quantised) {
        o << "  \"height_low_m\": " << number(ix.range.low) << ",\n"
          << "  \"height_high_m\": " << number(ix.range.high) << ",\n"
          << "  \"metres_per_unit\": " << number(span / 65535.0)
          << ",\n"
          // Unreal maps 0..65535 to ±256 cm times Z scale / 100, and X/Y scale is the cell in cm; Unity's terrain
          // height is the whole range in metres.
          << "  \"unreal\": {\"x_scale\": " << number(ix.cell * 100.0) << ", \"y_scale\": " << number(ix.cell * 100.0)
          << ", \"z_scale\": " << number(span * 100.0 / 512.0)
          << ", \"z_location_cm\": " << number((ix.range.low + 0.5 * span) * 100.0) << "},\n"
          << "  \"unity\": {\"terrain_height_m\": " << number(span) << ", \"y_position_m\": " << number(ix.range.low)
          << ", \"tile_width_m\": " << number((ix.tile_size - 1) * ix.cell) << "},\n";
    }
    o << "  \"tiles\": [\n";
    for (std::size_t i = 0; i < ix.tiles.size(); ++i) {
        const Tile& t = ix.tiles[i];
        o << "    {\"file\": " << json_string(t.file) << ", \"column\": " << t.column << ", \"row\": " << t.row
          << ", \"x0\": " << t.x0 << ", \"y0\": " << t.y0 << ", \"width\": " << t.width << ", \"height\": " << t.height
          << ", \"origin_m\": [" << number(t.x0 * ix.cell) << ", " << number(t.y0 * ix.cell) << "]}"
          << (i + 1 < ix.tiles.size() ? "," : "") << "\n";
    }
    o << "  ]\n}\n";
    return o.str();
}

std::string raw_tile_vrt(const Index& ix, const Tile& t) {
    const int bytes = ix.format == Format::r32 ? 4 : 2;
    std::ostringstream o;
    o << "<VRTDataset rasterXSize=\"" << t.width << "\" rasterYSize=\"" << t.height << "\">\n"
      << "  <VRTRasterBand dataType=\"" << (bytes == 4 ? "Float32" : "UInt16")
      << "\" band=\"1\" subClass=\"VRTRawRasterBand\">\n"
      << "    <SourceFilename relativeToVRT=\"1\">" << xml_text(t.file) << "</SourceFilename>\n"
      << "    <ImageOffset>0</ImageOffset>\n"
      << "    <PixelOffset>" << bytes << "</PixelOffset>\n"
      << "    <LineOffset>" << bytes * t.width << "</LineOffset>\n"
      << "    <ByteOrder>LSB</ByteOrder>\n"
      << "  </VRTRasterBand>\n"
      << "</VRTDataset>\n";
    return o.str();
}

std::string mosaic_vrt(const Index& ix) {
    const bool quantised = ix.format != Format::r32;
    std::ostringstream o;
    o << "<VRTDataset rasterXSize=\"" << ix.width << "\" rasterYSize=\"" << ix.height
      << "\">\n"
      // x east, y north (GDAL's convention): the north-west corner at (0, 0), rows running south
      << "  <GeoTransform>0, " << number(ix.cell) << ", 0, 0, 0, " << number(-ix.cell) << "</GeoTransform>\n"
      << "  <VRTRasterBand dataType=\"" << (quantised ? "UInt16" : "Float32") << "\" band=\"1\">\n";
    if (quantised)
        o << "    <Offset>" << number(ix.range.low) << "</Offset>\n"
          << "    <Scale>" << number((ix.range.high - ix.range.low) / 65535.0) << "</Scale>\n";
    for (const Tile& t : ix.tiles) {
        const std::string source = ix.format == Format::png16 ? t.file : t.file + ".vrt";
        o << "    <SimpleSource>\n"
          << "      <SourceFilename relativeToVRT=\"1\">" << xml_text(source) << "</SourceFilename>\n"
          << "      <SourceBand>1</SourceBand>\n"
          << "      <SrcRect xOff=\"0\" yOff=\"0\" xSize=\"" << t.width << "\" ySize=\"" << t.height << "\"/>\n"
          << "      <DstRect xOff=\"" << t.x0 << "\" yOff=\"" << t.y0 << "\" xSize=\"" << t.width << "\" ySize=\""
          << t.height << "\"/>\n"
          << "    </SimpleSource>\n";
    }
    o << "  </VRTRasterBand>\n</VRTDataset>\n";
    return o.str();
}

}  // namespace orogen::tiles_export
