// export:tiles — registers the tiled heightmap writer (tiles.hpp) with the kernel.
#include "tiles.hpp"

#include <orogen/gltf/gltf_writer.hpp>
#include "lod.hpp"
#include <orogen/mesh/terrain_mesh.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>
#include <orogen/tiles.hpp>

#include <cstring>
#include <filesystem>
#include <limits>

namespace {

using namespace orogen;
using namespace orogen::tiles_export;

void check(CheckContext& ctx) {
    if (ctx.text("format") == "glb") {
        for (const char* raster : {"low", "high", "compression", "vrt"})
            if (ctx.given(raster))
                ctx.error(raster,
                          std::string(raster) +
                              " applies to the raster formats (png16, r16, r32); format=glb "
                              "writes meshes in metres (see scale)");
        return;
    }
    for (const char* mesh : {"scale", "texture", "skirts"})
        if (ctx.given(mesh))
            ctx.error(mesh, std::string(mesh) + " applies to format=glb (the meshes); the raster formats ignore it");
    const bool low = ctx.given("low"), high = ctx.given("high");
    if (low != high)
        ctx.error(low ? "low" : "high",
                  "give both low and high (the heights written as 0 and 65535), or neither "
                  "to use the terrain's own lowest and highest point");
    else if (low && !(ctx.real("high") > ctx.real("low"))) ctx.error("high", "high must be above low");
    if ((low || high) && ctx.text("format") == "r32")  // reported with the above: every mistake at once
        ctx.error(low ? "low" : "high", "low and high set the 16-bit scale; format=r32 writes metres as they are");
}

/// The heights at a lattice of the whole grid: from the ranks that hold them (collective) or, in one
/// process, from the grid itself.
lod::Samples sample(const Heightmap& hm, Tiling* tiling, AxisSamples columns, AxisSamples rows) {
    lod::Samples s;
    for (int i = 0; i < columns.size(); ++i) s.xs.push_back(columns.at(i));
    for (int j = 0; j < rows.size(); ++j) s.ys.push_back(rows.at(j));
    if (tiling) {
        s.h = tiling->fetch_samples(hm.heights().data(), columns, rows);
    } else {
        s.h.reserve(s.xs.size() * s.ys.size());
        const ConstGridView g = hm.view();
        for (int y : s.ys)
            for (int x : s.xs) s.h.push_back(g.at(x, y));
    }
    return s;
}

/// format=glb: the chunked level-of-detail pyramid (lod.hpp), each chunk a .glb, the index a 3D Tiles
/// tileset. In a tiled run each rank writes the chunks whose middle sample lies in its tile, fetching the
/// samples they are made of from the ranks that hold them; rank 0 writes the tileset.
NodeOutputs run_pyramid(NodeContext& ctx, const Heightmap& hm, Tiling* tiling) {
    const int rank = tiling ? tiling->rank() : 0;
    const int width = tiling ? tiling->grid_width() : hm.width();
    const int height = tiling ? tiling->grid_height() : hm.height();
    const double cell = hm.cell(), scale = ctx.real("scale");
    const int tile_size = int(ctx.integer("tile_size")), texture = int(ctx.integer("texture"));
    const bool skirts = ctx.flag("skirts");
    const std::filesystem::path index_path = ctx.text("path");
    const std::filesystem::path folder = index_path.parent_path();
    if (width < 2 || height < 2) throw BadInput("export:tiles: the terrain needs at least 2 × 2 samples");
    const formats::raw::Range range = formats::raw::min_max(hm.view());
    float lo = float(range.low), hi = float(range.high);
    if (tiling) {  // the whole grid's (float minima and maxima are exact in any order)
        lo = tiling->reduce(lo, Tiling::Reduce::min);
        hi = tiling->reduce(hi, Tiling::Reduce::max);
    }

    const std::vector<lod::Chunk> chunks = lod::pyramid(width, height, tile_size, index_path.stem().string());
    const int levels = chunks.back().level + 1;
    std::vector<std::size_t> mine;  // indices into chunks
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        const lod::Chunk& c = chunks[i];
        if (!tiling || tiling->rank_at(c.x0 + (c.x1 - c.x0) / 2, c.y0 + (c.y1 - c.y0) / 2) == rank) mine.push_back(i);
    }
    std::vector<std::filesystem::path> targets;
    for (std::size_t i : mine) targets.push_back(ctx.output_path((folder / chunks[i].file).string()));
    // Every rank takes part in as many fetches as the rank with the most chunks.
    float most = float(mine.size());
    if (tiling) most = tiling->reduce(most, Tiling::Reduce::max);
    // Per chunk, for the tileset: deviation, min x y z, max x y z (floats: a maximum over the ranks
    // merges them exactly; one process rounds them the same way).
    constexpr int kInfo = 7;
    std::vector<float> info(chunks.size() * kInfo, -std::numeric_limits<float>::infinity());
    constexpr std::size_t kGroup = 8;  // chunks fetched, then meshed and written in parallel
    const std::size_t rounds = std::size_t(most);
    for (std::size_t first = 0; first < rounds; first += kGroup) {
        ctx.check_cancelled();
        const std::size_t end = std::min(first + kGroup, rounds);
        struct Work {
            std::size_t chunk;
            lod::Samples area, rows, columns;
        };
        std::vector<Work> work;
        for (std::size_t r = first; r < end; ++r) {
            if (r < mine.size()) {
                const lod::Chunk& c = chunks[mine[r]];
                const auto area = lod::chunk_lattice(c, width, height);
                const auto edges = lod::edge_lattices(c, width, height, levels);
                Work w{mine[r], sample(hm, tiling, area[0], area[1]), sample(hm, tiling, edges[0][0], edges[0][1]),
                       sample(hm, tiling, edges[1][0], edges[1][1])};
                work.push_back(std::move(w));
            } else if (tiling) {  // nothing of its own to write this round: serve the others
                for (int k = 0; k < 3; ++k) tiling->fetch_samples(hm.heights().data(), {}, {});
            }
        }
        parallel_for(0, std::int64_t(work.size()), 1, [&](std::int64_t w0, std::int64_t w1) {
            for (auto k = std::size_t(w0); k < std::size_t(w1); ++k) {
                const Work& w = work[k];
                const lod::Chunk& c = chunks[w.chunk];
                const double skirt =
                    skirts ? lod::skirt_depth(c, w.rows, w.columns, width, height, levels, cell, scale) : 0.0;
                const lod::Mesh mesh = lod::chunk_mesh(c, w.area, width, height, cell, scale, skirt);
                const int tw = std::max(1, std::min(texture, 2 * (c.x1 - c.x0)));
                const int th = std::max(1, std::min(texture, 2 * (c.y1 - c.y0)));
                const std::vector<std::uint8_t> png =
                    encode_rgba_png(lod::chunk_texture(c, w.area, cell, lo, hi, tw, th), tw, th, 1);  // fastest level
                gltf::MeshData data{mesh.positions, mesh.normals, mesh.texcoords, mesh.indices, mesh.min, mesh.max};
                const std::string name = c.file.substr(0, c.file.size() - 4);
                gltf::write_mesh(data, png, lod::translation(c, cell), name, targets[first + k]);
                float* out = &info[w.chunk * kInfo];
                out[0] = float(lod::deviation(c, w.area, width, height, scale));
                for (int a = 0; a < 3; ++a)
                    out[1 + a] = mesh.min[std::size_t(a)], out[4 + a] = mesh.max[std::size_t(a)];
            }
        });
        ctx.progress(double(std::min(end, mine.size())) / double(std::max<std::size_t>(mine.size(), 1)));
    }
    if (tiling) tiling->reduce(std::span<float>(info), Tiling::Reduce::max);
    if (rank != 0) return {};
    std::vector<lod::Written> written(chunks.size());
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        const float* in = &info[i * kInfo];
        written[i].deviation = double(in[0]);
        for (int a = 0; a < 3; ++a)
            written[i].min[std::size_t(a)] = in[1 + a], written[i].max[std::size_t(a)] = in[4 + a];
    }
    const std::string json = lod::tileset_json(chunks, written, width, height, tile_size, cell, scale);
    write_file_atomically(ctx.output_path(index_path.string()),
                          {reinterpret_cast<const std::uint8_t*>(json.data()), json.size()});
    std::size_t top = 0;
    for (const lod::Chunk& c : chunks) top += c.level == 0;
    ctx.info("wrote " + std::to_string(chunks.size()) + " glTF chunks in " + std::to_string(levels) + " levels (" +
             std::to_string(top) + " at full resolution) and the 3D Tiles tileset " + index_path.string());
    return {};
}

