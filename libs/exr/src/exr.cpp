#include <orogen/exr/exr.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <openexr.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace orogen::exr {

Compression parse_compression(const std::string& name) {
    if (name == "none") return Compression::none;
    if (name == "rle") return Compression::rle;
    if (name == "zips") return Compression::zips;
    if (name == "zip") return Compression::zip;
    if (name == "piz") return Compression::piz;
    throw BadInput("unknown compression '" + name + "' (use zip, zips, piz, rle or none: the lossless ones)");
}

std::string channel_name_problem(const std::string& name) {
    if (name.empty()) return "a channel name cannot be empty";
    if (name.size() > 255)
        return "a channel name has at most 255 bytes, '" + name.substr(0, 40) + "...' has " +
            std::to_string(name.size());
    if (name.find('\0') != std::string::npos) return "a channel name cannot hold a NUL byte";
    return "";
}

// ------------------------------------------------------------------ write

void write(const fs::path& path, int width, int height, std::span<const Plane> planes, const WriteOptions& options) {
    if (width < 1 || height < 1) throw Error("cannot write an empty image as OpenEXR");
    if (planes.empty()) throw Error("an OpenEXR file needs at least one channel");
    Imf::Header header(width, height);  // data and display windows (0, 0)-(width - 1, height - 1)
    header.lineOrder() = Imf::INCREASING_Y;  // row 0, the north edge, first
    switch (options.compression) {
        case Compression::none: header.compression() = Imf::NO_COMPRESSION; break;
        case Compression::rle: header.compression() = Imf::RLE_COMPRESSION; break;
        case Compression::zips: header.compression() = Imf::ZIPS_COMPRESSION; break;
        case Compression::zip: header.compression() = Imf::ZIP_COMPRESSION; break;
        case Compression::piz: header.compression() = Imf::PIZ_COMPRESSION; break;
    }
    header.insert("cellSize", Imf::DoubleAttribute(options.cell));
    header.insert("heightUnits", Imf::StringAttribute("m"));
    if (!options.layer.empty()) header.insert("orogenLayer", Imf::StringAttribute(options.layer));
    Imf::FrameBuffer frame;
    const std::size_t row = std::size_t(width) * sizeof(float);
    for (const Plane& p : planes) {
        if (const std::string problem = channel_name_problem(p.channel); !problem.empty()) throw BadInput(problem);
        if (header.channels().findChannel(p.channel))
            throw BadInput("two channels are named '" + p.channel + "'; an OpenEXR file's channel names are distinct");
        header.channels().insert(p.channel, Imf::Channel(Imf::FLOAT));
        // The heightmap's own rows: nothing is copied.
        frame.insert(p.channel,
                     Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(p.data)), sizeof(float), row));
    }
    try {
        // Blocks are compressed on OpenEXR's process-wide pool, grown (never shrunk) to what is asked for; they
        // are written in row order whatever the thread count, so the bytes do not depend on it (tested).
        const int threads = std::clamp(options.threads, 1, 256);
        if (threads > 1) {
            static std::mutex pool;
            const std::lock_guard lock(pool);
            if (Imf::globalThreadCount() < threads) Imf::setGlobalThreadCount(threads);
        }
        Imf::OutputFile file(path.c_str(), header, threads > 1 ? threads : 0);
        file.setFrameBuffer(frame);
        file.writePixels(height);
    } catch (const std::exception& e) { throw Error("OpenEXR could not write " + path.string() + ": " + e.what()); }
}

// ------------------------------------------------------------------- read

std::string to_string(SampleType type) {
    switch (type) {
        case SampleType::uint32: return "32-bit unsigned integer";
        case SampleType::half: return "16-bit float (half)";
        case SampleType::float32: return "32-bit float";
    }
    return "?";
}

