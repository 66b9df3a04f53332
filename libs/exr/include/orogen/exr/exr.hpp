// exr.hpp — heightmaps as OpenEXR, the film and VFX pipelines' float image format (Houdini, Nuke,
// Gaea's and World Machine's float exports, Blender).
//
// Writing (OpenEXR's C++ API): one single-part scanline file, 32-bit float channels, the heights in the
// channel `channel` (default "Y", which viewers show as grayscale) and each layer in a channel named after
// it; or one such file per layer. Lossless compression only (none, rle, zips, zip, piz). Rows run north
// to south (EXR's y grows downwards), the data window is (0, 0)–(width − 1, height − 1). The header
// carries two custom attributes: `cellSize` (double, metres between vertices) and `heightUnits`
// (string, "m"); a file of one layer also `orogenLayer` (string: "height" or the layer's name).
//
// Reading (OpenEXRCore, the C API built for untrusted files): a single-part scanline or tiled file, one
// float or half channel as heights (half converts exactly), optionally others as layers. Everything is
// checked before the image is allocated: the header, the channel's type and sampling, the declared size
// against the memory budget (orogen::heightmap_memory_problem), and every chunk of the part against the
// file — each must lie inside it, none may overlap another, and together they must be big enough to hold
// what they claim to decompress to (at most 1032:1 for zlib, 64:1 for RLE, 1:1 uncompressed). So a
// truncated, forged or hostile file fails with one message before anything large is allocated; OpenEXR's
// own allocations are capped as well (by the file's size while the header is parsed).
//
// The only place OpenEXR's headers are included is exr.cpp.
#pragma once

#include <orogen/error.hpp>
#include <orogen/grid.hpp>
#include <orogen/values.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace orogen::exr {

enum class Compression { none, rle, zips, zip, piz };
/// "none" | "rle" | "zips" | "zip" | "piz"; throws orogen::BadInput naming them for anything else.
Compression parse_compression(const std::string& name);

/// One channel's data: `width` × `height` floats, rows north to south.
struct Plane {
    std::string channel;
    const float* data = nullptr;
};

struct WriteOptions {
    Compression compression = Compression::zip;
    double cell = 1.0;  ///< written as the cellSize attribute (metres)
    std::string layer;  ///< written as orogenLayer if not empty (one-layer files)
    int threads = 1;  ///< compression threads (OpenEXR's pool); the bytes do not depend on it
};

/// Writes `planes` (each width × height floats) as FLOAT channels of one scanline EXR at `path` (a temporary
/// name: the caller renames it). Channel names must be distinct and non-empty. Throws orogen::Error with
/// OpenEXR's message if the file cannot be written. The bytes depend only on the arguments.
void write(const std::filesystem::path& path, int width, int height, std::span<const Plane> planes,
           const WriteOptions& options);

/// "" if `name` can be a channel name, else why not (for check time).
std::string channel_name_problem(const std::string& name);

// ------------------------------------------------------------------ reading

enum class SampleType { uint32, half, float32 };
std::string to_string(SampleType type);

struct ChannelInfo {
    std::string name;
    SampleType type = SampleType::float32;
    int x_sampling = 1, y_sampling = 1;
};

/// What an EXR file declares, checked (see the file comment) but without its samples.
struct FileInfo {
    int width = 0, height = 0;
    std::vector<ChannelInfo> channels;  ///< as the file lists them (alphabetical)
    std::optional<double> cell;  ///< the cellSize attribute, metres, if present
    std::string height_units;  ///< the heightUnits attribute, "" if absent
    std::string compression;  ///< "zip", "piz"...
    bool tiled = false;
    const ChannelInfo* find(const std::string& name) const;
    std::string channel_list() const;  ///< "A, B, Y" — for messages
};

struct ReadOptions {
    std::string channel = "Y";  ///< read as the heights
    std::vector<std::string> layers;  ///< channels read as layers of the same name
    bool all_layers = false;  ///< every other readable channel as a layer
    double cell = 0.0;  ///< metres; 0 = the cellSize attribute
};

/// A BadInput about the channels asked for; `param` names the parameter to blame ("channel" or "layers").
class ChannelError : public BadInput {
public:
    ChannelError(std::string message, std::string param);
    std::string param;
};

/// The file's header and chunk layout, checked for reading `options` (the channels exist and are float or
/// half with no subsampling, the size fits the memory budget, the chunks fit the file). Throws orogen::BadInput naming the file and what is wrong (ChannelError for the channels).
FileInfo probe(const std::filesystem::path& path, const ReadOptions& options);
/// probe(), then the samples. Throws orogen::BadInput without a cell size (options.cell 0 and no cellSize
/// attribute) and for a non-finite sample (naming the first).
std::shared_ptr<Heightmap> read(const std::filesystem::path& path, const ReadOptions& options);

/// The same two on bytes in memory; `name` is for messages only (the fuzz target, tests).
FileInfo probe_bytes(std::span<const std::uint8_t> bytes, const std::string& name, const ReadOptions& options);
std::shared_ptr<Heightmap> read_bytes(std::span<const std::uint8_t> bytes, const std::string& name,
                                      const ReadOptions& options);

}  // namespace orogen::exr