NodeOutputs run(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    // In a tiled (MPI) run the heightmap is this rank's tile of the grid; each rank writes the engine tiles
    // whose middle lies in its tile, rank 0 the index and the VRTs (the same files, bytes and names
    // as one process writes).
    Tiling* tiling = ctx.tiling();
    const int rank = tiling ? tiling->rank() : 0;
    const Format format = format_named(ctx.text("format"));
    if (format == Format::glb) return run_pyramid(ctx, hm, tiling);
    const int tile_size = int(ctx.integer("tile_size"));
    const std::filesystem::path index_path = ctx.text("path");
    const std::string stem = index_path.stem().string();
    const std::filesystem::path folder = index_path.parent_path();

    Index index;
    index.format = format;
    index.width = tiling ? tiling->grid_width() : hm.width();
    index.height = tiling ? tiling->grid_height() : hm.height();
    index.tile_size = tile_size;
    index.cell = hm.cell();
    if (ctx.real("low") != 0.0 || ctx.real("high") != 0.0) {
        index.range = formats::raw::Range{ctx.real("low"), ctx.real("high")};
    } else {
        index.range = formats::raw::min_max(hm.view());
        if (tiling) {  // the whole grid's (float minima and maxima are exact in any order)
            float lo = float(index.range.low), hi = float(index.range.high);
            lo = tiling->reduce(lo, Tiling::Reduce::min);
            hi = tiling->reduce(hi, Tiling::Reduce::max);
            index.range = {double(lo), double(hi)};
        }
    }
    index.tiles = layout(index.width, index.height, tile_size, stem, format);
    const Tile& last = index.tiles.back();
    const bool one_small = index.tiles.size() == 1 && (last.width != tile_size || last.height != tile_size);
    if (one_small)
        ctx.warn("the grid (" + std::to_string(last.width) + " × " + std::to_string(last.height) +
                 " samples) is smaller than one tile of " + std::to_string(tile_size) +
                 ", so it is written as one tile of its own size; a smaller tile_size cuts it into tiles");
    else if (last.width != tile_size || last.height != tile_size)
        ctx.warn("the last tiles are " + std::to_string(last.width) + " × " + std::to_string(last.height) +
                 " samples where the others are " + std::to_string(tile_size) + "; for equal tiles use a grid of k·" +
                 std::to_string(tile_size - 1) + " + 1 samples a side");

    // This rank's engine tiles (those whose middle sample lies in its tile: the ranks get about equal shares
    // even when the engine tiles are nearly as large as theirs), and the samples they cover (`box`, fetched
    // from the ranks that hold them).
    std::vector<Tile> mine;
    for (const Tile& t : index.tiles)
        if (!tiling || tiling->rank_at(t.x0 + (t.width - 1) / 2, t.y0 + (t.height - 1) / 2) == rank) mine.push_back(t);
    TileRect box{};
    if (!mine.empty()) {
        int x0 = index.width, y0 = index.height, x1 = 0, y1 = 0;
        for (const Tile& t : mine) {
            x0 = std::min(x0, t.x0), y0 = std::min(y0, t.y0);
            x1 = std::max(x1, t.x0 + t.width), y1 = std::max(y1, t.y0 + t.height);
        }
        box = {x0, y0, x1 - x0, y1 - y0};
    }
    std::vector<float> fetched;
    if (tiling) fetched = tiling->fetch(hm.heights().data(), box);
    const ConstGridView grid = tiling ? ConstGridView{fetched.data(), box.width, box.height, hm.cell()} : hm.view();
    for (Tile& t : mine) t.x0 -= box.x0, t.y0 -= box.y0;  // now within `grid` (box is the whole grid for one process)

    // Where each file goes (the kernel's bookkeeping, on this thread), then the tiles encoded and written in
    // parallel: each tile's bytes depend on its samples only, so the files are the same on any thread count.
    std::vector<std::filesystem::path> targets;
    for (const Tile& t : mine) targets.push_back(ctx.output_path((folder / t.file).string()));
    const bool vrt = ctx.flag("vrt");
    std::vector<std::filesystem::path> raw_vrts;  // rank 0 writes them all (text, a few hundred bytes each)
    if (vrt && format != Format::png16 && rank == 0)
        for (const Tile& t : index.tiles) raw_vrts.push_back(ctx.output_path((folder / (t.file + ".vrt")).string()));
    const int level = int(ctx.integer("compression"));
    std::vector<std::size_t> clamped(mine.size(), 0);
    std::size_t done = 0;
    for (std::size_t first = 0; first < mine.size(); first += 8) {  // in groups, for progress and Ctrl-C
        ctx.check_cancelled();
        const std::size_t end = std::min(first + 8, mine.size());
        parallel_for(std::int64_t(first), std::int64_t(end), 1, [&](std::int64_t i0, std::int64_t i1) {
            for (std::int64_t i = i0; i < i1; ++i) {
                const Tile& t = mine[std::size_t(i)];
                const std::vector<float> samples = cut(grid, t);
                const ConstGridView view{samples.data(), t.width, t.height, hm.cell()};
                AtomicFile file(targets[std::size_t(i)]);
                if (format == Format::r32) {
                    std::vector<std::uint8_t> bytes(samples.size() * 4);
                    std::memcpy(bytes.data(), samples.data(), bytes.size());  // little-endian x86-64 and ARM
                    file.write(bytes);
                } else {
                    const std::vector<std::uint16_t> q =
                        formats::raw::quantize16(view, index.range, &clamped[std::size_t(i)]);
                    if (format == Format::png16) {
                        write_gray_png(file.stream(), t.width, t.height, 16, q, level);
                    } else {
                        std::vector<std::uint8_t> bytes(q.size() * 2);
                        for (std::size_t k = 0; k < q.size(); ++k) {
                            bytes[2 * k] = std::uint8_t(q[k] & 0xFF);
                            bytes[2 * k + 1] = std::uint8_t(q[k] >> 8);
                        }
                        file.write(bytes);
                    }
                }
                file.commit();
            }
        });
        done = end;
        ctx.progress(double(done) / double(mine.size()));
    }
    std::size_t outside = 0;
    for (std::size_t c : clamped) outside += c;
    if (tiling) outside = std::size_t(tiling->reduce(std::int64_t(outside), Tiling::Reduce::sum));
    if (outside > 0) ctx.warn(std::to_string(outside) + " samples lie outside low..high and were clamped to its ends");

    for (std::size_t i = 0; i < raw_vrts.size(); ++i) {
        const std::string text = raw_tile_vrt(index, index.tiles[i]);
        write_file_atomically(raw_vrts[i], {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    }
    if (rank != 0) return {};
    if (vrt) {
        const std::string text = mosaic_vrt(index);
        write_file_atomically(ctx.output_path((folder / (stem + ".vrt")).string()),
                              {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    }
    const std::string json = index_json(index);
    write_file_atomically(ctx.output_path(index_path.string()),
                          {reinterpret_cast<const std::uint8_t*>(json.data()), json.size()});
    // What was written, in the same words as the warning above: one tile of the grid's size, or the count.
    const std::string size = std::to_string(last.width) + " × " + std::to_string(last.height);
    ctx.info((one_small ? "wrote 1 tile of " + size + " samples"
                        : "wrote " + std::to_string(index.tiles.size()) +
                      (index.tiles.size() == 1 ? " tile" : " tiles") + " of " + std::to_string(tile_size) +
                      " samples (" + std::to_string(last.column + 1) + " × " + std::to_string(last.row + 1) + ")" +
                      (last.width != tile_size || last.height != tile_size ? ", the last ones " + size : "")) +
             ", " + index_path.string() + (vrt ? " and " + (folder / (stem + ".vrt")).string() : std::string()));
    return {};
}

}  // namespace

OROGEN_PLUGIN("export-tiles", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "tiles",
        .summary = "cut the heightmap into engine tiles (16-bit PNG or RAW) that share their edges, with a JSON index "
                   "and a GDAL VRT; or into glTF chunks in levels of detail with a 3D Tiles tileset",
        .description =
            "Tiles of tile_size samples a side start every tile_size - 1 samples, so neighbours share their edge row "
            "or column bit for bit (no seams in Unreal's World Partition or Unity's terrain tiles). Every tile uses "
            "one height scale (low..high, default the terrain's own range). Files <stem>_x<column>_y<row>.png "
            "(.r16, .r32) beside the index <stem>.json (sizes, cell, height scale, Unreal and Unity scale settings, "
            "every tile's place) and, with vrt=true, <stem>.vrt, which GDAL and QGIS open as the whole terrain "
            "(metres, through its offset and scale). Unreal sizes: 127, 253, 505, 1009, 2017, 4033; Unity: 2^n + 1. "
            "format=glb writes a chunked level-of-detail pyramid instead: level 0 the tiles at full resolution, each "
            "level above keeping every other sample of 2 x 2 chunks below it, up to one chunk; every chunk a textured "
            ".glb <stem>_l<level>_x<column>_y<row>.glb with skirts, and the index an OGC 3D Tiles 1.1 tileset "
            "(Cesium, Cesium for Unreal and Unity) with each chunk's geometric error.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to cut"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".json"}).help("the index; the tiles go beside it"),
                Param::choice("format", {"png16", "r16", "r32", "glb"}, "png16")
                    .help("png16: 16-bit grayscale PNG; r16: RAW unsigned 16-bit little-endian; r32: RAW float metres; "
                          "glb: textured glTF meshes in levels of detail, the index a 3D Tiles tileset"),
                Param::integer("tile_size", 505)
                    .min(2)
                    .max(65537)
                    .unit("samples")
                    .help("samples per tile side, the shared edge included (Unreal: 127, 253, 505, 1009, 2017, 4033)"),
                Param::real("low", 0.0)
                    .unit("m")
                    .help("height written as 0 (with high; both 0 = the terrain's lowest)"),
                Param::real("high", 0.0)
                    .unit("m")
                    .help("height written as 65535 (with low; both 0 = the terrain's highest)"),
                Param::boolean("vrt", true).help("also write <stem>.vrt, the tiles as one GDAL raster"),
                Param::integer("compression", 6).min(0).max(12).help("png16: deflate level (libdeflate), 0 to 12"),
                Param::real("scale", 1.0).min(0.0, true).help("glb: vertical exaggeration (heights × scale)"),
                Param::integer("texture", 512)
                    .min(1)
                    .max(8192)
                    .unit("pixels")
                    .help("glb: largest side of each chunk's colour texture"),
                Param::boolean("skirts", true)
                    .help("glb: hang a strip below each chunk's edges, deep enough to close the cracks where chunks of "
                          "different levels meet"),
            },
        .tile_halo = 0,  // tiled: each rank writes the engine tiles whose middle is in its tile
        .check = check,
        .run = run,
    });
}