const ChannelInfo* FileInfo::find(const std::string& name) const {
    for (const auto& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

std::string FileInfo::channel_list() const {
    std::string s;
    for (const auto& c : channels) s += (s.empty() ? "" : ", ") + c.name;
    return s.empty() ? "none" : s;
}

namespace {

// OpenEXRCore calls back without a way to pass our state to the allocator, and always on the calling
// thread (we never hand it threads): the cap on one allocation and the latest message are per thread.
thread_local std::size_t alloc_cap = std::numeric_limits<std::size_t>::max();
thread_local std::string last_message;

void* capped_alloc(std::size_t bytes) { return bytes > alloc_cap ? nullptr : std::malloc(bytes); }
void plain_free(void* p) { std::free(p); }

void on_error(exr_const_context_t, exr_result_t code, const char* message) {
    last_message = message && *message ? message : exr_get_default_error_message(code);
}

/// Sets alloc_cap for a scope.
class AllocCap {
public:
    explicit AllocCap(std::size_t cap) : saved_(alloc_cap) { alloc_cap = cap; }
    ~AllocCap() { alloc_cap = saved_; }
    AllocCap(const AllocCap&) = delete;
    AllocCap& operator=(const AllocCap&) = delete;

private:
    std::size_t saved_;
};

/// The bytes to read: a file (by descriptor, read with pread) or a buffer.
struct Source {
    std::string name;
    int fd = -1;
    std::span<const std::uint8_t> bytes;
    std::uint64_t size = 0;
    ~Source() {
        if (fd >= 0) ::close(fd);
    }
};

std::int64_t source_read(exr_const_context_t, void* user, void* buffer, std::uint64_t want, std::uint64_t offset,
                         exr_stream_error_func_ptr_t) {
    const auto* s = static_cast<const Source*>(user);
    if (offset >= s->size) return 0;
    const std::uint64_t n = std::min<std::uint64_t>(want, s->size - offset);
    if (s->fd < 0) {
        std::memcpy(buffer, s->bytes.data() + offset, n);
        return std::int64_t(n);
    }
    std::uint64_t done = 0;
    while (done < n) {
        const ssize_t r = ::pread(s->fd, static_cast<char*>(buffer) + done, n - done, off_t(offset + done));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;
        done += std::uint64_t(r);
    }
    return done == 0 && n > 0 ? -1 : std::int64_t(done);
}

std::int64_t source_size(exr_const_context_t, void* user) {
    return std::int64_t(static_cast<const Source*>(user)->size);
}

void open_file(Source& s, const fs::path& path) {
    s.name = path.string();
    if (const std::string problem = regular_file_problem(path); !problem.empty())
        throw BadInput("cannot read " + s.name + ": it " + problem);
    s.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    struct stat st {};
    if (s.fd < 0 || ::fstat(s.fd, &st) != 0) throw BadInput("cannot read " + s.name + ": " + std::strerror(errno));
    s.size = std::uint64_t(st.st_size);
}

struct Context {
    exr_context_t ctx = nullptr;
    Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    ~Context() {
        if (ctx) exr_finish(&ctx);
    }
};

struct Decoder {
    exr_const_context_t ctx = nullptr;
    exr_decode_pipeline_t pipe = EXR_DECODE_PIPELINE_INITIALIZER;
    Decoder() = default;
    Decoder(const Decoder&) = delete;
    Decoder& operator=(const Decoder&) = delete;
    ~Decoder() {
        if (ctx && pipe.channels) exr_decoding_destroy(ctx, &pipe);
    }
};

constexpr std::uint8_t kMagic[4] = {0x76, 0x2f, 0x31, 0x01};

const char* compression_name(exr_compression_t c) {
    switch (c) {
        case EXR_COMPRESSION_NONE: return "none";
        case EXR_COMPRESSION_RLE: return "rle";
        case EXR_COMPRESSION_ZIPS: return "zips";
        case EXR_COMPRESSION_ZIP: return "zip";
        case EXR_COMPRESSION_PIZ: return "piz";
        case EXR_COMPRESSION_PXR24: return "pxr24";
        case EXR_COMPRESSION_B44: return "b44";
        case EXR_COMPRESSION_B44A: return "b44a";
        case EXR_COMPRESSION_DWAA: return "dwaa";
        case EXR_COMPRESSION_DWAB: return "dwab";
        default: return "unknown";
    }
}

/// The most a chunk can decompress to per stored byte: deflate at most 1032:1, EXR's RLE 128 bytes in 2,
/// PIZ's Huffman coding with run lengths about 410:1 (a run of at most 255 16-bit symbols in 10 bits).
std::uint64_t max_ratio(exr_compression_t c) {
    switch (c) {
        case EXR_COMPRESSION_NONE: return 1;
        case EXR_COMPRESSION_RLE: return 64;
        case EXR_COMPRESSION_ZIPS:
        case EXR_COMPRESSION_ZIP: return 1032;
        case EXR_COMPRESSION_PIZ: return 512;
        default: return 0;
    }
}

struct Chunk {
    exr_chunk_info_t info;
    int x = 0, y = 0;  ///< its first sample, relative to the data window
};

/// An opened, checked file: the context, what it declares, its chunks (level 0) and which channels to read.
struct Opened {
    Context context;
    FileInfo info;
    std::vector<Chunk> chunks;
    std::vector<std::string> wanted;  ///< the height channel, then the layers
    std::uint64_t largest_chunk = 0;  ///< bytes, packed or unpacked
};

[[noreturn]] void refuse(const Source& s, const std::string& what) {
    throw BadInput("cannot read " + s.name + ": " + what);
}

std::string core_message(exr_result_t rv) {
    std::string m = last_message.empty() ? exr_get_default_error_message(rv) : last_message;
    last_message.clear();
    return m;
}

void require_channel(const Source& s, const FileInfo& info, const std::string& name, const char* param) {
    const ChannelInfo* c = info.find(name);
    if (!c) {
        throw ChannelError("cannot read " + s.name + ": it has no channel '" + name +
                               "' (its channels are: " + info.channel_list() + "); give " + param + "=NAME",
                           param);
    }
    if (c->type == SampleType::uint32)
        throw ChannelError("cannot read " + s.name + ": channel '" + name + "' holds " + to_string(c->type) +
                               "s; import:exr reads 32-bit or 16-bit float channels",
                           param);
    if (c->x_sampling != 1 || c->y_sampling != 1)
        throw ChannelError("cannot read " + s.name + ": channel '" + name + "' is subsampled (" +
                               std::to_string(c->x_sampling) + "x" + std::to_string(c->y_sampling) +
                               "); import:exr reads channels with a sample at every pixel",
                           param);
}

/// The magic number, then OpenEXRCore's context over `s` with allocations capped by the file's size.
void start_reading(Source& s, Opened& o) {
    // The magic number first, for a clear word on a file that is not an EXR at all.
    std::uint8_t head[4] = {};
    if (s.size < 8 || source_read(nullptr, &s, head, 4, 0, nullptr) != 4 || std::memcmp(head, kMagic, 4) != 0)
        refuse(s, "it is not an OpenEXR file (it does not begin with the EXR magic number 76 2f 31 01)");

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.alloc_fn = capped_alloc;
    init.free_fn = plain_free;
    init.user_data = &s;
    init.read_fn = source_read;
    init.size_fn = source_size;
    init.max_image_width = init.max_image_height = 1 << 24;
    init.max_tile_width = init.max_tile_height = 1 << 16;
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    last_message.clear();
    {
        // Nothing in a header is bigger than the file it is in.
        AllocCap cap(std::size_t(s.size) + (1u << 16));
        const exr_result_t rv = exr_start_read(&o.context.ctx, s.name.c_str(), &init);
        if (rv != EXR_ERR_SUCCESS)
            refuse(s, "its header is damaged or not one OpenEXR reads (OpenEXR: " + core_message(rv) + ")");
    }
}

/// One flat part, its data window, channel list, compression and the attributes export:exr writes, into
/// o.info. Returns the storage (scanline or tiled).
exr_storage_t read_header(Source& s, Opened& o) {
    exr_const_context_t ctx = o.context.ctx;
    int parts = 0;
    exr_get_count(ctx, &parts);
    if (parts != 1)
        refuse(s,
               "it has " + std::to_string(parts) +
                   " parts; import:exr reads single-part files (split it with "
                   "exrmultipart -separate)");
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_get_storage(ctx, 0, &storage);
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        refuse(s, "it holds deep data (several samples a pixel); import:exr reads flat scanline or tiled images");
    o.info.tiled = storage == EXR_STORAGE_TILED;

    exr_attr_box2i_t window{};
    if (exr_result_t rv = exr_get_data_window(ctx, 0, &window); rv != EXR_ERR_SUCCESS)
        refuse(s, "it has no data window (OpenEXR: " + core_message(rv) + ")");
    const std::int64_t w = std::int64_t(window.max.x) - window.min.x + 1;
    const std::int64_t h = std::int64_t(window.max.y) - window.min.y + 1;
    if (w < 1 || h < 1 || w > 1000000 || h > 1000000)
        refuse(s,
               "its data window is " + std::to_string(w) + "x" + std::to_string(h) +
                   " samples; a heightmap has 1 to 1000000 on each side");
    o.info.width = int(w);
    o.info.height = int(h);

    const exr_attr_chlist_t* list = nullptr;
    if (exr_result_t rv = exr_get_channels(ctx, 0, &list); rv != EXR_ERR_SUCCESS || !list)
        refuse(s, "it has no channel list (OpenEXR: " + core_message(rv) + ")");
    for (int i = 0; i < list->num_channels; ++i) {
        const exr_attr_chlist_entry_t& e = list->entries[i];
        ChannelInfo c;
        c.name.assign(e.name.str ? e.name.str : "", e.name.str ? std::size_t(std::max(e.name.length, 0)) : 0);
        c.type = e.pixel_type == EXR_PIXEL_UINT ? SampleType::uint32
            : e.pixel_type == EXR_PIXEL_HALF    ? SampleType::half
                                                : SampleType::float32;
        c.x_sampling = e.x_sampling;
        c.y_sampling = e.y_sampling;
        o.info.channels.push_back(std::move(c));
    }

    exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
    exr_get_compression(ctx, 0, &compression);
    o.info.compression = compression_name(compression);
    if (max_ratio(compression) == 0)
        refuse(s,
               "it is compressed with " + o.info.compression +
                   ", which import:exr does not read (it reads the lossless none, rle, zips, zip and piz, so "
                   "heights come back bit for bit); save it again with one of those, e.g. exrmaketiled -z zip "
                   "IN.exr OUT.exr");

    // The custom attributes export:exr writes.
    const exr_attribute_t* attr = nullptr;
    if (exr_get_attribute_by_name(ctx, 0, "cellSize", &attr) == EXR_ERR_SUCCESS && attr) {
        double cell = std::numeric_limits<double>::quiet_NaN();
        if (attr->type == EXR_ATTR_DOUBLE) cell = attr->d;
        else if (attr->type == EXR_ATTR_FLOAT) cell = attr->f;
        if (!(std::isfinite(cell) && cell > 0.0 && cell <= 1e6))
            refuse(s,
                   "its cellSize attribute must be a number of metres above 0 and at most 1e6 (a double); give "
                   "cell=METRES to override it");
        o.info.cell = cell;
    }
    if (exr_get_attribute_by_name(ctx, 0, "heightUnits", &attr) == EXR_ERR_SUCCESS && attr &&
        attr->type == EXR_ATTR_STRING && attr->string && attr->string->str)
        o.info.height_units.assign(attr->string->str, std::size_t(std::max(attr->string->length, 0)));

    return storage;
}

/// The channels to read into o.wanted: the heights' channel first, then the layers asked for.
void choose_channels(const Source& s, const ReadOptions& options, Opened& o) {
    // What to read.
    require_channel(s, o.info, options.channel, "channel");
    o.wanted.push_back(options.channel);
    if (options.all_layers) {
        for (const auto& c : o.info.channels)
            if (c.name != options.channel && c.type != SampleType::uint32 && c.x_sampling == 1 && c.y_sampling == 1)
                o.wanted.push_back(c.name);
    } else {
        for (const auto& name : options.layers) {
            if (name == options.channel)
                throw ChannelError("cannot read " + s.name + ": channel '" + name +
                                       "' is already read as the heights; name other channels in layers",
                                   "layers");
            if (std::find(o.wanted.begin(), o.wanted.end(), name) != o.wanted.end())
                throw ChannelError("cannot read " + s.name + ": layers names channel '" + name + "' twice", "layers");
            require_channel(s, o.info, name, "layers");
            o.wanted.push_back(name);
        }
    }
}

/// The memory budget: one heightmap, and all the wanted channels together.
void check_budget(Source& s, const Opened& o) {
    const std::int64_t w = o.info.width, h = o.info.height;
    // The memory budget: one heightmap, and all of them together.
    if (const std::string problem = heightmap_memory_problem(double(w), double(h)); !problem.empty())
        refuse(s, "its data window is " + std::to_string(w) + "x" + std::to_string(h) + " samples, which " + problem);
    if (o.wanted.size() > 1) {
        const double total = double(w) * double(h) * 4.0 * double(o.wanted.size());
        if (total > double(heightmap_memory_limit()))
            refuse(s,
                   "its " + std::to_string(o.wanted.size()) + " channels to read (the heights and " +
                       std::to_string(o.wanted.size() - 1) + " layers) need " + human_bytes(total) +
                       ", more than the " + human_bytes(double(heightmap_memory_limit())) +
                       " allowed here; read fewer layers");
    }
}

/// The chunks of the full-resolution level into o.chunks: each inside the file, none overlapping another,
/// each stored big enough for what it decompresses to.
void index_chunks(Source& s, exr_storage_t storage, Opened& o) {
    exr_const_context_t ctx = o.context.ctx;
    const std::int64_t w = o.info.width, h = o.info.height;
    exr_attr_box2i_t window{};
    exr_get_data_window(ctx, 0, &window);
    std::int32_t chunk_count = 0;
    if (exr_result_t rv = exr_get_chunk_count(ctx, 0, &chunk_count); rv != EXR_ERR_SUCCESS || chunk_count < 1)
        refuse(s, "it declares no image data (OpenEXR: " + core_message(rv) + ")");
    if (std::uint64_t(chunk_count) * 8 > s.size)
        refuse(s,
               "it is truncated: its " + std::to_string(chunk_count) + " chunks' offset table alone needs " +
                   human_bytes(double(chunk_count) * 8) + ", and the file has " + human_bytes(double(s.size)));
    AllocCap cap(std::size_t(s.size) + (1u << 16));
    auto add_chunk = [&](exr_result_t rv, const exr_chunk_info_t& ci, std::int64_t x, std::int64_t y) {
        if (rv != EXR_ERR_SUCCESS)
            refuse(s,
                   "it is truncated or damaged: chunk " + std::to_string(o.chunks.size() + 1) + " of its image " +
                       "cannot be read (OpenEXR: " + core_message(rv) + ")");
        if (ci.data_offset > s.size || ci.packed_size > s.size - ci.data_offset)
            refuse(s, "it is truncated: chunk " + std::to_string(o.chunks.size() + 1) + " runs past its end");
        const std::uint64_t ratio = max_ratio(exr_compression_t(ci.compression));
        if (ratio == 0 || ci.unpacked_size > ci.packed_size * ratio + 64)
            refuse(s,
                   "it is damaged: chunk " + std::to_string(o.chunks.size() + 1) + " claims to hold " +
                       human_bytes(double(ci.unpacked_size)) + " in " + human_bytes(double(ci.packed_size)) +
                       ", more than " + o.info.compression + " compression can");
        o.largest_chunk = std::max({o.largest_chunk, ci.unpacked_size, ci.packed_size});
        o.chunks.push_back({ci, int(x), int(y)});
    };
    if (storage == EXR_STORAGE_SCANLINE) {
        std::int32_t lines = 0;
        if (exr_result_t rv = exr_get_scanlines_per_chunk(ctx, 0, &lines); rv != EXR_ERR_SUCCESS || lines < 1)
            refuse(s, "its lines per chunk are unknown (OpenEXR: " + core_message(rv) + ")");
        for (std::int64_t y = 0; y < h; y += lines) {
            exr_chunk_info_t ci{};
            add_chunk(exr_read_scanline_chunk_info(ctx, 0, int(window.min.y + y), &ci), ci, 0, y);
            if (ci.width != w || ci.height < 1 || ci.height > h - y)
                refuse(s, "it is damaged: chunk " + std::to_string(o.chunks.size()) + " does not cover whole rows");
        }
    } else {
        std::int32_t lw = 0, lh = 0, tw = 0, th = 0;
        if (exr_result_t rv = exr_get_level_sizes(ctx, 0, 0, 0, &lw, &lh); rv != EXR_ERR_SUCCESS || lw != w || lh != h)
            refuse(s, "its tile levels do not match its data window (OpenEXR: " + core_message(rv) + ")");
        if (exr_result_t rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th); rv != EXR_ERR_SUCCESS || tw < 1 || th < 1)
            refuse(s, "its tile size is unknown (OpenEXR: " + core_message(rv) + ")");
        for (std::int64_t y = 0, ty = 0; y < h; y += th, ++ty)
            for (std::int64_t x = 0, tx = 0; x < w; x += tw, ++tx) {
                exr_chunk_info_t ci{};
                add_chunk(exr_read_tile_chunk_info(ctx, 0, int(tx), int(ty), 0, 0, &ci), ci, x, y);
                if (ci.width != std::min<std::int64_t>(tw, w - x) || ci.height != std::min<std::int64_t>(th, h - y))
                    refuse(s,
                           "it is damaged: tile (" + std::to_string(tx) + ", " + std::to_string(ty) +
                               ") is not the size its tiling says");
            }
    }
    std::vector<std::pair<std::uint64_t, std::uint64_t>> spans;
    spans.reserve(o.chunks.size());
    for (const auto& c : o.chunks) spans.emplace_back(c.info.data_offset, c.info.packed_size);
    std::sort(spans.begin(), spans.end());
    for (std::size_t i = 1; i < spans.size(); ++i)
        if (spans[i - 1].first + spans[i - 1].second > spans[i].first)
            refuse(s,
                   "it is damaged: two chunks of its image share the same bytes (at offset " +
                       std::to_string(spans[i].first) + ")");
}

void open_checked(Source& s, const ReadOptions& options, Opened& o) {
    start_reading(s, o);
    const exr_storage_t storage = read_header(s, o);
    choose_channels(s, options, o);
    check_budget(s, o);
    index_chunks(s, storage, o);
}

/// Decodes chunk `c` into its rows of `planes` (the wanted channels, `w` samples a row) with `dec`, set up on
/// its first chunk and updated after. Throws orogen::BadInput naming the chunk.
void decode_chunk(const Source& s, const Opened& o, const Chunk& c, Decoder& dec,
                  std::vector<std::vector<float>>& planes, int w) {
    exr_const_context_t ctx = dec.ctx;
    exr_result_t rv = dec.pipe.channels ? exr_decoding_update(ctx, 0, &c.info, &dec.pipe)
                                        : exr_decoding_initialize(ctx, 0, &c.info, &dec.pipe);
    if (rv != EXR_ERR_SUCCESS)
        refuse(s, "chunk at row " + std::to_string(c.y) + " cannot be decoded (OpenEXR: " + core_message(rv) + ")");
    const bool first = dec.pipe.unpack_and_convert_fn == nullptr;
    for (int k = 0; k < dec.pipe.channel_count; ++k) {
        exr_coding_channel_info_t& out = dec.pipe.channels[k];
        out.decode_to_ptr = nullptr;
        const auto it = std::find(o.wanted.begin(), o.wanted.end(), std::string(out.channel_name));
        if (it == o.wanted.end()) continue;
        if (out.width != c.info.width || out.height != c.info.height)
            refuse(s, "it is damaged: channel '" + *it + "' does not fill its chunks");
        out.decode_to_ptr = reinterpret_cast<std::uint8_t*>(planes[std::size_t(it - o.wanted.begin())].data() +
                                                            std::size_t(c.y) * std::size_t(w) + std::size_t(c.x));
        out.user_pixel_stride = sizeof(float);
        out.user_line_stride = std::int32_t(std::size_t(w) * sizeof(float));
        out.user_bytes_per_element = sizeof(float);
        out.user_data_type = EXR_PIXEL_FLOAT;
    }
    if (first) {
        rv = exr_decoding_choose_default_routines(ctx, 0, &dec.pipe);
        if (rv != EXR_ERR_SUCCESS) refuse(s, "its channels cannot be decoded (OpenEXR: " + core_message(rv) + ")");
    }
    rv = exr_decoding_run(ctx, 0, &dec.pipe);
    if (rv != EXR_ERR_SUCCESS)
        refuse(s,
               "it is damaged: the chunk at row " + std::to_string(c.y) + ", column " + std::to_string(c.x) +
                   " does not decode (OpenEXR: " + core_message(rv) + ")");
}

std::shared_ptr<Heightmap> read_source(Source& s, const ReadOptions& options) {
    Opened o;
    open_checked(s, options, o);
    double cell = options.cell;
    if (cell <= 0.0) {
        if (!o.info.cell) refuse(s, "it has no cellSize attribute to take a cell size from; give cell=METRES");
        cell = *o.info.cell;
    }
    const int w = o.info.width, h = o.info.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    std::vector<std::vector<float>> planes(o.wanted.size());
    for (auto& p : planes) p.resize(n);  // every sample is written below: each chunk's rows are decoded in full

    // The chunks decode in parallel, each worker with its own pipeline (OpenEXRCore reads one context from
    // several threads; source_read is pread or memcpy). Each writes its own rows of the planes; a damaged
    // chunk is reported by the lowest index, so the message does not depend on the threads.
    exr_const_context_t ctx = o.context.ctx;
    std::mutex failure_mutex;
    std::size_t failed_at = o.chunks.size();
    std::string failure;
    auto decode = [&](std::int64_t lo, std::int64_t hi) {
        // OpenEXR's buffers for one chunk at a time (packed, unpacked and the codec's scratch).
        AllocCap cap(std::size_t(o.largest_chunk) * 2 + (1u << 22));
        Decoder dec;
        dec.ctx = ctx;
        for (std::int64_t i = lo; i < hi; ++i) {
            const Chunk& c = o.chunks[std::size_t(i)];
            try {
                decode_chunk(s, o, c, dec, planes, w);
            } catch (const BadInput& e) {
                const std::lock_guard lock(failure_mutex);
                if (std::size_t(i) < failed_at) {
                    failed_at = std::size_t(i);
                    failure = e.what();
                }
                // A pipeline that failed half way is not reused.
                if (dec.pipe.channels) exr_decoding_destroy(ctx, &dec.pipe);
                dec.pipe = EXR_DECODE_PIPELINE_INITIALIZER;
            }
        }
    };
    // Small images (and the fuzz target's) on this thread: waking workers would cost more than it saves.
    if (o.chunks.size() >= 8 && n * planes.size() >= (std::size_t(1) << 20))
        parallel_for(0, std::int64_t(o.chunks.size()), 1, decode);
    else decode(0, std::int64_t(o.chunks.size()));
    if (failed_at < o.chunks.size()) throw BadInput(failure);

    for (std::size_t p = 0; p < planes.size(); ++p) {
        const auto bad = std::find_if(planes[p].begin(), planes[p].end(), [](float v) { return !std::isfinite(v); });
        if (bad != planes[p].end()) {
            const std::size_t i = std::size_t(bad - planes[p].begin());
            refuse(s,
                   "sample (" + std::to_string(i % std::size_t(w)) + ", " + std::to_string(i / std::size_t(w)) +
                       ") of channel '" + o.wanted[p] + "' is " + (std::isnan(*bad) ? "NaN" : "infinite") +
                       "; heights and layers must be finite numbers");
        }
    }
    auto hm = std::make_shared<Heightmap>(w, h, cell, std::move(planes[0]));
    for (std::size_t p = 1; p < planes.size(); ++p) hm->set_layer(o.wanted[p], std::move(planes[p]));
    return hm;
}

}  // namespace

ChannelError::ChannelError(std::string message, std::string param_name)
    : BadInput(std::move(message)), param(std::move(param_name)) {}

FileInfo probe(const fs::path& path, const ReadOptions& options) {
    Source s;
    open_file(s, path);
    Opened o;
    open_checked(s, options, o);
    return o.info;
}

std::shared_ptr<Heightmap> read(const fs::path& path, const ReadOptions& options) {
    Source s;
    open_file(s, path);
    return read_source(s, options);
}

FileInfo probe_bytes(std::span<const std::uint8_t> bytes, const std::string& name, const ReadOptions& options) {
    Source s;
    s.name = name;
    s.bytes = bytes;
    s.size = bytes.size();
    Opened o;
    open_checked(s, options, o);
    return o.info;
}

std::shared_ptr<Heightmap> read_bytes(std::span<const std::uint8_t> bytes, const std::string& name,
                                      const ReadOptions& options) {
    Source s;
    s.name = name;
    s.bytes = bytes;
    s.size = bytes.size();
    return read_source(s, options);
}

}  // namespace orogen::exr
